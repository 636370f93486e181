#include "slide_command.h"
#include <iostream>
#include "cli.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "deformkit/error.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/scene/weights_file.h"

namespace deformkit::harness {
namespace {

namespace fs = std::filesystem;

// Comma-separated numbers; false when a field is empty, not a number, or not finite.
bool parseNumbers(std::string_view text, std::vector<double>& out) {
    out.clear();
    size_t start = 0;
    while (true) {
        const size_t comma = text.find(',', start);
        const std::string field(
            text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
        if (field.empty()) return false;
        // Decimal numbers only (from_chars, not strtod: "0x1" is no coordinate), spaces around them.
        const char* begin = field.data();
        const char* last = field.data() + field.size();
        while (begin < last && *begin == ' ')
            ++begin;
        if (begin < last && *begin == '+') ++begin;
        double value = 0.0;
        const auto [end, error] = std::from_chars(begin, last, value, std::chars_format::general);
        if (error != std::errc() || end == begin) return false;
        const char* rest = end;
        while (rest < last && *rest == ' ')
            ++rest;
        if (rest != last || !std::isfinite(value)) return false;
        out.push_back(value);
        if (comma == std::string_view::npos) return true;
        start = comma + 1;
    }
}

}  // namespace

glm::dvec3 parsePoint(std::string_view text, const std::string& option) {
    std::vector<double> v;
    if (!parseNumbers(text, v) || v.size() != 3) {
        throw InvalidInput(formatError(option, "", "'" + std::string(text) + "' is not a point",
                                       "three finite numbers: x,y,z"));
    }
    return {v[0], v[1], v[2]};
}

slide::Falloff parseFalloff(std::string_view text, const std::string& option) {
    if (text == "smooth") return slide::Falloff::smooth();
    if (text == "linear") return slide::Falloff::linear();
    std::vector<double> v;
    if (!parseNumbers(text, v)) {
        throw InvalidInput(formatError(option, "", "'" + std::string(text) + "' is not a falloff",
                                       "smooth, linear, or ramp samples v0,v1,... in [0, 1]"));
    }
    std::vector<float> samples(v.begin(), v.end());
    return slide::Falloff::ramp(samples, option);
}

slide::SlideResult slideCommand(const SlideCommand& command) {
    // The output is never one of the files read: the slid mesh would replace the rest mesh.
    std::vector<io::FileUse> files = {{command.out, "the output (--out)", true}, {command.mesh, "the mesh"}};
    if (command.weights) files.push_back({*command.weights, "the weights (--weights)"});
    if (command.weightsPtex) files.push_back({*command.weightsPtex, "the weights (--weights-ptex)"});
    io::requireFilesApart(files);
    io::ObjContent obj = io::readMesh(command.mesh);
    const size_t count = static_cast<size_t>(obj.mesh.numVertices());
    if (command.weights && command.weightsPtex) {
        throw InvalidInput(
            formatError("--weights-ptex", "", "is given with --weights", "one source of painted weights"));
    }
    const std::vector<float> weights =
        command.weights       ? scene::readWeightsFile(*command.weights, count)
        : command.weightsPtex ? ptex::weightsFromPtex(obj.mesh, command.mesh.string(), *command.weightsPtex,
                                                      command.weightsChannel, "--weights-ptex")
                              : std::vector<float>{};
    slide::Slider slider(obj.mesh, {command.handle}, command.options, command.mesh.string());
    const std::vector<slide::SlideDrive> drives = {{command.to - command.from, command.falloff}};
    std::vector<glm::vec3> points(obj.mesh.points().begin(), obj.mesh.points().end());
    slide::SlideResult result;
    slider.evaluate(drives, points, weights, command.envelope, &result);
    obj.mesh.setPoints(points);
    io::writeObj(command.out, obj.mesh, obj.groups);
    return result;
}

std::string slideSummary(const fs::path& out, const slide::SlideResult& result) {
    std::string text =
        "wrote " + out.string() + ": moved " + std::to_string(result.moved) + ", limited " +
        std::to_string(result.limited) + " (boundary-stopped " + std::to_string(result.boundaryStopped) +
        ", walk-limit-stopped " + std::to_string(result.walkLimitStopped) + "), flipped triangles " +
        std::to_string(result.flippedTriangles) + ", unreachable " + std::to_string(result.unreachable) +
        ", without a tangent plane " + std::to_string(result.withoutTangentPlane) +
        ", degenerate triangles " + std::to_string(result.degenerateTriangles);
    if (!result.foldScale.empty() && result.foldScale[0] < 1.0) {
        std::ostringstream scale;
        scale << result.foldScale[0];
        text += ", fold limit: drag scaled to " + scale.str();
    }
    if (result.welded > 0) {
        text += "; " + std::to_string(result.welded) +
                " split vertices welded onto a coincident vertex (counts are of welded vertices)";
    }
    return text;
}

void addSlideCommand(CommandLine& cli) {
    struct Options {
        SlideCommand command;
        std::string mesh, out, from, to, falloff = "smooth", weights, weightsPtex, region = "euclidean",
                                         surface = "cage", paintedWeights = "scale";
    };
    auto o = std::make_shared<Options>();
    Command slide = cli.add("slide", "Slide vertices over the surface around a handle (Pinskiy)", [o] {
        SlideCommand& c = o->command;
        c.mesh = o->mesh;
        c.out = o->out;
        c.from = parsePoint(o->from, "--from");
        c.to = parsePoint(o->to, "--to");
        c.falloff = parseFalloff(o->falloff);
        if (!o->weights.empty()) c.weights = o->weights;
        if (!o->weightsPtex.empty()) c.weightsPtex = o->weightsPtex;
        c.handle.region =
            o->region == "geodesic" ? slide::RegionMetric::Geodesic : slide::RegionMetric::Euclidean;
        c.options.surface = o->surface == "limit" ? slide::SurfaceMode::Limit : slide::SurfaceMode::Cage;
        c.options.weights = o->paintedWeights == "falloff" ? slide::PaintedWeights::AreFalloff
                                                           : slide::PaintedWeights::ScaleFalloff;
        const slide::SlideResult result = slideCommand(c);
        std::cout << slideSummary(o->out, result) << "\n";
        return 0;
    });
    slide.option("MESH", o->mesh, "mesh (.obj, .gltf, .glb, .fbx, .ply, .dae)").required();
    slide.option("--handle", o->command.handle.vertex, "handle vertex index (0-based)").required();
    slide.option("--from", o->from, "start locator x,y,z").required();
    slide.option("--to", o->to, "end locator x,y,z: the handle region slides by to - from").required();
    slide.option("--radius", o->command.handle.radius, "support radius, scene units").required();
    slide.option("--out", o->out, "output mesh (.obj): the slid positions, UVs, faces and groups").required();
    slide.option("--falloff", o->falloff, "smooth, linear, or ramp samples v0,v1,... over distance/radius")
        .showDefault();
    slide.option("--weights", o->weights, "painted weights: a JSON array of one number per vertex");
    const Option ptex = slide.option("--weights-ptex", o->weightsPtex,
                                     "painted weights from a Ptex map of the mesh (per-vertex values)");
    slide
        .option("--weights-channel", o->command.weightsChannel,
                "the Ptex map's channel (needs --weights-ptex)")
        .showDefault()
        .needs(ptex);
    slide
        .option("--painted-weights", o->paintedWeights,
                "scale (weight x falloff) or falloff (the paper's: the weight is the falloff, the radius "
                "only bounds the region)")
        .choices({"scale", "falloff"})
        .showDefault();
    slide.flag("--fold-limit", o->command.options.foldLimit,
               "scale the drag down so that no triangle of the region flips");
    slide.option("--envelope", o->command.envelope, "scales every slide").showDefault();
    slide.option("--region", o->region, "euclidean (3D distance) or geodesic (over the surface)")
        .choices({"euclidean", "geodesic"})
        .showDefault();
    slide.option("--surface", o->surface, "cage (the mesh) or limit (its Catmull-Clark limit surface)")
        .choices({"cage", "limit"})
        .showDefault();
    slide
        .option("--max-walk", o->command.options.maxWalkTriangles,
                "triangles one vertex may cross before it stops")
        .positive()
        .showDefault();
    slide
        .option("--weld-tolerance", o->command.options.weldTolerance,
                "split vertices within this distance are one vertex (0: exactly coincident)")
        .showDefault();
}

}  // namespace deformkit::harness
