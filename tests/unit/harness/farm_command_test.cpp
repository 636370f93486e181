#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/farm_plan.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "eval_command.h"
#include "farm_command.h"
#include "farm_plan_edits.h"
#include "mesh_support.h"
#include "point_cache_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

// Two objects over 7 frames, both animated, so every frame's output differs.
const char* kScene = R"({"deformkit_scene": 1, "frames": [1, 7], "objects": [
  {"name": "tube", "mesh": "tube.obj", "stack": [
    {"type": "twist", "params": {"handleY": [0, 1, 0],
       "endAngle": {"keys": [{"frame": 1, "value": 0, "interpolation": "linear"}, {"frame": 7, "value": 1.5}]}}}]},
  {"name": "bent", "mesh": "tube.obj", "stack": [
    {"type": "bend", "params": {"curvature": {"keys": [{"frame": 1, "value": 0.1}, {"frame": 7, "value": 0.9}]}}}]}]})";

struct Shot {
    test::TempDir dir;
    fs::path scene;
    Shot() {
        io::writeObj(dir / "tube.obj", test::tube({.rings = 6, .sides = 10, .uvs = test::TubeUVs::Wrapped}));
        scene = dir / "shot.json";
        test::writeText(scene, kScene);
    }
};

// The names a task of frames first..last must list: frame by frame, objects in scene order.
std::vector<std::string> namesOf(int first, int last) {
    std::vector<std::string> names;
    char buffer[64];
    for (int f = first; f <= last; ++f) {
        for (const char* object : {"tube", "bent"}) {
            std::snprintf(buffer, sizeof(buffer), "%s.%04d.obj", object, f);
            names.emplace_back(buffer);
        }
    }
    return names;
}

}  // namespace

TEST_CASE("farm plan: 7 frames in chunks of 3 make tasks 1-3, 4-6, 7-7 with every object's outputs",
          "[harness][farm]") {
    Shot shot;
    harness::FarmPlanCommand command;
    command.scene = shot.scene;
    command.chunk = 3;
    command.outDir = shot.dir / "out";  // created
    const scene::FarmPlan plan = harness::farmPlanCommand(command);

    REQUIRE(plan.tasks.size() == 3);
    const int ranges[3][2] = {{1, 3}, {4, 6}, {7, 7}};
    for (size_t k = 0; k < 3; ++k) {
        CHECK(plan.tasks[k].firstFrame == ranges[k][0]);
        CHECK(plan.tasks[k].lastFrame == ranges[k][1]);
        CHECK(plan.tasks[k].outputs == namesOf(ranges[k][0], ranges[k][1]));
        CHECK(plan.tasks[k].tiles.empty());
    }
    CHECK(plan.tasks[2].outputs == std::vector<std::string>{"tube.0007.obj", "bent.0007.obj"});
    CHECK(plan.scene.is_absolute());
    CHECK(plan.scene == fs::absolute(shot.scene).lexically_normal());
    CHECK(plan.outDir == fs::absolute(shot.dir / "out").lexically_normal());

    // The file, read back as JSON by a second parser, holds the same plan.
    const fs::path file = shot.dir / "out" / "farm_plan.json";
    REQUIRE(fs::is_regular_file(file));
    const nlohmann::json j = nlohmann::json::parse(test::readText(file));
    CHECK(j["deformkit_farm_plan"] == 1);
    CHECK(j["scene"] == plan.scene.string());
    CHECK(j["out"] == plan.outDir.string());
    CHECK(j["chunk"] == 3);
    REQUIRE(j["tasks"].size() == 3);
    CHECK(j["tasks"][1]["frames"] == nlohmann::json::array({4, 6}));
    CHECK(j["tasks"][1]["tiles"] == nlohmann::json::array());
    CHECK(j["tasks"][1]["outputs"].get<std::vector<std::string>>() == namesOf(4, 6));
    CHECK(test::filesIn(shot.dir / "out") ==
          std::vector<fs::path>{"farm_plan.json"});  // atomic: no temporary

    // --plan elsewhere; a frame list never makes a task across its gap.
    command.plan = shot.dir / "plans" / "p.json";
    command.frames = {1, 2, 3, 4, 7};
    const scene::FarmPlan gaps = harness::farmPlanCommand(command);
    REQUIRE(gaps.tasks.size() == 3);
    CHECK(gaps.tasks[1].firstFrame == 4);
    CHECK(gaps.tasks[1].lastFrame == 4);
    CHECK(gaps.tasks[2].firstFrame == 7);
    CHECK(fs::is_regular_file(shot.dir / "plans" / "p.json"));
    const scene::FarmPlan reread = scene::readFarmPlan(shot.dir / "plans" / "p.json");
    CHECK(reread.tasks.size() == 3);
    CHECK(reread.tasks[0].outputs == namesOf(1, 3));

    command.chunk = 0;
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::farmPlanCommand(command); }),
               Contains("--chunk: is 0"));
}

