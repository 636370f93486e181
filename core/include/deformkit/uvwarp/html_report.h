#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/shot_log.h"

namespace deformkit::uvwarp {

// A UV-warp shot as one HTML page a farm TD reads at a glance (`deformkit report`, `uvwarp --report`,
// `eval --report`, `farm report`, Python's shot_report, the Blender add-on's bake). Readable offline: no
// network, no script; plots are inline SVG, thumbnails inline PNG (up to 1 MB of them, then beside the
// page), full-size pictures (at most 2048 px a side) beside the page in `<page stem>_files/`. Per object and
// tile:
// - plots over frames of the figures the logs carry, measured on the delivered maps: rigid stretch
//   removed, inverted triangles, off-chart texels, seconds; the worst frame (the least stretch removed)
//   marked;
// - at the worst frame, pictures over the tile's UV layout: the rigid stretch left through the map and
//   without the warp (heatmaps, folds and off-chart texels marked), the texture plain and warped (the
//   rigidity map when the shot has no texture);
// - the inputs and options the worst frame's map records (its provenance header), its outputs and how to
//   run the shot again.
// Then the logs' problems (file and line) and, for a farm plan, the tasks whose frames are missing.
//
// The pictures are made again from files: the worst frame's redirect map, and the rest mesh, deformed
// positions, rigidity map and texture its header names (an OBJ or mesh file, a point cache's frame; a
// relative name is looked for in the working folder, the log's folder, the map's folder and
// `searchFolders`). A host whose inputs are not files gives them through the callbacks. A picture that
// cannot be made is said in the page, not thrown.

// The geometry of an object's frame for its heatmaps.
struct ReportGeometry {
    geom::Mesh rest;                  // with UVs
    std::vector<glm::vec3> deformed;  // the rest mesh's vertex count
};

struct HtmlReportOptions {
    std::string title = "UV warp shot";
    // Command lines that run the shot again, shown as given. Empty: one `deformkit uvwarp` line made from
    // the worst frame's header when its inputs are files.
    std::vector<std::string> rerun;
    // A farm plan's tasks: a task whose tiles and frames (a mesh task: whose frames) the logs do not show
    // written or skipped is listed as missing or failed, with its command line.
    struct Task {
        int index = 0;
        int first = 0, last = 0;  // frames, inclusive
        std::vector<int> tiles;   // empty: a mesh task (its lines have no tile)
        // The (object, tile) pairs the task writes maps for; empty: any object's line counts for a tile.
        std::vector<std::pair<std::string, int>> objectTiles;
        std::string rerun;
    };
    std::vector<Task> tasks;
    std::vector<std::filesystem::path> searchFolders;
    // Optional sources for inputs that are not files (a DCC's evaluated mesh, painted maps): return nullopt
    // to fall back to the header's files.
    std::function<std::optional<ReportGeometry>(const std::string& object, int frame)> geometry;
    std::function<std::optional<io::Image>(const std::string&object, int tile)> rigidity, texture;
    int32_t thumbnail = 256;  // pixels, the inline pictures' longest side
};

struct HtmlReportResult {
    std::vector<std::filesystem::path> files;  // the page, then the pictures beside it
    int64_t problems = 0;                      // log problems and missing or failed tasks
    std::vector<std::string> notes;            // pictures that could not be made, and why
};

// Writes the page (atomically, as every picture) and its folder of pictures. Throws IoError when the page's
// folder does not exist or cannot be written; InvalidInput for a thumbnail size below 16.
HtmlReportResult writeHtmlReport(const ShotLog& log, const std::filesystem::path& page,
                                 const HtmlReportOptions& options = {});

// Makes the page's folder and its folder of pictures where missing, for a caller that writes the page after
// long work: one that cannot be made fails first (IoError naming it), before the work.
void prepareHtmlReport(const std::filesystem::path& page);

// The colour of remaining rigid stretch e (| length ratio - 1 |) in the heatmaps: 0 dark blue through
// yellow at kHeatmapTop and above.
inline constexpr double kHeatmapTop = 0.25;
[[nodiscard]] glm::vec3 heatmapColour(double e);

}  // namespace deformkit::uvwarp
