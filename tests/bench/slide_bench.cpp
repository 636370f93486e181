// Sliding deformation (Pinskiy, slide/slider.h) on a 1,002,001-vertex wavy height field, one handle in the
// middle whose radius makes 500 (the paper's Maya figure), 10k, 100k or all vertices active. Bind and
// evaluate are timed apart; evaluate is timed in the steady state of a drag (local maps grown by one
// evaluate first) on all threads and on one (the speed-up), and the first evaluate after bind, which grows
// the maps, on its own. Target: 100k active vertices evaluated in under one 60 Hz frame (16.7 ms) on
// 2 cores.
//
// In-run reference (scripts/bench_table.py): a soft translate of the same active vertices, what a
// soft-modification deformer does with the same falloff and drag (each vertex moved by falloff x drag in
// 3D, off the surface). Both count active vertices as items, so the ratio slide / soft translate is the
// soft translate's time over the slide's: the fraction of the slide's cost that is the per-vertex work
// any falloff deformer does, the rest being what keeping vertices on the surface costs. Compared at one
// thread, so it measures work per vertex and not how either scales.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/geom/primitives.h"
#include "deformkit/slide/slider.h"

namespace {

using namespace deformkit;
using namespace deformkit::slide;

constexpr int32_t kCells = 1000;                                      // quads per side of the unit square
constexpr int64_t kAllVertices = int64_t{kCells + 1} * (kCells + 1);  // 1,002,001
constexpr double kEdge = 1.0 / kCells;                                // grid edge length in x and y

struct Input {
    geom::Mesh mesh;
    int32_t handle = -1;
    std::vector<double> sortedDistance;  // every vertex's 3D distance to the handle, ascending
};

// z = 0.04 sin(4 pi x + 0.7) cos(3 pi y + 0.4): slopes up to ~0.5, curvature radius >= ~0.16 (160 edges),
// so the surface is smooth at the scale of a drag yet curved enough that the local maps and walks do real
// work (on a plane every exponential map would be exact and trivial).
const Input& input() {
    static const Input in = [] {
        Input in;
        geom::Mesh grid = geom::makeGrid({kCells, kCells, 1.0f, 1.0f});
        const double pi = std::acos(-1.0);
        std::vector<glm::vec3> points(grid.points().begin(), grid.points().end());
        for (glm::vec3& p : points) {
            p.z = static_cast<float>(0.04 * std::sin(4.0 * pi * p.x + 0.7) * std::cos(3.0 * pi * p.y + 0.4));
        }
        grid.setPoints(points);
        in.mesh = std::move(grid);
        in.handle = (kCells / 2) * (kCells + 1) + kCells / 2;  // (0.5, 0.5)
        // The same distance the Euclidean support region measures, so radius = the k-th smallest distance
        // makes at least k vertices active (more only on ties).
        const glm::dvec3 p0(points[in.handle]);
        in.sortedDistance.resize(points.size());
        for (size_t v = 0; v < points.size(); ++v)
            in.sortedDistance[v] = glm::length(glm::dvec3(points[v]) - p0);
        std::sort(in.sortedDistance.begin(), in.sortedDistance.end());
        return in;
    }();
    return in;
}

std::vector<SlideHandle> handleFor(int64_t activeTarget) {
    const Input& in = input();
    const auto k = static_cast<size_t>(std::clamp<int64_t>(activeTarget, 1, kAllVertices));
    return {{in.handle, in.sortedDistance[k - 1], RegionMetric::Euclidean}};
}

// An animator's drag: 3 edges in x and 2 in y (3.6 edge lengths) at the handle, fading with the smooth
// falloff to nothing at the region's edge.
SlideDrive drag() {
    SlideDrive drive;
    drive.displacement = glm::dvec3(3.0 * kEdge, 2.0 * kEdge, 0.0);
    return drive;
}

// Bound once per region size and warmed by one evaluate of the drag: the steady state of a drag, shared
// by the evaluate benchmarks of that size (binding 1M vertices takes seconds).
Slider& warmSlider(int64_t activeTarget) {
    static std::map<int64_t, std::unique_ptr<Slider>> sliders;
    std::unique_ptr<Slider>& slider = sliders[activeTarget];
    if (!slider) {
        slider = std::make_unique<Slider>(input().mesh, handleFor(activeTarget));
        std::vector<glm::vec3> points(input().mesh.points().begin(), input().mesh.points().end());
        const SlideDrive drive = drag();
        slider->evaluate({&drive, 1}, points);
    }
    return *slider;
}

void setActiveCounter(benchmark::State& state, const Slider& slider) {
    state.counters["active"] = static_cast<double>(slider.activeVertices().size());
}

// A mesh equal to the input but with nothing cached (the half-edge connectivity the binding builds is
// cached in a mesh and shared by its copies): what a host hands over when it binds a mesh it just read.
geom::Mesh freshMesh() {
    const geom::Mesh& mesh = input().mesh;
    geom::Mesh::Data data;
    data.points.assign(mesh.points().begin(), mesh.points().end());
    data.faceCounts.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    data.faceIndices.assign(mesh.faceIndices().begin(), mesh.faceIndices().end());
    return geom::Mesh(std::move(data), "slide bench grid");
}

void BM_SlideBind(benchmark::State& state) {
    const std::vector<SlideHandle> handles = handleFor(state.range(0));
    std::optional<geom::Mesh> mesh;
    std::optional<Slider> slider;
    for (auto _ : state) {
        state.PauseTiming();
        slider.reset();  // freeing the previous binding is not part of binding
        mesh.reset();
        mesh.emplace(freshMesh());
        state.ResumeTiming();
        slider.emplace(*mesh, handles);
        benchmark::ClobberMemory();
    }
    setActiveCounter(state, *slider);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(slider->activeVertices().size()));
}

