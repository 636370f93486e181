// What a frame of a shot written as files costs with the shot preset at 1024²: each frame solved from the
// identity, refined on a grid of twice the cells (the preset's refinement by the grid's size), its redirect
// map made (inversion and fold repair) and measured (the delivered figures the log reports), as
// `deformkit uvwarp` does between reading the OBJ and writing the EXR.
//
// BM_UvWarpSpotShotFrame, the reference: Spot (its own UVs) stretched from 1x to 1.4x along its length over
// 24 frames, without refinement and without the density heuristic (the frame the requirement below was set
// against). BM_UvWarpRiggedShotFrame: the rigged Fox running (tests/data/fox: 24 frames of its Run clip
// skinned in Blender), the shot preset, the argument its refinement sweeps: 0 (none, the reference of the
// others), -1 (the shot preset: 4 at 1024²), 8, 16. Rigid disks of radius 0.025 on a 0.1 lattice inside the
// charts. Counters (medians over the frames): frame_ms, solve_ms, redirect_ms, measure_ms; removed_pct
// (median rigid stretch removed, delivered), inverted (delivered inverted triangles, all frames), repaired
// (inverted triangles the fold repair unfolded, all frames); on the Fox, ratio_to_spot = its frame_ms over
// Spot's and, refined, ratio_to_plain = its frame_ms over the unrefined Fox's, in the same run. Requirement:
// a rigged character's shot frame at most 1.5x the 0.31-0.37 s it cost before the fold repair, on 2 cores.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/obj.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/tile_warp.h"

namespace {

using namespace deformkit;
using namespace deformkit::uvwarp;
using Clock = std::chrono::steady_clock;

constexpr int kFrames = 24;
constexpr int32_t kTexels = 1024;
double spotFrameMs = 0.0;  // BM_UvWarpSpotShotFrame's median, for the Fox's ratio

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

// Rigid disks of radius 0.025 on a 0.1 lattice, at texels whose 7 x 7 neighbourhood lies inside the derived
// warp mask (3 texels off its border band: about docs/uvwarp_quality.md's 4-texel margin inside the charts).
io::Image disks(const geom::Mesh& mesh) {
    const io::Image mask = deriveWarpMask(mesh, 1001, kTexels);
    io::Image rigidity(kTexels, kTexels, 1);
    for (int32_t y = 0; y < kTexels; ++y) {
        for (int32_t x = 0; x < kTexels; ++x) {
            const double u = (x + 0.5) / kTexels, v = 1.0 - (y + 0.5) / kTexels;
            const double du = u - (std::floor(u * 10.0) + 0.5) / 10.0,
                         dv = v - (std::floor(v * 10.0) + 0.5) / 10.0;
            bool inside = std::hypot(du, dv) < 0.025;
            for (int32_t dy = -3; dy <= 3 && inside; ++dy)
                for (int32_t dx = -3; dx <= 3 && inside; ++dx)
                    inside = mask.at(std::clamp(x + dx, 0, kTexels - 1), std::clamp(y + dy, 0, kTexels - 1),
                                     0) >= 0.5f;
            rigidity.at(x, y, 0) = inside ? 1.0f : 0.0f;
        }
    }
    return rigidity;
}

double foxFrameMs = 0.0;  // BM_UvWarpRiggedShotFrame/0's median, for the refined Fox's ratios

void shotFrames(benchmark::State& state, int model, int32_t refinementSweeps = 0) {
    const std::string data = DEFORMKIT_TEST_DATA;
    const geom::Mesh rest =
        io::readObj(model == 0 ? data + "/spot/spot_quadrangulated.obj" : data + "/fox/rest.obj").mesh;
    std::vector<std::vector<glm::vec3>> frames;
    for (int f = 0; f < kFrames; ++f) {
        if (model == 0) {
            const float s = 1.0f + 0.4f * static_cast<float>(f) / static_cast<float>(kFrames - 1);
            std::vector<glm::vec3>& p = frames.emplace_back(rest.points().begin(), rest.points().end());
            for (glm::vec3& q : p)
                q.x *= s;
        } else {
            char name[32];
            std::snprintf(name, sizeof(name), "/fox/anim.%04d.obj", f + 1);
            const geom::Mesh posed = io::readObj(data + name).mesh;
            frames.emplace_back(posed.points().begin(), posed.points().end());
        }
    }
    const io::Image rigidity = disks(rest);
    TileWarpOptions options = presetOptions(Preset::Shot, kTexels);
    options.refinementSweeps = refinementSweeps;
    // The reference is the frame the requirement was set against: Spot with the shot preset as it was then,
    // without refinement and without the density heuristic's orientation preservation.
    if (model == 0) options.orientationDensity = 0;
    std::vector<double> frameMs, solveMs, redirectMs, measureMs, removed;
    int64_t inverted = 0, repaired = 0;
    for (auto _ : state) {
        TileWarp warp(rest, 1001, rigidity, {}, options);
        io::Image redirect;
        for (const std::vector<glm::vec3>& points : frames) {
            const Clock::time_point start = Clock::now();
            warp.solve(points);
            const double solved = msSince(start);
            const FoldRepair repair = warp.redirect(redirect);
            const double mapped = msSince(start);
            const DeliveredMetrics m = warp.measure(redirect);
            const double total = msSince(start);
            frameMs.push_back(total);
            solveMs.push_back(solved);
            redirectMs.push_back(mapped - solved);
            measureMs.push_back(total - mapped);
            removed.push_back(100.0 * m.removed);
            inverted += m.invertedTriangles;
            repaired += repair.invertedFound;
        }
    }
    state.counters["frame_ms"] = median(frameMs);
    state.counters["solve_ms"] = median(solveMs);
    state.counters["redirect_ms"] = median(redirectMs);
    state.counters["measure_ms"] = median(measureMs);
    state.counters["removed_pct"] = median(removed);
    state.counters["inverted"] = static_cast<double>(inverted);
    state.counters["repaired"] = static_cast<double>(repaired);
    state.SetItemsProcessed(static_cast<int64_t>(frameMs.size()));
    if (model == 0) spotFrameMs = median(frameMs);
    if (model == 1 && refinementSweeps == 0) foxFrameMs = median(frameMs);
    if (model == 1 && spotFrameMs > 0.0) state.counters["ratio_to_spot"] = median(frameMs) / spotFrameMs;
    if (refinementSweeps != 0 && foxFrameMs > 0.0)
        state.counters["ratio_to_plain"] = median(frameMs) / foxFrameMs;
}
void BM_UvWarpSpotShotFrame(benchmark::State& state) {
    shotFrames(state, 0);
}
void BM_UvWarpRiggedShotFrame(benchmark::State& state) {
    shotFrames(state, 1, static_cast<int32_t>(state.range(0)));
}
// Spot first, then the unrefined Fox: the ratios need their medians.
BENCHMARK(BM_UvWarpSpotShotFrame)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_UvWarpRiggedShotFrame)
    ->Arg(0)
    ->Arg(kAutomaticRefinement)
    ->Arg(8)
    ->Arg(16)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
