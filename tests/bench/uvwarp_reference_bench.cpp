// How far the UV-warp solver's PBD solve is from the optimum of the model it approximates, on real layouts:
// the model's energy (tests/unit/uvwarp/reference_solver.h: segment lengths weighted by rigidity, and the
// regularisation) minimised to convergence by Levenberg-Marquardt from the PBD solve, fold-free. One run per
// case (Iterations(1)); what matters is the counters, not the time:
// - pbd_removed_pct, optimum_removed_pct: the rigid stretch removed on the grid (WarpMetrics);
// - gap_pts: optimum minus PBD; energy_ratio: the PBD solve's energy over the optimum's (1: at the optimum);
// - delivered_pbd_pct, delivered_optimum_pct: the same through each warp's redirect map as delivered
//   (inverted and fold-repaired, measured by RedirectMetrics); inverted_pbd, inverted_optimum: the inverted
//   triangles the fold repair found in each map (it delivers none).
// BM_UvWarpReference/model/pose/cells: model 0 = Spot (its own UVs, rigid disks inside its charts), pose 0 =
// stretched 1.4x along its length, 1 = bent 0.6 rad per unit along it (about 60 degrees end to end), 2 = bent
// about its length as tests/python/test_uvwarp_spot.py bends it (0.6 rad per unit of z, 59 degrees); model 1
// = the rigged Fox (tests/data/fox), pose = a frame of its Run clip (18: the one that keeps least of its
// rigid stretch removed, where skinning collapses a triangle at a front leg to 12% of its area). The default
// schedule from the identity.
// With --maps DIR (before the benchmark's own flags) each case also writes, for pictures
// (scripts/uvwarp_pictures.py ceiling): reference_<model>_<pose>_<cells>_rigidity.exr (the painted disks),
// _pbd.exr and _optimum.exr (the two redirect maps as delivered, fold-repaired).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/uvwarp/geometry_image.h"
#include "deformkit/uvwarp/inversion.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/metrics.h"
#include "deformkit/uvwarp/redirect_metrics.h"
#include "deformkit/uvwarp/redirect_repair.h"
#include "deformkit/uvwarp/solver.h"
#include "uvwarp/reference_solver.h"

