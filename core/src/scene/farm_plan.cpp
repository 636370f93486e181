#include "deformkit/scene/farm_plan.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/read_file.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "scene/json_reading.h"

namespace deformkit::scene {

namespace fs = std::filesystem;
using detail::json;

namespace {

constexpr const char* kPlanExpected = "a DeformKit farm plan (docs/farm.md)";

// Every tile some object's UV-warp stage warps over `frames` (uvwarpWarpedTiles), ascending.
std::vector<int> warpedTiles(const Scene& scene, std::span<const int> frames) {
    std::vector<int> tiles;
    for (const SceneObject& object : scene.objects) {
        if (!object.uvwarp) continue;
        for (int tile : uvwarpWarpedTiles(*object.uvwarp, frames))
            tiles.push_back(tile);
    }
    std::sort(tiles.begin(), tiles.end());
    tiles.erase(std::unique(tiles.begin(), tiles.end()), tiles.end());
    return tiles;
}

// Checks a plan's JSON, naming the plan file and the JSON path of what is wrong.
class PlanReader {
  public:
    explicit PlanReader(const fs::path& source) : source_(source) {}

    FarmPlan plan(const json& root) const {
        requireObject(root, "", {"deformkit_farm_plan", "scene", "out", "chunk", "warmUp", "tasks"});
        const json& version = member(root, "", "deformkit_farm_plan");
        if (!version.is_number_integer() || version.get<int64_t>() != kFarmPlanVersion) {
            fail("deformkit_farm_plan", "is " + version.dump(),
                 std::to_string(kFarmPlanVersion) + ", the plan version this deformkit reads");
        }
        FarmPlan plan;
        plan.scene = path(member(root, "", "scene"), "scene");
        plan.outDir = path(member(root, "", "out"), "out");
        plan.chunk = integer(member(root, "", "chunk"), "chunk");
        if (plan.chunk < 1) fail("chunk", "is " + std::to_string(plan.chunk), "a whole number >= 1");
        if (root.contains("warmUp")) {  // optional: a plan without it warms up nothing
            plan.warmUp = integer(root.at("warmUp"), "warmUp");
            if (plan.warmUp < 0) fail("warmUp", "is " + std::to_string(plan.warmUp), "a whole number >= 0");
        }
        const json& tasks = member(root, "", "tasks");
        if (!tasks.is_array() || tasks.empty()) fail("tasks", "is " + describe(tasks), "a non-empty array");
        for (size_t k = 0; k < tasks.size(); ++k)
            plan.tasks.push_back(task(tasks[k], "tasks[" + std::to_string(k) + "]", plan.chunk));
        return plan;
    }

  private:
    // As many frames as the CLI takes in one --frames list: a task of more is a hand-edited plan.
    static constexpr int64_t kMaxTaskFrames = 1000000;

    FarmTask task(const json& j, const std::string& at, int chunk) const {
        requireObject(j, at, {"frames", "tiles", "outputs", "maps"});
        FarmTask task;
        const json& frames = member(j, at, "frames");
        if (!frames.is_array() || frames.size() != 2)
            fail(at + ".frames", "is " + describe(frames), "[first, last]");
        task.firstFrame = integer(frames[0], at + ".frames[0]");
        task.lastFrame = integer(frames[1], at + ".frames[1]");
        const int64_t count = int64_t{task.lastFrame} - task.firstFrame + 1;
        if (count < 1 || count > chunk || count > kMaxTaskFrames) {
            fail(at + ".frames", "is " + frames.dump() + ", " + std::to_string(count) + " frames",
                 "first <= last and at most chunk (" + std::to_string(chunk) + ") frames, at most " +
                     std::to_string(kMaxTaskFrames));
        }
        const json& tiles = member(j, at, "tiles");
        if (!tiles.is_array()) fail(at + ".tiles", "is " + describe(tiles), "an array of UDIM tiles");
        for (size_t i = 0; i < tiles.size(); ++i) {
            const std::string element = at + ".tiles[" + std::to_string(i) + "]";
            const int tile = integer(tiles[i], element);
            if (tile < 1001 || tile > 9999) fail(element, "is " + tiles[i].dump(), "a UDIM tile, 1001..9999");
            if (!task.tiles.empty() && tile <= task.tiles.back())
                fail(element, "is " + tiles[i].dump(), "tiles in ascending order, each once");
            task.tiles.push_back(tile);
        }
        const json& outputs = member(j, at, "outputs");
        if (!outputs.is_array()) fail(at + ".outputs", "is " + describe(outputs), "an array of file names");
        for (size_t i = 0; i < outputs.size(); ++i) {
            const std::string element = at + ".outputs[" + std::to_string(i) + "]";
            if (!outputs[i].is_string()) fail(element, "is " + describe(outputs[i]), "a file name");
            const std::string name = outputs[i].get<std::string>();
            if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos)
                fail(element, "is \"" + name + "\"", "a file name in the output folder, without '/'");
            task.outputs.push_back(name);
        }
        if (const auto it = j.find("maps"); it != j.end()) {  // UV-warp tasks
            if (!it->is_array() || task.tiles.empty())
                fail(at + ".maps", "is " + describe(*it), "a UV-warp task's array of map files");
            for (size_t i = 0; i < it->size(); ++i) {
                const std::string element = at + ".maps[" + std::to_string(i) + "]";
                if (!(*it)[i].is_string()) fail(element, "is " + describe((*it)[i]), "a file name");
                task.maps.push_back((*it)[i].get<std::string>());
            }
        }
        return task;
    }

