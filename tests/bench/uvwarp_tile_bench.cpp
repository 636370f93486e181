// A fully covered UV tile at production sizes, as a farm job solves it: a plane whose UVs fill tile 1001,
// rigid disks painted over the whole tile, the deformed pose (a stretch growing from 1x to 1.8x along u and a
// wave across v) solved cold with the shot preset (a farm job's: the default schedule, every frame from the
// identity, refined on a grid of twice the cells up to 1024 cells). One TileWarp per run: bind (geometry
// images, maps, hierarchy, the refining grid's), the cold solve, the redirect map with its repair, and the
// delivered figures a farm job logs.
//
// BM_UvWarpTileScale/T, T texels (= grid cells) per side. Counters: bind_s, solve_s, redirect_s, measure_s;
// bind_ratio = bind / solve (target <= 0.25); peak_bytes_per_cell = the process's peak resident memory over
// the run (VmHWM, reset before the inputs are made) less its resident memory before them, per cell of the
// T x T grid (target <= 40, so that a 16384^2 tile fits a 24 GB machine), the inputs (rigidity map) and the
// delivered map included; reduction_pct, inverted, off_chart: the delivered map's figures
// (redirect_metrics.h: rigid stretch removed, inverted texel triangles, off-chart texels). The quality
// target: at 8192^2 within 2 points of 2048^2.
//
// Sizes above 2048 take minutes and gigabytes: scripts/uvwarp_tile_scale.sh runs each size in a process of
// its own (DEFORMKIT_TILE_SIZES=8192), from 1024^2 to 16384^2, and prints the table.
//
// BM_UvWarpCoveredLiveFrame/T: the live preset (uvwarp::Preset::Live) on the same tile as a 24-frame
// animation, the pose growing from the rest pose (frame 1) to the one above (frame 24), played through one
// TileWarp as a preview plays it: per frame the geometry image, the warm-started solve and the redirect map.
// Counters: frame_ms (median over frames 2-24; target 33 ms at 1024^2, 141 ms at 2048^2), solve_ms and
// redirect_ms (medians), target_ratio = frame_ms / target, restarts (frames solved again from the identity,
// SolveStats::coldRestart), worst_gap_pts: at frames 4, 7, 13 and 24 the shot preset's rigid stretch removed
// (the frame from the identity, untimed) minus the live frame's, both measured on the delivered map
// (target: <= 2 points), and worst_gap_frame its frame.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/tile_warp.h"

namespace {

using namespace deformkit;
using namespace deformkit::uvwarp;
using Clock = std::chrono::steady_clock;

constexpr int kTile = 1001;
constexpr int kQuads = 128;  // mesh quads per side

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// A /proc/self/status figure in bytes (VmRSS, VmHWM), 0 where the file is not there.
double statusBytes(const std::string& key) {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line)) {
        if (line.rfind(key + ":", 0) != 0) continue;
        return std::stod(line.substr(key.size() + 1)) * 1024.0;  // "VmHWM:   123456 kB"
    }
    return 0.0;
}

// Resets VmHWM to the current resident size (Linux >= 4.0); false where that is not possible.
bool resetPeak() {
    std::ofstream clear("/proc/self/clear_refs");
    clear << "5";
    return static_cast<bool>(clear);
}

// The plane [0, 1]^2 (z = 0) with UVs filling tile 1001, kQuads x kQuads quads.
geom::Mesh coveredPlane() {
    geom::Mesh::Data d;
    for (int j = 0; j <= kQuads; ++j)
        for (int i = 0; i <= kQuads; ++i) {
            const float x = static_cast<float>(i) / kQuads, y = static_cast<float>(j) / kQuads;
            d.points.emplace_back(x, y, 0.0f);
            d.uvs.emplace_back(x, y);
        }
    for (int j = 0; j < kQuads; ++j)
        for (int i = 0; i < kQuads; ++i) {
            const int a = j * (kQuads + 1) + i;
            d.faceCounts.push_back(4);
            d.faceIndices.insert(d.faceIndices.end(), {a, a + 1, a + kQuads + 2, a + kQuads + 1});
        }
    d.uvIndices = d.faceIndices;
    return geom::Mesh(std::move(d), "covered plane");
}

// The pose: x -> x (1 + 0.4 x) (stretch 1x at u = 0 to 1.8x at u = 1), z = 0.05 sin(2 pi y); `amount` in
// [0, 1] scales both, from the rest pose (0) to the pose (1).
std::vector<glm::vec3> pose(const geom::Mesh& mesh, float amount = 1.0f) {
    std::vector<glm::vec3> out;
    for (const glm::vec3& p : mesh.points())
        out.emplace_back(p.x * (1.0f + 0.4f * amount * p.x), p.y,
                         0.05f * amount * std::sin(6.2831853f * p.y));
    return out;
}

// Rigid disks of radius 0.02 of the tile, centres 0.06 apart, over the tile but its outer 0.05.
io::Image rigidDisks(int32_t texels) {
    io::Image rigidity(texels, texels, 1);
    const double t = texels;
    const double radius = 0.02 * t;
    for (double cy = 0.08 * t; cy < 0.95 * t; cy += 0.06 * t) {
        for (double cx = 0.08 * t; cx < 0.95 * t; cx += 0.06 * t) {
            const auto y0 = static_cast<int32_t>(cy - radius), y1 = static_cast<int32_t>(cy + radius);
            const auto x0 = static_cast<int32_t>(cx - radius), x1 = static_cast<int32_t>(cx + radius);
            for (int32_t y = y0; y <= y1; ++y)
                for (int32_t x = x0; x <= x1; ++x)
                    if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) < radius) rigidity.at(x, y, 0) = 1.0f;
        }
    }
    return rigidity;
}

