#include <catch2/catch.hpp>

#include <omp.h>

#include <set>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/farm_plan.h"
#include "deformkit/scene/scene.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/tile_warp.h"
#include "eval_command.h"
#include "farm_command.h"
#include "farm_plan_edits.h"
#include "mesh_support.h"
#include "scene/uvwarp_scene_support.h"
#include "test_support.h"

// The UV-warp stage of scenes through `deformkit eval` and farm tasks, checked against TileWarp driven
// directly by a DeformerStack built in the test (the scene's own reading: tests/unit/scene).

using namespace deformkit;
using Catch::Contains;
namespace fs = std::filesystem;
using namespace test::uvwarp_scene;

TEST_CASE("scene uvwarp: eval writes per tile and frame the maps of TileWarp fed by the stack",
          "[harness][uvwarp][eval]") {
    Shot shot;
    harness::EvalCommand command;
    command.scene = shot.scene;
    command.outDir = shot.dir / "eval";
    command.previews = false;
    const harness::EvalReport report = harness::evalCommand(command);
    REQUIRE(report.uvwarpLines.size() >= 2);
    CHECK_THAT(report.uvwarpLines[0], Contains("tubes tile 1001: 3 frames written (3 baked)"));
    // Each frame's stack is evaluated once and feeds the OBJ and both tiles.
    CHECK(report.evaluations == std::vector<int64_t>{3});

    // The reference: one TileWarp per tile, solved over frames 1..3 in order with the same options,
    // fed by the stack built by hand.
    uvwarp::TileWarpOptions options = uvwarp::shotOptions();  // and the scene's params
    options.solver.iterations = 6;
    options.solver.warmStart = true;
    const io::Image rigidity = uvwarp::readRigidityMap(shot.dir / "rig.1001.exr", 1001);
    for (int tile : {1001, 1002}) {
        uvwarp::TileWarp warp(shot.rest, tile, rigidity, {}, options);
        for (int frame = 1; frame <= 3; ++frame) {
            const std::vector<glm::vec3> points = stackPoints(shot.rest, frame);
            warp.solve(points);
            const io::Image expected = warp.redirect();
            const fs::path file = command.outDir / scene::uvwarpRedirectName("tubes", tile, frame);
            const io::Image written = io::readImage(file);
            REQUIRE(written.width == expected.width);
            REQUIRE(written.channels == 2);
            // Float EXR: the solver's floats exactly.
            CHECK(written.pixels == expected.pixels);
            // Not the identity: the taper stretches the rigid disks, the warp moves texels.
            const uvwarp::WarpMetrics m = warp.metrics();
            CHECK(m.rigidStretchError < 0.8 * m.identityStretchError);
            CHECK(m.foldOvers == 0);
            if (tile == 1001) {
                // The bake: bakeTexture through the same redirect, written as a half-float EXR. Its texels
                // are bilinear blends of multiples of 1/256 in [0, 1): half floats keep 11 significant
                // bits, so each is within 2^-12 of the float value.
                const io::Image bake = uvwarp::bakeTexture(test::exactHalfTexture(kTexels), expected);
                const io::Image baked = io::readImage(command.outDir / ("tubes.bake.1001." +
                                                                        std::string(frame == 1   ? "0001"
                                                                                    : frame == 2 ? "0002"
                                                                                                 : "0003") +
                                                                        ".exr"));
                REQUIRE(baked.pixels.size() == bake.pixels.size());
                for (size_t i = 0; i < bake.pixels.size(); ++i)
                    REQUIRE(std::abs(baked.pixels[i] - bake.pixels[i]) <= 1.0f / 4096.0f);
            }
        }
    }
    // No bake for tile 1002 (no texture there), meshes for every frame.
    CHECK(!fs::exists(command.outDir / "tubes.bake.1002.0001.exr"));
    CHECK(fs::exists(command.outDir / "tubes.0003.obj"));
}