    const json& member(const json& object, const std::string& at, const char* key) const {
        const auto it = object.find(key);
        if (it == object.end()) fail(join(at, key), "is missing", kPlanExpected);
        return *it;
    }

    void requireObject(const json& j, const std::string& at, std::initializer_list<const char*> keys) const {
        if (!j.is_object()) fail(at, "is " + describe(j), "an object");
        for (const auto& item : j.items()) {
            bool known = false;
            for (const char* key : keys)
                known = known || item.key() == key;
            if (!known) fail(join(at, item.key()), "is not a plan key", kPlanExpected);
        }
    }

    int integer(const json& j, const std::string& at) const {
        if (!j.is_number_integer() || j.get<int64_t>() < -kMaxFrameNumber ||
            j.get<int64_t>() > kMaxFrameNumber) {
            fail(at, "is " + describe(j),
                 "a whole number from -" + std::to_string(kMaxFrameNumber) + " to " +
                     std::to_string(kMaxFrameNumber));
        }
        return static_cast<int>(j.get<int64_t>());
    }

    fs::path path(const json& j, const std::string& at) const {
        if (!j.is_string() || j.get<std::string>().empty()) fail(at, "is " + describe(j), "a path");
        const fs::path p = j.get<std::string>();
        return p.is_absolute() ? p : io::absolutePath(source_.parent_path() / p);
    }

    static std::string describe(const json& j) {
        const std::string text = j.dump();
        return text.size() <= 60 ? text : text.substr(0, 57) + "...";
    }

    static std::string join(const std::string& at, const std::string& key) {
        return at.empty() ? key : at + "." + key;
    }

    [[noreturn]] void fail(const std::string& at, const std::string& problem,
                           const std::string& expected) const {
        throw InvalidInput(formatError(source_.string(), at.empty() ? "(root)" : at, problem, expected));
    }

    fs::path source_;
};

}  // namespace

std::vector<std::string> farmTaskOutputs(const Scene& scene, int first, int last,
                                         const std::vector<int>& tiles) {
    std::vector<std::string> outputs;
    for (int f = first; f <= last; ++f) {
        for (const SceneObject& object : scene.objects) {
            if (tiles.empty()) {
                outputs.push_back(frameFileName(object.name, f));
                continue;
            }
            for (int tile : tiles) {
                for (std::string& name : uvwarpOutputs(object, tile, f))
                    outputs.push_back(std::move(name));
            }
        }
    }
    return outputs;
}

namespace {

// The last `count` frames of the plan's tasks before `frame`, ascending.
std::vector<int> plannedFramesBefore(const FarmPlan& plan, int frame, int count) {
    std::set<int> before;
    for (const FarmTask& task : plan.tasks) {
        const int64_t last = std::min<int64_t>(task.lastFrame, int64_t{frame} - 1);
        for (int64_t f = std::max<int64_t>(task.firstFrame, last - count + 1); f <= last; ++f)
            before.insert(static_cast<int>(f));
    }
    std::vector<int> frames(before.begin(), before.end());
    if (frames.size() > static_cast<size_t>(count)) frames.erase(frames.begin(), frames.end() - count);
    return frames;
}

}  // namespace

