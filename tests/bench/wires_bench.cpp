// Wires (paper §4.4) and its smooth variant (§5.3): 4 wire curves on a 1,001,000-vertex grid, bind and
// evaluate timed apart. Evaluate runs on all threads and on 1 thread (the speed-up), and the generic
// engine path (Wires::transformations + evaluateWarp) is the in-run reference for the fast path.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <vector>

#include "deformkit/geom/primitives.h"
#include "deformkit/warp/curve.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/wires.h"

namespace {

using namespace deformkit;
using namespace deformkit::warp;

const std::vector<glm::vec3>& gridPoints() {
    static const std::vector<glm::vec3> points = [] {
        const geom::Mesh grid = geom::makeGrid({1000, 999, 1.0f, 1.0f});
        return std::vector<glm::vec3>(grid.points().begin(), grid.points().end());
    }();
    return points;
}

// Four wavy Catmull-Rom curves across the unit grid (8 controls, 8 samples per span: 57 points each),
// radius 0.12; the wires lift and bend them.
std::vector<Wire> fourWires() {
    std::vector<Wire> wires;
    for (int i = 0; i < 4; ++i) {
        std::vector<glm::vec3> ref, moved;
        for (int c = 0; c < 8; ++c) {
            const float x = c / 7.0f, y = 0.15f + 0.23f * i + 0.04f * std::sin(6.0f * x + i);
            ref.push_back({x, y, 0.0f});
            moved.push_back(
                {x, y + 0.03f * std::cos(5.0f * x), 0.1f * std::sin(3.14159f * x) * (i % 2 ? 1.0f : -1.0f)});
        }
        Wire w;
        w.reference = sampleCurve(ref, CurveType::CatmullRom, 8);
        w.wire = sampleCurve(moved, CurveType::CatmullRom, 8);
        w.radius = 0.12f;
        w.scale = 1.2f;
        wires.push_back(std::move(w));
    }
    return wires;
}

WiresVariant variantOf(const benchmark::State& state) {
    return state.range(0) == 0 ? WiresVariant::Original : WiresVariant::Smooth;
}

void BM_WiresBind(benchmark::State& state) {
    const auto& rest = gridPoints();
    Wires wires(fourWires(), {variantOf(state), 1.0f, 0});
    for (auto _ : state) {
        wires.bind(rest);
        benchmark::DoNotOptimize(wires.fields().offsets.data());
    }
    state.counters["entries"] = static_cast<double>(wires.fields().offsets.back());
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(rest.size()));
}

void evaluateLoop(benchmark::State& state, int threads) {
    const auto& rest = gridPoints();
    Wires wires(fourWires(), {variantOf(state), 1.0f, 0});
    wires.bind(rest);
    std::vector<glm::vec3> points = rest;
    const int saved = omp_get_max_threads();
    if (threads > 0) omp_set_num_threads(threads);
    for (auto _ : state) {
        state.PauseTiming();
        points = rest;
        state.ResumeTiming();
        wires.evaluate(points);
        benchmark::DoNotOptimize(points.data());
    }
    omp_set_num_threads(saved);
    state.counters["threads"] = threads > 0 ? threads : saved;
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(rest.size()));
}

void BM_WiresEvaluate(benchmark::State& state) {
    evaluateLoop(state, 0);
}
void BM_WiresEvaluate1Thread(benchmark::State& state) {
    evaluateLoop(state, 1);
}

// Reference: the same warp through the generic engine (transformations recomputed every evaluation), for
// the original variant only: the smooth variant's engine run (~12M entries, each recomposed through
// toAffine) takes seconds and would dominate the bench.
void BM_WiresEngineEvaluate(benchmark::State& state) {
    const auto& rest = gridPoints();
    Wires wires(fourWires(), {variantOf(state), 1.0f, 0});
    SparseFields fields;
    wires.bind(rest, fields);
    Transformations transforms;
    std::vector<glm::vec3> out(rest.size());
    for (auto _ : state) {
        wires.transformations(transforms);
        evaluateWarp(rest, fields, transforms, out, wires.engineOptions());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(rest.size()));
}

// Argument 0: original variant, 1: smooth variant.
BENCHMARK(BM_WiresBind)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(0.3);
BENCHMARK(BM_WiresEvaluate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(0.3)->UseRealTime();
BENCHMARK(BM_WiresEvaluate1Thread)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3)
    ->UseRealTime();
BENCHMARK(BM_WiresEngineEvaluate)->Arg(0)->Unit(benchmark::kMillisecond)->MinTime(0.3)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