TEST_CASE("farm run: the tasks write the bytes of deformkit eval, and a rerun skips every frame",
          "[harness][farm]") {
    Shot shot;
    harness::FarmPlanCommand planCommand;
    planCommand.scene = shot.scene;
    planCommand.chunk = 3;
    planCommand.outDir = shot.dir / "farm";
    (void)harness::farmPlanCommand(planCommand);
    const fs::path planFile = harness::farmPlanPath(planCommand);

    harness::EvalCommand evalCommand;
    evalCommand.scene = shot.scene;
    evalCommand.outDir = shot.dir / "eval";
    (void)harness::evalCommand(evalCommand);

    std::vector<std::string> lines;
    for (int k = 0; k < 3; ++k) {
        std::ostringstream log;
        const scene::FarmTaskReport report = harness::farmRunCommand({planFile, k}, &log);
        CHECK(report.skipped.empty());
        CHECK(report.files.size() == 2 * report.written.size());
        std::istringstream in(log.str());
        for (std::string line; std::getline(in, line);)
            lines.push_back(line);
    }
    // One JSON line per frame, in frame order, each naming its task.
    REQUIRE(lines.size() == 7);
    for (int f = 1; f <= 7; ++f) {
        const nlohmann::json line = nlohmann::json::parse(lines[f - 1]);
        CHECK(line["frame"] == f);
        CHECK(line["task"] == (f - 1) / 3);
        CHECK(line["status"] == "written");
        CHECK(line["seconds"].get<double>() >= 0.0);
    }
    // Byte for byte what eval writes (the reference: one uninterrupted eval over all frames), and nothing
    // else in the folder but the plan.
    std::vector<fs::path> expectedFiles{"farm_plan.json"};
    for (const std::string& name : namesOf(1, 7)) {
        expectedFiles.emplace_back(name);
        const std::string farm = test::readText(shot.dir / "farm" / name);
        CHECK(!farm.empty());
        CHECK(farm == test::readText(shot.dir / "eval" / name));
    }
    std::sort(expectedFiles.begin(), expectedFiles.end());
    CHECK(test::filesIn(shot.dir / "farm") == expectedFiles);
    // The frames differ from each other (the scene is animated), so equality above is not vacuous.
    CHECK(test::readText(shot.dir / "farm" / "tube.0002.obj") !=
          test::readText(shot.dir / "farm" / "tube.0003.obj"));

    // Rerun: every frame skipped, no file touched. Modification times are set back an hour first so that a
    // rewrite within the file system's timestamp granularity would still show.
    const auto past = fs::file_time_type::clock::now() - std::chrono::hours(1);
    for (const std::string& name : namesOf(1, 7))
        fs::last_write_time(shot.dir / "farm" / name, past);
    for (int k = 0; k < 3; ++k) {
        std::ostringstream log;
        const scene::FarmTaskReport report = harness::farmRunCommand({planFile, k}, &log);
        CHECK(report.written.empty());
        CHECK(report.files.empty());
        CHECK(report.skipped.size() == (k < 2 ? 3u : 1u));
        CHECK_THAT(log.str(), Contains("\"status\":\"skipped\""));
    }
    for (const std::string& name : namesOf(1, 7))
        CHECK(fs::last_write_time(shot.dir / "farm" / name) == past);

    // One output gone: its frame is written again (that object only), with the same bytes.
    fs::remove(shot.dir / "farm" / "bent.0005.obj");
    const scene::FarmTaskReport again = harness::farmRunCommand({planFile, 1});
    CHECK(again.written == std::vector<int>{5});
    CHECK(again.skipped == std::vector<int>{4, 6});
    REQUIRE(again.files.size() == 1);
    CHECK(again.files[0].filename() == "bent.0005.obj");
    CHECK(test::readText(shot.dir / "farm" / "bent.0005.obj") ==
          test::readText(shot.dir / "eval" / "bent.0005.obj"));
    CHECK(fs::last_write_time(shot.dir / "farm" / "tube.0005.obj") == past);
}