FarmPlan planFarm(const Scene& scene, const fs::path& sceneFile, const fs::path& outDir,
                  const FarmPlanOptions& options) {
    if (options.chunk < 1) {
        throw InvalidInput(formatError("farm plan", "chunk", "is " + std::to_string(options.chunk),
                                       "a whole number of frames per task >= 1"));
    }
    if (options.tilesPerTask < 1) {
        throw InvalidInput(formatError("farm plan", "tilesPerTask",
                                       "is " + std::to_string(options.tilesPerTask),
                                       "a whole number of UDIM tiles per task >= 1"));
    }
    if (options.warmUp < 0) {
        throw InvalidInput(formatError("farm plan", "warmUp", "is " + std::to_string(options.warmUp),
                                       "a whole number of frames >= 0"));
    }
    if (outDir.empty()) throw InvalidInput(formatError("farm plan", "output folder", "is empty", "a folder"));
    std::vector<int> frames = options.frames;
    if (frames.empty()) {
        for (int f = scene.firstFrame; f <= scene.lastFrame; ++f)
            frames.push_back(f);
    }
    // What eval checks before any work, the plan checks too: a task must not be the first to find a slide
    // vertex out of range or a UV-warp stage without any rigidity map.
    SceneEvaluator(scene).check(frames);
    for (size_t o = 0; o < scene.objects.size(); ++o)
        requireRigidityMaps(scene, o, frames);
    FarmPlan plan;
    plan.scene = io::absolutePath(sceneFile);
    plan.outDir = io::absolutePath(outDir);
    plan.chunk = options.chunk;
    plan.warmUp = options.warmUp;
    // Runs of consecutive frames, each at most `chunk` long.
    std::vector<std::pair<int, int>> ranges;
    for (size_t i = 0; i < frames.size();) {
        size_t end = i + 1;
        while (end < frames.size() && static_cast<int>(end - i) < options.chunk &&
               frames[end] == frames[end - 1] + 1)
            ++end;
        ranges.emplace_back(frames[i], frames[end - 1]);
        i = end;
    }
    for (const auto& [first, last] : ranges) {
        FarmTask task;
        task.firstFrame = first;
        task.lastFrame = last;
        task.outputs = farmTaskOutputs(scene, first, last, {});
        plan.tasks.push_back(std::move(task));
    }
    const std::vector<int> tiles = warpedTiles(scene, frames);
    for (const auto& [first, last] : ranges) {
        for (size_t t = 0; t < tiles.size(); t += static_cast<size_t>(options.tilesPerTask)) {
            FarmTask task;
            task.firstFrame = first;
            task.lastFrame = last;
            task.tiles.assign(
                tiles.begin() + static_cast<ptrdiff_t>(t),
                tiles.begin() + static_cast<ptrdiff_t>(
                                    std::min(tiles.size(), t + static_cast<size_t>(options.tilesPerTask))));
            task.outputs = farmTaskOutputs(scene, first, last, task.tiles);
            task.maps = uvwarpOptionalMaps(scene, first, last, task.tiles);
            plan.tasks.push_back(std::move(task));
        }
    }
    return plan;
}

std::string formatFarmPlan(const FarmPlan& plan) {
    // One task per line: a plan of thousands of tasks stays readable and diffable.
    std::ostringstream out;
    out << "{\n  \"deformkit_farm_plan\": " << kFarmPlanVersion
        << ",\n  \"scene\": " << json(plan.scene.string()).dump()
        << ",\n  \"out\": " << json(plan.outDir.string()).dump() << ",\n  \"chunk\": " << plan.chunk
        << ",\n  \"warmUp\": " << plan.warmUp << ",\n  \"tasks\": [";
    for (size_t k = 0; k < plan.tasks.size(); ++k) {
        const FarmTask& t = plan.tasks[k];
        json task = {{"frames", {t.firstFrame, t.lastFrame}}, {"tiles", t.tiles}, {"outputs", t.outputs}};
        if (!t.tiles.empty()) task["maps"] = t.maps;
        out << (k ? ",\n    " : "\n    ") << task.dump();
    }
    out << "\n  ]\n}\n";
    return out.str();
}

void writeFarmPlan(const FarmPlan& plan, const fs::path& path) {
    io::requireExtension(path, {".json"}, "a farm plan (JSON)");
    if (path.has_parent_path()) io::createFolder(path.parent_path());
    io::writeFileAtomically(path, formatFarmPlan(plan));
}

FarmPlan parseFarmPlan(std::string_view text, const fs::path& source) {
    return PlanReader(source).plan(detail::parseJson(text, source.string(), kPlanExpected));
}

