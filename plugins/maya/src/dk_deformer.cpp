#include "dk_deformer.h"

#include <algorithm>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <maya/MAngle.h>
#include <maya/MDagModifier.h>
#include <maya/MDistance.h>
#include <maya/MFloatArray.h>
#include <maya/MFnCompoundAttribute.h>
#include <maya/MFnDependencyNode.h>
#include <maya/MFnEnumAttribute.h>
#include <maya/MFnMatrixAttribute.h>
#include <maya/MFnMesh.h>
#include <maya/MFnNumericAttribute.h>
#include <maya/MFnNurbsCurve.h>
#include <maya/MFnTypedAttribute.h>
#include <maya/MGlobal.h>
#include <maya/MIntArray.h>
#include <maya/MPlug.h>
#include <maya/MPointArray.h>
#include <maya/MRampAttribute.h>

#include "deformkit/error.h"
#include "maya_mesh.h"

namespace deformkit::maya {

namespace {

// Maya's error for a node: the message in the Script Editor, the output left as its input.
MStatus report(const MPxNode& node, const std::string& message) {
    MGlobal::displayError(MString(node.name()) + ": " + message.c_str());
    return MS::kFailure;
}

MayaMatrix matrixValue(MDataBlock& block, const MObject& attribute) {
    return toMaya(block.inputValue(attribute).asMatrix());
}

glm::dvec3 translation(const MayaMatrix& m) {
    return {m.m[3][0], m.m[3][1], m.m[3][2]};
}

geom::Mesh meshOf(const MObject& data, const std::string& what) {
    return geom::Mesh(meshDataOf(data, false), what);
}

// A NURBS curve as a wire takes it: `samples` points at evenly spaced parameters over its knot domain
// (0: four per CV, at least 16), so the wire follows the curve, not its control hull; in world space, as
// appendPoints reads cages. A rest curve and its
// current copy are sampled at the same parameters, so their points correspond.
void appendCurvePoints(const MObject& data, int samples, std::vector<glm::dvec3>& out) {
    if (!data.hasFn(MFn::kNurbsCurve)) return;
    const MFnNurbsCurve curve(data);
    const int n = samples > 1 ? samples : std::max(16, 4 * curve.numCVs());
    double start = 0.0, end = 1.0;
    curve.getKnotDomain(start, end);
    MPoint p;
    for (int i = 0; i < n; ++i) {
        curve.getPointAtParam(start + (end - start) * static_cast<double>(i) / (n - 1), p, MSpace::kWorld);
        out.emplace_back(p.x, p.y, p.z);
    }
}

// A mesh's points appended to `out`, read through `scratch` (both kept by the node). Cages and curves come
// from world-space plugs (worldMesh[0], worldSpace[0]), whose data holds the shape's points and its world
// matrix: read in MSpace::kWorld, as cvwrap reads its driver, the matrix is applied (data without one reads
// as its points).
void appendPoints(const MObject& data, MPointArray& scratch, std::vector<glm::dvec3>& out) {
    if (data.hasFn(MFn::kMesh)) {
        MFnMesh(data).getPoints(scratch, MSpace::kWorld);
    } else {
        scratch.clear();
    }
    for (unsigned i = 0; i < scratch.length(); ++i)
        out.emplace_back(scratch[i].x, scratch[i].y, scratch[i].z);
}

}  // namespace

MayaMatrix toMaya(const MMatrix& m) {
    MayaMatrix out;
    double values[4][4];
    m.get(values);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            out.m[r][c] = values[r][c];
    return out;
}

MStatus DkDeformer::addNumeric(MObject& attribute, const char* name, const char* shortName,
                               MFnNumericData::Type type, double value, bool keyable) {
    MFnNumericAttribute fn;
    attribute = fn.create(name, shortName, type, value);
    fn.setKeyable(keyable);
    return addAttribute(attribute);
}

MStatus DkDeformer::addUnit(MObject& attribute, const char* name, const char* shortName,
                            MFnUnitAttribute::Type type, double value) {
    MFnUnitAttribute fn;
    attribute = fn.create(name, shortName, type, value);
    fn.setKeyable(true);
    return addAttribute(attribute);
}

MStatus DkDeformer::addMatrix(MObject& attribute, const char* name, const char* shortName, bool array) {
    MFnMatrixAttribute fn;
    attribute = fn.create(name, shortName);
    fn.setArray(array);
    fn.setUsesArrayDataBuilder(array);
    return addAttribute(attribute);
}

void DkDeformer::affectsOutput(std::initializer_list<MObject*> attributes) {
    for (MObject* attribute : attributes)
        attributeAffects(*attribute, outputGeom);
}

MStatus DkDeformer::addRebindAttribute(MObject& attribute) {
    addNumeric(attribute, "rebind", "rbd", MFnNumericData::kBoolean, 0.0, false);
    return attributeAffects(attribute, outputGeom);
}

MStatus DkDeformer::deform(MDataBlock& block, MItGeometry& iter, const MMatrix& geometryWorld,
                           unsigned int multiIndex) {
    const float envelope = block.inputValue(MPxDeformerNode::envelope).asFloat();
    if (envelope == 0.0f) return MS::kSuccess;  // the output is the input: nothing read, nothing checked
    try {
        const std::string label = MString(name()).asChar();
        NodeGeometry& geometry = geometries_.at(multiIndex);
        NodeCore& core = geometry.core(hostType(block), label);
        // The rest: this geometry's input mesh, at its first evaluation, on a topology change, or on rebind.
        MArrayDataHandle inputs = block.outputArrayValue(input);
        inputs.jumpToElement(multiIndex);
        const MObject data = inputs.outputValue().child(inputGeom).asMesh();
        MFnMesh mesh(data);
        mesh.getVertices(counts_, indices_);
        const auto copy = [](const MIntArray& from, std::vector<int32_t>& to) {
            to.resize(from.length());
            for (unsigned k = 0; k < from.length(); ++k)
                to[k] = from[k];
        };
        copy(counts_, faceCounts_);
        copy(indices_, faceIndices_);
        const bool rebindNow = block.inputValue(rebindAttribute()).asBool();
        if (geometry.takesRest(rebindNow, faceCounts_, faceIndices_)) core.setRest(meshOf(data, label));
        // Parameters rebuilt in place; the core pushes only those that changed (and the host layer validates
        // only what it is given), so a frame that moves nothing costs comparisons.
        parameters(block, toMaya(geometryWorld), parameters_);
        core.set(parameters_);
        // Positions in bulk, into and out of the core's own buffers (no allocation once warm).
        const auto vertices = static_cast<unsigned>(core.stack().rest().numVertices());
        if (static_cast<unsigned>(iter.count()) != vertices) {
            // A deformer set of some of the vertices: the whole mesh, its members weighted, theirs moved.
            mesh.getPoints(positions_, MSpace::kObject);
            all_.resize(positions_.length());
            for (unsigned k = 0; k < positions_.length(); ++k)
                all_[k] = {static_cast<float>(positions_[k].x), static_cast<float>(positions_[k].y),
                           static_cast<float>(positions_[k].z)};
            members_.clear();
            memberWeights_.clear();
            for (iter.reset(); !iter.isDone(); iter.next()) {
                members_.push_back(iter.index());
                memberWeights_.push_back(weightValue(block, multiIndex, iter.index()));
            }
            moved_.resize(members_.size());
            core.evaluateMembers(all_, members_, memberWeights_, envelope, moved_);
            positions_.setLength(static_cast<unsigned>(moved_.size()));
            for (size_t k = 0; k < moved_.size(); ++k)
                positions_[static_cast<unsigned>(k)] = MPoint(moved_[k].x, moved_[k].y, moved_[k].z);
            iter.setAllPositions(positions_);
            return MS::kSuccess;
        }
        iter.allPositions(positions_);
        const unsigned n = positions_.length();
        const std::span<glm::vec3> points = core.points(n);
        const std::span<float> weights = core.weights(n);
        bool painted = false;
        unsigned i = 0;
        for (iter.reset(); !iter.isDone() && i < n; iter.next(), ++i) {
            weights[i] = weightValue(block, multiIndex, iter.index());
            painted = painted || weights[i] != 1.0f;
        }
        for (unsigned k = 0; k < n; ++k) {
            const MPoint& p = positions_[k];
            points[k] = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
        }
        core.evaluateBuffers(envelope, painted);
        for (unsigned k = 0; k < n; ++k)
            positions_[k] = MPoint(points[k].x, points[k].y, points[k].z);
        iter.setAllPositions(positions_);
    } catch (const Error& e) {
        return report(*this, e.what());
    }
    return MS::kSuccess;
}

// ---- dkSlide -------------------------------------------------------------------------------------------

const MTypeId DkSlide::id(0x0013A6C0);
MObject DkSlide::rebind, DkSlide::vertex, DkSlide::radius, DkSlide::geodesic, DkSlide::limitSurface,
    DkSlide::weightsAreFalloff, DkSlide::foldLimit, DkSlide::falloff, DkSlide::startMatrix,
    DkSlide::endMatrix;

MStatus DkSlide::initialize() {
    addNumeric(vertex, "vertex", "vtx", MFnNumericData::kInt, 0.0, false);
    addUnit(radius, "radius", "rad", MFnUnitAttribute::kDistance, 1.0);
    addNumeric(geodesic, "geodesic", "geo", MFnNumericData::kBoolean, 1.0);
    addNumeric(limitSurface, "limitSurface", "lsf", MFnNumericData::kBoolean, 0.0);
    addNumeric(weightsAreFalloff, "weightsAreFalloff", "waf", MFnNumericData::kBoolean, 0.0);
    addNumeric(foldLimit, "foldLimit", "fdl", MFnNumericData::kBoolean, 0.0);
    falloff = MRampAttribute::createCurveRamp("falloff", "fof");
    addAttribute(falloff);
    addMatrix(startMatrix, "startMatrix", "stm");
    addMatrix(endMatrix, "endMatrix", "enm");
    addRebindAttribute(rebind);
    affectsOutput({&vertex, &radius, &geodesic, &limitSurface, &weightsAreFalloff, &foldLimit, &falloff,
                   &startMatrix, &endMatrix});
    return MS::kSuccess;
}

void DkSlide::parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) {
    SlideInputs& in = in_;
    in.vertex = block.inputValue(vertex).asInt();
    in.radius = block.inputValue(radius).asDistance().asCentimeters();
    in.geodesic = block.inputValue(geodesic).asBool();
    in.limitSurface = block.inputValue(limitSurface).asBool();
    in.weightsAreFalloff = block.inputValue(weightsAreFalloff).asBool();
    in.foldLimit = block.inputValue(foldLimit).asBool();
    MRampAttribute ramp(thisMObject(), falloff);
    ramp.getEntries(rampIndices_, rampPositions_, rampValues_, rampInterpolations_);
    in.falloff.clear();
    for (unsigned i = 0; i < rampPositions_.length(); ++i)
        in.falloff.push_back({rampPositions_[i], rampValues_[i], rampInterpolations_[i]});
    if (in.falloff.empty()) in.falloff.assign({{0.0, 1.0, 2}, {1.0, 0.0, 2}});
    in.startWorld = translation(matrixValue(block, startMatrix));
    in.endWorld = translation(matrixValue(block, endMatrix));
    in.geometryWorld = geometryWorld;
    slideParameters(in, out);
}

