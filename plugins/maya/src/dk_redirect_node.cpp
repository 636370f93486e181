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

std::string withFrame(std::string pattern, int frame) {
    const size_t at = pattern.find("####");
    if (at == std::string::npos) return pattern;
    char digits[16];
    std::snprintf(digits, sizeof digits, "%04d", frame);
    return pattern.replace(at, 4, digits);
}

}  // namespace

const MTypeId DkUvRedirect::id(0x0013A6C5);
MObject DkUvRedirect::inMesh, DkUvRedirect::restMesh, DkUvRedirect::rigidity, DkUvRedirect::mask,
    DkUvRedirect::tile, DkUvRedirect::resolution, DkUvRedirect::output, DkUvRedirect::time,
    DkUvRedirect::outFile;

MStatus DkUvRedirect::initialize() {
    MFnTypedAttribute typed;
    inMesh = typed.create("inMesh", "inm", MFnData::kMesh);
    addAttribute(inMesh);
    restMesh = typed.create("restMesh", "rsm", MFnData::kMesh);
    addAttribute(restMesh);
    const std::tuple<MObject*, const char*, const char*> strings[] = {
        {&rigidity, "rigidity", "rig"}, {&mask, "mask", "msk"}, {&output, "output", "out"}};
    for (const auto& [attribute, name, shortName] : strings) {
        MFnTypedAttribute fn;
        *attribute = fn.create(name, shortName, MFnData::kString);
        addAttribute(*attribute);
    }
    MFnNumericAttribute numeric;
    tile = numeric.create("tile", "til", MFnNumericData::kInt, 1001);
    addAttribute(tile);
    resolution = numeric.create("resolution", "res", MFnNumericData::kInt, 0);
    addAttribute(resolution);
    MFnUnitAttribute unit;
    time = unit.create("time", "tim", MFnUnitAttribute::kTime, 0.0);
    addAttribute(time);
    outFile = typed.create("outFile", "ouf", MFnData::kString);
    typed.setWritable(false);
    typed.setStorable(false);
    addAttribute(outFile);
    for (MObject* in : {&inMesh, &restMesh, &rigidity, &mask, &tile, &resolution, &output, &time})
        attributeAffects(*in, outFile);
    return MS::kSuccess;
}

MStatus DkUvRedirect::compute(const MPlug& plug, MDataBlock& block) {
    if (plug != outFile) return MS::kUnknownParameter;
    try {
        const int tileNumber = block.inputValue(tile).asInt();
        const std::string rigidityPattern = block.inputValue(rigidity).asString().asChar();
        const std::string maskPattern = block.inputValue(mask).asString().asChar();
        const int cells = block.inputValue(resolution).asInt();
        const std::string key = rigidityPattern + "|" + maskPattern + "|" + std::to_string(tileNumber) + "|" +
                                std::to_string(cells);
        if (!core_ || key != coreKey_) {
            const geom::Mesh rest =
                meshWithUVs(block.inputValue(restMesh).asMesh(), MString(name()).asChar());
            const io::Image rig =
                io::readImage(io::expandUdim(rigidityPattern, tileNumber), {0, "rigidity map"});
            const io::Image msk = maskPattern.empty() ? io::Image()
                                                      : io::readImage(io::expandUdim(maskPattern, tileNumber),
                                                                      {0, "warp mask"});
            uvwarp::TileWarpOptions options;
            options.cells = cells;
            core_ = std::make_unique<RedirectCore>(rest, tileNumber, rig, msk, options, rigidityPattern);
            coreKey_ = key;
        }
        MFnMesh deformed(block.inputValue(inMesh).asMesh());
        MPointArray points;
        deformed.getPoints(points, MSpace::kObject);
        std::vector<glm::vec3> p;
        p.reserve(points.length());
        for (unsigned i = 0; i < points.length(); ++i)
            p.emplace_back(static_cast<float>(points[i].x), static_cast<float>(points[i].y),
                           static_cast<float>(points[i].z));
        const int frame = static_cast<int>(std::lround(block.inputValue(time).asTime().as(MTime::uiUnit())));
        const io::Image map = core_->solve(frame, p);
        const std::string path =
            withFrame(io::expandUdim(block.inputValue(output).asString().asChar(), tileNumber), frame);
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