TEST_CASE(
    "scene uvwarp: farm tasks are frame ranges x tiles; warmed up from the shot's start they write eval's "
    "bytes, and resume",
    "[harness][uvwarp][farm]") {
    Shot shot;
    harness::FarmPlanCommand planCommand;
    planCommand.scene = shot.scene;
    planCommand.chunk = 2;  // frames 1-2 and 3
    planCommand.outDir = shot.dir / "farm";
    REQUIRE(planCommand.warmUp == 6);  // the default: the task of frame 3 first solves frames 1 and 2
    const scene::FarmPlan plan = harness::farmPlanCommand(planCommand);
    const fs::path planFile = harness::farmPlanPath(planCommand);
    // 2 mesh tasks, then 2 ranges x 2 tiles.
    REQUIRE(plan.tasks.size() == 6);
    CHECK(plan.tasks[0].tiles.empty());
    CHECK(plan.tasks[1].tiles.empty());
    CHECK(plan.tasks[2].tiles == std::vector<int>{1001});
    CHECK(plan.tasks[2].firstFrame == 1);
    CHECK(plan.tasks[2].lastFrame == 2);
    CHECK(plan.tasks[2].outputs ==
          std::vector<std::string>{"tubes.redirect.1001.0001.exr", "tubes.bake.1001.0001.exr",
                                   "tubes.redirect.1001.0002.exr", "tubes.bake.1001.0002.exr"});
    CHECK(plan.tasks[3].tiles == std::vector<int>{1002});
    CHECK(plan.tasks[5].outputs == std::vector<std::string>{"tubes.redirect.1002.0003.exr"});
    // The plan file reads back the same.
    const scene::FarmPlan read = scene::readFarmPlan(planFile);
    REQUIRE(read.tasks.size() == 6);
    CHECK(read.tasks[4].tiles == std::vector<int>{1001});

    for (int k = 0; k < 6; ++k) {
        std::ostringstream log;
        const scene::FarmTaskReport report = harness::farmRunCommand({planFile, k}, &log);
        CHECK(report.skipped.empty());
        if (k >= 2) {
            // One JSON line per tile and frame, naming task, object and tile; the warm-up frames before the
            // range (from the scene's first frame) without outputs.
            std::istringstream in(log.str());
            int written = 0, warmUp = 0;
            for (std::string line; std::getline(in, line);) {
                const nlohmann::json j = nlohmann::json::parse(line);
                CHECK(j["task"] == k);
                CHECK(j["object"] == "tubes");
                CHECK(j["tile"] == plan.tasks[k].tiles[0]);
                const bool before = j["frame"].get<int>() < plan.tasks[k].firstFrame;
                CHECK(j["status"] == (before ? "warm-up" : "written"));
                CHECK(j.contains("redirect") == !before);
                (before ? warmUp : written) += 1;
            }
            CHECK(written == plan.tasks[k].lastFrame - plan.tasks[k].firstFrame + 1);
            CHECK(warmUp == plan.tasks[k].firstFrame - 1);
        }
    }
    // The reference: one eval over the whole shot. The warm-up reaches back to the shot's first frame, so
    // every task solves exactly the frames the uninterrupted run solved before its outputs.
    harness::EvalCommand eval123;
    eval123.scene = shot.scene;
    eval123.outDir = shot.dir / "eval123";
    eval123.previews = false;
    (void)harness::evalCommand(eval123);
    std::vector<fs::path> expected{"farm_plan.json"};
    for (const scene::FarmTask& task : plan.tasks) {
        for (const std::string& name : task.outputs) {
            expected.emplace_back(name);
            CAPTURE(name);
            CHECK(test::readText(shot.dir / "farm" / name) == test::readText(eval123.outDir / name));
        }
    }
    // Eval given the scene by a relative path writes the same bytes: both name their inputs by absolute
    // path in the maps' provenance.
    harness::EvalCommand relative = eval123;
    relative.scene = fs::relative(shot.scene, fs::current_path());
    REQUIRE(relative.scene.is_relative());
    relative.outDir = shot.dir / "eval_relative";
    (void)harness::evalCommand(relative);
    for (const scene::FarmTask& task : plan.tasks) {
        for (const std::string& name : task.outputs) {
            CAPTURE(name);
            CHECK(test::readText(shot.dir / "farm" / name) == test::readText(relative.outDir / name));
        }
    }
    // Without warm-up a task starts cold at its first frame: eval over its range alone is the reference.
    harness::FarmPlanCommand coldCommand = planCommand;
    coldCommand.warmUp = 0;
    coldCommand.outDir = shot.dir / "cold";
    const scene::FarmPlan cold = harness::farmPlanCommand(coldCommand);
    CHECK(scene::readFarmPlan(harness::farmPlanPath(coldCommand)).warmUp == 0);
    CHECK(scene::readFarmPlan(planFile).warmUp == 6);
    harness::EvalCommand eval3 = eval123;
    eval3.frames = {3};
    eval3.outDir = shot.dir / "eval3";
    (void)harness::evalCommand(eval3);
    for (int k = 2; k < 6; ++k) {
        (void)harness::farmRunCommand({harness::farmPlanPath(coldCommand), k});
        if (cold.tasks[k].firstFrame != 3) continue;
        for (const std::string& name : cold.tasks[k].outputs) {
            CAPTURE(name);
            CHECK(test::readText(shot.dir / "cold" / name) == test::readText(eval3.outDir / name));
            CHECK(test::readText(shot.dir / "cold" / name) != test::readText(eval123.outDir / name));
        }
    }
    std::sort(expected.begin(), expected.end());
    CHECK(test::filesIn(shot.dir / "farm") == expected);
    // Frames differ (the shot is animated), so the equalities are not vacuous.
    CHECK(test::readText(shot.dir / "farm" / "tubes.redirect.1001.0001.exr") !=
          test::readText(shot.dir / "farm" / "tubes.redirect.1001.0002.exr"));

    // A redirect map lost: the task replays frame 1 for the warm start and writes frame 2's map again, the
    // same bytes; the bake of frame 2, still there, is kept.
    const fs::path lost = shot.dir / "farm" / "tubes.redirect.1001.0002.exr";
    const std::string before = test::readText(lost);
    const auto past = fs::file_time_type::clock::now() - std::chrono::hours(1);
    fs::last_write_time(shot.dir / "farm" / "tubes.bake.1001.0002.exr", past);
    fs::remove(lost);
    std::ostringstream log;
    const scene::FarmTaskReport again = harness::farmRunCommand({planFile, 2}, &log);
    CHECK(again.written == std::vector<int>{2});
    CHECK(again.skipped == std::vector<int>{1});
    CHECK(again.files == std::vector<fs::path>{lost});
    CHECK(test::readText(lost) == before);
    CHECK(fs::last_write_time(shot.dir / "farm" / "tubes.bake.1001.0002.exr") == past);
    CHECK_THAT(log.str(), Contains("\"status\":\"replayed\""));
}

