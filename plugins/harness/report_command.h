#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "deformkit/uvwarp/html_report.h"

// `deformkit report`: a UV-warp shot's logs as one HTML page (uvwarp/html_report.h):
//
//   deformkit report LOG... [--out report.html] [--title TEXT] [--scene SCENE.json]
//   deformkit report --plan PLAN.json [LOG...] [--out report.html]    a farm shot (also `farm report PLAN`)
//
// Logs are read in any order and merged; a folder stands for the logs in it (*.jsonl, *.log). With a farm
// plan, a task whose frames are missing is listed with the command that runs it again; without logs, the
// plan's Slurm logs are read (<plan folder>/<plan name>.*.log, as `farm submit --slurm` names them). With a
// plan or a scene, the heatmaps' geometry is the scene evaluated at the worst frame (a shot written as
// point caches, or whose mesh tasks have not run, has no per-frame OBJ to read).
namespace deformkit::harness {

struct ReportCommand {
    std::vector<std::filesystem::path> logs;
    std::optional<std::filesystem::path> plan;
    std::optional<std::filesystem::path> scene;  // an eval shot's scene, for the heatmaps' geometry
    // The page; empty: report.html in the plan's output folder, else beside the first log.
    std::filesystem::path out;
    std::string title;
    std::vector<std::string> rerun;  // command lines shown as given (a host that knows how it ran)
};

struct ReportCommandResult {
    std::filesystem::path page;
    uvwarp::HtmlReportResult report;
    int64_t logLines = 0;
};

// The geometry of a scene's object at a frame, for a report's heatmaps: the scene is read and its stacks
// bound when first asked for.
[[nodiscard]] std::function<std::optional<uvwarp::ReportGeometry>(const std::string&, int)> sceneGeometry(
    const std::filesystem::path& scene);

// Throws InvalidInput when there is no log to read (none given and none beside the plan), IoError when the
// page cannot be written, as readFarmPlan for a bad plan. Broken logs are reported in the page.
ReportCommandResult reportCommand(const ReportCommand& command);

}  // namespace deformkit::harness
