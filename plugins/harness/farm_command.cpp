#include "farm_command.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "process.h"
#include "report_command.h"
#include "uvwarp_command.h"

namespace deformkit::harness {

namespace fs = std::filesystem;

fs::path farmPlanPath(const FarmPlanCommand& command) {
    return command.plan.empty() ? command.outDir / "farm_plan.json" : command.plan;
}

scene::FarmPlan farmPlanCommand(const FarmPlanCommand& command, std::vector<std::string>* notes) {
    if (command.chunk < 1) {
        throw InvalidInput(formatError("--chunk", "", "is " + std::to_string(command.chunk),
                                       "a whole number of frames per task >= 1"));
    }
    if (command.tilesPerTask < 1) {
        throw InvalidInput(formatError("--tiles-per-task", "", "is " + std::to_string(command.tilesPerTask),
                                       "a whole number of UDIM tiles per task >= 1"));
    }
    if (command.warmUp < 0) {
        throw InvalidInput(formatError("--warm-up", "", "is " + std::to_string(command.warmUp),
                                       "a whole number of frames >= 0"));
    }
    if (command.outDir.empty()) throw InvalidInput(formatError("--out", "", "is empty", "an output folder"));
    scene::FarmPlanOptions options;
    options.frames = command.frames;
    options.chunk = command.chunk;
    options.tilesPerTask = command.tilesPerTask;
    options.warmUp = command.warmUp;
    const scene::Scene scene = readScene(command.scene);
    const scene::FarmPlan plan = scene::planFarm(scene, command.scene, command.outDir, options);
    // The UV-warp stages planned as eval plans them before it writes anything (map patterns that match no
    // file, maps of the wrong size, outputs named as inputs): a scene eval refuses is refused here, not by
    // every task on the farm.
    std::vector<int> frames;
    for (const scene::FarmTask& task : plan.tasks)
        for (int f = task.firstFrame; f <= task.lastFrame; ++f)
            frames.push_back(f);
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    // Outputs, the plan and the scene's inputs apart: a task would skip an input it takes for a finished
    // output, and the plan be written over the scene.
    const fs::path planFile = farmPlanPath(command);
    scene::requireFarmFilesApart(scene, plan, planFile, true);
    for (size_t o = 0; o < scene.objects.size(); ++o) {
        if (!scene.objects[o].uvwarp) continue;
        scene::UvWarpStageRun run;
        run.frames = frames;
        run.tiles = scene.objects[o].uvwarp->tiles;
        run.outDir = plan.outDir;
        const std::optional<uvwarp::ShotSolver> solver = scene::uvwarpStageSolver(scene, o, run);
        if (solver && notes) {
            for (const std::string& note : solver->plannedNotes())
                notes->push_back("object '" + scene.objects[o].name + "': " + note);
        }
    }
    io::createFolder(plan.outDir);
    scene::writeFarmPlan(plan, planFile);
    return plan;
}

scene::FarmTaskReport farmRunCommand(const FarmRunCommand& command, std::ostream* log) {
    const scene::FarmPlan plan = scene::readFarmPlan(command.plan);
    const int numTasks = static_cast<int>(plan.tasks.size());
    if (command.task < 0 || command.task >= numTasks) {
        throw InvalidInput(formatError(command.plan.string(), "--task",
                                       "is " + std::to_string(command.task) + ", the plan has " +
                                           std::to_string(numTasks) + (numTasks == 1 ? " task" : " tasks"),
                                       "a task index from 0 to " + std::to_string(numTasks - 1)));
    }
    scene::SceneReadOptions options;
    options.ptexWeights = ptex::weightsFromPtex;
    return scene::runFarmTask(plan, command.plan, command.task, options, log);
}

int farmExitCode(const std::exception& error) {
    if (dynamic_cast<const InvalidInput*>(&error) || dynamic_cast<const ParseError*>(&error) ||
        dynamic_cast<const FarmReportRefused*>(&error))
        return 2;
    return 1;
}

namespace {

// `--output=` for a log beside the plan, `pattern` the file name with Slurm's own replacement symbols (%A,
// %a, %j). sbatch reads the whole path as a pattern: a '%' of the folder or the plan's name is written %%; a
// backslash anywhere turns every symbol off (the tasks' logs would overwrite one another, and Slurm drops
// the backslash, so the folder is not found), so such a path is refused.
std::string slurmOutput(const fs::path& planAbs, const std::string& suffix) {
    const std::string literal = (planAbs.parent_path() / planAbs.stem()).string();
    if (literal.find('\\') != std::string::npos) {
        throw InvalidInput(
            formatError(planAbs.string(), "",
                        "has a backslash in its path, which sbatch's --output reads as 'no patterns'",
                        "a plan whose folder and name have no backslash"));
    }
    std::string escaped;
    for (const char c : literal)
        escaped += c == '%' ? std::string("%%") : std::string(1, c);
    return "--output=" + escaped + suffix;
}

}  // namespace

std::vector<std::string> farmSbatchArguments(const scene::FarmPlan& plan, const fs::path& planFile,
                                             const fs::path& deformkit,
                                             const std::vector<std::string>& extra) {
    const fs::path planAbs = io::absolutePath(planFile);
    std::vector<std::string> args = {
        "--parsable",
        "--array=0-" + std::to_string(plan.tasks.size() - 1),
        "--job-name=deformkit-farm-" + plan.scene.stem().string(),
        // Slurm's %A (job) and %a (array index, the task) keep one log per task beside the plan.
        slurmOutput(planAbs, ".%A_%a.log"),
    };
    args.insert(args.end(), extra.begin(), extra.end());
    args.push_back("--wrap=exec " + shellQuote(io::absolutePath(deformkit).string()) + " farm run " +
                   shellQuote(planAbs.string()) + " --task \"$SLURM_ARRAY_TASK_ID\"");
    return args;
}

namespace {

// The task array's own sbatch options in `extra`, which the report job must not take: --array (the report
// would run once per element), --output and --error (its output would land among the task logs), and
// --job-name. Each as "--name=value", "--name value", "-x value" or "-xvalue".
struct ArrayOptions {
    std::vector<std::string> rest;  // every other argument, in order
    std::string output;             // the value of the array's --output, if given
};

ArrayOptions splitArrayOptions(const std::vector<std::string>& extra) {
    static const std::pair<const char*, const char*> kOptions[] = {
        {"--array", "-a"}, {"--output", "-o"}, {"--error", "-e"}, {"--job-name", "-J"}};
    ArrayOptions split;
    for (size_t i = 0; i < extra.size(); ++i) {
        const std::string& a = extra[i];
        bool taken = false;
        for (const auto& [name, letter] : kOptions) {
            std::string value;
            if (a == name || a == letter) {
                if (i + 1 < extra.size()) value = extra[++i];
            } else if (a.rfind(std::string(name) + "=", 0) == 0) {
                value = a.substr(std::string(name).size() + 1);
            } else if (a.size() > 2 && a.rfind(letter, 0) == 0) {
                value = a.substr(2);
            } else {
                continue;
            }
            if (std::string(name) == "--output") split.output = value;
            taken = true;
            break;
        }
        if (!taken) split.rest.push_back(a);
    }
    return split;
}

}  // namespace

std::vector<std::string> farmReportSbatchArguments(const scene::FarmPlan& plan, const fs::path& planFile,
                                                   const fs::path& deformkit,
                                                   const std::vector<std::string>& extra,
                                                   const std::string& arrayJob) {
    const fs::path planAbs = io::absolutePath(planFile);
    std::vector<std::string> args = {
        "--parsable",
        "--dependency=afterany:" + arrayJob,
        "--job-name=deformkit-report-" + plan.scene.stem().string(),
        slurmOutput(planAbs, "-report.%j.out"),
    };
    const ArrayOptions split = splitArrayOptions(extra);
    args.insert(args.end(), split.rest.begin(), split.rest.end());
    std::string wrap = "exec " + shellQuote(io::absolutePath(deformkit).string()) + " report --plan " +
                       shellQuote(planAbs.string());
    // Task logs moved by the array's --output are read from that folder.
    if (!split.output.empty())
        wrap += " " + shellQuote(io::absolutePath(fs::path(split.output)).parent_path().string());
    args.push_back("--wrap=" + wrap);
    return args;
}

namespace {

// Runs sbatch; returns the job id it prints (--parsable: "jobid" or "jobid;cluster").
std::string submitJob(const fs::path& sbatch, const std::vector<std::string>& args, const char* what) {
    const ProgramResult result = runProgram(sbatch, args);
    if (result.status != 0) {
        std::string said = trim(result.err.empty() ? result.out : result.err);
        for (char& c : said)
            if (c == '\n') c = ' ';
        throw Error(formatError(sbatch.string(), "",
                                "exited with status " + std::to_string(result.status) + ": " + said, what));
    }
    std::string id = trim(result.out);
    id = id.substr(0, id.find_first_of(";\n"));
    if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
        throw Error(formatError(sbatch.string(), "", "printed \"" + trim(result.out) + "\"", "a job id"));
    }
    return id;
}

}  // namespace