TEST_CASE(
    "farm run: an object driven by a point cache writes eval's bytes, each task reading only its frames",
    "[harness][farm][point_cache]") {
    Shot shot;
    // Frames 1-7 of a tube swaying along x, written by eval as the OBJs and the PC2 of one object.
    test::writeText(shot.dir / "sway.json", R"({"deformkit_scene": 1, "frames": [1, 7], "objects": [
      {"name": "tube", "mesh": "tube.obj", "stack": [{"type": "bend", "params": {"curvature": {"keys": [
        {"frame": 1, "value": 0.1}, {"frame": 7, "value": 0.9}]}}}]}]})");
    harness::EvalCommand sway;
    sway.scene = shot.dir / "sway.json";
    sway.outDir = shot.dir / "sway";
    sway.previews = false;
    sway.cache = "pc2";
    (void)harness::evalCommand(sway);
    // Frame 1 of the cache is broken with a NaN: a task of frames 4-6 never reads it.
    std::string bytes = test::readText(shot.dir / "sway" / "tube.pc2");
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(bytes.data() + 32 + 4, &nan, 4);  // sample 0, vertex 0, y
    test::writeText(shot.dir / "sway.pc2", bytes);
    test::writeText(shot.dir / "cached.json", R"({"deformkit_scene": 1, "frames": [1, 7], "objects": [
      {"name": "tube", "mesh": "tube.obj", "deformed": "sway.pc2", "stack": [{"type": "twist", "params": {
        "handleY": [0, 1, 0], "endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": 7, "value": 1.5}]}}}]}]})");
    test::writeText(shot.dir / "sequence.json", R"({"deformkit_scene": 1, "frames": [1, 7], "objects": [
      {"name": "tube", "mesh": "tube.obj", "deformed": "sway/tube.####.obj", "stack": [{"type": "twist", "params": {
        "handleY": [0, 1, 0], "endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": 7, "value": 1.5}]}}}]}]})");

    harness::FarmPlanCommand planCommand;
    planCommand.scene = shot.dir / "cached.json";
    planCommand.chunk = 3;
    planCommand.outDir = shot.dir / "farm";
    (void)harness::farmPlanCommand(planCommand);
    const scene::FarmTaskReport report = harness::farmRunCommand({harness::farmPlanPath(planCommand), 1});
    CHECK(report.written == std::vector<int>{4, 5, 6});
    harness::EvalCommand reference;
    reference.scene = shot.dir / "sequence.json";
    reference.outDir = shot.dir / "eval";
    reference.previews = false;
    reference.frames = {4, 5, 6};
    (void)harness::evalCommand(reference);
    for (int f = 4; f <= 6; ++f) {
        const std::string name = scene::frameFileName("tube", f);
        CHECK(test::readText(shot.dir / "farm" / name) == test::readText(shot.dir / "eval" / name));
    }
    CHECK(test::readText(shot.dir / "farm" / "tube.0004.obj") !=
          test::readText(shot.dir / "sway" / "tube.0004.obj"));
    // The task holding frame 1 stops there, naming the scene, the object's input, the cache and the vertex.
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] {
            (void)harness::farmRunCommand({harness::farmPlanPath(planCommand), 0});
        }),
        Contains("cached.json: objects[0].deformed: ") && Contains("sway.pc2: frame 1: vertex 0: is ("));
}

