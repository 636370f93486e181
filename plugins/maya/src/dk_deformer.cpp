#include "dk_deformer.h"

#include <string>
#include <utility>
#include <vector>

#include <maya/MDagModifier.h>
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

std::vector<glm::dvec3> worldPoints(const MObject& data, MSpace::Space space) {
    std::vector<glm::dvec3> out;
    if (data.hasFn(MFn::kNurbsCurve)) {
        MFnNurbsCurve fn(data);
        MPointArray cvs;
        fn.getCVs(cvs, space);
        for (unsigned i = 0; i < cvs.length(); ++i)
            out.emplace_back(cvs[i].x, cvs[i].y, cvs[i].z);
    } else if (data.hasFn(MFn::kMesh)) {
        MFnMesh fn(data);
        MPointArray points;
        fn.getPoints(points, space);
        for (unsigned i = 0; i < points.length(); ++i)
            out.emplace_back(points[i].x, points[i].y, points[i].z);
    }
    return out;
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
    try {
        const std::string type = hostType();
        if (!core_ || core_->stack().deformer(0).type() != type) {
            core_ = std::make_unique<NodeCore>(type, MString(name()).asChar());
        }
        // The rest: the input mesh, captured at the first evaluation, on a topology change, or on rebind.
        MArrayDataHandle inputs = block.outputArrayValue(input);
        inputs.jumpToElement(multiIndex);
        const MObject data = inputs.outputValue().child(inputGeom).asMesh();
        const bool rebindNow = block.inputValue(rebindAttribute()).asBool();
        if (!core_->hasRest() || rebindNow != rebindSeen_ ||
            static_cast<int32_t>(iter.count()) != core_->stack().rest().numVertices()) {
            core_->setRest(meshOf(data, MString(name()).asChar()));
            rebindSeen_ = rebindNow;
        }
        core_->set(parameters(block, toMaya(geometryWorld)));

        std::vector<glm::vec3> points;
        points.reserve(iter.count());
        std::vector<float> weights;
        weights.reserve(iter.count());
        bool painted = false;
        for (iter.reset(); !iter.isDone(); iter.next()) {
            const MPoint p = iter.position();
            points.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
            weights.push_back(weightValue(block, multiIndex, iter.index()));
            painted = painted || weights.back() != 1.0f;
        }
        core_->setWeights(painted ? std::span<const float>(weights) : std::span<const float>());
        core_->evaluate(points, envelope);
        size_t i = 0;
        for (iter.reset(); !iter.isDone(); iter.next(), ++i)
            iter.setPosition(MPoint(points[i].x, points[i].y, points[i].z));
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
    addNumeric(radius, "radius", "rad", MFnNumericData::kDouble, 1.0);
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

Parameters DkSlide::parameters(MDataBlock& block, const MayaMatrix& geometryWorld) {
    SlideInputs in;
    in.vertex = block.inputValue(vertex).asInt();
    in.radius = block.inputValue(radius).asDouble();
    in.geodesic = block.inputValue(geodesic).asBool();
    in.limitSurface = block.inputValue(limitSurface).asBool();
    in.weightsAreFalloff = block.inputValue(weightsAreFalloff).asBool();
    in.foldLimit = block.inputValue(foldLimit).asBool();
    MRampAttribute ramp(thisMObject(), falloff);
    MIntArray indices, interpolations;
    MFloatArray positions, values;
    ramp.getEntries(indices, positions, values, interpolations);
    in.falloff.clear();
    for (unsigned i = 0; i < positions.length(); ++i)
        in.falloff.push_back({positions[i], values[i], interpolations[i]});
    if (in.falloff.empty()) in.falloff = {{0.0, 1.0, 2}, {1.0, 0.0, 2}};
    in.startWorld = translation(matrixValue(block, startMatrix));
    in.endWorld = translation(matrixValue(block, endMatrix));
    in.geometryWorld = geometryWorld;
    return slideParameters(in);
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
    DkBarr::curvature, DkBarr::lowBound, DkBarr::highBound;

MStatus DkBarr::initialize() {
    MFnEnumAttribute fn;
    kind = fn.create("kind", "knd", 1);
    fn.addField("taper", 0);
    fn.addField("twist", 1);
    fn.addField("bend", 2);
    addAttribute(kind);
    addMatrix(handleMatrix, "handleMatrix", "hdm");
    addNumeric(startValue, "startValue", "stv", MFnNumericData::kDouble, 0.0);
    addNumeric(endValue, "endValue", "env", MFnNumericData::kDouble, 1.0);
    addNumeric(curvature, "curvature", "cur", MFnNumericData::kDouble, 0.5);
    addNumeric(lowBound, "lowBound", "lwb", MFnNumericData::kDouble, -1.0);
    addNumeric(highBound, "highBound", "hib", MFnNumericData::kDouble, 1.0);
    addRebindAttribute(rebind);
    affectsOutput({&kind, &handleMatrix, &startValue, &endValue, &curvature, &lowBound, &highBound});
    return MS::kSuccess;
}

const char* DkBarr::hostType() const {
    return kind_ == 0 ? "taper" : kind_ == 1 ? "twist" : "bend";
}

Parameters DkBarr::parameters(MDataBlock& block, const MayaMatrix& geometryWorld) {
    kind_ = block.inputValue(kind).asShort();
    BarrInputs in;
    in.type = hostType();
    in.handleWorld = matrixValue(block, handleMatrix);
    in.geometryWorld = geometryWorld;
    in.startValue = block.inputValue(startValue).asDouble();
    in.endValue = block.inputValue(endValue).asDouble();
    in.curvature = block.inputValue(curvature).asDouble();
    in.lowBound = block.inputValue(lowBound).asDouble();
    in.highBound = block.inputValue(highBound).asDouble();
    return barrParameters(in);
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

Parameters DkFrameLattice::parameters(MDataBlock& block, const MayaMatrix& geometryWorld) {
    FrameLatticeInputs in;
    const int3& d = block.inputValue(divisions).asInt3();
    in.divisions = {d[0], d[1], d[2]};
    in.basis = block.inputValue(basis).asShort();
    in.baseLatticeWorld = matrixValue(block, baseMatrix);
    in.geometryWorld = geometryWorld;
    MArrayDataHandle controls = block.inputArrayValue(controlMatrix);
    for (unsigned i = 0; i < controls.elementCount(); ++i, controls.next())
        in.controlsWorld.push_back(toMaya(controls.inputValue().asMatrix()));
    return frameLatticeParameters(in);
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

Parameters DkWire::parameters(MDataBlock& block, const MayaMatrix& geometryWorld) {
    WireInputs in;
    in.geometryWorld = geometryWorld;
    in.dropoff = {block.inputValue(dropoff).asDouble()};
    in.scale = {block.inputValue(scale).asDouble()};
    in.smooth = block.inputValue(smooth).asBool();
    MArrayDataHandle rest = block.inputArrayValue(restCurve), now = block.inputArrayValue(curve);
    for (unsigned i = 0; i < rest.elementCount(); ++i, rest.next()) {
        // Curves connected from world-space plugs (worldSpace[0]) carry world positions.
        const std::vector<glm::dvec3> points = worldPoints(rest.inputValue().asNurbsCurve(), MSpace::kObject);
        in.restWorld.insert(in.restWorld.end(), points.begin(), points.end());
        in.curveSizes.push_back(static_cast<int>(points.size()));
    }
    for (unsigned i = 0; i < now.elementCount(); ++i, now.next()) {
        const std::vector<glm::dvec3> points = worldPoints(now.inputValue().asNurbsCurve(), MSpace::kObject);
        in.curveWorld.insert(in.curveWorld.end(), points.begin(), points.end());
    }
    return wireParameters(in);
}

// ---- dkMeshWarp ----------------------------------------------------------------------------------------

const MTypeId DkMeshWarp::id(0x0013A6C4);
MObject DkMeshWarp::rebind, DkMeshWarp::restCage, DkMeshWarp::cage;

MStatus DkMeshWarp::initialize() {
    MFnTypedAttribute typed;
    restCage = typed.create("restCage", "rcg", MFnData::kMesh);
    addAttribute(restCage);
    cage = typed.create("cage", "cag", MFnData::kMesh);
    addAttribute(cage);
    addRebindAttribute(rebind);
    affectsOutput({&restCage, &cage});
    return MS::kSuccess;
}

Parameters DkMeshWarp::parameters(MDataBlock& block, const MayaMatrix& geometryWorld) {
    MeshWarpInputs in;
    in.geometryWorld = geometryWorld;
    const MObject rest = block.inputValue(restCage).asMesh(), now = block.inputValue(cage).asMesh();
    in.restCageWorld = worldPoints(rest, MSpace::kObject);
    in.cageWorld = worldPoints(now, MSpace::kObject);
    MFnMesh fn(rest);
    MIntArray counts, indices;
    fn.getVertices(counts, indices);
    for (unsigned i = 0; i < counts.length(); ++i)
        in.faceCounts.push_back(counts[i]);
    for (unsigned i = 0; i < indices.length(); ++i)
        in.faceIndices.push_back(indices[i]);
    return meshWarpParameters(in);
}

}  // namespace deformkit::maya
