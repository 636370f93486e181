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
    DkUvRedirect::orientation, DkUvRedirect::preset, DkUvRedirect::tile, DkUvRedirect::output,
    DkUvRedirect::time, DkUvRedirect::outFile;
std::vector<RedirectOptionAttribute> DkUvRedirect::optionSpecs;
std::vector<MObject> DkUvRedirect::options;

MStatus DkUvRedirect::initialize() {
    inMesh = meshAttribute("inMesh", "inm");
    addAttribute(inMesh);
    restMesh = meshAttribute("restMesh", "rsm");
    addAttribute(restMesh);
    const std::tuple<MObject*, const char*, const char*> strings[] = {{&rigidity, "rigidity", "rig"},
                                                                      {&mask, "mask", "msk"},
                                                                      {&orientation, "orientation", "ori"},
                                                                      {&preset, "preset", "prs"},
                                                                      {&output, "output", "out"}};
    for (const auto& [attribute, name, shortName] : strings) {
        MFnTypedAttribute fn;
        *attribute = fn.create(name, shortName, MFnData::kString);
        addAttribute(*attribute);
    }
    MFnNumericAttribute tileFn;
    tile = tileFn.create("tile", "til", MFnNumericData::kInt, 1001);
    addAttribute(tile);
    // One attribute per UV-warp option, named as the library declares it, with the library's default.
    optionSpecs = redirectOptionAttributes();
    options.clear();
    for (const RedirectOptionAttribute& a : optionSpecs) {
        const MString name(std::string(a.spec->name).c_str());
        MObject attribute;
        if (a.kind == RedirectOptionAttribute::Kind::Text) {
            MFnTypedAttribute fn;
            MFnStringData text;
            attribute = fn.create(name, name, MFnData::kString, text.create(MString(a.text.c_str())));
        } else {
            const MFnNumericData::Type type =
                a.kind == RedirectOptionAttribute::Kind::Int      ? MFnNumericData::kInt
                : a.kind == RedirectOptionAttribute::Kind::Double ? MFnNumericData::kDouble
                                                                  : MFnNumericData::kBoolean;
            MFnNumericAttribute fn;
            attribute = fn.create(name, name, type, a.number);
            if (a.minimum) fn.setMin(*a.minimum);
            if (a.maximum) fn.setMax(*a.maximum);
        }
        addAttribute(attribute);
        options.push_back(attribute);
    }
    MFnUnitAttribute unit;
    time = unit.create("time", "tim", MFnUnitAttribute::kTime, 0.0);
    addAttribute(time);
    MFnTypedAttribute typed;
    outFile = typed.create("outFile", "ouf", MFnData::kString);
    typed.setWritable(false);
    typed.setStorable(false);
    addAttribute(outFile);
    for (MObject* in : {&inMesh, &restMesh, &rigidity, &mask, &orientation, &preset, &tile, &output, &time})
        attributeAffects(*in, outFile);
    for (const MObject& option : options)
        attributeAffects(option, outFile);
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
        in.preset = block.inputValue(preset).asString().asChar();
        for (size_t i = 0; i < optionSpecs.size(); ++i) {
            MDataHandle value = block.inputValue(options[i]);
            switch (optionSpecs[i].kind) {
                case RedirectOptionAttribute::Kind::Int:
                    setRedirectOption(in, optionSpecs[i], value.asInt(), {});
                    break;
                case RedirectOptionAttribute::Kind::Double:
                    setRedirectOption(in, optionSpecs[i], value.asDouble(), {});
                    break;
                case RedirectOptionAttribute::Kind::Boolean:
                    setRedirectOption(in, optionSpecs[i], value.asBool() ? 1.0 : 0.0, {});
                    break;
                case RedirectOptionAttribute::Kind::Text:
                    setRedirectOption(in, optionSpecs[i], 0.0, value.asString().asChar());
                    break;
            }
        }
        const int frame = static_cast<int>(std::lround(block.inputValue(time).asTime().as(MTime::uiUnit())));
        // The rest mesh is read every frame (a copy of its points, polygons and UVs): a new one, or one
        // edited, builds the solver again.
        const geom::Mesh rest = meshWithUVs(block.inputValue(restMesh).asMesh(), MString(name()).asChar());
        if (node_.needsBuild(in, &rest)) node_.build(rest, in, frame, in.rigidity);
        MFnMesh deformed(block.inputValue(inMesh).asMesh());
        MPointArray points;
        deformed.getPoints(points, MSpace::kObject);
        points_.resize(points.length());
        for (unsigned i = 0; i < points.length(); ++i)
            points_[i] = {static_cast<float>(points[i].x), static_cast<float>(points[i].y),
                          static_cast<float>(points[i].z)};
        const io::Image map = node_.solve(in, frame, points_);
        for (const std::string& note : node_.takeNotes())
            MGlobal::displayWarning(MString(name()) + ": " + note.c_str());
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
