#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "mesh_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;

namespace {

const char* kAnimated = R"({"deformkit_scene": 1, "frames": [1, 10], "objects": [{"name": "tube",
    "mesh": "tube.obj", "stack": [
    {"type": "twist", "params": {"endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": 10, "value": 2}]},
        "startAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": 4, "value": 0.3}, {"frame": 10, "value": -0.2}]}}},
    {"type": "taper", "envelope": {"keys": [{"frame": 1, "value": 0.2}, {"frame": 10, "value": 1}]},
        "params": {"endScale": {"keys": [{"frame": 1, "value": 1}, {"frame": 10, "value": 1.8}]}}}]}]})";

}  // namespace

TEST_CASE("evaluator: animated controls bind once per deformer over 10 frames", "[host][evaluator]") {
    test::TempDir dir;
    io::writeObj(dir / "tube.obj", test::tube());
    scene::SceneEvaluator evaluator(scene::parseScene(kAnimated, dir / "shot.json"));
    host::DeformerStack& stack = evaluator.stack(0);
    std::vector<glm::vec3> previous;
    for (int frame = 1; frame <= 10; ++frame) {
        const geom::Mesh& out = evaluator.evaluate(0, frame);
        // Every frame moves the mesh (the twist's end angle changes each frame).
        if (frame > 1) CHECK_FALSE(test::sameBits(out.points(), previous));
        previous.assign(out.points().begin(), out.points().end());
    }
    CHECK(stack.bindCount(0) == 1);
    CHECK(stack.bindCount(1) == 1);
    CHECK(stack.bindCount() == 2);
    CHECK(stack.get(0, "endAngle") == std::vector<double>{2.0});
    CHECK(stack.envelope(1) == 1.0);

    // A new rest mesh rebinds both entries once, and the output follows it.
    stack.setRest(test::tube({.radius = 0.25f}));
    const geom::Mesh& thin = evaluator.evaluate(0, 10);
    const geom::Mesh& thinAgain = evaluator.evaluate(0, 10);
    CHECK(stack.bindCount(0) == 2);
    CHECK(stack.bindCount(1) == 2);
    // The bottom ring (y = -1, twist angle startAngle, taper scale 1) keeps radius 0.25 after a rotation.
    CHECK(glm::length(glm::vec2(thinAgain.points()[0].x, thinAgain.points()[0].z)) ==
          Approx(0.25).margin(1e-6));  // float rotation of a 0.25 vector: a few ulps
    (void)thin;
}

TEST_CASE("evaluator: a frame's result does not depend on the frames evaluated before", "[host][evaluator]") {
    test::TempDir dir;
    io::writeObj(dir / "tube.obj", test::tube());
    scene::SceneEvaluator played(scene::parseScene(kAnimated, dir / "shot.json"));
    for (int frame = 1; frame <= 7; ++frame)
        (void)played.evaluate(0, frame);
    scene::SceneEvaluator alone(scene::parseScene(kAnimated, dir / "shot.json"));
    // Same values set on stacks bound to the same rest mesh: bit-identical (a farm job at frame 7 alone).
    CHECK(test::sameBits(played.evaluate(0, 7).points(), alone.evaluate(0, 7).points()));
    CHECK(alone.stack(0).bindCount() == 2);
}

TEST_CASE("evaluator: an animated bind-time parameter rebinds when its value moves", "[host][evaluator]") {
    test::TempDir dir;
    io::writeObj(dir / "tube.obj", test::tube());
    const std::string text = R"({"deformkit_scene": 1, "frames": [1, 10], "objects": [{"name": "tube",
        "mesh": "tube.obj", "stack": [{"type": "twist", "params": {"handleOrigin": {"keys": [
        {"frame": 1, "value": [0, 0, 0]}, {"frame": 4, "value": [0, 0.5, 0], "interpolation": "constant"}]},
        "endAngle": 1}}]}]})";
    scene::SceneEvaluator evaluator(scene::parseScene(text, dir / "shot.json"));
    for (int frame = 1; frame <= 10; ++frame)
        (void)evaluator.evaluate(0, frame);
    // The origin moves on frames 2, 3 and 4 (Bezier from 1 to 4, then held): binds at 1, 2, 3, 4.
    CHECK(evaluator.stack(0).bindCount(0) == 4);
    CHECK(evaluator.stack(0).get(0, "endAngle") == std::vector<double>{1.0});
}

TEST_CASE("evaluator: constraints checked at bind name the scene, path and frame",
          "[host][evaluator][errors]") {
    test::TempDir dir;
    io::writeObj(dir / "tube.obj", test::tube());
    const std::string text = R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [{"name": "tube",
        "mesh": "tube.obj", "stack": [{"type": "twist", "params": {"lowBound": 1, "highBound": {"keys": [
        {"frame": 1, "value": 2, "interpolation": "linear"}, {"frame": 3, "value": 0}]}}}]}]})";
    scene::SceneEvaluator evaluator(scene::parseScene(text, dir / "shot.json"));
    CHECK_NOTHROW(evaluator.evaluate(0, 1));
    try {
        (void)evaluator.evaluate(0, 3);
        FAIL("no error");
    } catch (const InvalidInput& e) {
        CHECK_THAT(e.what(), Contains((dir / "shot.json").string()) && Contains("objects[0].stack") &&
                                 Contains("frame 3") && Contains("stack entry 0 (twist 'twist1')"));
    }
    CHECK_THROWS_AS(evaluator.evaluate(1, 1), InvalidInput);
}
