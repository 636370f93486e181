// Barr taper, twist and bend on a 1,001,000-vertex grid: bind and evaluate timed apart. Evaluate runs the
// direct path with all threads and with one (the speed-up), and the generic engine path (per-point
// transformations through evaluateWarp) as the in-run reference the direct path is measured against;
// BM_BarrDeform is the checked call a host or the Python module's bound evaluate makes
// (scripts/bench_python.py's reference for it), BM_BarrDeformSmall the same on 110 points.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <memory>
#include <vector>

#include "deformkit/geom/primitives.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/engine.h"

namespace {

using namespace deformkit;
using namespace deformkit::warp;

const std::vector<glm::vec3>& grid() {
    static const std::vector<glm::vec3> points = [] {
        const geom::Mesh mesh = geom::makeGrid({1000, 999, 4.0f, 1.0f});
        return std::vector<glm::vec3>(mesh.points().begin(), mesh.points().end());
    }();
    return points;
}

// The axis runs along the grid's long side through its middle; the bend bends out of its plane.
const AxisFrame kFrame{{0.0f, 0.5f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}};

std::unique_ptr<AxialWarp> makeWarp(int kind) {
    switch (kind) {
        case 0:
            return std::make_unique<TaperWarp>(
                kFrame, ProfileCurve({0.0f, 1.0f, 2.5f, 4.0f}, {1.0f, 0.6f, 1.3f, 0.4f}, "taper"));
        case 1:
            return std::make_unique<TwistWarp>(kFrame,
                                               ProfileCurve({0.0f, 2.0f, 4.0f}, {0.0f, 1.0f, 3.0f}, "twist"));
        default:
            return std::make_unique<BendWarp>(kFrame, BendParams{0.8f, 2.0f, 0.5f, 3.5f});
    }
}

void setLabel(benchmark::State& state, int kind) {
    state.SetLabel(kind == 0 ? "taper" : kind == 1 ? "twist" : "bend");
}

void BM_BarrBind(benchmark::State& state) {
    const int kind = static_cast<int>(state.range(0));
    auto warp = makeWarp(kind);
    (void)grid();  // built before the timing, not by the first iteration
    SparseFields fields;
    for (auto _ : state) {
        warp->bind(grid(), fields);
        benchmark::DoNotOptimize(fields.offsets.data());
    }
    setLabel(state, kind);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().size()));
}

void evaluateDirect(benchmark::State& state, bool oneThread) {
    const int kind = static_cast<int>(state.range(0));
    auto warp = makeWarp(kind);
    SparseFields fields;
    warp->bind(grid(), fields);
    std::vector<glm::vec3> out(grid().size());
    const int threads = omp_get_max_threads();
    if (oneThread) omp_set_num_threads(1);
    for (auto _ : state) {
        warp->evaluate(grid(), out);
        benchmark::DoNotOptimize(out.data());
    }
    if (oneThread) omp_set_num_threads(threads);
    setLabel(state, kind);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().size()));
}

void BM_BarrEvaluate(benchmark::State& state) {
    evaluateDirect(state, false);
}
void BM_BarrEvaluate1Thread(benchmark::State& state) {
    evaluateDirect(state, true);
}

// What a host pays for a bound warp: AxialWarp::deform, the evaluate with its check of the points
// (finite coordinates) and the envelope; the path the Python module's bound evaluate and the hosts take.
void BM_BarrDeform(benchmark::State& state) {
    const int kind = static_cast<int>(state.range(0));
    auto warp = makeWarp(kind);
    warp->bind(grid());
    std::vector<glm::vec3> out(grid().size());
    for (auto _ : state) {
        warp->deform(grid(), out, {}, 1.0f);
        benchmark::DoNotOptimize(out.data());
    }
    setLabel(state, kind);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().size()));
}

// The same call on a 110-point grid (10 x 9 cells), where the work is next to nothing: what a call costs
// around it (scripts/bench_python.py sets the Python module's same call against it).
void BM_BarrDeformSmall(benchmark::State& state) {
    const geom::Mesh mesh = geom::makeGrid({10, 9, 4.0f, 1.0f});
    const std::vector<glm::vec3> points(mesh.points().begin(), mesh.points().end());
    auto warp = makeWarp(0);
    warp->bind(points);
    std::vector<glm::vec3> out(points.size());
    for (auto _ : state) {
        warp->deform(points, out, {}, 1.0f);
        benchmark::DoNotOptimize(out.data());
    }
    setLabel(state, 0);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(points.size()));
}

// The generic path: per-point transformations (the paper's per-point sampling) + Eq. 3.
void BM_BarrEvaluateEngine(benchmark::State& state) {
    const int kind = static_cast<int>(state.range(0));
    auto warp = makeWarp(kind);
    SparseFields fields;
    warp->bind(grid(), fields);
    Transformations transforms;
    std::vector<glm::vec3> out(grid().size());
    for (auto _ : state) {
        warp->transformations(transforms);
        evaluateWarp(grid(), fields, transforms, out);
        benchmark::DoNotOptimize(out.data());
    }
    setLabel(state, kind);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().size()));
}

}  // namespace

BENCHMARK(BM_BarrBind)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->MinTime(0.3);
BENCHMARK(BM_BarrEvaluate)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->MinTime(0.3)->UseRealTime();
BENCHMARK(BM_BarrDeform)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->MinTime(0.3)->UseRealTime();
BENCHMARK(BM_BarrDeformSmall)->Unit(benchmark::kMicrosecond)->MinTime(0.3)->UseRealTime();
BENCHMARK(BM_BarrEvaluate1Thread)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3)
    ->UseRealTime();
BENCHMARK(BM_BarrEvaluateEngine)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3)
    ->UseRealTime();

BENCHMARK_MAIN();