MStatus DkSlide::accessoryNodeSetup(MDagModifier& modifier) {
    // The start and end locators at the origin; deformkit_maya.create_slide() places them at the handle.
    MStatus status;
    const std::pair<MObject, const char*> locators[] = {{startMatrix, "dkSlideStart"},
                                                        {endMatrix, "dkSlideEnd"}};
    for (const auto& [attribute, label] : locators) {
        MObject locator = modifier.createNode("locator", MObject::kNullObj, &status);
        if (!status) return status;
        modifier.renameNode(locator, label);
        MFnDependencyNode fn(locator);
        status = modifier.connect(fn.findPlug("worldMatrix", false).elementByLogicalIndex(0),
                                  MPlug(thisMObject(), attribute));
        if (!status) return status;
    }
    return MS::kSuccess;
}

// ---- dkBarr --------------------------------------------------------------------------------------------

const MTypeId DkBarr::id(0x0013A6C1);
MObject DkBarr::rebind, DkBarr::kind, DkBarr::handleMatrix, DkBarr::startValue, DkBarr::endValue,
    DkBarr::startAngle, DkBarr::endAngle, DkBarr::curvature, DkBarr::lowBound, DkBarr::highBound;

MStatus DkBarr::initialize() {
    MFnEnumAttribute fn;
    kind = fn.create("kind", "knd", 1);
    fn.addField("taper", 0);
    fn.addField("twist", 1);
    fn.addField("bend", 2);
    addAttribute(kind);
    addMatrix(handleMatrix, "handleMatrix", "hdm");
    // Taper's scales are numbers; twist's angles and bend's curvature (an angle per handle length) are
    // angles, so that typed degrees and a connected joint rotation mean what they say.
    addNumeric(startValue, "startValue", "stv", MFnNumericData::kDouble, 1.0);
    addNumeric(endValue, "endValue", "env", MFnNumericData::kDouble, 1.0);
    addUnit(startAngle, "startAngle", "sta", MFnUnitAttribute::kAngle, 0.0);
    addUnit(endAngle, "endAngle", "ena", MFnUnitAttribute::kAngle, 1.0);
    addUnit(curvature, "curvature", "cur", MFnUnitAttribute::kAngle, 0.5);
    addNumeric(lowBound, "lowBound", "lwb", MFnNumericData::kDouble, -1.0);
    addNumeric(highBound, "highBound", "hib", MFnNumericData::kDouble, 1.0);
    addRebindAttribute(rebind);
    affectsOutput({&kind, &handleMatrix, &startValue, &endValue, &startAngle, &endAngle, &curvature,
                   &lowBound, &highBound});
    return MS::kSuccess;
}

