#pragma once

#include <filesystem>
#include <map>
#include <vector>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/metrics.h"
#include "deformkit/uvwarp/redirect_metrics.h"

namespace deformkit::harness {

// The demo's UV warp: the tube bent (Barr bend) so that one side stretches about 1.5x and the other
// squashes, and the side tile's texture re-parameterised so the painted rigid features keep their size.
struct DemoUvWarp {
    geom::Mesh bent;                     // the tube bent, same topology and UVs
    io::Image redirect;                  // tile 1001's W^-1, T x T x 2
    io::Image warpedAlbedo;              // tile 1001's albedo baked through the redirect
    uvwarp::WarpMetrics metrics;         // of the side tile's warp, on the solver's grid (diagnostics)
    uvwarp::DeliveredMetrics delivered;  // of its redirect map, what the previews show
};

// resolution: the maps' texels per side; the solver's grid has min(resolution, 256) cells.
[[nodiscard]] DemoUvWarp makeDemoUvWarp(const geom::Mesh& tube, const io::Image& rigidity,
                                        const io::Image& mask, const io::Image& albedo);

// Writes demo-out/uvwarp/: tube_bent.obj, redirect.1001.exr, albedo_warped.<UDIM>.png, previews of the
// stretched and the squashed side before and after (outer_before.png, ...), a 2 x 2 sheet uvwarp.png and
// metrics.json. `albedo` holds every tile's colour texture.
std::vector<std::filesystem::path> writeDemoUvWarp(const geom::Mesh& tube, const io::Image& rigidity,
                                                   const io::Image& mask,
                                                   const std::map<int, io::Image>& albedo,
                                                   const std::filesystem::path& outDir);

// The demo's UV-warp shot: the tube bent a little more each frame up to makeDemoUvWarp's pose, over
// kDemoShotFrames frames, written as `deformkit uvwarp` would from the demo's files in outDir (tube.obj,
// rigidity, mask and albedo maps): demo-out/uvwarp/shot/ holds the bent tube per frame (tube.####.obj),
// the redirect maps and bakes, and the shot's log (uvwarp.jsonl); demo-out/uvwarp/report.html is the
// shot's page (uvwarp/html_report.h).
inline constexpr int kDemoShotFrames = 8;
std::vector<std::filesystem::path> writeDemoUvWarpShot(const geom::Mesh& tube, int32_t cells,
                                                       const std::filesystem::path& outDir);

}  // namespace deformkit::harness