TEST_CASE("scene uvwarp: an animated rigidity map (rig.<UDIM>.####.exr) is followed frame by frame",
          "[harness][uvwarp][eval]") {
    // The disks at frames 1-2, rigidity 0 at frame 3: eval's maps equal a TileWarp given the new map at
    // frame 3, and the farm plan sees the tiles of the animated map.
    Shot shot;
    io::ImageWriteOptions floats;
    floats.type = io::PixelType::Float;
    for (int tile : {1001, 1002})
        for (int frame = 1; frame <= 3; ++frame)
            io::writeImage(
                shot.dir / ("rig." + std::to_string(tile) + ".000" + std::to_string(frame) + ".exr"),
                frame <= 2 ? disks() : io::Image(kTexels, kTexels, 1), floats);
    std::string text = kScene;
    text.replace(text.find("rig.<UDIM>.exr"), std::string("rig.<UDIM>.exr").size(), "rig.<UDIM>.####.exr");
    test::writeText(shot.scene, text);
    harness::EvalCommand command;
    command.scene = shot.scene;
    command.outDir = shot.dir / "eval";
    command.previews = false;
    const harness::EvalReport report = harness::evalCommand(command);
    REQUIRE(!report.uvwarpLines.empty());
    CHECK_THAT(report.uvwarpLines[0], Contains("maps changed at 1 frame"));
    uvwarp::TileWarpOptions options = uvwarp::shotOptions();  // and the scene's params
    options.solver.iterations = 6;
    options.solver.warmStart = true;
    for (int tile : {1001, 1002}) {
        uvwarp::TileWarp warp(shot.rest, tile, disks(), {}, options);
        for (int frame = 1; frame <= 3; ++frame) {
            if (frame == 3) warp.setMaps(io::Image(kTexels, kTexels, 1));
            warp.solve(stackPoints(shot.rest, frame));
            const io::Image written =
                io::readImage(command.outDir / scene::uvwarpRedirectName("tubes", tile, frame));
            CHECK(written.pixels == warp.redirect().pixels);
        }
    }
    const scene::Scene parsed = scene::readScene(shot.scene);
    CHECK(scene::uvwarpWarpedTiles(*parsed.objects[0].uvwarp, std::vector<int>{1}) ==
          std::vector<int>{1001, 1002});
    CHECK(scene::uvwarpWarpedTiles(*parsed.objects[0].uvwarp, std::vector<int>{7}).empty());  // no map at 7
    CHECK(scene::uvwarpWarpedTiles(*parsed.objects[0].uvwarp, std::vector<int>{7, 3}) ==
          std::vector<int>{1001, 1002});

    // A tile whose animated map starts after the run's first frame is warped or not whatever frame the
    // run starts at: the run over frames 1-3 refuses it, naming the missing frame and the stage, before
    // anything is written (it was left unwarped there and warped from frame 2 on, so frame 2's maps
    // depended on where the run began); the run from frame 2 warps it.
    fs::remove(shot.dir / "rig.1002.0001.exr");
    command.outDir = shot.dir / "from1";
    const std::string missing = test::errorOf<IoError>([&] { (void)harness::evalCommand(command); });
    CHECK_THAT(missing,
               Contains(shot.scene.string() + ": objects[0].stack[1]: ") &&
                   Contains("rig.1002.0001.exr: frame 1: does not exist (expected a map for every frame"));
    CHECK_FALSE(fs::exists(command.outDir / "tubes.0001.obj"));
    harness::FarmPlanCommand plan;
    plan.scene = shot.scene;
    plan.outDir = shot.dir / "farm1";
    CHECK_THAT(test::errorOf<IoError>([&] { (void)harness::farmPlanCommand(plan); }),
               Contains("rig.1002.0001.exr: frame 1: does not exist"));
    command.outDir = shot.dir / "from2";
    command.frames = {2, 3};
    (void)harness::evalCommand(command);
    CHECK(fs::exists(command.outDir / scene::uvwarpRedirectName("tubes", 1002, 2)));
}

