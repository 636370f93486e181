#include <catch2/catch.hpp>

#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "mesh_support.h"
#include "point_cache_support.h"
#include "test_support.h"

// Objects whose mesh is a frame sequence (an animated input under the stack, as after skinning).

using namespace deformkit;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

// A tube around the Y axis, swaying along X with the frame and shrinking in radius: every frame differs.
geom::Mesh tubeAt(int frame, int rings = 5, int sides = 8) {
    geom::Mesh::Data d;
    test::appendTube(d, {.rings = rings, .sides = sides, .radius = 0.5f - 0.02f * static_cast<float>(frame)});
    for (glm::vec3& p : d.points)
        p.x += 0.05f * static_cast<float>(frame) * p.y;
    return geom::Mesh(std::move(d), "tube");
}

std::string sceneText(const std::string& objectExtra, const std::string& mesh = "anim.####.obj") {
    return R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [{"name": "tube", "mesh": ")" + mesh +
           R"(", )" + objectExtra + R"("stack": [
      {"type": "twist", "envelope": 0.5, "params": {"endAngle": {"keys": [{"frame": 1, "value": 0.2, "interpolation": "linear"},
                                                                {"frame": 3, "value": 1.0}]}}}]}]})";
}

}  // namespace

TEST_CASE("sequence input: each frame's positions enter the stack bound to the rest frame",
          "[host][evaluator]") {
    test::TempDir dir;
    for (int f = 1; f <= 3; ++f)
        io::writeObj(dir / ("anim.000" + std::to_string(f) + ".obj"), tubeAt(f));
    for (int restFrame : {1, 2}) {
        CAPTURE(restFrame);
        const std::string extra = restFrame == 1 ? "" : R"("restFrame": 2, )";
        scene::SceneEvaluator evaluator(scene::parseScene(sceneText(extra), dir / "shot.json"));
        CHECK(evaluator.scene().objects[0].meshFile ==
              dir / ("anim.000" + std::to_string(restFrame) + ".obj"));
        // The reference: a stack bound to the rest frame's mesh, evaluated on each frame's positions.
        host::DeformerStack stack;
        stack.setRest(tubeAt(restFrame));
        const size_t twist = stack.add(host::makeDeformer("twist", "t"));
        stack.setEnvelope(twist, 0.5);
        for (int f = 1; f <= 3; ++f) {
            stack.set(twist, "endAngle", 0.2 + 0.4 * (f - 1));
            const geom::Mesh input = tubeAt(f);
            std::vector<glm::vec3> expected(input.points().begin(), input.points().end());
            stack.evaluate(expected);
            const geom::Mesh& got = evaluator.evaluate(0, f);
            REQUIRE(got.numVertices() == input.numVertices());
            CHECK(std::memcmp(got.points().data(), expected.data(), expected.size() * sizeof(glm::vec3)) ==
                  0);
            // Not the rest pose pushed through the stack: the input moves.
            if (f != restFrame) CHECK(got.points()[0] != evaluator.scene().objects[0].rest.points()[0]);
        }
        CHECK(evaluator.stack(0).bindCount() == 1);  // bound once, to the rest frame
    }
}

TEST_CASE("sequence input: missing, fractional and mismatched frames name the scene, the mesh and the file",
          "[host][evaluator][errors]") {
    test::TempDir dir;
    for (int f = 1; f <= 2; ++f)
        io::writeObj(dir / ("anim.000" + std::to_string(f) + ".obj"), tubeAt(f));
    io::writeObj(dir / "anim.0003.obj", tubeAt(3, 4, 8));  // one ring fewer
    scene::SceneEvaluator evaluator(scene::parseScene(sceneText(""), dir / "shot.json"));
    const std::string source = (dir / "shot.json").string();
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)evaluator.evaluate(0, 4); }),
               Contains(source + ": objects[0].mesh: ") && Contains("anim.0004.obj: frame 4: is missing"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)evaluator.evaluate(0, 1.5); }),
               Contains(source + ": objects[0].mesh: frame 1.5 of the animated input ") &&
                   Contains("(expected whole frames for an object with an animated input)"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)evaluator.evaluate(0, 3); }),
               Contains(source + ": objects[0].mesh: ") && Contains("anim.0003.obj: has 32 vertices"));
    // Frames that exist still evaluate after the errors.
    CHECK(evaluator.evaluate(0, 2).numVertices() == tubeAt(2).numVertices());

    io::writeObj(dir / "tube.obj", tubeAt(1));
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)scene::parseScene(
                       R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [{"name": "t",
                        "mesh": "tube.obj", "restFrame": 2, "stack": []}]})",
                       dir / "shot.json");
               }),
               Contains(source + ": objects[0].restFrame: is given for the single mesh "));
    CHECK_THAT(test::errorOf<InvalidInput>(
                   [&] { (void)scene::parseScene(sceneText(R"("restFrame": 9, )"), dir / "shot.json"); }),
               Contains(source + ": objects[0].mesh: names the sequence ") && Contains("rest frame 9"));
}

