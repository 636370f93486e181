// The UV-warp stage of scenes as the reader makes it (scene/scene.h, scene/uvwarp_stage.h): the last stack
// entry becomes the object's texture-space stage with its options, tiles and outputs; bad entries name the
// scene file and the JSON path.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/scene.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "scene/uvwarp_scene_support.h"
#include "test_support.h"

using namespace deformkit;
using namespace test::uvwarp_scene;
using Catch::Contains;

TEST_CASE("scene uvwarp: the last stack entry becomes the object's texture-space stage", "[scene][uvwarp]") {
    Shot shot;
    const scene::Scene scene = scene::readScene(shot.scene);
    REQUIRE(scene.objects.size() == 1);
    const scene::SceneObject& object = scene.objects[0];
    CHECK(object.stack.size() == 1);  // the taper; the UV warp is not a geometric deformer
    REQUIRE(object.uvwarp.has_value());
    CHECK(object.uvwarp->label == "uvwarp2");
    CHECK(object.uvwarp->path == "objects[0].stack[1]");
    CHECK(object.uvwarp->tiles == std::vector<int>{1001, 1002});  // every tile of the rest UVs
    CHECK(object.uvwarp->rigidity == shot.dir / "rig.<UDIM>.exr");
    CHECK(object.uvwarp->options.solver.iterations == 6);
    CHECK(object.uvwarp->options.solver.tolerance == 0.0f);
    std::string withTolerance = kScene;
    const std::string params = R"("params": {"iterations": 6, "warmStart": true})";
    withTolerance.replace(withTolerance.find(params), params.size(),
                          R"("params": {"iterations": 6, "warmStart": true, "tolerance": 0.25})");
    test::writeText(shot.scene, withTolerance);
    CHECK(scene::readScene(shot.scene).objects[0].uvwarp->options.solver.tolerance == 0.25f);
    std::string relaxed = kScene;
    relaxed.replace(relaxed.find(params), params.size(),
                    R"("params": {"iterations": 6, "warmStart": true, "coarseRelaxation": 1.4, "maxLevels": 4,
                       "coldIterations": 2})");
    test::writeText(shot.scene, relaxed);
    CHECK(scene::readScene(shot.scene).objects[0].uvwarp->options.solver.coarseRelaxation == 1.4f);
    CHECK(scene::readScene(shot.scene).objects[0].uvwarp->options.solver.maxLevels == 4);
    CHECK(scene::readScene(shot.scene).objects[0].uvwarp->options.solver.coldIterations == 2);
    CHECK(object.uvwarp->options.solver.coarseRelaxation == 1.0f);  // the paper's, by default
    test::writeText(shot.scene, kScene);
    CHECK(object.uvwarp->options.solver.smoothing == uvwarp::SolverOptions{}.smoothing);
    CHECK(scene::uvwarpWarpedTiles(*object.uvwarp, std::vector<int>{1}) == std::vector<int>{1001, 1002});
    CHECK(scene::uvwarpOutputs(object, 1001, 7) ==
          std::vector<std::string>{"tubes.redirect.1001.0007.exr", "tubes.bake.1001.0007.exr"});
    CHECK(scene::uvwarpOutputs(object, 1002, -2) ==
          std::vector<std::string>{"tubes.redirect.1002.-0002.exr"});
    CHECK(scene::uvwarpOutputs(object, 1003, 1).empty());
}

TEST_CASE("scene uvwarp: bad UV-warp entries name the scene file and the JSON path",
          "[scene][uvwarp][errors]") {
    Shot shot;
    io::writeObj(shot.dir / "nouv.obj",
                 geom::Mesh(geom::Mesh::Data{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {3}, {0, 1, 2}}));
    const std::string head =
        R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [{"name": "t", "mesh": ")";
    struct Case {
        const char* mesh;
        const char* stack;
        const char* message;
    };
    const Case cases[] = {
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr"}, {"type": "twist"}])",
         ": objects[0].stack[0].type: is \"uvwarp\" at entry 0 of 2 (expected the UV warp as the last entry"},
        {"nouv.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr"}])",
         ": objects[0].stack[0]: is a UV warp on a rest mesh without UVs"},
        {"tubes.obj", R"([{"type": "uvwarp"}])", ": objects[0].stack[0].rigidity: is missing"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.exr"}])",
         ": objects[0].stack[0].rigidity: is \"rig.exr\", without a UDIM token"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "tiles": [1001, 1005]}])",
         ": objects[0].stack[0].tiles[1]: is 1005, a tile without UV faces (expected a tile of the rest "
         "mesh: "
         "1001 1002)"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "tiles": [1002, 1001, 1002]}])",
         ": objects[0].stack[0].tiles[2]: is 1002, listed before (expected each tile once)"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "resolution": 48}])",
         ": objects[0].stack[0].resolution: is 48"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "envelope": 0.5}])",
         ": objects[0].stack[0].envelope: is not a known key"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"damping": 2}}])",
         ": objects[0].stack[0].params.damping: is 2 (expected a number from 0 to 1)"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"tolerance": -0.1}}])",
         ": objects[0].stack[0].params.tolerance: is -0.1 (expected a number from 0 (off) to 1, grid cells)"},
        {"tubes.obj",
         R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"coarseRelaxation": 0.5}}])",
         ": objects[0].stack[0].params.coarseRelaxation: is 0.5 (expected a number from 1 to 2)"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"maxLevels": -2}}])",
         ": objects[0].stack[0].params.maxLevels: is -2 (expected a whole number from 0 (no cap) to 16)"},
        {"tubes.obj",
         R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"coldIterations": -1}}])",
         ": objects[0].stack[0].params.coldIterations: is -1 (expected a whole number from 0 (iterations) to "
         "100000)"},
        {"tubes.obj",
         R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"sweepsPerLevel": [0, 0]}}])",
         ": objects[0].stack[0].params.sweepsPerLevel: is [0,0] (expected a list of whole numbers from 0 to "
         "1000, not all 0; empty: by the grid's size, 4 8 16 up to 1024 cells, 4 8 16 32 64 from 2048; where "
         "a refinement follows, the finest level 2 from 1024 cells, and 2 8 64 16 at 1024)"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"warmStart": 0}}])",
         ": objects[0].stack[0].params.warmStart: is 0 (expected true or false)"},
        {"tubes.obj", R"([{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "filter": "lanczos"}])",
         ": objects[0].stack[0].filter: is \"lanczos\""},
        {"tubes.obj", R"([{"type": "uvwarps"}])", "uvwarp (last entry)"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.stack);
        const std::string text = head + c.mesh + R"(", "stack": )" + c.stack + "}]}";
        const std::string what =
            test::errorOf<InvalidInput>([&] { (void)scene::parseScene(text, shot.dir / "bad.json"); });
        CHECK_THAT(what, Contains((shot.dir / "bad.json").string() + c.message) ||
                             (Contains((shot.dir / "bad.json").string()) && Contains(c.message)));
    }
}