TEST_CASE("scene uvwarp: farm plans check their tiles", "[harness][uvwarp][farm][errors]") {
    Shot shot;
    harness::FarmPlanCommand planCommand;
    planCommand.scene = shot.scene;
    planCommand.chunk = 3;
    planCommand.outDir = shot.dir / "farm";
    planCommand.tilesPerTask = 2;
    const scene::FarmPlan plan = harness::farmPlanCommand(planCommand);
    REQUIRE(plan.tasks.size() == 2);
    CHECK(plan.tasks[1].tiles == std::vector<int>{1001, 1002});
    const fs::path planFile = harness::farmPlanPath(planCommand);
    const std::string good = test::readText(planFile);
    const test::PlanEdit cases[] = {
        {"\"tiles\":[1001,1002]", "\"tiles\":[1002,1001]",
         ": tasks[1].tiles[1]: is 1001 (expected tiles in ascending order, each once)"},
        {"\"tiles\":[1001,1002]", "\"tiles\":[5]",
         ": tasks[1].tiles[0]: is 5 (expected a UDIM tile, 1001..9999)"},
        {"\"tiles\":[1001,1002]", "\"tiles\":[1001]",
         ": tasks[1].outputs[2]: is \"tubes.redirect.1002.0001.exr\", the scene makes "
         "\"tubes.redirect.1001.0002.exr\""},
    };
    test::checkPlanEdits(good, planFile, cases);
    // A tile without its rigidity map gets no task, and the plan says why, as eval does (it was left out
    // without a word).
    fs::remove(shot.dir / "rig.1002.exr");
    std::vector<std::string> notes;
    const scene::FarmPlan without = harness::farmPlanCommand(planCommand, &notes);
    for (const scene::FarmTask& task : without.tasks)
        CHECK(std::ranges::find(task.tiles, 1002) == task.tiles.end());
    REQUIRE(notes.size() == 1);
    CHECK_THAT(notes[0], Contains("object 'tubes': tile 1002: left unwarped: no rigidity map '") &&
                             Contains("rig.1002.exr'"));
    harness::EvalCommand eval;
    eval.scene = shot.scene;
    eval.outDir = shot.dir / "eval";
    eval.previews = false;
    const harness::EvalReport evaluated = harness::evalCommand(eval);
    CHECK(std::ranges::count_if(evaluated.uvwarpLines, [](const std::string& line) {
              return line.find("tile 1002: left unwarped: no rigidity map") != std::string::npos;
          }) == 1);
    planCommand.tilesPerTask = 0;
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::farmPlanCommand(planCommand); }),
               Contains("--tiles-per-task: is 0"));
}