FarmPlan readFarmPlan(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
        throw InvalidInput(
            formatError(path.string(), "", "does not exist", "a plan from deformkit farm plan"));
    }
    if (fs::is_directory(path, ec)) {  // bad input (exit 2), as a missing plan: a retry would fail alike
        throw InvalidInput(formatError(path.string(), "", "is a folder", "a plan from deformkit farm plan"));
    }
    return parseFarmPlan(io::readFile(path, "farm plan"), path);
}

void requireFarmFilesApart(const Scene& scene, const FarmPlan& plan, const fs::path& planFile,
                           bool planWritten, std::optional<int> task) {
    std::vector<io::FileUse> files;
    std::vector<int> frames;
    for (size_t i = 0; i < plan.tasks.size(); ++i) {
        if (task && static_cast<int>(i) != *task) continue;
        const FarmTask& t = plan.tasks[i];
        for (const std::string& name : t.outputs)
            files.push_back({plan.outDir / name, "an output of task " + std::to_string(i), true});
        for (int f = t.firstFrame; f <= t.lastFrame; ++f)
            frames.push_back(f);
    }
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    files.push_back({planFile, "the farm plan", planWritten});
    for (io::FileUse& input : sceneInputFiles(scene, frames))
        files.push_back(std::move(input));
    io::requireFilesApart(files);
}