TEST_CASE("farm run: a bad plan or task index is InvalidInput naming the file and the JSON path or index",
          "[harness][farm][errors]") {
    Shot shot;
    harness::FarmPlanCommand planCommand;
    planCommand.scene = shot.scene;
    planCommand.chunk = 3;
    planCommand.outDir = shot.dir / "farm";
    (void)harness::farmPlanCommand(planCommand);
    const fs::path planFile = harness::farmPlanPath(planCommand);
    const std::string good = test::readText(planFile);

    SECTION("task index out of range") {
        for (int task : {3, -1}) {
            const std::string what = test::errorOf<InvalidInput>([&] {
                (void)harness::farmRunCommand({planFile, task});
            });
            CHECK_THAT(what, Contains(planFile.string() + ": --task: is " + std::to_string(task) +
                                      ", the plan has 3 tasks (expected a task index from 0 to 2)"));
        }
        CHECK(harness::farmExitCode(InvalidInput("x")) == 2);
    }
    SECTION("text that is not JSON") {
        test::writeText(planFile, good.substr(0, good.size() / 2));
        const std::string what = test::errorOf<ParseError>([&] {
            (void)harness::farmRunCommand({planFile, 0});
        });
        CHECK_THAT(what, Contains(planFile.string() + ": ") && Contains("farm plan"));
        CHECK(harness::farmExitCode(ParseError("x")) == 2);
    }
    SECTION("bad values name their JSON path") {
        const test::PlanEdit cases[] = {
            {"\"frames\":[4,6]", "\"frames\":[4,9]", ": tasks[1].frames: is [4,9], 6 frames"},
            {"\"frames\":[7,7]", "\"frames\":[7]", ": tasks[2].frames: is [7] (expected [first, last])"},
            {"\"frames\":[7,7]", "\"frames\":[7,1500000000]",
             ": tasks[2].frames[1]: is 1500000000 (expected a whole number from -1000000000 to 1000000000)"},
            {"\"bent.0006.obj\"],\"tiles\":[]", "\"bent.0006.obj\"],\"tiles\":[1001]",
             ": tasks[1].outputs[0]: is \"tube.0004.obj\", the scene makes nothing"},
            {"\"tiles\":[]", "\"tiles\":1001", ": tasks[0].tiles: is 1001 (expected an array of UDIM tiles)"},
            {"\"deformkit_farm_plan\": 1", "\"deformkit_farm_plan\": 2", ": deformkit_farm_plan: is 2"},
            {"\"chunk\": 3", "\"chunk\": 3, \"chunks\": 3", ": chunks: is not a plan key"},
            // A hand-edited chunk lets a task claim more frames than any command line gives.
            {"\"chunk\": 3,\n  \"warmUp\": 6,\n  \"tasks\": [\n    {\"frames\":[1,3]",
             "\"chunk\": 1000000000,\n  \"warmUp\": 6,\n  \"tasks\": [\n    {\"frames\":[1,1000001]",
             ": tasks[0].frames: is [1,1000001], 1000001 frames (expected first <= last and at most chunk "
             "(1000000000) frames, at most 1000000)"},
            {"\"tube.0004.obj\"", "\"../tube.0004.obj\"", ": tasks[1].outputs[0]: is \"../tube.0004.obj\""},
            {"\"tube.0004.obj\"", "\"tube.4.obj\"",
             ": tasks[1].outputs[0]: is \"tube.4.obj\", the scene makes "
             "\"tube.0004.obj\""},
        };
        test::checkPlanEdits(good, planFile, cases);
    }
    SECTION("a folder with an output's name is not a finished output: the run names it") {
        fs::create_directories(shot.dir / "farm" / "tube.0001.obj");
        const std::string what = test::errorOf<Error>([&] { (void)harness::farmRunCommand({planFile, 0}); });
        CHECK_THAT(what, Contains("tube.0001.obj") && Contains("folder"));
        fs::remove(shot.dir / "farm" / "tube.0001.obj");
    }
    SECTION("a missing plan is bad input; an unwritable output folder is worth a retry") {
        const fs::path missing = shot.dir / "nope.json";
        CHECK_THAT(test::errorOf<InvalidInput>([&] {
                       (void)harness::farmRunCommand({missing, 0});
                   }),
                   Contains(missing.string() + ": does not exist"));
        fs::create_directories(shot.dir / "folder.json");  // a folder named as the plan: bad input too
        CHECK_THAT(test::errorOf<InvalidInput>([&] {
                       (void)harness::farmRunCommand({shot.dir / "folder.json", 0});
                   }),
                   Contains("folder.json: is a folder (expected a plan from deformkit farm plan)"));
        CHECK(harness::farmExitCode(IoError("x")) == 1);
        CHECK(harness::farmExitCode(std::runtime_error("x")) == 1);
        if (!test::runningAsRoot()) {
            fs::permissions(shot.dir / "farm", fs::perms::owner_read | fs::perms::owner_exec);
            CHECK_THAT(test::errorOf<IoError>([&] {
                           (void)harness::farmRunCommand({planFile, 0});
                       }),
                       Contains("not writable"));
        }
    }
    // Nothing was written by a failing run.
    CHECK(test::filesIn(shot.dir / "farm") == std::vector<fs::path>{"farm_plan.json"});
}

