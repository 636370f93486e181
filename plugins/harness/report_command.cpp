#include "report_command.h"

#include <algorithm>
#include <iostream>
#include <memory>
#include <optional>
#include <utility>

#include "cli.h"
#include "commands.h"
#include "deformkit/error.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/farm_plan.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "deformkit/uvwarp/shot_log.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

// The logs a folder holds, by name.
std::vector<fs::path> logsIn(const fs::path& folder, const std::string& prefix = {}) {
    std::vector<fs::path> out;
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
        const std::string name = entry.path().filename().string();
        const std::string ext = entry.path().extension().string();
        if (entry.is_regular_file(ec) && (ext == ".jsonl" || ext == ".log") && name.rfind(prefix, 0) == 0) {
            out.push_back(entry.path());
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

// The geometry callback over the scene `read` gives when first asked for (called once).
std::function<std::optional<uvwarp::ReportGeometry>(const std::string&, int)> sceneGeometryOf(
    std::function<scene::Scene()> read) {
    return [read = std::move(read), evaluator = std::shared_ptr<scene::SceneEvaluator>()](
               const std::string& object, int frame) mutable -> std::optional<uvwarp::ReportGeometry> {
        if (!evaluator) evaluator = std::make_shared<scene::SceneEvaluator>(read());
        const scene::Scene& s = evaluator->scene();
        for (size_t o = 0; o < s.objects.size(); ++o) {
            if (s.objects[o].name != object) continue;
            const geom::Mesh& mesh = evaluator->evaluate(o, frame);
            return uvwarp::ReportGeometry{s.objects[o].rest,
                                          std::vector<glm::vec3>(mesh.points().begin(), mesh.points().end())};
        }
        return std::nullopt;
    };
}

}  // namespace

std::function<std::optional<uvwarp::ReportGeometry>(const std::string&, int)> sceneGeometry(
    const fs::path& scene) {
    return sceneGeometryOf([scene] { return readScene(scene); });
}

ReportCommandResult reportCommand(const ReportCommand& command) {
    uvwarp::HtmlReportOptions options;
    if (!command.title.empty()) options.title = command.title;
    options.rerun = command.rerun;
    std::vector<fs::path> logs;
    for (const fs::path& log : command.logs) {
        std::error_code ec;
        if (fs::is_directory(log, ec)) {
            const std::vector<fs::path> inside = logsIn(log);
            logs.insert(logs.end(), inside.begin(), inside.end());
        } else {
            logs.push_back(log);
        }
    }
    fs::path page = command.out;
    std::vector<std::pair<fs::path, std::string>> planFiles;  // the plan and its outputs, by what they are
    if (command.plan) {
        const scene::FarmPlan plan = scene::readFarmPlan(*command.plan);
        const fs::path planFile = fs::absolute(*command.plan);
        planFiles.emplace_back(planFile, "the plan");
        for (size_t k = 0; k < plan.tasks.size(); ++k)
            for (const std::string& output : plan.tasks[k].outputs)
                planFiles.emplace_back(plan.outDir / output,
                                       "an output of task " + std::to_string(k) + " of the plan");
        if (command.logs.empty()) logs = logsIn(planFile.parent_path(), planFile.stem().string() + ".");
        // Which objects write maps of which tiles, so that a task killed after one object's maps and
        // before another's is missing; without the scene, any object's line counts for its tile.
        std::optional<scene::Scene> planned;
        try {
            planned = readScene(plan.scene);
        } catch (const Error&) {
        }
        for (size_t k = 0; k < plan.tasks.size(); ++k) {
            const scene::FarmTask& task = plan.tasks[k];
            std::vector<std::pair<std::string, int>> objectTiles;
            if (planned) {
                for (const scene::SceneObject& object : planned->objects)
                    for (const int tile : task.tiles)
                        if (!scene::uvwarpOutputs(object, tile, task.firstFrame).empty())
                            objectTiles.emplace_back(object.name, tile);
            }
            options.tasks.push_back(
                {static_cast<int>(k), task.firstFrame, task.lastFrame, task.tiles, std::move(objectTiles),
                 "deformkit farm run " + planFile.string() + " --task " + std::to_string(k)});
        }
        options.searchFolders.push_back(plan.outDir);
        // The heatmaps' geometry as the tasks made it (the mesh tasks' OBJs may not be there), from the
        // scene read above when it could be.
        if (planned) {
            auto read = std::make_shared<scene::Scene>(std::move(*planned));
            options.geometry = sceneGeometryOf([read] { return std::move(*read); });
        } else {
            options.geometry = sceneGeometry(plan.scene);
        }
        options.rerun.push_back("deformkit farm submit --slurm " + planFile.string() +
                                "   # every task: finished frames are skipped");
        if (page.empty()) page = plan.outDir / "report.html";
        if (options.title == uvwarp::HtmlReportOptions{}.title)
            options.title = "Farm shot " + plan.scene.stem().string();
    }
    if (command.scene) options.geometry = sceneGeometry(*command.scene);
    if (logs.empty()) {
        throw InvalidInput(formatError(
            "report", "", "has no log to read",
            command.plan ? "logs given, or " + command.plan->stem().string() + ".*.log beside the plan"
                         : std::string("a JSON-lines shot log (uvwarp --log, farm run)")));
    }
    if (page.empty()) page = logs.front().parent_path() / "report.html";
    // The page is written over no log it reads and no output of the plan (a map the page replaced would be
    // skipped as done by a task run again).
    const auto key = [](const fs::path& path) {  // absolute, links of its existing part resolved
        std::error_code error;
        const fs::path resolved = fs::weakly_canonical(path, error);
        return (error ? fs::absolute(path) : resolved).lexically_normal();
    };
    const fs::path pageKey = key(page);
    for (const fs::path& file : logs) {
        if (key(file) == pageKey) {
            throw InvalidInput(formatError(page.string(), "", "is a log the page reads",
                                           "a page apart from the shot's logs and outputs"));
        }
    }
    for (const auto& [file, what] : planFiles) {
        if (key(file) == pageKey)
            throw InvalidInput(formatError(page.string(), "", "is " + what,
                                           "a page apart from the shot's logs and outputs"));
    }
    uvwarp::ShotLog log;
    for (const fs::path& file : logs)
        uvwarp::readShotLogFile(file, log);
    // Nor over a map or bake a log names (as the job named it: relative to where the job ran, which is
    // here or the log's folder).
    for (const uvwarp::ShotLogLine& line : log.lines) {
        for (const std::string& output : {line.redirect, line.bake}) {
            if (output.empty()) continue;
            const fs::path named(output);
            if (key(named) == pageKey || key(fs::path(line.file).parent_path() / named) == pageKey) {
                throw InvalidInput(formatError(page.string(), "",
                                               "is an output the log " + line.file + " names",
                                               "a page apart from the shot's logs and outputs"));
            }
        }
    }
    ReportCommandResult result;
    result.page = page;
    result.logLines = static_cast<int64_t>(log.lines.size());
    result.report = uvwarp::writeHtmlReport(log, page, options);
    return result;
}

void addReportCommand(CommandLine& cli) {
    struct Options {
        ReportCommand command;
        std::vector<std::string> logs;
        std::string plan, scene;
    };
    auto o = std::make_shared<Options>();
    Command report = cli.add(
        "report",
        "Write a UV-warp shot's logs as one HTML page: plots over frames, heatmaps at the worst frame", [o] {
            ReportCommand& c = o->command;
            c.logs.assign(o->logs.begin(), o->logs.end());
            if (!o->plan.empty()) c.plan = o->plan;
            if (!o->scene.empty()) c.scene = o->scene;
            const ReportCommandResult r = reportCommand(c);
            std::cout << "report: wrote " << r.page.string() << " (" << r.logLines << " log lines, "
                      << r.report.files.size() - 1 << " pictures beside it; " << r.report.problems
                      << (r.report.problems == 1 ? " problem" : " problems") << ")\n";
            for (const std::string& note : r.report.notes)
                std::cout << "report: " << note << "\n";
            return 0;
        });
    report.option("LOGS", o->logs, "JSON-lines logs (uvwarp --log, farm run), or folders of them; any order");
    report.option("--plan", o->plan, "a farm plan: check its tasks; without LOGS read its Slurm logs");
    report.option("--out", o->command.out,
                  "the page; default: report.html beside the logs (a plan's output folder)");
    report.option("--title", o->command.title, "the page's title");
    report.option(
        "--scene", o->scene,
        "an eval shot's scene: the heatmaps' geometry evaluated from it (no per-frame OBJs needed)");
}

}  // namespace deformkit::harness