FarmTaskReport runFarmTask(const FarmPlan& plan, const fs::path& planFile, int task,
                           const SceneReadOptions& readOptions, std::ostream* log, Interrupter* interrupter) {
    using Clock = std::chrono::steady_clock;
    const std::string planName = planFile.string();
    const int numTasks = static_cast<int>(plan.tasks.size());
    if (task < 0 || task >= numTasks) {
        throw InvalidInput(formatError(planName, "task",
                                       "is " + std::to_string(task) + ", the plan has " +
                                           std::to_string(numTasks) + (numTasks == 1 ? " task" : " tasks"),
                                       "a task index from 0 to " + std::to_string(numTasks - 1)));
    }
    const FarmTask& t = plan.tasks[static_cast<size_t>(task)];
    const std::string taskPath = "tasks[" + std::to_string(task) + "]";
    std::error_code ec;
    if (!fs::exists(plan.scene, ec)) {
        throw InvalidInput(formatError(planName, "scene", "'" + plan.scene.string() + "' does not exist",
                                       "the scene the plan was made from"));
    }
    SceneEvaluator evaluator(readScene(plan.scene, readOptions));
    const Scene& scene = evaluator.scene();
    const std::vector<std::string> expected = farmTaskOutputs(scene, t.firstFrame, t.lastFrame, t.tiles);
    if (expected != t.outputs) {
        // A map the plan was made with and that has gone is named itself (it is not the scene that changed):
        // bad input, exit 2, as any missing file the scene names (docs/farm.md, Exit codes).
        if (const std::string missing =
                missingPlannedMap(scene, t.outputs, t.firstFrame, t.lastFrame, t.tiles);
            !missing.empty()) {
            throw InvalidInput(formatError(planName, taskPath, missing,
                                           "the maps the plan was made with, there while its tasks run"));
        }
        size_t i = 0;
        while (i < expected.size() && i < t.outputs.size() && expected[i] == t.outputs[i])
            ++i;
        const std::string listed = i < t.outputs.size() ? "\"" + t.outputs[i] + "\"" : "nothing";
        const std::string made = i < expected.size() ? "\"" + expected[i] + "\"" : "nothing";
        throw InvalidInput(formatError(planName, taskPath + ".outputs[" + std::to_string(i) + "]",
                                       "is " + listed + ", the scene makes " + made,
                                       "the outputs of the scene as planned (plan again after changing it)"));
    }
    // The optional maps as planned: one removed would give the tile a derived mask (or the density
    // heuristic), one added a mask the other tasks did not have.
    if (!t.tiles.empty()) {
        const std::vector<std::string> maps = uvwarpOptionalMaps(scene, t.firstFrame, t.lastFrame, t.tiles);
        for (const std::string& file : t.maps) {
            if (std::find(maps.begin(), maps.end(), file) == maps.end()) {
                throw InvalidInput(formatError(planName, taskPath + ".maps",
                                               "names " + file + ", which does not exist now",
                                               "the maps the plan was made with, there while its tasks run"));
            }
        }
        for (const std::string& file : maps) {
            if (std::find(t.maps.begin(), t.maps.end(), file) == t.maps.end()) {
                throw InvalidInput(
                    formatError(planName, taskPath + ".maps",
                                "does not name " + file + ", which the scene's stage reads now",
                                "the maps the plan was made with (plan again after adding one)"));
            }
        }
    }
    // A UV-warp stage added to the scene after planning has no task: every task checks the plan still
    // covers the tiles the scene warps over the plan's frames, as planned.
    std::set<int> planned;
    std::set<int> planFrames;
    for (const FarmTask& other : plan.tasks) {
        planned.insert(other.tiles.begin(), other.tiles.end());
        for (int f = other.firstFrame; f <= other.lastFrame; ++f)
            planFrames.insert(f);
    }
    const std::vector<int> frameList(planFrames.begin(), planFrames.end());
    for (const int tile : warpedTiles(scene, frameList)) {
        if (!planned.contains(tile)) {
            throw InvalidInput(
                formatError(planName, "tasks",
                            "have no task for UDIM tile " + std::to_string(tile) + ", which the scene warps",
                            "a task per tile the scene warps (plan again after changing it)"));
        }
    }
    requireFarmFilesApart(scene, plan, planFile, false, task);
    io::createFolder(plan.outDir);

    FarmTaskReport report;
    report.task = task;
    const size_t numObjects = evaluator.numObjects();
    if (!t.tiles.empty()) {
        // Frames whose outputs all exist are reported skipped (the run may still replay them for the warm
        // start); the others written.
        for (int frame = t.firstFrame; frame <= t.lastFrame; ++frame) {
            bool all = true;
            for (const std::string& name : farmTaskOutputs(scene, frame, frame, t.tiles))
                all = all && fs::is_regular_file(plan.outDir / name, ec);
            (all ? report.skipped : report.written).push_back(frame);
        }
        UvWarpStageRun run;
        // Up to plan.warmUp of the planned frames before the range warm-start the task, as they warm-start
        // an uninterrupted run of the plan's frames (which may have gaps).
        run.frames = plannedFramesBefore(plan, t.firstFrame, plan.warmUp);
        run.warmUpFrames = static_cast<int32_t>(run.frames.size());
        for (int frame = t.firstFrame; frame <= t.lastFrame; ++frame)
            run.frames.push_back(frame);
        run.tiles = t.tiles;
        run.outDir = plan.outDir;
        run.skipExisting = true;
        run.log = log;
        run.logTask = task;
        for (size_t o = 0; o < numObjects; ++o) {
            if (!scene.objects[o].uvwarp) continue;
            const uvwarp::ShotReport warped = runUvWarpStage(evaluator, o, run, interrupter);
            for (const uvwarp::ShotTileReport& tile : warped.tiles)
                report.files.insert(report.files.end(), tile.files.begin(), tile.files.end());
        }
        return report;
    }
    const int64_t frames = int64_t{t.lastFrame} - t.firstFrame + 1;
    const InterrupterScope scope(interrupter, "farm task", frames);
    for (int frame = t.firstFrame; frame <= t.lastFrame; ++frame) {
        const Clock::time_point start = Clock::now();
        bool wrote = false;
        for (size_t o = 0; o < numObjects; ++o) {
            const fs::path file = plan.outDir / frameFileName(scene.objects[o].name, frame);
            // An output that exists is complete: every write is atomic. (A folder in its place is not one:
            // writing there then names it.)
            if (fs::is_regular_file(file, ec)) continue;
            io::writeObj(file, evaluator.evaluate(o, frame), scene.objects[o].groups);
            report.files.push_back(file);
            wrote = true;
        }
        (wrote ? report.written : report.skipped).push_back(frame);
        if (log) {
            const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
            // In the order a person reads it: task, frame, status, seconds.
            const nlohmann::ordered_json line = {{"task", task},
                                                 {"frame", frame},
                                                 {"status", wrote ? "written" : "skipped"},
                                                 {"seconds", std::round(seconds * 1e4) / 1e4}};
            *log << line.dump() << "\n" << std::flush;
        }
        const std::string unit = "frame " + std::to_string(frame) + (wrote ? " written" : " skipped");
        if (interrupter && interrupter->wasInterrupted(frame - t.firstFrame + 1, frames, unit)) {
            throw Cancelled(formatError(planName, taskPath, "cancelled after " + unit,
                                        "outputs written so far are complete; a rerun resumes"));
        }
    }
    return report;
}

}  // namespace deformkit::scene