TEST_CASE("farm submit: one sbatch job array element per task running farm run --task",
          "[harness][farm][slurm]") {
    Shot shot;
    harness::FarmPlanCommand planCommand;
    planCommand.scene = shot.scene;
    planCommand.chunk = 2;  // 7 frames: 4 tasks
    planCommand.outDir = shot.dir / "farm";
    const scene::FarmPlan plan = harness::farmPlanCommand(planCommand);
    const fs::path planFile = harness::farmPlanPath(planCommand);
    const fs::path planAbs = fs::absolute(planFile).lexically_normal();

    const std::vector<std::string> args =
        harness::farmSbatchArguments(plan, planFile, "/opt/dk/bin/deformkit", {"--partition=batch"});
    const std::vector<std::string> expected = {
        "--parsable",
        "--array=0-3",
        "--job-name=deformkit-farm-shot",
        "--output=" + (planAbs.parent_path() / "farm_plan.%A_%a.log").string(),
        "--partition=batch",
        "--wrap=exec '/opt/dk/bin/deformkit' farm run '" + planAbs.string() +
            "' --task \"$SLURM_ARRAY_TASK_ID\""};
    CHECK(args == expected);

    // A stand-in sbatch that records its arguments and answers like `sbatch --parsable`.
    const fs::path fake = shot.dir / "sbatch";
    test::writeText(
        fake, "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\n' \"$a\"; done >\"$0.args\"\necho '4242;c1'\n");
    fs::permissions(fake, fs::perms::owner_all);
    harness::FarmSubmitCommand submit;
    submit.plan = planFile;
    submit.sbatch = fake.string();
    submit.deformkit = "/opt/dk/bin/deformkit";
    submit.sbatchArgs = harness::splitArguments("--partition=batch", "--sbatch-args");
    CHECK(harness::farmSubmitCommand(submit) == "4242");
    std::string recorded;
    for (const std::string& a : expected)
        recorded += a + "\n";
    CHECK(test::readText(shot.dir / "sbatch.args") == recorded);

    // With the report: a second job after the array, whatever its tasks' exit codes, writing the shot's page.
    test::writeText(fake,
                    "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\n' \"$a\"; done >>\"$0.args\"\n"
                    "if [ -e \"$0.n\" ]; then echo 4243; else touch \"$0.n\"; echo '4242;c1'; fi\n");
    fs::remove(shot.dir / "sbatch.args");
    submit.report = true;
    std::string reportJob;
    CHECK(harness::farmSubmitCommand(submit, &reportJob) == "4242");
    CHECK(reportJob == "4243");
    const std::vector<std::string> reportArgs = harness::farmReportSbatchArguments(
        plan, planFile, "/opt/dk/bin/deformkit", {"--partition=batch"}, "4242");
    CHECK(reportArgs == std::vector<std::string>{
                            "--parsable", "--dependency=afterany:4242", "--job-name=deformkit-report-shot",
                            "--output=" + (planAbs.parent_path() / "farm_plan-report.%j.out").string(),
                            "--partition=batch",
                            "--wrap=exec '/opt/dk/bin/deformkit' report --plan '" + planAbs.string() + "'"});
    for (const std::string& a : reportArgs)
        recorded += a + "\n";
    // The array's own options stay with the array (a report array of 9 jobs, the report's output among the
    // task logs); logs the array's --output moved are read from that folder.
    for (const std::vector<std::string>& arrayOptions :
         {std::vector<std::string>{"--array=0-8%2", "--output=/logs/x/%A_%a.log", "-Jname", "--error",
                                   "/e/%a"},
          std::vector<std::string>{"-a", "0-8", "-o", "/logs/x/%A_%a.log", "--job-name=n", "-e/e/%a"}}) {
        std::vector<std::string> extra = arrayOptions;
        extra.insert(extra.begin(), "--partition=batch");
        CHECK(harness::farmReportSbatchArguments(plan, planFile, "/opt/dk/bin/deformkit", extra, "4242") ==
              std::vector<std::string>{
                  "--parsable", "--dependency=afterany:4242", "--job-name=deformkit-report-shot",
                  "--output=" + (planAbs.parent_path() / "farm_plan-report.%j.out").string(),
                  "--partition=batch",
                  "--wrap=exec '/opt/dk/bin/deformkit' report --plan '" + planAbs.string() + "' '/logs/x'"});
    }
    CHECK(test::readText(shot.dir / "sbatch.args") == recorded);

    // The array accepted, the report job refused: the array's id is in the error, and exit code 2 (submitting
    // again would queue a second array).
    fs::remove(shot.dir / "sbatch.n");
    test::writeText(
        fake,
        "#!/bin/sh\nif [ -e \"$0.n\" ]; then echo 'sbatch: error: Job dependency problem' >&2; exit 1; "
        "fi\ntouch \"$0.n\"; echo '4242;c1'\n");
    try {
        (void)harness::farmSubmitCommand(submit, &reportJob);
        FAIL("no error");
    } catch (const harness::FarmReportRefused& e) {
        CHECK(e.arrayJob == "4242");
        CHECK_THAT(e.what(),
                   Contains("Job dependency problem") &&
                       Contains("the job array 4242 is queued and runs without it: do not submit the "
                                "plan again, run 'deformkit farm report "));
        CHECK(harness::farmExitCode(e) == 2);
    }
    submit.report = false;

    // sbatch refusing the job: its message, exit code 1.
    test::writeText(fake, "#!/bin/sh\necho 'sbatch: error: invalid partition specified: nope' >&2\nexit 1\n");
    try {
        (void)harness::farmSubmitCommand(submit);
        FAIL("no error");
    } catch (const Error& e) {
        CHECK_THAT(e.what(),
                   Contains("exited with status 1: sbatch: error: invalid partition specified: nope"));
        CHECK(harness::farmExitCode(e) == 1);
    }

    // No sbatch on PATH: InvalidInput (exit 2) saying so.
    submit.sbatch = "deformkit-test-no-such-sbatch";
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::farmSubmitCommand(submit); }),
               Contains("deformkit-test-no-such-sbatch: not found on PATH"));
}