TEST_CASE(
    "sequence input: a point cache or an OBJ sequence under \"deformed\" drives the stack as the mesh "
    "sequence does",
    "[host][evaluator][point_cache]") {
    test::TempDir dir;
    std::vector<std::vector<glm::vec3>> positions;
    for (int f = 1; f <= 3; ++f) {
        io::writeObj(dir / ("anim.000" + std::to_string(f) + ".obj"), tubeAt(f));
        // As the OBJ reader gives them, so that every input carries the same floats.
        const io::ObjContent obj = io::readObj(dir / ("anim.000" + std::to_string(f) + ".obj"));
        const auto p = obj.mesh.points();
        positions.emplace_back(p.begin(), p.end());
    }
    io::writeObj(dir / "tube.obj", tubeAt(1));
    test::writeText(dir / "anim.pc2", test::pc2Bytes(1.0f, 1.0f, positions));
    test::writeText(dir / "anim.mdd", test::mddBytes({0.0f, 0.5f, 1.0f}, positions));
    scene::SceneEvaluator reference(scene::parseScene(sceneText(""), dir / "shot.json"));
    for (const std::string& extra :
         {std::string(R"("deformed": "anim.pc2", )"), std::string(R"("deformed": "anim.mdd", )"),
          std::string(R"("deformed": "anim.mdd", "cacheStart": 1, )"),
          std::string(R"("deformed": "anim.%04d.obj", )")}) {
        CAPTURE(extra);
        scene::SceneEvaluator evaluator(scene::parseScene(sceneText(extra, "tube.obj"), dir / "shot.json"));
        const std::vector<int> frames{1, 2, 3};
        evaluator.check(frames);
        for (int f = 1; f <= 3; ++f) {
            const geom::Mesh& want = reference.evaluate(0, f);
            const geom::Mesh& got = evaluator.evaluate(0, f);
            CHECK(test::sameBits(got.points(), want.points()));
        }
    }

    const std::string source = (dir / "shot.json").string();
    auto parse = [&](const std::string& extra, const std::string& mesh = "tube.obj") {
        return scene::parseScene(sceneText(extra, mesh), dir / "shot.json");
    };
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)parse(R"("deformed": "anim.obj", )"); }),
               Contains(source + ": objects[0].deformed: is ") && Contains("no point cache"));
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] { (void)parse(R"("deformed": "anim.pc2", )", "anim.####.obj"); }),
        Contains(source + ": objects[0].deformed: is given with the sequence "));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)parse(R"("cacheStart": 1, )"); }),
               Contains(source + ": objects[0].cacheStart: is given without a point cache"));
    // The cache's vertex count against the rest mesh's, and its frames against the evaluated ones.
    io::writeObj(dir / "fine.obj", tubeAt(1, 6, 8));
    CHECK_THAT(test::errorOf<InvalidInput>(
                   [&] { scene::SceneEvaluator e(parse(R"("deformed": "anim.pc2", )", "fine.obj")); }),
               Contains(source + ": objects[0].deformed: ") &&
                   Contains("anim.pc2: header: has 40 vertices") &&
                   Contains("expected 48 vertices, as the rest mesh"));
    scene::SceneEvaluator late(parse(R"("deformed": "anim.pc2", )"));
    const std::vector<int> beyond{3, 4};
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] { late.check(beyond); }),
        Contains(source + ": objects[0].deformed: ") && Contains("anim.pc2: frame 4: is not in the cache"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)late.evaluate(0, 4); }),
               Contains(source + ": objects[0].deformed: ") &&
                   Contains("anim.pc2: frame 4: is not in the cache (expected one of its frames 1 to 3)"));
    // A frame is read alone: a NaN in frame 1 does not stop frames 2 and 3.
    auto broken = positions;
    broken[0][5].x = std::numeric_limits<float>::quiet_NaN();
    test::writeText(dir / "broken.pc2", test::pc2Bytes(1.0f, 1.0f, broken));
    scene::SceneEvaluator partial(parse(R"("deformed": "broken.pc2", )"));
    CHECK(test::sameBits(partial.evaluate(0, 3).points(), reference.evaluate(0, 3).points()));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)partial.evaluate(0, 1); }),
               Contains(source + ": objects[0].deformed: ") && Contains("broken.pc2: frame 1: vertex 5"));
}