// The first evaluate after bind (first touch of the per-vertex scratch); timed by hand around evaluate
// alone, a fresh binding per iteration.
void BM_SlideFirstEvaluate(benchmark::State& state) {
    const Input& in = input();
    const std::vector<SlideHandle> handles = handleFor(state.range(0));
    const SlideDrive drive = drag();
    std::vector<glm::vec3> points(in.mesh.points().begin(), in.mesh.points().end());
    std::optional<Slider> slider;
    for (auto _ : state) {
        slider.reset();
        slider.emplace(in.mesh, handles);
        const auto start = std::chrono::steady_clock::now();
        slider->evaluate({&drive, 1}, points);
        const auto stop = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(points.data());
        state.SetIterationTime(std::chrono::duration<double>(stop - start).count());
    }
    setActiveCounter(state, *slider);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(slider->activeVertices().size()));
}

// The slide moves the region over the points passed in, so each iteration puts the active vertices back
// (a copy of those alone, not of the 12 MB of points): every evaluate sees the rest surface.
void evaluateLoop(benchmark::State& state, int threads) {
    Slider& slider = warmSlider(state.range(0));
    const std::span<const glm::vec3> rest = input().mesh.points();
    std::vector<glm::vec3> points(rest.begin(), rest.end());
    const SlideDrive drive = drag();
    const int saved = omp_get_max_threads();
    if (threads > 0) omp_set_num_threads(threads);
    for (auto _ : state) {
        slider.evaluate({&drive, 1}, points);
        for (int32_t v : slider.activeVertices())
            points[v] = rest[v];
        benchmark::DoNotOptimize(points.data());
        benchmark::ClobberMemory();
    }
    omp_set_num_threads(saved);
    setActiveCounter(state, slider);
    state.counters["threads"] = threads > 0 ? threads : saved;
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(slider.activeVertices().size()));
}

void BM_SlideEvaluate(benchmark::State& state) {
    evaluateLoop(state, 0);
}
void BM_SlideEvaluate1Thread(benchmark::State& state) {
    evaluateLoop(state, 1);
}

// Reference: the soft translate of the same region (vertices, normalised distances, falloff and drag as
// the slide), in double like the slide's final write.
void softTranslateLoop(benchmark::State& state, int threads) {
    const Slider& slider = warmSlider(state.range(0));
    const SupportRegion& region = slider.region(0);
    const SlideDrive drive = drag();
    std::vector<glm::vec3> points(input().mesh.points().begin(), input().mesh.points().end());
    const auto count = static_cast<int32_t>(region.vertices.size());
    const int saved = omp_get_max_threads();
    if (threads > 0) omp_set_num_threads(threads);
    for (auto _ : state) {
#pragma omp parallel for schedule(static)
        for (int32_t k = 0; k < count; ++k) {
            const double f = drive.falloff(region.normalizedDistance[k]);
            if (f == 0.0) continue;
            const int32_t v = region.vertices[k];
            points[v] = glm::vec3(glm::dvec3(points[v]) + f * drive.displacement);
        }
        benchmark::DoNotOptimize(points.data());
        benchmark::ClobberMemory();
    }
    omp_set_num_threads(saved);
    setActiveCounter(state, slider);
    state.counters["threads"] = threads > 0 ? threads : saved;
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(slider.activeVertices().size()));
}

void BM_SlideSoftTranslate(benchmark::State& state) {
    softTranslateLoop(state, 0);
}
void BM_SlideSoftTranslate1Thread(benchmark::State& state) {
    softTranslateLoop(state, 1);
}

