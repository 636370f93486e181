// The coarse-mesh warp (paper §6): a 502-vertex control sphere (25 segments x 21 rings) just outside a
// 999,002-vertex sphere (1000 x 1000). Bind (weights on the rest surface, sparse, through the support
// grid) and evaluate (a new target cage: the per-vertex least-squares maps, then Eq. 3 over the cached
// fields) timed apart; evaluate on all threads and on one, so the table shows the speed-up.
#include <benchmark/benchmark.h>

#include <omp.h>

#include <cmath>
#include <vector>

#include "deformkit/geom/primitives.h"
#include "deformkit/warp/mesh_warp.h"

namespace {

using namespace deformkit;
using namespace deformkit::warp;

struct Input {
    std::vector<glm::vec3> rest;
    geom::Mesh cage = geom::makeSphere({1.05f, 25, 21});  // 25 * 20 + 2 = 502 control vertices
    std::vector<glm::vec3> target;
};

const Input& input() {
    static const Input in = [] {
        Input in;
        const geom::Mesh surface = geom::makeSphere({1.0f, 1000, 1000});
        in.rest.assign(surface.points().begin(), surface.points().end());
        in.target.assign(in.cage.points().begin(), in.cage.points().end());
        for (size_t c = 0; c < in.target.size(); ++c) {
            in.target[c] +=
                glm::vec3(0.03f * std::sin(0.7f * c), 0.04f * std::cos(1.3f * c), 0.05f * std::sin(0.4f * c));
        }
        return in;
    }();
    return in;
}

void BM_MeshWarpBind(benchmark::State& state) {
    const Input& in = input();
    MeshWarp warp(in.cage);
    SparseFields fields;
    for (auto _ : state) {
        warp.bind(in.rest, fields);
        benchmark::ClobberMemory();
    }
    state.counters["entries/point"] =
        static_cast<double>(fields.weight.size()) / static_cast<double>(in.rest.size());
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(in.rest.size()));
}

void evaluateLoop(benchmark::State& state, int threads) {
    const Input& in = input();
    const int saved = omp_get_max_threads();
    if (threads > 0) omp_set_num_threads(threads);
    MeshWarp warp(in.cage);
    WarpDeformer deformer(warp);
    deformer.bind(in.rest);
    std::vector<glm::vec3> points = in.rest;
    for (auto _ : state) {
        state.PauseTiming();
        std::copy(in.rest.begin(), in.rest.end(), points.begin());
        state.ResumeTiming();
        warp.setTarget(in.target);
        deformer.evaluate(points);
        benchmark::DoNotOptimize(points.data());
    }
    omp_set_num_threads(saved);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(in.rest.size()));
}

void BM_MeshWarpEvaluate(benchmark::State& state) {
    evaluateLoop(state, 0);
}
void BM_MeshWarpEvaluate1Thread(benchmark::State& state) {
    evaluateLoop(state, 1);
}

// Moving controls: the 502 least-squares edge maps alone, independent of the point count.
void BM_MeshWarpTransformations(benchmark::State& state) {
    const Input& in = input();
    MeshWarp warp(in.cage);
    Transformations t;
    for (auto _ : state) {
        warp.setTarget(in.target);
        warp.transformations(t);
        benchmark::DoNotOptimize(t.affine.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(in.target.size()));
}

}  // namespace

BENCHMARK(BM_MeshWarpBind)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshWarpEvaluate)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshWarpEvaluate1Thread)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshWarpTransformations)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
