#pragma once

#include <exception>
#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/scene/farm_plan.h"

// `deformkit farm`: a scene's evaluation cut into independent tasks for a render farm (docs/farm.md), over
// the library's plans and tasks (scene/farm_plan.h):
//
//   deformkit farm plan SCENE --frames A-B --chunk N [--tiles-per-task T] --out DIR [--plan PLAN.json]
//   deformkit farm run PLAN --task K
//   deformkit farm submit --slurm PLAN [--sbatch-args "..."] [--report]
//   deformkit farm report PLAN [--out report.html]      the shot's page from the tasks' logs
//   (report_command.h)
//
// Exit codes of `farm run`: 0 done, 2 bad input a retry cannot cure, 1 anything else.
namespace deformkit::harness {

struct FarmPlanCommand {
    std::filesystem::path scene;
    // Frames, ascending (parseFrames("1-24")); empty: the scene's "frames" range. Tasks never span a gap
    // of a list such as 1-10,15.
    std::vector<int> frames;
    int chunk = 10;                // frames per task at most, >= 1
    int tilesPerTask = 1;          // UDIM tiles per UV-warp task at most, >= 1
    int warmUp = 6;                // frames a UV-warp task solves before its range, >= 0
    std::filesystem::path outDir;  // created when missing
    std::filesystem::path plan;    // empty: outDir / "farm_plan.json"
};

// Reads the scene (checking it the way eval does), cuts the frames into tasks (scene::planFarm) and writes
// the plan JSON atomically. Returns the plan as written (paths absolute). Throws InvalidInput naming the
// option for a chunk or tile count below 1, and as evalCommand for a bad scene. `notes`, when given, receives
// what the UV-warp stages' planning says, as eval prints it, per object ("object 'body': tile 1002: left
// unwarped: no rigidity map 'rig.1002.exr'").
scene::FarmPlan farmPlanCommand(const FarmPlanCommand& command, std::vector<std::string>* notes = nullptr);

// The plan file farmPlanCommand writes for `command`.
[[nodiscard]] std::filesystem::path farmPlanPath(const FarmPlanCommand& command);

struct FarmRunCommand {
    std::filesystem::path plan;
    int task = 0;  // index into the plan's tasks
};

// Runs one task (scene::runFarmTask, the scene read with every weight source the CLI has); `log` gets its
// JSON lines. Throws as scene::runFarmTask, a task index out of range naming --task.
scene::FarmTaskReport farmRunCommand(const FarmRunCommand& command, std::ostream* log = nullptr);

// The exit code for an exception out of the farm commands: 2 for InvalidInput and ParseError (bad input:
// a retry writes nothing new), 1 for anything else (a file system or a scheduler failing, worth a retry).
[[nodiscard]] int farmExitCode(const std::exception& error);

struct FarmSubmitCommand {
    std::filesystem::path plan;
    std::vector<std::string> sbatchArgs;  // extra sbatch options, after DeformKit's (so they win)
    std::filesystem::path deformkit;      // the binary the tasks run; empty: this process's executable
    std::string sbatch = "sbatch";        // looked up on PATH unless it holds a '/'
    // Also submit a job that runs after the array, whatever its tasks' exit codes (afterany), and writes
    // the shot's page: `deformkit report --plan PLAN` (report.html in the plan's output folder).
    bool report = false;
};

// The sbatch arguments of the report job after job array `arrayJob`: --parsable, --dependency=afterany,
// --job-name, --output beside the plan (<plan name>-report.%j.out, not read as a task's log), the extra
// arguments but the array's own (--array, --output, --error, --job-name), and --wrap running "exec DEFORMKIT
// report --plan PLAN", with the folder of the array's --output when the extra arguments moved the logs.
[[nodiscard]] std::vector<std::string> farmReportSbatchArguments(const scene::FarmPlan& plan,
                                                                 const std::filesystem::path& planFile,
                                                                 const std::filesystem::path& deformkit,
                                                                 const std::vector<std::string>& extra,
                                                                 const std::string& arrayJob);

// The sbatch arguments (without the program) that submit `plan` as a job array, one element per task, its
// index the task: --parsable --array=0-(N-1) --job-name --output beside the plan, the extra arguments,
// and --wrap running "exec DEFORMKIT farm run PLAN --task $SLURM_ARRAY_TASK_ID".
[[nodiscard]] std::vector<std::string> farmSbatchArguments(const scene::FarmPlan& plan,
                                                           const std::filesystem::path& planFile,
                                                           const std::filesystem::path& deformkit,
                                                           const std::vector<std::string>& extra);

// The job array was queued but sbatch refused the report job after it: exit code 2 (submitting the plan
// again would queue a second array); the message names the array and how to write the page instead.
struct FarmReportRefused : Error {
    FarmReportRefused(std::string array, const std::string& message)
        : Error(message), arrayJob(std::move(array)) {}
    std::string arrayJob;
};

// Reads the plan, runs sbatch and returns the job id it prints; with `report`, sets `reportJob` to the
// report job's id. InvalidInput when sbatch is not found (naming PATH), as readFarmPlan for a bad plan;
// Error with sbatch's output when it fails; FarmReportRefused when only the report job is refused.
std::string farmSubmitCommand(const FarmSubmitCommand& command, std::string* reportJob = nullptr);

// Splits a shell-like argument string: whitespace separates, '...' and "..." quote, backslash escapes
// outside single quotes. InvalidInput naming `option` for an unterminated quote.
[[nodiscard]] std::vector<std::string> splitArguments(std::string_view text, const std::string& option);

}  // namespace deformkit::harness