TEST_CASE("farm submit: a '%' of the plan's path reaches sbatch as %%, a backslash is refused",
          "[harness][farm][slurm]") {
    // sbatch reads --output as a pattern: '100%x_%j' in a folder name would become the job's name and id,
    // and every element fail to open its log.
    scene::FarmPlan plan;
    plan.scene = "/shows/x/shot.json";
    plan.tasks.resize(2);
    const std::vector<std::string> args =
        harness::farmSbatchArguments(plan, "/shows/r2 100%x_%j/plan%.json", "/opt/dk/bin/deformkit", {});
    CHECK(std::find(args.begin(), args.end(), "--output=/shows/r2 100%%x_%%j/plan%%.%A_%a.log") !=
          args.end());
    const std::vector<std::string> report = harness::farmReportSbatchArguments(
        plan, "/shows/r2 100%x_%j/plan%.json", "/opt/dk/bin/deformkit", {}, "123");
    CHECK(std::find(report.begin(), report.end(), "--output=/shows/r2 100%%x_%%j/plan%%-report.%j.out") !=
          report.end());
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)harness::farmSbatchArguments(plan, "/shows/back\\slash/plan.json",
                                                      "/opt/dk/bin/deformkit", {});
               }),
               Contains("/shows/back\\slash/plan.json: has a backslash in its path"));
}

TEST_CASE("farm submit: --sbatch-args splits like a shell", "[harness][farm]") {
    CHECK(harness::splitArguments("  --partition=batch   --comment='two words' \"a\\\"b\" c\\ d ",
                                  "--sbatch-args") ==
          std::vector<std::string>{"--partition=batch", "--comment=two words", "a\"b", "c d"});
    CHECK(harness::splitArguments("", "--sbatch-args").empty());
    CHECK_THAT(
        test::errorOf<InvalidInput>([] { (void)harness::splitArguments("--comment='x", "--sbatch-args"); }),
        Contains("--sbatch-args: has an unterminated ' quote"));
}

TEST_CASE("eval and farm plan check every input before any work: a vertex out of range, no rigidity map",
          "[harness][farm][eval][errors]") {
    // The second object's slide handle is vertex 99999 of a 60-vertex tube: eval must find it before it
    // writes the first object's frame 1, and farm plan before it plans tasks that would all fail.
    Shot shot;
    std::string text = kScene;
    text.replace(text.find(R"({"type": "bend")"), 0,
                 R"({"type": "slide", "params": {"vertex": 99999, "radius": 0.5}}, )");
    test::writeText(shot.scene, text);
    harness::EvalCommand eval;
    eval.scene = shot.scene;
    eval.outDir = shot.dir / "eval";
    const std::string evalError = test::errorOf<InvalidInput>([&] { (void)harness::evalCommand(eval); });
    CHECK_THAT(evalError, Contains("objects[1].stack") && Contains("99999"));
    CHECK_FALSE(fs::exists(shot.dir / "eval"));
    harness::FarmPlanCommand plan;
    plan.scene = shot.scene;
    plan.outDir = shot.dir / "farm";
    CHECK(test::errorOf<InvalidInput>([&] { (void)harness::farmPlanCommand(plan); }) == evalError);
    CHECK_FALSE(fs::exists(shot.dir / "farm"));

    // Values that go bad after the first frame: a stepped key to a vertex out of range at frame 5, and a
    // radius whose Bezier keys (1 at frames 1 and 4, a steep tangent) overshoot below 0 in between. Found
    // before frame 1 is written, naming the frame.
    for (const auto& [params, where] :
         {std::pair{R"({"vertex": {"keys": [{"frame": 1, "value": 3, "interpolation": "constant"},
                                            {"frame": 5, "value": 99999}]}, "radius": 0.5})",
                    "frame 5: stack entry 0 (slide 'slide1'): parameter 'vertex': is 99999"},
          std::pair{
              R"({"vertex": 3, "radius": {"keys": [
                      {"frame": 1, "value": 1, "tangent": "explicit", "in": 0, "out": 0},
                      {"frame": 4, "value": 1, "tangent": "explicit", "in": 2.5, "out": 0}]}})",
              "params.radius: frame 3: stack entry 0 (slide 'slide1'): parameter 'radius': is -0.111"}}) {
        text = kScene;
        text.replace(text.find(R"({"type": "bend")"), 0,
                     std::string(R"({"type": "slide", "params": )") + params + "}, ");
        test::writeText(shot.scene, text);
        const std::string late = test::errorOf<InvalidInput>([&] { (void)harness::evalCommand(eval); });
        CHECK_THAT(late, Contains("objects[1].") && Contains(where));
        CHECK_FALSE(fs::exists(shot.dir / "eval"));
        CHECK(test::errorOf<InvalidInput>([&] { (void)harness::farmPlanCommand(plan); }) == late);
        CHECK_FALSE(fs::exists(shot.dir / "farm"));
    }

    // A UV-warp stage whose rigidity pattern finds no map: eval and plan refuse it alike, before any output.
    text = kScene;
    const size_t twistEnd = text.find("}}}]}") + 3;  // after the twist entry, inside the first stack
    text.replace(twistEnd, 0, R"(, {"type": "uvwarp", "rigidity": "rig.<UDIM>.exr"})");
    test::writeText(shot.scene, text);
    const std::string noMap = test::errorOf<IoError>([&] { (void)harness::evalCommand(eval); });
    CHECK_THAT(noMap, Contains("objects[0].stack[1].rigidity") && Contains("no tile has a rigidity map"));
    CHECK_FALSE(fs::exists(shot.dir / "eval" / "tube.0001.obj"));
    const std::string planNoMap = test::errorOf<IoError>([&] { (void)harness::farmPlanCommand(plan); });
    CHECK_THAT(planNoMap, Contains("objects[0].stack[1].rigidity") && Contains("no tile has a rigidity map"));
    CHECK_FALSE(fs::exists(shot.dir / "farm" / "farm_plan.json"));

    // The maps there but wrong as eval checks them (a mask pattern that matches nothing, a map of another
    // size): the plan is refused with eval's message, not written for tasks that would all fail.
    io::writeImage(shot.dir / "rig.1001.exr", io::Image(32, 32, 1, 0.0f));
    io::writeImage(shot.dir / "mask16.1001.exr", io::Image(16, 16, 1, 1.0f));
    for (const char* mask : {"msk.<UDIM>.exr", "mask16.<UDIM>.exr"}) {
        std::string withMask = kScene;
        withMask.replace(
            twistEnd, 0,
            std::string(R"(, {"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "mask": ")") + mask + R"("})");
        test::writeText(shot.scene, withMask);
        const std::string evalMask = test::errorOf<InvalidInput>([&] { (void)harness::evalCommand(eval); });
        CHECK_THAT(evalMask, Contains("objects[0].stack[1]"));
        CHECK(test::errorOf<InvalidInput>([&] { (void)harness::farmPlanCommand(plan); }) == evalMask);
        CHECK_FALSE(fs::exists(shot.dir / "farm" / "farm_plan.json"));
    }
}

