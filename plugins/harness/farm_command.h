#pragma once

#include <exception>
#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

// `deformkit farm`: a scene's evaluation (deformkit eval, docs/scene.md) cut into independent tasks for a
// render farm (docs/farm.md):
//
//   deformkit farm plan SCENE --frames A-B --chunk N [--tiles-per-task T] --out DIR [--plan PLAN.json]
//   deformkit farm run PLAN --task K
//   deformkit farm submit --slurm PLAN [--sbatch-args "..."]
//
// A plan lists tasks, each a range of at most N consecutive frames with the files it writes (the names of
// deformkit eval): first the mesh tasks (DIR/<object>.<frame>.obj for every object), then, when objects
// have a UV-warp stage, one task per frame range and group of at most --tiles-per-task UDIM tiles writing
// those tiles' redirect maps and bakes (scene_uvwarp.h; memory bounded by one tile's solver, warm start
// within the task's frames, a cold start at its first frame). A task binds the scene's stacks once and
// evaluates its frames in order; outputs that exist are kept (a UV-warp task replays the warm start up to
// its last missing output), and every output is written atomically, so a task killed and run again
// finishes with the bytes an uninterrupted run writes. Exit codes of `farm run`: 0 done, 2 bad input a
// retry cannot cure, 1 anything else.
namespace deformkit::harness {

// The plan format version farm run reads.
inline constexpr int kFarmPlanVersion = 1;

// One task: frames firstFrame..lastFrame (inclusive, ascending) of every object of the scene.
struct FarmTask {
    int firstFrame = 0;
    int lastFrame = 0;
    // Empty: the task writes the objects' meshes. Otherwise UDIM tiles, ascending: the task runs the UV-warp
    // stages of the objects that have one, for these tiles only (no meshes).
    std::vector<int> tiles;
    // File names in the plan's output folder, frame by frame, objects in scene order.
    std::vector<std::string> outputs;
};

struct FarmPlan {
    std::filesystem::path scene;   // absolute
    std::filesystem::path outDir;  // absolute
    int chunk = 1;                 // frames per task at most
    std::vector<FarmTask> tasks;   // the task index is the position
};

struct FarmPlanCommand {
    std::filesystem::path scene;
    // Frames, ascending (parseFrames("1-24")); empty: the scene's "frames" range. Tasks never span a gap
    // of a list such as 1-10,15.
    std::vector<int> frames;
    int chunk = 10;                // frames per task at most, >= 1
    int tilesPerTask = 1;          // UDIM tiles per UV-warp task at most, >= 1
    std::filesystem::path outDir;  // created when missing
    std::filesystem::path plan;    // empty: outDir / "farm_plan.json"
};

// Reads the scene (checking it the way eval does), cuts the frames into tasks and writes the plan JSON
// atomically. Returns the plan as written (paths absolute). Throws InvalidInput for a chunk below 1, and
// as evalCommand for a bad scene.
FarmPlan farmPlanCommand(const FarmPlanCommand& command);

// The plan file farmPlanCommand writes for `command`.
[[nodiscard]] std::filesystem::path farmPlanPath(const FarmPlanCommand& command);

// The plan's JSON text.
[[nodiscard]] std::string formatFarmPlan(const FarmPlan& plan);

// Parses plan JSON text; `source` names it in messages. Throws ParseError for text that is not JSON and
// InvalidInput naming the JSON path ("plan.json: tasks[1].frames: ...") for anything else.
[[nodiscard]] FarmPlan parseFarmPlan(std::string_view text, const std::filesystem::path& source);

// Reads and parses a plan file; a missing file is InvalidInput, an unreadable one IoError.
[[nodiscard]] FarmPlan readFarmPlan(const std::filesystem::path& path);

struct FarmRunCommand {
    std::filesystem::path plan;
    int task = 0;  // index into the plan's tasks
};

struct FarmRunReport {
    int task = 0;
    std::vector<int> written;                  // frames with at least one output written, ascending
    std::vector<int> skipped;                  // frames whose outputs all existed
    std::vector<std::filesystem::path> files;  // written
};

// Runs one task. `log` gets JSON lines, flushed as they are done: for a mesh task one per frame,
//   {"task":0,"frame":1,"status":"written","seconds":0.012}   (status "written" or "skipped")
// and for a UV-warp task one per object, tile and frame, as `deformkit uvwarp --log` writes them, with
// "task" and "object" added.
// Throws InvalidInput / ParseError for bad input (plan, scene, task index out of range, a plan whose
// outputs differ from what the scene makes, a value the deformers reject at evaluation); IoError for a
// scene or output that cannot be read or written.
FarmRunReport farmRunCommand(const FarmRunCommand& command, std::ostream* log = nullptr);

// The exit code for an exception out of the farm commands: 2 for InvalidInput and ParseError (bad input:
// a retry writes nothing new), 1 for anything else (a file system or a scheduler failing, worth a retry).
[[nodiscard]] int farmExitCode(const std::exception& error);

struct FarmSubmitCommand {
    std::filesystem::path plan;
    std::vector<std::string> sbatchArgs;  // extra sbatch options, after DeformKit's (so they win)
    std::filesystem::path deformkit;      // the binary the tasks run; empty: this process's executable
    std::string sbatch = "sbatch";        // looked up on PATH unless it holds a '/'
};

// The sbatch arguments (without the program) that submit `plan` as a job array, one element per task, its
// index the task: --parsable --array=0-(N-1) --job-name --output beside the plan, the extra arguments,
// and --wrap running "exec DEFORMKIT farm run PLAN --task $SLURM_ARRAY_TASK_ID".
[[nodiscard]] std::vector<std::string> farmSbatchArguments(const FarmPlan& plan,
                                                           const std::filesystem::path& planFile,
                                                           const std::filesystem::path& deformkit,
                                                           const std::vector<std::string>& extra);

// Reads the plan, runs sbatch and returns the job id it prints. InvalidInput when sbatch is not found
// (naming PATH), as readFarmPlan for a bad plan; Error with sbatch's output when it fails.
std::string farmSubmitCommand(const FarmSubmitCommand& command);

// Splits a shell-like argument string: whitespace separates, '...' and "..." quote, backslash escapes
// outside single quotes. InvalidInput naming `option` for an unterminated quote.
[[nodiscard]] std::vector<std::string> splitArguments(std::string_view text, const std::string& option);

}  // namespace deformkit::harness