const char* DkBarr::hostType(MDataBlock& block) {
    const short k = block.inputValue(kind).asShort();
    return k == 0 ? "taper" : k == 1 ? "twist" : "bend";
}

void DkBarr::parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) {
    BarrInputs& in = in_;
    in.type = hostType(block);
    in.handleWorld = matrixValue(block, handleMatrix);
    in.geometryWorld = geometryWorld;
    const bool twist = in.type == std::string("twist");
    in.startValue =
        twist ? block.inputValue(startAngle).asAngle().asRadians() : block.inputValue(startValue).asDouble();
    in.endValue =
        twist ? block.inputValue(endAngle).asAngle().asRadians() : block.inputValue(endValue).asDouble();
    in.curvature = block.inputValue(curvature).asAngle().asRadians();
    in.lowBound = block.inputValue(lowBound).asDouble();
    in.highBound = block.inputValue(highBound).asDouble();
    barrParameters(in, out);
}

MStatus DkBarr::accessoryNodeSetup(MDagModifier& modifier) {
    MStatus status;
    MObject handle = modifier.createNode("locator", MObject::kNullObj, &status);
    if (!status) return status;
    modifier.renameNode(handle, "dkBarrHandle");
    MFnDependencyNode fn(handle);
    return modifier.connect(fn.findPlug("worldMatrix", false).elementByLogicalIndex(0),
                            MPlug(thisMObject(), handleMatrix));
}