// The shot's twisted tube given a UV-warp stage (`stage`: the entry's keys after its type, maps written by
// the caller), planned into shot.dir/farm: the plan and the index of its first UV-warp task.
static std::pair<scene::FarmPlan, int> planWithUvStage(const Shot& shot, const std::string& stage) {
    std::string text = kScene;
    const size_t twistEnd = text.find("}}}]}") + 3;
    text.replace(twistEnd, 0, R"(, {"type": "uvwarp", )" + stage + "}");
    test::writeText(shot.scene, text);
    harness::FarmPlanCommand planCommand;
    planCommand.scene = shot.scene;
    planCommand.outDir = shot.dir / "farm";
    scene::FarmPlan plan = harness::farmPlanCommand(planCommand);
    int uvTask = -1;
    for (size_t k = 0; k < plan.tasks.size() && uvTask < 0; ++k)
        if (!plan.tasks[k].tiles.empty()) uvTask = static_cast<int>(k);
    REQUIRE(uvTask >= 0);
    return {std::move(plan), uvTask};
}

TEST_CASE("farm run: a map removed after planning is named, not taken for a changed scene",
          "[harness][farm][errors]") {
    Shot shot;
    io::writeImage(shot.dir / "rig.1001.exr", io::Image(32, 32, 1, 0.0f));
    io::writeImage(shot.dir / "col.1001.exr", io::Image(32, 32, 3, 0.5f));
    const auto [plan, uvTask] =
        planWithUvStage(shot, R"("rigidity": "rig.<UDIM>.exr", "texture": "col.<UDIM>.exr")");
    harness::FarmRunCommand run;
    run.plan = shot.dir / "farm" / "farm_plan.json";
    run.task = uvTask;
    for (const char* file : {"col.1001.exr", "rig.1001.exr"}) {
        fs::rename(shot.dir / file, shot.dir / "gone.exr");
        const std::string error = test::errorOf<InvalidInput>([&] { (void)harness::farmRunCommand(run); });
        CHECK_THAT(error,
                   Contains(std::string(".stack[1].") + (file[0] == 'c' ? "texture: " : "rigidity: ")) &&
                       Contains(std::string(file) + " does not exist (expected the maps the plan was made "
                                                    "with, there while its tasks run)"));
        CHECK_THAT(error, !Contains("plan again"));
        fs::rename(shot.dir / "gone.exr", shot.dir / file);
    }
}