// An animated input: a 100,489-vertex wavy grid (316 x 316 quads, the same surface) with 10k vertices
// active, handed over by a stack whose earlier deformer changes every frame. Frames alternate between two
// bends of the grid about the y axis (0.5 and 0.6 radians over its width), so every evaluate sees new
// points and the handle's frame turns. Per frame: the host's copy of its input into the output buffer and
// one evaluate, as DeformerStack does. The steady figure is the same loop with the rest points every frame.
struct AnimatedInput {
    geom::Mesh mesh;
    std::vector<glm::vec3> frames[2];
    std::vector<SlideHandle> handles;
};

const AnimatedInput& animatedInput() {
    static const AnimatedInput in = [] {
        constexpr int32_t kSide = 316;
        AnimatedInput in;
        geom::Mesh grid = geom::makeGrid({kSide, kSide, 1.0f, 1.0f});
        const double pi = std::acos(-1.0);
        std::vector<glm::vec3> points(grid.points().begin(), grid.points().end());
        for (glm::vec3& p : points)
            p.z = static_cast<float>(0.04 * std::sin(4.0 * pi * p.x + 0.7) * std::cos(3.0 * pi * p.y + 0.4));
        grid.setPoints(points);
        for (int f = 0; f < 2; ++f) {
            const double bend = 0.5 + 0.1 * f;  // radians over the unit width
            for (const glm::vec3& p : points) {
                const double a = bend * p.x, r = 1.0 / bend;
                in.frames[f].emplace_back(r * std::sin(a) + p.z * std::sin(a), p.y,
                                          r * (1.0 - std::cos(a)) + p.z * std::cos(a));
            }
        }
        const int32_t handle = (kSide / 2) * (kSide + 1) + kSide / 2;
        const glm::dvec3 p0(points[handle]);
        std::vector<double> distance(points.size());
        for (size_t v = 0; v < points.size(); ++v)
            distance[v] = glm::length(glm::dvec3(points[v]) - p0);
        std::nth_element(distance.begin(), distance.begin() + 9'999, distance.end());
        in.handles = {{handle, distance[9'999], RegionMetric::Euclidean}};
        in.mesh = std::move(grid);
        return in;
    }();
    return in;
}

void animatedLoop(benchmark::State& state, bool changing) {
    const AnimatedInput& in = animatedInput();
    Slider slider(in.mesh, in.handles);
    const SlideDrive drive{glm::dvec3(3.0 / 316, 2.0 / 316, 0.0), Falloff::smooth()};
    std::vector<glm::vec3> points(in.mesh.points().size());
    int frame = 0;
    for (auto _ : state) {
        const std::span<const glm::vec3> incoming =
            changing ? std::span<const glm::vec3>(in.frames[frame ^= 1]) : in.mesh.points();
        std::copy(incoming.begin(), incoming.end(), points.begin());
        slider.evaluate({&drive, 1}, points);
        benchmark::DoNotOptimize(points.data());
        benchmark::ClobberMemory();
    }
    state.counters["active"] = static_cast<double>(slider.activeVertices().size());
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(slider.activeVertices().size()));
}

void BM_SlideFrameChangingInput(benchmark::State& state) {
    animatedLoop(state, true);
}
void BM_SlideFrameSteadyInput(benchmark::State& state) {
    animatedLoop(state, false);
}

void regionSizes(benchmark::internal::Benchmark* b) {
    for (int64_t active : {int64_t{500}, int64_t{10'000}, int64_t{100'000}, kAllVertices})
        b->Arg(active);
}

}  // namespace

// Argument: the active vertices asked for (the radius is the distance of the k-th nearest vertex); the
// "active" counter gives the count the binding reached.
BENCHMARK(BM_SlideBind)->Apply(regionSizes)->Iterations(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SlideFirstEvaluate)
    ->Apply(regionSizes)
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK(BM_SlideEvaluate)->Apply(regionSizes)->Unit(benchmark::kMillisecond)->MinTime(0.3)->UseRealTime();
BENCHMARK(BM_SlideEvaluate1Thread)
    ->Apply(regionSizes)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3)
    ->UseRealTime();
BENCHMARK(BM_SlideSoftTranslate)
    ->Apply(regionSizes)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3)
    ->UseRealTime();
BENCHMARK(BM_SlideSoftTranslate1Thread)
    ->Apply(regionSizes)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3)
    ->UseRealTime();

// 100k-vertex mesh, 10k active, all threads (target for the changing input: 16 ms on 2 cores).
BENCHMARK(BM_SlideFrameChangingInput)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
BENCHMARK(BM_SlideFrameSteadyInput)->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();

BENCHMARK_MAIN();