std::string farmSubmitCommand(const FarmSubmitCommand& command, std::string* reportJob) {
    const scene::FarmPlan plan = scene::readFarmPlan(command.plan);
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
    const std::string id =
        submitJob(sbatch, farmSbatchArguments(plan, command.plan, deformkit, command.sbatchArgs),
                  "the job array accepted");
    if (command.report) {
        // The array is queued now: a refused report job must not lead anyone to submit the plan again.
        try {
            const std::string report = submitJob(
                sbatch, farmReportSbatchArguments(plan, command.plan, deformkit, command.sbatchArgs, id),
                "the report job accepted");
            if (reportJob) *reportJob = report;
        } catch (const Error& e) {
            throw FarmReportRefused(id, std::string(e.what()) + "; the job array " + id +
                                            " is queued and runs without it: do not submit the plan again, "
                                            "run 'deformkit farm report " +
                                            fs::absolute(command.plan).string() + "' once its tasks end");
        }
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
    Command farm = cli.group(
        "farm",
        "Cut a scene's evaluation into render-farm tasks, run one task, or submit them (docs/farm.md)");

    struct PlanOptions {
        FarmPlanCommand command;
        std::string scene, out, plan;
    };
    auto p = std::make_shared<PlanOptions>();
    Command plan =
        cli.add(farm, "plan", "Write a plan: tasks of at most --chunk frames with their output files", [p] {
            FarmPlanCommand& c = p->command;
            c.scene = p->scene;
            c.outDir = p->out;
            c.plan = p->plan;
            std::vector<std::string> notes;
            const scene::FarmPlan made = farmPlanCommand(c, &notes);
            for (const std::string& note : notes)
                std::cout << "farm: " << note << "\n";
            std::cout << "farm: wrote " << farmPlanPath(c).string() << ": " << made.tasks.size()
                      << (made.tasks.size() == 1 ? " task" : " tasks") << "\n";
            return 0;
        });
    plan.option("SCENE", p->scene, "scene (.json, docs/scene.md)").required();
    plan.option(
        "--frames", [p](const std::string& value) { p->command.frames = parseFrames(value); }, "the scene's",
        "frames: 1-240, or a list such as 1-10,15 (an empty value is refused)");
    plan.option("--chunk", p->command.chunk, "frames per task at most").showDefault();
    plan.option("--tiles-per-task", p->command.tilesPerTask,
                "UDIM tiles per UV-warp task at most (scenes with a uvwarp stage)")
        .showDefault();
    plan.option(
            "--warm-up", p->command.warmUp,
            "with a scene's \"warmStart\": true, frames a UV-warp task solves before its range, so its maps "
            "hardly depend on the chunking (without it, none: each frame is solved from the identity)")
        .showDefault();
    plan.option("--out", p->out, "output folder of the tasks: <object>.<frame 4 digits>.obj").required();
    plan.option("--plan", p->plan, "plan file to write; default: <out>/farm_plan.json");

    // Exit codes a farm manager acts on: 2 bad input (no retry), 1 anything else (worth a retry).
    const auto farmExit = [](const std::function<void()>& work) {
        try {
            work();
            return 0;
        } catch (const std::bad_alloc&) {
            throw;  // the CLI's own message and exit code (1)
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
    Command run =
        cli.add(farm, "run",
                "Run one task of a plan, skipping frames already written; JSON lines on stdout. Exit 0 "
                "done, 2 bad input, 1 worth a retry",
                [r, farmExit] {
                    return farmExit([&] {
                        r->command.plan = r->plan;
                        (void)farmRunCommand(r->command, &std::cout);
                    });
                });
    run.option("PLAN", r->plan, "plan (.json) from deformkit farm plan").required();
    run.option("--task", r->command.task, "task index, from 0").required();

    struct SubmitOptions {
        FarmSubmitCommand command;
        std::string plan, sbatchArgs;
        bool slurm = false;
    };
    auto s = std::make_shared<SubmitOptions>();
    Command submit = cli.add(
        farm, "submit", "Submit a plan as a job array, one element per task; prints the job id",
        [s, farmExit] {
            return farmExit([&] {
                s->command.plan = s->plan;
                s->command.sbatchArgs = splitArguments(s->sbatchArgs, "--sbatch-args");
                std::string reportJob;
                try {
                    std::cout << farmSubmitCommand(s->command, &reportJob) << "\n";
                } catch (const FarmReportRefused& e) {
                    std::cout << e.arrayJob << "\n";  // the array's id, as when all went well
                    throw;
                }
                if (!reportJob.empty()) {
                    std::cerr << "farm: report job " << reportJob
                              << " writes report.html into the plan's output folder after the tasks\n";
                }
            });
        });
    submit.flag("--slurm", s->slurm, "submit with Slurm's sbatch (the one scheduler supported)").required();
    submit.flag(
        "--report", s->command.report,
        "also submit a job that writes the shot's HTML page after every task (deformkit report --plan)");
    submit.option("PLAN", s->plan, "plan (.json) from deformkit farm plan").required();
    submit.option("--sbatch-args", s->sbatchArgs,
                  "extra sbatch options, e.g. \"--partition=batch --time=1:00:00\"");

    struct ReportOptions {
        ReportCommand command;
        std::string plan;
        std::vector<std::string> logs;
    };
    auto r2 = std::make_shared<ReportOptions>();
    Command report =
        cli.add(farm, "report",
                "Write the shot's HTML page from the tasks' logs, listing missing or failed tasks "
                "(deformkit report --plan)",
                [r2] {
                    r2->command.plan = r2->plan;
                    r2->command.logs.assign(r2->logs.begin(), r2->logs.end());
                    const ReportCommandResult result = reportCommand(r2->command);
                    std::cout << "farm: report " << result.page.string() << " (" << result.logLines
                              << " log lines, " << result.report.problems
                              << (result.report.problems == 1 ? " problem" : " problems") << ")\n";
                    return 0;
                });
    report.option("PLAN", r2->plan, "plan (.json) from deformkit farm plan").required();
    report.option("--log", r2->logs,
                  "the tasks' logs or folders of them; default: <plan name>.*.log beside the plan");
    report.option("--out", r2->command.out, "the page; default: report.html in the plan's output folder");
}

}  // namespace deformkit::harness