TEST_CASE("scene uvwarp: eval writes the same bytes with 1 and 2 threads", "[harness][uvwarp][eval]") {
    Shot shot;
    const int threads = omp_get_max_threads();
    std::vector<std::string> runs[2];
    for (int t = 1; t <= 2; ++t) {
        omp_set_num_threads(t);
        harness::EvalCommand command;
        command.scene = shot.scene;
        command.outDir = shot.dir / ("eval" + std::to_string(t));
        const harness::EvalReport report = harness::evalCommand(command);
        for (const fs::path& file : report.files)
            runs[t - 1].push_back(file.filename().string() + "\n" + test::readText(file));
    }
    omp_set_num_threads(threads);
    REQUIRE(runs[0].size() == runs[1].size());
    REQUIRE(runs[0].size() > 10);  // meshes, previews, maps, bakes, the contact sheet
    for (size_t i = 0; i < runs[0].size(); ++i)
        CHECK(runs[0][i] == runs[1][i]);
}

namespace {

// The chunk tests' shot: kScene over 24 frames, without a texture, warm-started or not.
std::string chunkShot(bool warmStart) {
    std::string longer = kScene;
    const auto replace = [&](const std::string& from, const std::string& to) {
        longer.replace(longer.find(from), from.size(), to);
    };
    replace(R"("frames": [1, 3])", R"("frames": [1, 24])");
    replace(R"({"frame": 3, "value": 1.8})", R"({"frame": 24, "value": 1.9})");
    replace(R"("texture": "col.<UDIM>.exr",)", "");
    if (!warmStart) replace(R"("warmStart": true)", R"("warmStart": false)");
    return longer;
}

// One uninterrupted eval of shot.scene into shot.dir / folder.
fs::path evalShot(const Shot& shot, const std::string& folder) {
    harness::EvalCommand eval;
    eval.scene = shot.scene;
    eval.outDir = shot.dir / folder;
    eval.previews = false;
    (void)harness::evalCommand(eval);
    return eval.outDir;
}

// shot.scene as farm tasks in chunks of 8 frames with `warmUp` warm-up frames, run one after the other into
// shot.dir / folder.
fs::path farmShot(const Shot& shot, int warmUp, const std::string& folder) {
    harness::FarmPlanCommand plan;
    plan.scene = shot.scene;
    plan.chunk = 8;
    plan.warmUp = warmUp;
    plan.outDir = shot.dir / folder;
    const scene::FarmPlan made = harness::farmPlanCommand(plan);
    for (size_t k = 0; k < made.tasks.size(); ++k)
        (void)harness::farmRunCommand({harness::farmPlanPath(plan), static_cast<int>(k)});
    return plan.outDir;
}

// The redirect maps of `tile` and `frame` in an eval's or a farm's output folder.
io::Image redirectIn(const fs::path& folder, int tile, int frame) {
    char name[64];
    std::snprintf(name, sizeof(name), "tubes.redirect.%d.%04d.exr", tile, frame);
    return io::readImage(folder / name);
}

}  // namespace

