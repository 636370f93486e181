#include "dk_redirect_node.h"

#include <maya/MFloatArray.h>
#include <maya/MFnMesh.h>
#include <maya/MFnNumericAttribute.h>
#include <maya/MFnStringData.h>
#include <maya/MFnTypedAttribute.h>
#include <maya/MFnUnitAttribute.h>
#include <maya/MGlobal.h>
#include <maya/MIntArray.h>
#include <maya/MPointArray.h>
#include <maya/MTime.h>

#include <cmath>
#include <cstdio>
#include <tuple>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/io/udim.h"
#include "maya_mesh.h"

namespace deformkit::maya {

namespace {

geom::Mesh meshWithUVs(const MObject& data, const std::string& what) {
    return geom::Mesh(meshDataOf(data, true), what);
}

}  // namespace

const MTypeId DkUvRedirect::id(0x0013A6C5);
MObject DkUvRedirect::inMesh, DkUvRedirect::restMesh, DkUvRedirect::rigidity, DkUvRedirect::mask,
    DkUvRedirect::orientation, DkUvRedirect::tile, DkUvRedirect::resolution, DkUvRedirect::iterations,
    DkUvRedirect::tolerance, DkUvRedirect::sweepsPerLevel, DkUvRedirect::orientationPreservation,
    DkUvRedirect::smoothing, DkUvRedirect::damping, DkUvRedirect::coarseStiffness,
    DkUvRedirect::coarseRelaxation, DkUvRedirect::levels, DkUvRedirect::maxLevels,
    DkUvRedirect::coldIterations, DkUvRedirect::densityRadius, DkUvRedirect::output, DkUvRedirect::time,
    DkUvRedirect::outFile;

MStatus DkUvRedirect::initialize() {
    MFnTypedAttribute typed;
    inMesh = typed.create("inMesh", "inm", MFnData::kMesh);
    addAttribute(inMesh);
    restMesh = typed.create("restMesh", "rsm", MFnData::kMesh);
    addAttribute(restMesh);
    const std::tuple<MObject*, const char*, const char*> strings[] = {
        {&rigidity, "rigidity", "rig"},
        {&mask, "mask", "msk"},
        {&orientation, "orientation", "ori"},
        {&sweepsPerLevel, "sweepsPerLevel", "spl"},
        {&output, "output", "out"}};
    for (const auto& [attribute, name, shortName] : strings) {
        MFnTypedAttribute fn;
        *attribute = fn.create(name, shortName, MFnData::kString);
        addAttribute(*attribute);
    }
    // The solver's options, with the library's defaults (uvwarp::SolverOptions, TileWarpOptions).
    const uvwarp::TileWarpOptions defaults;
    const std::tuple<MObject*, const char*, const char*, MFnNumericData::Type, double> numbers[] = {
        {&tile, "tile", "til", MFnNumericData::kInt, 1001},
        {&resolution, "resolution", "res", MFnNumericData::kInt, 0},
        {&iterations, "iterations", "itr", MFnNumericData::kInt, defaults.solver.iterations},
        {&tolerance, "tolerance", "tol", MFnNumericData::kDouble, defaults.solver.tolerance},
        {&orientationPreservation, "orientationPreservation", "orp", MFnNumericData::kDouble,
         defaults.solver.orientationPreservation},
        {&smoothing, "smoothing", "smt", MFnNumericData::kDouble, defaults.solver.smoothing},
        {&damping, "damping", "dmp", MFnNumericData::kDouble, defaults.solver.damping},
        {&coarseStiffness, "coarseStiffness", "cst", MFnNumericData::kDouble,
         defaults.solver.coarseStiffness},
        {&coarseRelaxation, "coarseRelaxation", "crx", MFnNumericData::kDouble,
         defaults.solver.coarseRelaxation},
        {&levels, "levels", "lvl", MFnNumericData::kInt, defaults.solver.levels},
        {&maxLevels, "maxLevels", "mxl", MFnNumericData::kInt, defaults.solver.maxLevels},
        {&coldIterations, "coldIterations", "cit", MFnNumericData::kInt, defaults.solver.coldIterations},
        {&densityRadius, "densityRadius", "dnr", MFnNumericData::kInt, defaults.densityOrientationRadius}};
    for (const auto& [attribute, name, shortName, type, value] : numbers) {
        MFnNumericAttribute fn;
        *attribute = fn.create(name, shortName, type, value);
        addAttribute(*attribute);
    }
    MFnUnitAttribute unit;
    time = unit.create("time", "tim", MFnUnitAttribute::kTime, 0.0);
    addAttribute(time);
    outFile = typed.create("outFile", "ouf", MFnData::kString);
    typed.setWritable(false);
    typed.setStorable(false);
    addAttribute(outFile);
    for (MObject* in : {&inMesh,
                        &restMesh,
                        &rigidity,
                        &mask,
                        &orientation,
                        &tile,
                        &resolution,
                        &iterations,
                        &tolerance,
                        &sweepsPerLevel,
                        &orientationPreservation,
                        &smoothing,
                        &damping,
                        &coarseStiffness,
                        &coarseRelaxation,
                        &levels,
                        &maxLevels,
                        &coldIterations,
                        &densityRadius,
                        &output,
                        &time})
        attributeAffects(*in, outFile);
    return MS::kSuccess;
}

MStatus DkUvRedirect::compute(const MPlug& plug, MDataBlock& block) {
    if (plug != outFile) return MS::kUnknownParameter;
    try {
        RedirectInputs in;
        in.tile = block.inputValue(tile).asInt();
        in.rigidity = block.inputValue(rigidity).asString().asChar();
        in.mask = block.inputValue(mask).asString().asChar();
        in.orientation = block.inputValue(orientation).asString().asChar();
        in.options.cells = block.inputValue(resolution).asInt();
        in.options.densityOrientationRadius = block.inputValue(densityRadius).asInt();
        uvwarp::SolverOptions& solver = in.options.solver;
        solver.iterations = block.inputValue(iterations).asInt();
        solver.tolerance = static_cast<float>(block.inputValue(tolerance).asDouble());
        const std::string sweeps = block.inputValue(sweepsPerLevel).asString().asChar();
        if (!sweeps.empty()) solver.sweepsPerLevel = sweepsFromText(sweeps);
        solver.orientationPreservation =
            static_cast<float>(block.inputValue(orientationPreservation).asDouble());
        solver.smoothing = static_cast<float>(block.inputValue(smoothing).asDouble());
        solver.damping = static_cast<float>(block.inputValue(damping).asDouble());
        solver.coarseStiffness = static_cast<float>(block.inputValue(coarseStiffness).asDouble());
        solver.coarseRelaxation = static_cast<float>(block.inputValue(coarseRelaxation).asDouble());
        solver.levels = block.inputValue(levels).asInt();
        solver.maxLevels = block.inputValue(maxLevels).asInt();
        solver.coldIterations = block.inputValue(coldIterations).asInt();
        const int frame = static_cast<int>(std::lround(block.inputValue(time).asTime().as(MTime::uiUnit())));
        if (node_.needsBuild(in)) {
            node_.build(meshWithUVs(block.inputValue(restMesh).asMesh(), MString(name()).asChar()), in, frame,
                        in.rigidity);
        }
        MFnMesh deformed(block.inputValue(inMesh).asMesh());
        MPointArray points;
        deformed.getPoints(points, MSpace::kObject);
        points_.resize(points.length());
        for (unsigned i = 0; i < points.length(); ++i)
            points_[i] = {static_cast<float>(points[i].x), static_cast<float>(points[i].y),
                          static_cast<float>(points[i].z)};
        const io::Image map = node_.solve(in, frame, points_);
        const std::string path = fileAt(block.inputValue(output).asString().asChar(), in.tile, frame);
        io::writeImage(path, map, {io::PixelType::Float, {}});
        block.outputValue(outFile).set(MString(path.c_str()));
        block.setClean(plug);
    } catch (const Error& e) {
        MGlobal::displayError(MString(name()) + ": " + e.what());
        return MS::kFailure;
    }
    return MS::kSuccess;
}

}  // namespace deformkit::maya