// ---- dkFrameLattice ------------------------------------------------------------------------------------

const MTypeId DkFrameLattice::id(0x0013A6C2);
MObject DkFrameLattice::rebind, DkFrameLattice::divisions, DkFrameLattice::basis, DkFrameLattice::baseMatrix,
    DkFrameLattice::controlMatrix;

MStatus DkFrameLattice::initialize() {
    MFnNumericAttribute numeric;
    divisions = numeric.create("divisions", "div", MFnNumericData::k3Int);
    numeric.setDefault(2, 2, 2);
    addAttribute(divisions);
    MFnEnumAttribute fn;
    basis = fn.create("basis", "bas", 0);
    fn.addField("bernstein", 0);
    fn.addField("bspline", 1);
    addAttribute(basis);
    addMatrix(baseMatrix, "baseMatrix", "bsm");
    addMatrix(controlMatrix, "controlMatrix", "ctm", true);
    addRebindAttribute(rebind);
    affectsOutput({&divisions, &basis, &baseMatrix, &controlMatrix});
    return MS::kSuccess;
}

void DkFrameLattice::parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) {
    FrameLatticeInputs& in = in_;
    const int3& d = block.inputValue(divisions).asInt3();
    in.divisions = {d[0], d[1], d[2]};
    in.basis = block.inputValue(basis).asShort();
    in.baseLatticeWorld = matrixValue(block, baseMatrix);
    in.geometryWorld = geometryWorld;
    in.controlsWorld.clear();
    MArrayDataHandle controls = block.inputArrayValue(controlMatrix);
    for (unsigned i = 0; i < controls.elementCount(); ++i, controls.next())
        in.controlsWorld.push_back(toMaya(controls.inputValue().asMatrix()));
    frameLatticeParameters(in, out);
}

