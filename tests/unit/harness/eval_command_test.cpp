#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/obj.h"
#include "eval_command.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;

namespace {

// A tube around the Y axis from y = -1 to 1 with UVs (u around, v along), quads.
geom::Mesh makeTube(int rings = 6, int sides = 10) {
    geom::Mesh::Data d;
    for (int r = 0; r < rings; ++r) {
        const float y = -1.0f + 2.0f * static_cast<float>(r) / static_cast<float>(rings - 1);
        for (int s = 0; s < sides; ++s) {
            const double a = 2.0 * std::numbers::pi * s / sides;
            d.points.emplace_back(0.5f * static_cast<float>(std::cos(a)), y,
                                  0.5f * static_cast<float>(std::sin(a)));
            d.uvs.emplace_back(static_cast<float>(s) / sides, static_cast<float>(r) / (rings - 1));
        }
    }
    for (int r = 0; r + 1 < rings; ++r) {
        for (int s = 0; s < sides; ++s) {
            const int s1 = (s + 1) % sides;
            d.faceCounts.push_back(4);
            d.faceIndices.insert(d.faceIndices.end(),
                                 {r * sides + s, r * sides + s1, (r + 1) * sides + s1, (r + 1) * sides + s});
        }
    }
    d.uvIndices = d.faceIndices;
    return geom::Mesh(std::move(d), "tube");
}

const char* kScene = R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [
  {"name": "tube", "mesh": "tube.obj", "stack": [
    {"type": "twist", "label": "twist1", "params": {"handleY": [0, 1, 0],
       "endAngle": {"keys": [{"frame": 1, "value": 0, "interpolation": "linear"}, {"frame": 3, "value": 1.5}]}}},
    {"type": "bend", "label": "bend1", "envelope": {"keys": [{"frame": 1, "value": 0}, {"frame": 3, "value": 1}]},
       "params": {"curvature": 0.8}}]},
  {"name": "still", "mesh": "tube.obj", "stack": []}]})";

}  // namespace

TEST_CASE("eval command: file names pad the frame to 4 digits after the sign", "[harness][eval]") {
    CHECK(harness::evalFileName("tube", 7) == "tube.0007.obj");
    CHECK(harness::evalFileName("tube", 12345) == "tube.12345.obj");
    CHECK(harness::evalFileName("tube", -3) == "tube.-0003.obj");
}

TEST_CASE("eval command: writes every object at every frame, equal to the stack evaluated directly",
          "[harness][eval]") {
    test::TempDir dir;
    const geom::Mesh tube = makeTube();
    io::writeObj(dir / "tube.obj", tube);
    test::writeText(dir / "shot.json", kScene);

    harness::EvalCommand command;
    command.scene = dir / "shot.json";
    command.outDir = dir / "out" / "frames";  // created when missing
    std::ostringstream progress;
    const harness::EvalReport report = harness::evalCommand(command, &progress);
    CHECK(report.frames == std::vector<int>{1, 2, 3});
    REQUIRE(report.files.size() == 6);
    for (int frame = 1; frame <= 3; ++frame) {
        CHECK(std::filesystem::is_regular_file(command.outDir / harness::evalFileName("tube", frame)));
        CHECK(std::filesystem::is_regular_file(command.outDir / harness::evalFileName("still", frame)));
    }
    // No temporaries left behind by the atomic writes.
    CHECK(std::distance(std::filesystem::directory_iterator(command.outDir), {}) == 6);
    CHECK_THAT(progress.str(), Contains("eval: frame 1 (1/3)") && Contains("eval: frame 3 (3/3)"));
    CHECK(report.binds == std::vector<int64_t>{2, 0});  // each deformer once; the bend skipped at envelope 0
                                                        // on frame 1 binds on frame 2

    // Reference: the same stack built by hand, at frame 2 (endAngle 0.75 exactly; the bend's envelope
    // Bezier between two auto keys at the midpoint is 0.5).
    host::DeformerStack stack;
    stack.setRest(tube);
    stack.add(host::makeDeformer("twist", "twist1"));
    stack.add(host::makeDeformer("bend", "bend1"));
    stack.set(0, "handleY", std::vector<double>{0, 1, 0});
    stack.set(0, "endAngle", 0.75);
    stack.set(1, "curvature", 0.8);
    stack.setEnvelope(1, 0.5);
    std::vector<glm::vec3> expected(tube.points().begin(), tube.points().end());
    stack.evaluate(expected);

    const io::ObjContent written = io::readObj(command.outDir / "tube.0002.obj");
    REQUIRE(written.mesh.numVertices() == tube.numVertices());
    CHECK(std::equal(written.mesh.faceIndices().begin(), written.mesh.faceIndices().end(),
                     tube.faceIndices().begin()));
    CHECK(written.mesh.hasUVs());
    // The writer's default 9 significant digits round-trip float32 exactly, so the tolerance is 0.
    float maxError = 0.0f, maxMove = 0.0f;
    for (int32_t v = 0; v < tube.numVertices(); ++v) {
        maxError = std::max(maxError, glm::length(written.mesh.points()[v] - expected[v]));
        maxMove = std::max(maxMove, glm::length(expected[v] - tube.points()[v]));
    }
    CHECK(maxError == 0.0f);
    CHECK(maxMove > 0.1f);  // the reference really deforms
    // The object with an empty stack is its rest mesh at every frame.
    const io::ObjContent still = io::readObj(command.outDir / "still.0003.obj");
    CHECK(std::equal(still.mesh.points().begin(), still.mesh.points().end(), tube.points().begin()));

    // --frames overrides the scene's range.
    command.frames = {5};
    command.outDir = dir / "five";
    CHECK(harness::evalCommand(command).files.size() == 2);
    CHECK(std::filesystem::is_regular_file(dir / "five" / "tube.0005.obj"));
}

TEST_CASE("eval command: a bad scene names the file and JSON path and writes nothing",
          "[harness][eval][errors]") {
    test::TempDir dir;
    io::writeObj(dir / "tube.obj", makeTube());
    std::string text = kScene;
    text.replace(text.find("\"curvature\""), std::strlen("\"curvature\""), "\"curvatur\"");
    test::writeText(dir / "shot.json", text);
    harness::EvalCommand command;
    command.scene = dir / "shot.json";
    command.outDir = dir / "out";
    try {
        (void)harness::evalCommand(command);
        FAIL("no error");
    } catch (const InvalidInput& e) {
        CHECK_THAT(e.what(),
                   Contains((dir / "shot.json").string() + ": objects[0].stack[1].params.curvatur"));
    }
    CHECK_FALSE(std::filesystem::exists(dir / "out"));
}
