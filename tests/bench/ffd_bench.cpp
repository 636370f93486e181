// FFD (paper §4.1) with 4x4x4 control points (divisions 3, 3, 3) on a 1,000,000-vertex grid: bind (local
// coordinates cached) and evaluate (a new target lattice) timed apart; evaluate on all threads and on one,
// so the table shows the speed-up; the portable kernel (no AVX2), the B-spline variant and FFD with frames
// beside it; BM_FfdEvaluateInto, input and output apart, is the call of the Python module's bound evaluate
// (scripts/bench_python.py's reference for it). scripts/bench_blender.py builds the same grid and lattice in
// Blender.
#include <benchmark/benchmark.h>

#include <omp.h>

#include <cmath>
#include <vector>

#include "deformkit/geom/primitives.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/ffd_frames.h"

namespace {

using namespace deformkit;
using namespace deformkit::warp;

struct Input {
    std::vector<glm::vec3> rest;
    Lattice lattice;
    std::vector<glm::vec3> target;
    std::vector<Frame> frames;
};

const Input& input() {
    static const Input in = [] {
        Input in;
        const geom::Mesh grid = geom::makeGrid({1000, 999, 1.0f, 1.0f});  // 1001 x 1000 = 1,001,000 vertices
        in.rest.assign(grid.points().begin(), grid.points().end());
        // A lattice around the grid, thick in z, slightly larger than it so every vertex is inside.
        in.lattice.origin = {-0.05f, -0.05f, -0.5f};
        in.lattice.axes = glm::mat3(glm::vec3(1.1f, 0, 0), glm::vec3(0, 1.1f, 0), glm::vec3(0, 0, 1.0f));
        in.lattice.divisions = {3, 3, 3};
        in.target = in.lattice.controlPoints();
        for (size_t c = 0; c < in.target.size(); ++c) {
            in.target[c] +=
                glm::vec3(0.02f * std::sin(0.7f * c), 0.03f * std::cos(1.3f * c), 0.1f * std::sin(0.4f * c));
        }
        for (size_t c = 0; c < in.target.size(); ++c) {
            const float a = 0.05f * static_cast<float>(c % 7);
            in.frames.push_back(
                {in.target[c], glm::mat3(glm::vec3(std::cos(a), std::sin(a), 0),
                                         glm::vec3(-std::sin(a), std::cos(a), 0), glm::vec3(0, 0, 1))});
        }
        return in;
    }();
    return in;
}

void bindLoop(benchmark::State& state, const FfdOptions& options) {
    const Input& in = input();
    Ffd ffd(in.lattice, options);
    for (auto _ : state) {
        ffd.bind(in.rest);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(in.rest.size()));
}

void BM_FfdBind(benchmark::State& state) {
    bindLoop(state, {});
}

// The B-spline binds the same bound coordinates (its evaluate computes the weights from them).
void BM_FfdBSplineBind(benchmark::State& state) {
    bindLoop(state, {FfdBasis::BSpline});
}

template <class W>
void evaluateLoop(benchmark::State& state, W& warp, int threads) {
    const Input& in = input();
    const int saved = omp_get_max_threads();
    if (threads > 0) omp_set_num_threads(threads);
    warp.bind(in.rest);
    std::vector<glm::vec3> points = in.rest;
    for (auto _ : state) {
        state.PauseTiming();
        std::copy(in.rest.begin(), in.rest.end(), points.begin());
        state.ResumeTiming();
        warp.evaluate(points);
        benchmark::DoNotOptimize(points.data());
    }
    omp_set_num_threads(saved);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(in.rest.size()));
}

void BM_FfdEvaluate(benchmark::State& state) {
    Ffd ffd(input().lattice);
    ffd.setTargets(input().target);
    evaluateLoop(state, ffd, 0);
}

// The call the Python module's bound evaluate with out= makes: input and output apart (points read, the
// caller's buffer written), no weights, envelope 1.
void BM_FfdEvaluateInto(benchmark::State& state) {
    const Input& in = input();
    Ffd ffd(in.lattice);
    ffd.setTargets(in.target);
    ffd.bind(in.rest);
    std::vector<glm::vec3> out(in.rest.size());
    for (auto _ : state) {
        ffd.evaluate(in.rest, out, {}, 1.0f);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(in.rest.size()));
}

void BM_FfdEvaluate1Thread(benchmark::State& state) {
    Ffd ffd(input().lattice);
    ffd.setTargets(input().target);
    evaluateLoop(state, ffd, 1);
}

// The portable kernel where the CPU would take the AVX2 one: the table shows what runtime dispatch buys.
void BM_FfdEvaluatePortable(benchmark::State& state) {
    Ffd ffd(input().lattice, {FfdBasis::Bernstein, FfdOutside::None, FfdKernel::Portable});
    ffd.setTargets(input().target);
    evaluateLoop(state, ffd, 0);
    state.SetLabel(ffdHasAvx2Kernel() ? "portable vs AVX2" : "no AVX2 here: both portable");
}

void BM_FfdBSplineEvaluate(benchmark::State& state) {
    Ffd ffd(input().lattice, {FfdBasis::BSpline});
    ffd.setTargets(input().target);
    evaluateLoop(state, ffd, 0);
}

void BM_FfdFramesEvaluate(benchmark::State& state) {
    FfdFrames frames(input().lattice);
    frames.setTargetFrames(input().frames);
    evaluateLoop(state, frames, 0);
}

// Moving controls: the per-control transformations only, independent of the point count.
void BM_FfdSetTargets(benchmark::State& state) {
    Ffd ffd(input().lattice);
    for (auto _ : state)
        ffd.setTargets(input().target);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(input().target.size()));
}

}  // namespace

BENCHMARK(BM_FfdBind)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdBSplineBind)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdEvaluate)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdEvaluateInto)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdEvaluate1Thread)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdEvaluatePortable)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdBSplineEvaluate)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdFramesEvaluate)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FfdSetTargets)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