void BM_UvWarpTileScale(benchmark::State& state) {
    const auto texels = static_cast<int32_t>(state.range(0));
    const geom::Mesh mesh = coveredPlane();
    const std::vector<glm::vec3> deformed = pose(mesh);
    for (auto _ : state) {
        const bool peakReset = resetPeak();
        const double before = statusBytes("VmRSS");
        const double cells = static_cast<double>(texels) * texels;
        // The phase's peak over the baseline, per cell; the next phase's peak is measured from here.
        double peak = 0.0;
        const auto phasePeak = [&](const char* name) {
            if (!peakReset) return;
            const double bytes = (statusBytes("VmHWM") - before) / cells;
            state.counters[name] = bytes;
            peak = std::max(peak, bytes);
            resetPeak();
        };
        io::Image rigidity = rigidDisks(texels);
        auto start = Clock::now();
        // The warp keeps the rigidity map (the delivered figures read it), as a farm job hands it over.
        TileWarp warp(mesh, kTile, std::move(rigidity), {}, presetOptions(Preset::Shot, texels));
        const double bind = secondsSince(start);
        phasePeak("peak_bind");
        start = Clock::now();
        warp.solve(deformed);
        const double solve = secondsSince(start);
        phasePeak("peak_solve");
        start = Clock::now();
        io::Image map;
        warp.redirect(map);
        const double redirect = secondsSince(start);
        phasePeak("peak_redirect");
        start = Clock::now();
        const DeliveredMetrics delivered = warp.measure(map);
        const double measure = secondsSince(start);
        phasePeak("peak_measure");
        state.counters["bind_s"] = bind;
        state.counters["solve_s"] = solve;
        state.counters["redirect_s"] = redirect;
        state.counters["measure_s"] = measure;
        state.counters["bind_ratio"] = bind / solve;
        if (peakReset) state.counters["peak_bytes_per_cell"] = peak;
        state.counters["reduction_pct"] = 100.0 * delivered.removed;
        state.counters["inverted"] = static_cast<double>(delivered.invertedTriangles);
        state.counters["off_chart"] = static_cast<double>(delivered.offChartTexels);
        state.counters["levels"] = warp.stats().levels;
        state.counters["iterations"] = warp.stats().iterations;
    }
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

void BM_UvWarpCoveredLiveFrame(benchmark::State& state) {
    constexpr int kFrames = 24;
    constexpr int kProbes[] = {4, 7, 13, 24};  // 1-based frames whose gap to the shot preset is measured
    const auto texels = static_cast<int32_t>(state.range(0));
    const geom::Mesh mesh = coveredPlane();
    const io::Image rigidity = rigidDisks(texels);
    std::vector<std::vector<glm::vec3>> frames;
    for (int f = 0; f < kFrames; ++f)
        frames.push_back(pose(mesh, static_cast<float>(f) / (kFrames - 1)));
    std::vector<double> shot;  // the shot preset's figure at each probe, untimed
    for (const int f : kProbes) {
        TileWarp cold(mesh, kTile, rigidity, {}, presetOptions(Preset::Shot, texels));
        cold.solve(frames[f - 1]);
        io::Image map;
        cold.redirect(map);
        shot.push_back(100.0 * cold.measure(map).removed);
    }
    std::vector<double> frameMs, solveMs, redirectMs;
    double worstGap = -100.0;
    int worstFrame = 0, restarts = 0;
    for (auto _ : state) {
        TileWarp live(mesh, kTile, rigidity, {}, presetOptions(Preset::Live, texels));
        io::Image map;
        for (int f = 1; f <= kFrames; ++f) {
            const auto start = Clock::now();
            live.solve(frames[f - 1]);
            const double solved = secondsSince(start) * 1e3;
            live.redirect(map);
            const double total = secondsSince(start) * 1e3;
            if (f > 1) {
                frameMs.push_back(total);
                solveMs.push_back(solved);
                redirectMs.push_back(total - solved);
                restarts += live.stats().coldRestart ? 1 : 0;
            }
            for (size_t p = 0; p < std::size(kProbes); ++p) {
                if (kProbes[p] != f) continue;
                const double gap = shot[p] - 100.0 * live.measure(map).removed;
                if (gap > worstGap) {
                    worstGap = gap;
                    worstFrame = f;
                }
            }
        }
    }
    const double target = texels >= 2048 ? 141.0 : 33.0;
    state.counters["frame_ms"] = median(frameMs);
    state.counters["solve_ms"] = median(solveMs);
    state.counters["redirect_ms"] = median(redirectMs);
    state.counters["target_ratio"] = median(frameMs) / target;
    state.counters["worst_gap_pts"] = worstGap;
    state.counters["worst_gap_frame"] = worstFrame;
    state.counters["restarts"] = restarts;
    state.SetItemsProcessed(state.iterations() * (kFrames - 1));
}

}  // namespace

// Sizes from DEFORMKIT_TILE_SIZES ("1024 2048 ... 16384"), 1024 and 2048 without it: scripts/bench.sh runs
// every benchmark five times, and the larger sizes take minutes and gigabytes each.
int main(int argc, char** argv) {
    const char* sizes = std::getenv("DEFORMKIT_TILE_SIZES");
    std::istringstream list(sizes != nullptr ? sizes : "1024 2048");
    for (int64_t texels = 0; list >> texels;) {
        benchmark::RegisterBenchmark("BM_UvWarpTileScale", BM_UvWarpTileScale)
            ->Arg(texels)
            ->Iterations(1)
            ->Unit(benchmark::kSecond)
            ->UseRealTime();
    }
    benchmark::RegisterBenchmark("BM_UvWarpCoveredLiveFrame", BM_UvWarpCoveredLiveFrame)
        ->Arg(1024)
        ->Arg(2048)
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
