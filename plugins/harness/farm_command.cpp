#include "farm_command.h"
#include <iostream>
#include "cli.h"
#include "uvwarp_command.h"

#include "commands.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "eval_command.h"

extern char** environ;

namespace deformkit::harness {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kPlanExpected = "a DeformKit farm plan (docs/farm.md)";

fs::path absolutePath(const fs::path& path) {
    return fs::absolute(path).lexically_normal();
}

// The outputs of a task of `scene`: without tiles the meshes of frames first..last, frame by frame,
// objects in scene order; with tiles the UV-warp outputs, frame by frame, objects in scene order, tiles
// ascending (uvwarpOutputs).
std::vector<std::string> taskOutputs(const scene::Scene& scene, int first, int last,
                                     const std::vector<int>& tiles) {
    std::vector<std::string> outputs;
    for (int f = first; f <= last; ++f) {
        for (const scene::SceneObject& object : scene.objects) {
            if (tiles.empty()) {
                outputs.push_back(scene::frameFileName(object.name, f));
                continue;
            }
            for (int tile : tiles) {
                for (std::string& name : scene::uvwarpOutputs(object, tile, f))
                    outputs.push_back(std::move(name));
            }
        }
    }
    return outputs;
}

// Every tile some object's UV-warp stage warps, ascending.
std::vector<int> warpedTiles(const scene::Scene& scene) {
    std::vector<int> tiles;
    for (const scene::SceneObject& object : scene.objects) {
        if (!object.uvwarp) continue;
        for (int tile : scene::uvwarpWarpedTiles(*object.uvwarp))
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
        requireObject(root, "", {"deformkit_farm_plan", "scene", "out", "chunk", "tasks"});
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
        const json& tasks = member(root, "", "tasks");
        if (!tasks.is_array() || tasks.empty()) fail("tasks", "is " + describe(tasks), "a non-empty array");
        for (size_t k = 0; k < tasks.size(); ++k)
            plan.tasks.push_back(task(tasks[k], "tasks[" + std::to_string(k) + "]", plan.chunk));
        return plan;
    }

  private:
    FarmTask task(const json& j, const std::string& at, int chunk) const {
        requireObject(j, at, {"frames", "tiles", "outputs"});
        FarmTask task;
        const json& frames = member(j, at, "frames");
        if (!frames.is_array() || frames.size() != 2)
            fail(at + ".frames", "is " + describe(frames), "[first, last]");
        task.firstFrame = integer(frames[0], at + ".frames[0]");
        task.lastFrame = integer(frames[1], at + ".frames[1]");
        const int64_t count = int64_t{task.lastFrame} - task.firstFrame + 1;
        if (count < 1 || count > chunk) {
            fail(at + ".frames", "is " + frames.dump() + ", " + std::to_string(count) + " frames",
                 "first <= last and at most chunk (" + std::to_string(chunk) + ") frames");
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
        if (!j.is_number_integer() || j.get<int64_t>() < -1000000000 || j.get<int64_t>() > 1000000000)
            fail(at, "is " + describe(j), "a whole number");
        return static_cast<int>(j.get<int64_t>());
    }

    fs::path path(const json& j, const std::string& at) const {
        if (!j.is_string() || j.get<std::string>().empty()) fail(at, "is " + describe(j), "a path");
        const fs::path p = j.get<std::string>();
        return p.is_absolute() ? p : absolutePath(source_.parent_path() / p);
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

std::string shellQuote(const std::string& text) {
    std::string quoted = "'";
    for (char c : text) {
        if (c == '\'')
            quoted += "'\\''";
        else
            quoted += c;
    }
    return quoted + "'";
}

// The program `name` resolves to: itself when it holds a '/', else the first executable on PATH.
fs::path findProgram(const std::string& name) {
    if (name.find('/') != std::string::npos)
        return ::access(name.c_str(), X_OK) == 0 ? fs::path(name) : fs::path();
    const char* pathEnv = std::getenv("PATH");
    std::string_view dirs = pathEnv ? pathEnv : "";
    while (!dirs.empty()) {
        const size_t colon = dirs.find(':');
        const std::string dir(dirs.substr(0, colon));
        dirs = colon == std::string_view::npos ? std::string_view() : dirs.substr(colon + 1);
        const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
        std::error_code ec;
        if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    return {};
}

std::string readAll(int fd) {
    std::string text;
    char buffer[4096];
    for (;;) {
        const ssize_t n = ::read(fd, buffer, sizeof(buffer));
        if (n > 0) {
            text.append(buffer, static_cast<size_t>(n));
        } else if (n == 0 || errno != EINTR) {
            break;
        }
    }
    return text;
}

std::string trim(std::string text) {
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
        text.pop_back();
    size_t start = 0;
    while (start < text.size() && std::isspace(static_cast<unsigned char>(text[start])))
        ++start;
    return text.substr(start);
}

struct ProgramResult {
    int status = 0;  // exit status, or 128 + signal
    std::string out, err;
};

// Runs `program` with `args` (no shell) and collects its standard output and error.
ProgramResult runProgram(const fs::path& program, const std::vector<std::string>& args) {
    int outPipe[2], errPipe[2];
    if (::pipe(outPipe) != 0) throw Error(formatError(program.string(), "", "cannot create a pipe"));
    if (::pipe(errPipe) != 0) {
        ::close(outPipe[0]);
        ::close(outPipe[1]);
        throw Error(formatError(program.string(), "", "cannot create a pipe"));
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, outPipe[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, errPipe[1], STDERR_FILENO);
    posix_spawn_file_actions_addclose(&actions, outPipe[0]);
    posix_spawn_file_actions_addclose(&actions, errPipe[0]);
    std::vector<std::string> argvStrings{program.string()};
    argvStrings.insert(argvStrings.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argvStrings)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    const int spawned = ::posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(outPipe[1]);
    ::close(errPipe[1]);
    ProgramResult result;
    if (spawned == 0) {
        // The outputs of sbatch are a line or two: reading them one after the other cannot fill a pipe.
        result.out = readAll(outPipe[0]);
        result.err = readAll(errPipe[0]);
    }
    ::close(outPipe[0]);
    ::close(errPipe[0]);
    if (spawned != 0) {
        throw Error(formatError(program.string(), "", std::string("cannot run: ") + std::strerror(spawned),
                                "an executable program"));
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    result.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return result;
}

}  // namespace

fs::path farmPlanPath(const FarmPlanCommand& command) {
    return command.plan.empty() ? command.outDir / "farm_plan.json" : command.plan;
}

FarmPlan farmPlanCommand(const FarmPlanCommand& command) {
    if (command.chunk < 1) {
        throw InvalidInput(formatError("--chunk", "", "is " + std::to_string(command.chunk),
                                       "a whole number of frames per task >= 1"));
    }
    if (command.tilesPerTask < 1) {
        throw InvalidInput(formatError("--tiles-per-task", "", "is " + std::to_string(command.tilesPerTask),
                                       "a whole number of UDIM tiles per task >= 1"));
    }
    if (command.outDir.empty()) throw InvalidInput(formatError("--out", "", "is empty", "an output folder"));
    const scene::Scene scene = readScene(command.scene);
    std::vector<int> frames = command.frames;
    if (frames.empty()) {
        for (int f = scene.firstFrame; f <= scene.lastFrame; ++f)
            frames.push_back(f);
    }
    FarmPlan plan;
    plan.scene = absolutePath(command.scene);
    plan.outDir = absolutePath(command.outDir);
    plan.chunk = command.chunk;
    // Runs of consecutive frames, each at most `chunk` long.
    std::vector<std::pair<int, int>> ranges;
    for (size_t i = 0; i < frames.size();) {
        size_t end = i + 1;
        while (end < frames.size() && static_cast<int>(end - i) < command.chunk &&
               frames[end] == frames[end - 1] + 1)
            ++end;
        ranges.emplace_back(frames[i], frames[end - 1]);
        i = end;
    }
    for (const auto& [first, last] : ranges) {
        FarmTask task;
        task.firstFrame = first;
        task.lastFrame = last;
        task.outputs = taskOutputs(scene, first, last, {});
        plan.tasks.push_back(std::move(task));
    }
    const std::vector<int> tiles = warpedTiles(scene);
    for (const auto& [first, last] : ranges) {
        for (size_t t = 0; t < tiles.size(); t += static_cast<size_t>(command.tilesPerTask)) {
            FarmTask task;
            task.firstFrame = first;
            task.lastFrame = last;
            task.tiles.assign(
                tiles.begin() + static_cast<ptrdiff_t>(t),
                tiles.begin() + static_cast<ptrdiff_t>(
                                    std::min(tiles.size(), t + static_cast<size_t>(command.tilesPerTask))));
            task.outputs = taskOutputs(scene, first, last, task.tiles);
            plan.tasks.push_back(std::move(task));
        }
    }
    io::createFolder(plan.outDir);
    const fs::path planFile = farmPlanPath(command);
    if (planFile.has_parent_path()) io::createFolder(planFile.parent_path());
    io::writeFileAtomically(planFile, formatFarmPlan(plan));
    return plan;
}

std::string formatFarmPlan(const FarmPlan& plan) {
    // One task per line: a plan of thousands of tasks stays readable and diffable.
    std::ostringstream out;
    out << "{\n  \"deformkit_farm_plan\": " << kFarmPlanVersion
        << ",\n  \"scene\": " << json(plan.scene.string()).dump()
        << ",\n  \"out\": " << json(plan.outDir.string()).dump() << ",\n  \"chunk\": " << plan.chunk
        << ",\n  \"tasks\": [";
    for (size_t k = 0; k < plan.tasks.size(); ++k) {
        const FarmTask& t = plan.tasks[k];
        const json task = {
            {"frames", {t.firstFrame, t.lastFrame}}, {"tiles", t.tiles}, {"outputs", t.outputs}};
        out << (k ? ",\n    " : "\n    ") << task.dump();
    }
    out << "\n  ]\n}\n";
    return out.str();
}

FarmPlan parseFarmPlan(std::string_view text, const fs::path& source) {
    json root;
    try {
        root = json::parse(text.begin(), text.end());
    } catch (const json::exception& e) {
        std::string what = e.what();
        const size_t at = what.find("] ");
        throw ParseError(formatError(source.string(), "",
                                     at == std::string::npos ? what : what.substr(at + 2), kPlanExpected));
    }
    return PlanReader(source).plan(root);
}

FarmPlan readFarmPlan(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
        throw InvalidInput(
            formatError(path.string(), "", "does not exist", "a plan from deformkit farm plan"));
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError(formatError(path.string(), "", "cannot open the plan", "a readable JSON file"));
    std::ostringstream text;
    text << in.rdbuf();
    return parseFarmPlan(text.str(), path);
}

FarmRunReport farmRunCommand(const FarmRunCommand& command, std::ostream* log) {
    using Clock = std::chrono::steady_clock;
    const FarmPlan plan = readFarmPlan(command.plan);
    const int numTasks = static_cast<int>(plan.tasks.size());
    if (command.task < 0 || command.task >= numTasks) {
        throw InvalidInput(formatError(command.plan.string(), "--task",
                                       "is " + std::to_string(command.task) + ", the plan has " +
                                           std::to_string(numTasks) + (numTasks == 1 ? " task" : " tasks"),
                                       "a task index from 0 to " + std::to_string(numTasks - 1)));
    }
    const FarmTask& task = plan.tasks[static_cast<size_t>(command.task)];
    const std::string taskPath = "tasks[" + std::to_string(command.task) + "]";
    std::error_code ec;
    if (!fs::exists(plan.scene, ec)) {
        throw InvalidInput(formatError(command.plan.string(), "scene",
                                       "'" + plan.scene.string() + "' does not exist",
                                       "the scene the plan was made from"));
    }
    scene::SceneEvaluator evaluator(readScene(plan.scene));
    const scene::Scene& scene = evaluator.scene();
    const std::vector<std::string> expected = taskOutputs(scene, task.firstFrame, task.lastFrame, task.tiles);
    if (expected != task.outputs) {
        size_t i = 0;
        while (i < expected.size() && i < task.outputs.size() && expected[i] == task.outputs[i])
            ++i;
        const std::string listed = i < task.outputs.size() ? "\"" + task.outputs[i] + "\"" : "nothing";
        const std::string made = i < expected.size() ? "\"" + expected[i] + "\"" : "nothing";
        throw InvalidInput(formatError(command.plan.string(),
                                       taskPath + ".outputs[" + std::to_string(i) + "]",
                                       "is " + listed + ", the scene makes " + made,
                                       "the outputs of the scene as planned (plan again after changing it)"));
    }
    io::createFolder(plan.outDir);

    FarmRunReport report;
    report.task = command.task;
    const size_t numObjects = evaluator.numObjects();
    if (!task.tiles.empty()) {
        // Frames whose outputs all exist are reported skipped (the run may still replay them for the warm
        // start); the others written.
        for (int frame = task.firstFrame; frame <= task.lastFrame; ++frame) {
            bool all = true;
            for (const std::string& name : taskOutputs(scene, frame, frame, task.tiles))
                all = all && fs::exists(plan.outDir / name, ec);
            (all ? report.skipped : report.written).push_back(frame);
        }
        scene::UvWarpStageRun run;
        for (int frame = task.firstFrame; frame <= task.lastFrame; ++frame)
            run.frames.push_back(frame);
        run.tiles = task.tiles;
        run.outDir = plan.outDir;
        run.skipExisting = true;
        run.log = log;
        run.logTask = command.task;
        for (size_t o = 0; o < numObjects; ++o) {
            if (!scene.objects[o].uvwarp) continue;
            const uvwarp::ShotReport warped = scene::runUvWarpStage(evaluator, o, run);
            for (const uvwarp::ShotTileReport& tile : warped.tiles)
                report.files.insert(report.files.end(), tile.files.begin(), tile.files.end());
        }
        return report;
    }
    for (int frame = task.firstFrame; frame <= task.lastFrame; ++frame) {
        const Clock::time_point start = Clock::now();
        bool wrote = false;
        for (size_t o = 0; o < numObjects; ++o) {
            const fs::path file = plan.outDir / scene::frameFileName(scene.objects[o].name, frame);
            // An output that exists is complete: every write is atomic.
            if (fs::exists(file, ec)) continue;
            io::writeObj(file, evaluator.evaluate(o, frame), scene.objects[o].groups);
            report.files.push_back(file);
            wrote = true;
        }
        (wrote ? report.written : report.skipped).push_back(frame);
        if (log) {
            const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
            // In the order a person reads it: task, frame, status, seconds.
            const nlohmann::ordered_json line = {{"task", command.task},
                                                 {"frame", frame},
                                                 {"status", wrote ? "written" : "skipped"},
                                                 {"seconds", std::round(seconds * 1e4) / 1e4}};
            *log << line.dump() << "\n" << std::flush;
        }
    }
    return report;
}

int farmExitCode(const std::exception& error) {
    if (dynamic_cast<const InvalidInput*>(&error) || dynamic_cast<const ParseError*>(&error)) return 2;
    return 1;
}

std::vector<std::string> farmSbatchArguments(const FarmPlan& plan, const fs::path& planFile,
                                             const fs::path& deformkit,
                                             const std::vector<std::string>& extra) {
    const fs::path planAbs = absolutePath(planFile);
    std::vector<std::string> args = {
        "--parsable",
        "--array=0-" + std::to_string(plan.tasks.size() - 1),
        "--job-name=deformkit-farm-" + plan.scene.stem().string(),
        // Slurm's %A (job) and %a (array index, the task) keep one log per task beside the plan.
        "--output=" + (planAbs.parent_path() / (planAbs.stem().string() + ".%A_%a.log")).string(),
    };
    args.insert(args.end(), extra.begin(), extra.end());
    args.push_back("--wrap=exec " + shellQuote(absolutePath(deformkit).string()) + " farm run " +
                   shellQuote(planAbs.string()) + " --task \"$SLURM_ARRAY_TASK_ID\"");
    return args;
}

std::string farmSubmitCommand(const FarmSubmitCommand& command) {
    const FarmPlan plan = readFarmPlan(command.plan);
    const fs::path sbatch = findProgram(command.sbatch);
    if (sbatch.empty()) {
        const char* pathEnv = std::getenv("PATH");
        throw InvalidInput(formatError(command.sbatch, "",
                                       std::string("not found on PATH (") + (pathEnv ? pathEnv : "") + ")",
                                       "Slurm's sbatch: submit from a host with the Slurm client commands"));
    }
    fs::path deformkit = command.deformkit;
    if (deformkit.empty()) {
        std::error_code ec;
        deformkit = fs::read_symlink("/proc/self/exe", ec);
        if (ec)
            throw Error(
                formatError("/proc/self/exe", "", "cannot be read", "the path of the running deformkit"));
    }
    const ProgramResult result =
        runProgram(sbatch, farmSbatchArguments(plan, command.plan, deformkit, command.sbatchArgs));
    if (result.status != 0) {
        std::string said = trim(result.err.empty() ? result.out : result.err);
        for (char& c : said)
            if (c == '\n') c = ' ';
        throw Error(formatError(sbatch.string(), "",
                                "exited with status " + std::to_string(result.status) + ": " + said,
                                "the job array accepted"));
    }
    // --parsable prints "jobid" or "jobid;cluster".
    std::string id = trim(result.out);
    id = id.substr(0, id.find_first_of(";\n"));
    if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
        throw Error(formatError(sbatch.string(), "", "printed \"" + trim(result.out) + "\"", "a job id"));
    }
    return id;
}

std::vector<std::string> splitArguments(std::string_view text, const std::string& option) {
    std::vector<std::string> args;
    std::string current;
    bool inWord = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (std::isspace(static_cast<unsigned char>(c))) {
            if (inWord) args.push_back(std::move(current));
            current.clear();
            inWord = false;
        } else if (c == '\'' || c == '"') {
            size_t k = i + 1;
            for (; k < text.size() && text[k] != c; ++k) {
                if (c == '"' && text[k] == '\\' && k + 1 < text.size()) ++k;
                current += text[k];
            }
            if (k == text.size()) {
                throw InvalidInput(
                    formatError(option, "", std::string("has an unterminated ") + c + " quote",
                                "shell-like arguments such as --partition=batch --time=1:00:00"));
            }
            i = k;
            inWord = true;
        } else if (c == '\\' && i + 1 < text.size()) {
            current += text[++i];
            inWord = true;
        } else {
            current += c;
            inWord = true;
        }
    }
    if (inWord) args.push_back(std::move(current));
    return args;
}

void addFarmCommands(CommandLine& cli) {
    CLI::App* farm = cli.app().add_subcommand(
        "farm",
        "Cut a scene's evaluation into render-farm tasks, run one task, or submit them (docs/farm.md)");
    farm->require_subcommand(1);

    struct PlanOptions {
        FarmPlanCommand command;
        std::string scene, frames, out, plan;
    };
    auto p = std::make_shared<PlanOptions>();
    CLI::App* plan =
        cli.add(*farm, "plan", "Write a plan: tasks of at most --chunk frames with their output files", [p] {
            FarmPlanCommand& c = p->command;
            c.scene = p->scene;
            c.outDir = p->out;
            c.plan = p->plan;
            if (!p->frames.empty()) c.frames = parseFrames(p->frames);
            const FarmPlan made = farmPlanCommand(c);
            std::cout << "farm: wrote " << farmPlanPath(c).string() << ": " << made.tasks.size()
                      << (made.tasks.size() == 1 ? " task" : " tasks") << "\n";
            return 0;
        });
    plan->add_option("SCENE", p->scene, "scene (.json, docs/scene.md)")->required();
    plan->add_option("--frames", p->frames, "frames: 1-240, or a list such as 1-10,15; default: the scene's");
    plan->add_option("--chunk", p->command.chunk, "frames per task at most")->capture_default_str();
    plan->add_option("--tiles-per-task", p->command.tilesPerTask,
                     "UDIM tiles per UV-warp task at most (scenes with a uvwarp stage)")
        ->capture_default_str();
    plan->add_option("--out", p->out, "output folder of the tasks: <object>.<frame 4 digits>.obj")
        ->required();
    plan->add_option("--plan", p->plan, "plan file to write; default: <out>/farm_plan.json");

    // Exit codes a farm manager acts on: 2 bad input (no retry), 1 anything else (worth a retry).
    const auto farmExit = [](const std::function<void()>& work) {
        try {
            work();
            return 0;
        } catch (const std::exception& e) {
            std::cerr << "deformkit: error: " << e.what() << "\n";
            return farmExitCode(e);
        }
    };
    struct RunOptions {
        FarmRunCommand command;
        std::string plan;
    };
    auto r = std::make_shared<RunOptions>();
    CLI::App* run =
        cli.add(*farm, "run",
                "Run one task of a plan, skipping frames already written; JSON lines on stdout. Exit 0 "
                "done, 2 bad input, 1 worth a retry",
                [r, farmExit] {
                    return farmExit([&] {
                        r->command.plan = r->plan;
                        (void)farmRunCommand(r->command, &std::cout);
                    });
                });
    run->add_option("PLAN", r->plan, "plan (.json) from deformkit farm plan")->required();
    run->add_option("--task", r->command.task, "task index, from 0")->required();

    struct SubmitOptions {
        FarmSubmitCommand command;
        std::string plan, sbatchArgs;
        bool slurm = false;
    };
    auto s = std::make_shared<SubmitOptions>();
    CLI::App* submit =
        cli.add(*farm, "submit", "Submit a plan as a job array, one element per task; prints the job id",
                [s, farmExit] {
                    return farmExit([&] {
                        s->command.plan = s->plan;
                        s->command.sbatchArgs = splitArguments(s->sbatchArgs, "--sbatch-args");
                        std::cout << farmSubmitCommand(s->command) << "\n";
                    });
                });
    submit->add_flag("--slurm", s->slurm, "submit with Slurm's sbatch (the one scheduler supported)")
        ->required();
    submit->add_option("PLAN", s->plan, "plan (.json) from deformkit farm plan")->required();
    submit->add_option("--sbatch-args", s->sbatchArgs,
                       "extra sbatch options, e.g. \"--partition=batch --time=1:00:00\"");
}

}  // namespace deformkit::harness
