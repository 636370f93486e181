#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/interrupter.h"
#include "deformkit/scene/scene.h"

// A scene's evaluation (docs/scene.md) cut into independent tasks for a render farm (docs/farm.md): the
// plan, its file, and the run of one task. `deformkit farm plan / run`, and any other scheduler's wrapper,
// call these.
//
// A plan lists tasks, each a range of at most `chunk` consecutive frames with the files it writes
// (scene/uvwarp_stage.h names them): first the mesh tasks (<object>.<frame>.obj for every object), then,
// when objects have a UV-warp stage, one task per frame range and group of at most `tilesPerTask` UDIM
// tiles writing those tiles' redirect maps and bakes (warm start within the task's frames, after up to
// `warmUp` frames before its range solved without outputs). A task binds the scene's stacks once and
// evaluates its frames in order; outputs that exist are kept (a UV-warp task replays the warm start up to its
// last missing output), and every output is written atomically, so a task killed and run again finishes with
// the bytes an uninterrupted run writes.
namespace deformkit::scene {

// The plan format version readFarmPlan reads.
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
    // UV-warp tasks: the warp masks and orientation maps there when the plan was made (uvwarpOptionalMaps),
    // absolute paths; the task refuses to run when the files there differ.
    std::vector<std::string> maps;
};

struct FarmPlan {
    std::filesystem::path scene;   // absolute
    std::filesystem::path outDir;  // absolute
    int chunk = 1;                 // frames per task at most
    // UV-warp tasks first solve up to this many frames before their range (within the scene's frames), so
    // that a frame's redirect map hardly depends on where its chunk began.
    int warmUp = 0;
    std::vector<FarmTask> tasks;  // the task index is the position
};

struct FarmPlanOptions {
    // Frames, ascending; empty: the scene's "frames" range. Tasks never span a gap of a list such as 1-10,15.
    std::vector<int> frames;
    int chunk = 10;        // frames per task at most, >= 1
    int tilesPerTask = 1;  // UDIM tiles per UV-warp task at most, >= 1
    int warmUp = 6;        // FarmPlan::warmUp, >= 0
};

// The plan of `scene` (read from `sceneFile`) writing into `outDir` (paths made absolute). Throws
// InvalidInput naming "chunk" or "tilesPerTask" when one is below 1.
[[nodiscard]] FarmPlan planFarm(const Scene& scene, const std::filesystem::path& sceneFile,
                                const std::filesystem::path& outDir, const FarmPlanOptions& options);

// The outputs of a task of `scene`: without tiles the meshes of frames first..last, frame by frame, objects
// in scene order; with tiles the UV-warp outputs, frame by frame, objects in scene order, tiles ascending.
[[nodiscard]] std::vector<std::string> farmTaskOutputs(const Scene& scene, int first, int last,
                                                       const std::vector<int>& tiles);

// Checks that no output of the plan's tasks (all of them, or task `task` alone) is a file the scene reads
// (the scene, rest meshes, animated inputs' frames of the tasks, weights files) or the plan file, and that
// the plan file, when `planWritten`, is no input either (io::requireFilesApart). Without it, a task skips an
// input it takes for its finished output, or the plan is written over the scene. Throws InvalidInput naming
// the file and both uses.
void requireFarmFilesApart(const Scene& scene, const FarmPlan& plan, const std::filesystem::path& planFile,
                           bool planWritten, std::optional<int> task = std::nullopt);

// The plan's JSON text, one task per line (a plan of thousands of tasks stays readable and diffable).
[[nodiscard]] std::string formatFarmPlan(const FarmPlan& plan);
// Writes it atomically, creating the file's folder.
void writeFarmPlan(const FarmPlan& plan, const std::filesystem::path& path);

// Parses plan JSON text; `source` names it in messages and its folder resolves relative paths. Throws
// ParseError for text that is not JSON and InvalidInput naming the JSON path ("plan.json: tasks[1].frames:
// ...") for anything else.
[[nodiscard]] FarmPlan parseFarmPlan(std::string_view text, const std::filesystem::path& source);
// Reads and parses a plan file; a missing file is InvalidInput, an unreadable one IoError.
[[nodiscard]] FarmPlan readFarmPlan(const std::filesystem::path& path);

struct FarmTaskReport {
    int task = 0;
    std::vector<int> written;                  // frames with at least one output written, ascending
    std::vector<int> skipped;                  // frames whose outputs all existed
    std::vector<std::filesystem::path> files;  // written
};

// Runs task `task` of `plan` (read from `planFile`, which messages name), reading the plan's scene with
// `readOptions` (the weight loaders the application has). `log` gets JSON lines, flushed as they are done:
// for a mesh task one per frame,
//   {"task":0,"frame":1,"status":"written","seconds":0.012}   (status "written" or "skipped")
// and for a UV-warp task one per object, tile and frame (uvwarp::ShotJob's lines with "task" and
// "object"). The interrupter, when given, is told after each frame (mesh tasks) or tile and frame. Throws
// InvalidInput / ParseError for bad input (the scene, a task index out of range, a plan whose outputs differ
// from what the scene makes, a value the deformers reject at evaluation); IoError for a scene or output that
// cannot be read or written; Cancelled when the interrupter asks.
FarmTaskReport runFarmTask(const FarmPlan& plan, const std::filesystem::path& planFile, int task,
                           const SceneReadOptions& readOptions, std::ostream* log = nullptr,
                           Interrupter* interrupter = nullptr);

}  // namespace deformkit::scene