// A frame's redirect map must not depend on where its farm chunk began. A 24-frame shot,
// warm-started, in chunks of 8: at the chunk starts (frames 9 and 17, whose warm-up does not reach back to
// frame 1) the maps of the farm tasks against those of one uninterrupted eval, largest difference over the
// tile in texels. With the default warm-up (6 frames) it must be at most 0.25 texel; without warm-up it is
// larger (so the bound is not met by accident).
TEST_CASE(
    "scene uvwarp: with warm-up frames a chunk's first map is the uninterrupted run's within 0.25 texel",
    "[harness][uvwarp][farm]") {
    Shot shot;
    test::writeText(shot.scene, chunkShot(true));
    const fs::path whole = evalShot(shot, "eval");
    double jumps[2] = {0.0, 0.0};  // without, with warm-up
    const int defaultWarmUp = harness::FarmPlanCommand{}.warmUp;
    REQUIRE(defaultWarmUp < 8);
    for (int warmUp : {0, defaultWarmUp}) {
        const fs::path farm = farmShot(shot, warmUp, "farm" + std::to_string(warmUp));
        for (int frame : {9, 17}) {
            for (int tile : {1001, 1002}) {
                const io::Image chunked = redirectIn(farm, tile, frame),
                                uninterrupted = redirectIn(whole, tile, frame);
                REQUIRE(chunked.pixels.size() == uninterrupted.pixels.size());
                for (size_t i = 0; i < uninterrupted.pixels.size(); ++i)
                    jumps[warmUp > 0] =
                        std::max(jumps[warmUp > 0],
                                 std::abs(double(chunked.pixels[i]) - uninterrupted.pixels[i]) * kTexels);
            }
        }
    }
    INFO("largest jump at a chunk start: " << jumps[0] << " texels cold, " << jumps[1] << " with "
                                           << defaultWarmUp << " warm-up frames");
    CHECK(jumps[1] <= 0.25);
    CHECK(jumps[0] > 0.25);
}

// By construction: with every frame solved from the identity (a scene's default) a frame's
// map depends on that frame alone, so farm tasks in chunks of 8, without warm-up, write every frame's map
// byte for byte as one uninterrupted eval does. Warm-started, the same chunks differ (the test could fail).
TEST_CASE("scene uvwarp: frames solved from the identity make chunked maps the uninterrupted run's bytes",
          "[harness][uvwarp][farm]") {
    Shot shot;
    int differing[2] = {0, 0};  // maps of frames 9 to 24 unlike the uninterrupted run's: warm, cold
    for (const bool coldFrames : {false, true}) {
        test::writeText(shot.scene, chunkShot(!coldFrames));
        const fs::path whole = evalShot(shot, coldFrames ? "eval-cold" : "eval-warm");
        const fs::path farm = farmShot(shot, 0, coldFrames ? "farm-cold" : "farm-warm");
        for (int frame = 9; frame <= 24; ++frame) {
            for (int tile : {1001, 1002}) {
                const io::Image chunked = redirectIn(farm, tile, frame),
                                uninterrupted = redirectIn(whole, tile, frame);
                REQUIRE(chunked.pixels.size() == uninterrupted.pixels.size());
                differing[coldFrames] += chunked.pixels != uninterrupted.pixels ? 1 : 0;
            }
        }
        if (coldFrames) {
            // The headers say how the maps were made.
            const io::ImageInfo info = io::readImageInfo(farm / "tubes.redirect.1001.0009.exr");
            std::string solver;
            for (const auto& [key, value] : info.attributes)
                if (key == "deformkit:uvwarp:solver") solver = value;
            CHECK(solver.find(R"("warmStart":false)") != std::string::npos);
        }
    }
    CHECK(differing[0] > 0);
    CHECK(differing[1] == 0);
}