// ---- dkWire --------------------------------------------------------------------------------------------

const MTypeId DkWire::id(0x0013A6C3);
MObject DkWire::rebind, DkWire::restCurve, DkWire::curve, DkWire::samples, DkWire::dropoff, DkWire::scale,
    DkWire::smooth;

MStatus DkWire::initialize() {
    MFnTypedAttribute typed;
    restCurve = typed.create("restCurve", "rcv", MFnData::kNurbsCurve);
    typed.setArray(true);
    addAttribute(restCurve);
    curve = typed.create("curve", "crv", MFnData::kNurbsCurve);
    typed.setArray(true);
    addAttribute(curve);
    addNumeric(samples, "samples", "smp", MFnNumericData::kInt, 0.0, false);
    addNumeric(dropoff, "dropoff", "dro", MFnNumericData::kDouble, 1.0);
    addNumeric(scale, "scale", "scl", MFnNumericData::kDouble, 1.0);
    addNumeric(smooth, "smooth", "smo", MFnNumericData::kBoolean, 1.0);
    addRebindAttribute(rebind);
    affectsOutput({&restCurve, &curve, &samples, &dropoff, &scale, &smooth});
    return MS::kSuccess;
}

void DkWire::parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) {
    WireInputs& in = in_;
    in.geometryWorld = geometryWorld;
    in.dropoff.assign(1, block.inputValue(dropoff).asDouble());
    in.scale.assign(1, block.inputValue(scale).asDouble());
    in.smooth = block.inputValue(smooth).asBool();
    const int count = block.inputValue(samples).asInt();
    in.restWorld.clear();
    in.curveWorld.clear();
    in.curveSizes.clear();
    MArrayDataHandle rest = block.inputArrayValue(restCurve), now = block.inputArrayValue(curve);
    for (unsigned i = 0; i < rest.elementCount(); ++i, rest.next()) {
        // Curves connected from world-space plugs (worldSpace[0]) carry world positions.
        const size_t before = in.restWorld.size();
        appendCurvePoints(rest.inputValue().asNurbsCurve(), count, in.restWorld);
        in.curveSizes.push_back(static_cast<int>(in.restWorld.size() - before));
    }
    for (unsigned i = 0; i < now.elementCount(); ++i, now.next())
        appendCurvePoints(now.inputValue().asNurbsCurve(), count, in.curveWorld);
    wireParameters(in, out);
}

// ---- dkMeshWarp ----------------------------------------------------------------------------------------

const MTypeId DkMeshWarp::id(0x0013A6C4);
MObject DkMeshWarp::rebind, DkMeshWarp::restCage, DkMeshWarp::cage;

MStatus DkMeshWarp::initialize() {
    restCage = meshAttribute("restCage", "rcg");
    addAttribute(restCage);
    cage = meshAttribute("cage", "cag");
    addAttribute(cage);
    addRebindAttribute(rebind);
    affectsOutput({&restCage, &cage});
    return MS::kSuccess;
}

void DkMeshWarp::parameters(MDataBlock& block, const MayaMatrix& geometryWorld, Parameters& out) {
    MeshWarpInputs& in = in_;
    in.geometryWorld = geometryWorld;
    const MObject rest = block.inputValue(restCage).asMesh(), now = block.inputValue(cage).asMesh();
    in.restCageWorld.clear();
    in.cageWorld.clear();
    appendPoints(rest, points_, in.restCageWorld);
    appendPoints(now, points_, in.cageWorld);
    MFnMesh(rest).getVertices(counts_, indices_);
    in.faceCounts.resize(counts_.length());
    for (unsigned i = 0; i < counts_.length(); ++i)
        in.faceCounts[i] = counts_[i];
    in.faceIndices.resize(indices_.length());
    for (unsigned i = 0; i < indices_.length(); ++i)
        in.faceIndices[i] = indices_[i];
    meshWarpParameters(in, out);
}

}  // namespace deformkit::maya