TEST_CASE("farm run: a warp mask or orientation map removed or added after planning is named",
          "[harness][farm][errors]") {
    // Either map is optional per tile: without the file the tile takes a derived mask or the density
    // heuristic, so a change after planning would warp this task's tiles unlike the tasks run before it.
    Shot shot;
    io::writeImage(shot.dir / "rig.1001.exr", io::Image(32, 32, 1, 0.0f));
    io::writeImage(shot.dir / "mask.1001.exr", io::Image(32, 32, 1, 1.0f));
    const auto [plan, uvTask] =
        planWithUvStage(shot, R"("rigidity": "rig.<UDIM>.exr", "mask": "mask.<UDIM>.exr")");
    const std::string mask = (shot.dir / "mask.1001.exr").string();
    CHECK(plan.tasks[static_cast<size_t>(uvTask)].maps == std::vector<std::string>{mask});
    // Written and read back.
    const fs::path planFile = shot.dir / "farm" / "farm_plan.json";
    CHECK(scene::readFarmPlan(planFile).tasks[static_cast<size_t>(uvTask)].maps ==
          std::vector<std::string>{mask});
    harness::FarmRunCommand run;
    run.plan = planFile;
    run.task = uvTask;

    fs::rename(mask, shot.dir / "gone.exr");
    std::string error = test::errorOf<InvalidInput>([&] { (void)harness::farmRunCommand(run); });
    CHECK_THAT(error, Contains("tasks[" + std::to_string(uvTask) + "].maps: names " + mask +
                               ", which does not exist now"));
    fs::rename(shot.dir / "gone.exr", mask);

    // A plan that lists no mask (made before the mask was painted): the mask found now is named.
    const std::string good = test::readText(planFile);
    std::string edited = good;
    const std::string listed = nlohmann::json(std::vector<std::string>{mask}).dump();
    REQUIRE(edited.find(listed) != std::string::npos);
    edited.replace(edited.find(listed), listed.size(), "[]");
    test::writeText(planFile, edited);
    error = test::errorOf<InvalidInput>([&] { (void)harness::farmRunCommand(run); });
    CHECK_THAT(error, Contains("does not name " + mask + ", which the scene's stage reads now") &&
                          Contains("plan again"));
    CHECK_FALSE(fs::exists(shot.dir / "farm" / scene::uvwarpRedirectName("tube", 1001, 1)));
    test::writeText(planFile, good);

    // As planned, the task runs.
    const scene::FarmTaskReport report = harness::farmRunCommand(run);
    CHECK_FALSE(report.written.empty());
    CHECK(fs::exists(shot.dir / "farm" / scene::uvwarpRedirectName("tube", 1001, 1)));
}

TEST_CASE("farm plan and run: an output that is an input, or a plan written over the scene, is refused",
          "[harness][farm][errors]") {
    // The scene's rest mesh named as a frame's output (the scene written for frame 1's mesh, planned into
    // its own folder): a task took the input for a finished output and reported the frame skipped.
    test::TempDir dir;
    io::writeObj(dir / "tube.0001.obj", test::tube({.rings = 6, .sides = 10}));
    test::writeText(dir / "shot.json", R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [
      {"name": "tube", "mesh": "tube.0001.obj", "stack": [{"type": "twist", "params": {"endAngle": 1.5}}]}]})");
    const std::string rest = test::readText(dir / "tube.0001.obj");
    harness::FarmPlanCommand plan;
    plan.scene = dir / "shot.json";
    plan.outDir = dir.path();
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::farmPlanCommand(plan); }),
               Contains("tube.0001.obj: is the rest mesh of ") && Contains(", and an output of task 0"));
    CHECK_FALSE(fs::exists(dir / "farm_plan.json"));
    // The plan named as the scene: refused, the scene kept.
    const std::string scene = test::readText(dir / "shot.json");
    plan.outDir = dir / "out";
    plan.plan = dir / "shot.json";
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::farmPlanCommand(plan); }),
               Contains("shot.json: is the scene, and the farm plan"));
    CHECK(test::readText(dir / "shot.json") == scene);
    // A plan moved to write into the scene's folder by hand: its task refuses to run, nothing written.
    plan.plan = dir / "out" / "farm_plan.json";
    (void)harness::farmPlanCommand(plan);
    std::string text = test::readText(plan.plan);
    const std::string out = "\"out\": " + nlohmann::json((dir / "out").string()).dump();
    REQUIRE(text.find(out) != std::string::npos);
    text.replace(text.find(out), out.size(), "\"out\": " + nlohmann::json(dir.path().string()).dump());
    test::writeText(plan.plan, text);
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)harness::farmRunCommand({plan.plan, 0});
               }),
               Contains("tube.0001.obj: is the rest mesh of ") && Contains(", and an output of task 0"));
    CHECK(test::readText(dir / "tube.0001.obj") == rest);
    CHECK_FALSE(fs::exists(dir / "tube.0002.obj"));
}