// A plan of frames with a gap (1-6 and 13-20, a shot cut out in between): the frames before a task that warm
// it up are the planned ones, as in an uninterrupted eval of those frames, never the frames of the gap (an
// animated input may have no file there). With the warm-up reaching the plan's first frame the farm writes
// eval's bytes, and the task's log says which frames warmed it up.
TEST_CASE("scene uvwarp: a task after a gap in the planned frames warms up on planned frames only",
          "[harness][uvwarp][farm]") {
    Shot shot;
    test::writeText(shot.scene, chunkShot(true));
    std::vector<int> frames;
    for (int f = 1; f <= 20; ++f)
        if (f <= 6 || f >= 13) frames.push_back(f);
    harness::EvalCommand eval;
    eval.scene = shot.scene;
    eval.outDir = shot.dir / "eval";
    eval.previews = false;
    eval.frames = frames;
    (void)harness::evalCommand(eval);

    harness::FarmPlanCommand plan;
    plan.scene = shot.scene;
    plan.frames = frames;
    plan.chunk = 8;
    plan.warmUp = 24;
    plan.outDir = shot.dir / "farm";
    const scene::FarmPlan made = harness::farmPlanCommand(plan);
    int checked = 0;
    for (size_t k = 0; k < made.tasks.size(); ++k) {
        std::ostringstream log;
        (void)harness::farmRunCommand({harness::farmPlanPath(plan), static_cast<int>(k)}, &log);
        if (made.tasks[k].tiles.empty() || made.tasks[k].firstFrame != 13) continue;
        std::set<int> warmUp;
        std::istringstream lines(log.str());
        for (std::string line; std::getline(lines, line);) {
            const nlohmann::json j = nlohmann::json::parse(line);
            if (j["status"] == "warm-up") warmUp.insert(j["frame"].get<int>());
        }
        CHECK(warmUp == std::set<int>{1, 2, 3, 4, 5, 6});
        ++checked;
    }
    CHECK(checked > 0);
    for (const int frame : frames)
        for (const int tile : {1001, 1002}) {
            CAPTURE(frame, tile);
            CHECK(redirectIn(plan.outDir, tile, frame).pixels == redirectIn(eval.outDir, tile, frame).pixels);
        }
}

// A UV-warp stage added to a scene after planning has no task: a mesh task of the old plan says so instead of
// writing the OBJs alone and leaving the maps unmade.
TEST_CASE("scene uvwarp: a plan made before a UV-warp stage was added is stale", "[harness][uvwarp][farm]") {
    Shot shot;
    std::string meshOnly = kScene;
    const std::string stage = R"(,
    {"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "texture": "col.<UDIM>.exr",
     "params": {"iterations": 6, "warmStart": true}})";
    REQUIRE(meshOnly.find(stage) != std::string::npos);
    meshOnly.erase(meshOnly.find(stage), stage.size());
    test::writeText(shot.scene, meshOnly);
    harness::FarmPlanCommand plan;
    plan.scene = shot.scene;
    plan.outDir = shot.dir / "farm";
    const scene::FarmPlan made = harness::farmPlanCommand(plan);
    REQUIRE(made.tasks.size() == 1);
    test::writeText(shot.scene, kScene);
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)harness::farmRunCommand({harness::farmPlanPath(plan), 0});
               }),
               Contains("farm_plan.json: tasks: have no task for UDIM tile 1001, which the scene warps") &&
                   Contains("plan again after changing it"));
    CHECK(test::filesIn(plan.outDir) == std::vector<fs::path>{"farm_plan.json"});
}