namespace {

using namespace deformkit;
using namespace deformkit::uvwarp;

std::filesystem::path mapsFolder;  // --maps: where the maps are written (empty: nowhere)

// Rigid disks of radius 0.025 on a 0.1 lattice, kept where the whole disk texel's 3 x 3 lies in a chart.
io::Image disksInCharts(const io::Image& mask, int32_t t) {
    io::Image disks(t, t, 1);
    for (int32_t y = 0; y < t; ++y) {
        for (int32_t x = 0; x < t; ++x) {
            const float u = (x + 0.5f) / t, v = 1.0f - (y + 0.5f) / t;
            float d = 1.0f;
            for (float cu = 0.05f; cu < 1.0f; cu += 0.1f)
                for (float cv = 0.05f; cv < 1.0f; cv += 0.1f)
                    d = std::min(d, std::hypot(u - cu, v - cv));
            bool inside = true;
            for (int32_t dy = -1; dy <= 1; ++dy)
                for (int32_t dx = -1; dx <= 1; ++dx)
                    inside = inside &&
                             mask.at(std::clamp(x + dx, 0, t - 1), std::clamp(y + dy, 0, t - 1), 0) >= 0.5f;
            disks.at(x, y, 0) = d < 0.025f && inside ? 1.0f : 0.0f;
        }
    }
    return disks;
}

std::vector<glm::vec3> posed(const geom::Mesh& mesh, int pose) {
    std::vector<glm::vec3> p(mesh.points().begin(), mesh.points().end());
    glm::vec3 centre(0.0f);
    for (const glm::vec3& q : p)
        centre += q / static_cast<float>(p.size());
    for (glm::vec3& q : p) {
        if (pose == 0) {
            q.x = centre.x + 1.4f * (q.x - centre.x);
        } else if (pose == 2) {
            // Bent about its length: turned about x by 0.6 rad per unit of z (59 degrees).
            const float a = 0.6f * (q.z - centre.z), y = q.y - centre.y;
            q = {q.x, centre.y + y * std::cos(a), q.z + y * std::sin(a)};
        } else {  // bent about z, 0.6 rad per unit along x: the axis onto a circle of radius 1 / 0.6
            const float k = 0.6f, a = k * (q.x - centre.x), r = q.y - centre.y;
            q = {centre.x + std::sin(a) * (1.0f / k - r), centre.y + 1.0f / k - std::cos(a) * (1.0f / k - r),
                 q.z};
        }
    }
    return p;
}

double removed(const WarpMetrics& m) {
    return m.identityStretchError > 0 ? 1.0 - m.rigidStretchError / m.identityStretchError : 0.0;
}

void BM_UvWarpReference(benchmark::State& state) {
    const int model = static_cast<int>(state.range(0));
    const int pose = static_cast<int>(state.range(1));
    const int32_t n = static_cast<int32_t>(state.range(2));
    const std::string data = DEFORMKIT_TEST_DATA;
    // Spot posed here, or the Fox's rest pose and one frame of its Run clip (tests/data/fox).
    const geom::Mesh mesh =
        io::readObj(model == 0 ? data + "/spot/spot_quadrangulated.obj" : data + "/fox/rest.obj").mesh;
    std::vector<glm::vec3> deformedPoints;
    if (model == 0) {
        deformedPoints = posed(mesh, pose);
    } else {
        char frame[32];
        std::snprintf(frame, sizeof(frame), "/fox/anim.%04d.obj", pose);
        const geom::Mesh frameMesh = io::readObj(data + frame).mesh;
        deformedPoints.assign(frameMesh.points().begin(), frameMesh.points().end());
    }
    const GeometryImager imager(mesh, 1001, n);
    const PointField rest = imager.sample(mesh.points());
    const PointField deformed = imager.sample(deformedPoints);
    const io::Image mask = deriveWarpMask(mesh, 1001, n);
    const io::Image disks = disksInCharts(mask, n);
    const PointField rigidity = rigidityAtPoints(disks, n);
    const PointField maskPoints = maskAtPoints(mask, n);
    for (auto _ : state) {
        Solver solver(rest, rigidity, maskPoints, {});
        const WarpGrid pbd = solver.solve(deformed);
        const PointField movable = solver.levelMovable(0);
        const test::ReferenceProblem problem{&rest, &deformed, &rigidity, &movable, SolverOptions{}.smoothing,
                                             1.0};
        const test::ReferenceResult best = test::minimiseReference(problem, pbd, 40);
        const RedirectMetrics delivered(mesh, 1001, disks, "spot");
        const ContentCheck onChart = [&](int32_t x, int32_t y, glm::dvec2 r) {
            return delivered.mayShow(x, y, r);
        };
        io::Image pbdMap = invertWarp(pbd, n), bestMap = invertWarp(best.warp, n);
        const FoldRepair pbdRepair = repairFolds(pbdMap, onChart), bestRepair = repairFolds(bestMap, onChart);
        const DeliveredMetrics dPbd = delivered.measure(deformedPoints, pbdMap);
        const DeliveredMetrics dBest = delivered.measure(deformedPoints, bestMap);
        const double pbdRemoved = removed(measureWarp(pbd, rest, deformed, rigidity, maskPoints));
        const double bestRemoved = removed(measureWarp(best.warp, rest, deformed, rigidity, maskPoints));
        state.counters["pbd_removed_pct"] = 100 * pbdRemoved;
        state.counters["optimum_removed_pct"] = 100 * bestRemoved;
        state.counters["gap_pts"] = 100 * (bestRemoved - pbdRemoved);
        state.counters["energy_ratio"] = best.startEnergy / best.energy;
        state.counters["delivered_pbd_pct"] = 100 * dPbd.removed;
        state.counters["delivered_optimum_pct"] = 100 * dBest.removed;
        state.counters["inverted_pbd"] = static_cast<double>(pbdRepair.invertedFound);
        state.counters["inverted_optimum"] = static_cast<double>(bestRepair.invertedFound);
        state.counters["lm_iterations"] = best.iterations;
        if (!mapsFolder.empty()) {
            const std::string stem = "reference_" + std::to_string(model) + "_" + std::to_string(pose) + "_" +
                                     std::to_string(n) + "_";
            io::writeImage(mapsFolder / (stem + "rigidity.exr"), disks);
            io::writeImage(mapsFolder / (stem + "pbd.exr"), pbdMap);
            io::writeImage(mapsFolder / (stem + "optimum.exr"), bestMap);
        }
    }
}
BENCHMARK(BM_UvWarpReference)
    ->Args({0, 0, 128})
    ->Args({0, 1, 128})
    ->Args({0, 0, 256})
    ->Args({0, 1, 256})
    ->Args({0, 2, 128})
    ->Args({0, 2, 256})
    ->Args({1, 18, 128})
    ->Args({1, 18, 256})
    ->Args({1, 9, 256})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

}  // namespace

int main(int argc, char** argv) {
    // --maps DIR, taken out before Google Benchmark reads the rest.
    int kept = 1;
    for (int k = 1; k < argc; ++k) {
        if (std::strcmp(argv[k], "--maps") == 0 && k + 1 < argc) {
            mapsFolder = argv[++k];
            std::filesystem::create_directories(mapsFolder);
        } else {
            argv[kept++] = argv[k];
        }
    }
    argc = kept;
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