TEST_CASE("scene uvwarp: eval refuses an output named as another or as a file it reads, before writing",
          "[harness][uvwarp][eval][errors]") {
    Shot shot;
    const std::string sceneText = test::readText(shot.scene);
    const fs::path out = shot.dir / "eval";
    const auto refused = [&](const fs::path& report, const std::string& first, const std::string& second) {
        harness::EvalCommand command;
        command.scene = shot.scene;
        command.outDir = out;
        command.previews = false;
        command.report = report;
        CHECK_THROWS_AS(harness::evalCommand(command), InvalidInput);
        CHECK_THROWS_WITH(harness::evalCommand(command),
                          Contains(report.string()) && Contains(first) && Contains(second));
        // Nothing written: no output folder, the scene as it was.
        CHECK_FALSE(fs::exists(out));
        CHECK(test::readText(shot.scene) == sceneText);
    };
    refused(shot.scene, "the scene", "the report (--report)");
    refused(shot.dir / "tubes.obj", "the rest mesh of", "the report (--report)");
    refused(out / "tubes.0002.obj", "the deformed mesh of tubes at frame 2", "the report (--report)");
    refused(out / "uvwarp.jsonl", "the UV-warp stages' log", "the report (--report)");
    refused(shot.dir / "rig.1002.exr", "the rigidity map of tile 1002", "the report (--report)");
    refused(out / scene::uvwarpRedirectName("tubes", 1002, 3), "the redirect map of tile 1002, frame 3",
            "the report (--report)");
    // Through a symbolic link to the output folder, left from an earlier run: nothing is written in it.
    fs::create_directory(out);
    fs::create_directory_symlink(out, shot.dir / "link");
    harness::EvalCommand linked;
    linked.scene = shot.scene;
    linked.outDir = out;
    linked.previews = false;
    linked.report = shot.dir / "link" / "tubes.0001.obj";
    CHECK_THROWS_WITH(harness::evalCommand(linked),
                      Contains(linked.report->string()) && Contains("the deformed mesh of tubes at frame 1"));
    CHECK(fs::is_empty(out));
    fs::remove(shot.dir / "link");
    fs::remove(out);

    // An OBJ sequence read as the animated input, evaluated into its own folder: each frame would be written
    // over the file it is read from.
    for (int frame = 0; frame <= 3; ++frame) {  // the rest pose at frame 0
        geom::Mesh posed = shot.rest;
        posed.setPoints(stackPoints(shot.rest, frame));
        io::writeObj(shot.dir / scene::frameFileName("tubes", frame), posed);
    }
    const fs::path sequenceScene = shot.dir / "sequence.json";
    test::writeText(sequenceScene, R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [
      {"name": "tubes", "mesh": "tubes.####.obj", "restFrame": 0, "stack": []}]})");
    harness::EvalCommand command;
    command.scene = sequenceScene;
    command.outDir = shot.dir.path();
    command.previews = false;
    const std::string before = test::readText(shot.dir / "tubes.0002.obj");
    CHECK_THROWS_AS(harness::evalCommand(command), InvalidInput);
    CHECK_THROWS_WITH(harness::evalCommand(command), Contains("tubes.0001.obj") &&
                                                         Contains("animated input") &&
                                                         Contains("the deformed mesh of tubes at frame 1"));
    CHECK(test::readText(shot.dir / "tubes.0002.obj") == before);
    // Into another folder it runs.
    command.outDir = shot.dir / "elsewhere";
    const harness::EvalReport report = harness::evalCommand(command);
    CHECK(report.files.size() == 3);
}
