// Beier-Neely image warp (paper §4.2, §5.2) on a 2048 x 2048 image with 32 segment pairs: the map of
// source positions (items = pixel * segments), on all threads and on 1 thread, for both variants; the
// resampling of a 3-channel image through that map (items = pixels); and, as the in-run reference, the
// generic engine path (bind fields + evaluateWarp over 3-D points) on a 256 x 256 grid, whose
// pixel * segments per second the fast 2-D path is compared with.
#include <benchmark/benchmark.h>

#include <omp.h>

#include <cmath>
#include <random>
#include <vector>

#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/image_warp.h"

namespace {

using namespace deformkit;
using namespace deformkit::warp;

constexpr int32_t kSize = 2048;
constexpr int32_t kSegments = 32;

std::vector<SegmentPair> segments(float size) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> pos(0.0f, size), jitter(-0.05f * size, 0.05f * size);
    std::vector<SegmentPair> pairs(kSegments);
    for (auto& s : pairs) {
        s.dstP = {pos(rng), pos(rng)};
        s.dstQ = {pos(rng), pos(rng)};
        s.srcP = s.dstP + glm::vec2(jitter(rng), jitter(rng));
        s.srcQ = s.dstQ + glm::vec2(jitter(rng), jitter(rng));
        s.a = 1.0f;
        s.b = 2.0f;
        s.p = 0.5f;
    }
    return pairs;
}

void mapBench(benchmark::State& state, BeierNeelyVariant variant, bool oneThread, float b,
              int32_t size = kSize) {
    std::vector<SegmentPair> pairs = segments(kSize);
    for (auto& s : pairs)
        s.b = b;
    const BeierNeelyWarp warp(pairs, {variant});
    std::vector<glm::vec2> map(static_cast<size_t>(size) * size);
    const int saved = omp_get_max_threads();
    if (oneThread) omp_set_num_threads(1);
    for (auto _ : state) {
        warp.mapPixelCentres(size, size, map);
        benchmark::DoNotOptimize(map.data());
    }
    omp_set_num_threads(saved);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(size) * size * kSegments);
}

void BM_BeierNeelyMap(benchmark::State& s) {
    mapBench(s, BeierNeelyVariant::Original, false, 2.0f);
}
void BM_BeierNeelyMap_1Thread(benchmark::State& s) {
    mapBench(s, BeierNeelyVariant::Original, true, 2.0f);
}
void BM_BeierNeelyMapGlobal(benchmark::State& s) {
    mapBench(s, BeierNeelyVariant::Global, false, 2.0f);
}
void BM_BeierNeelyMapGlobal_1Thread(benchmark::State& s) {
    mapBench(s, BeierNeelyVariant::Global, true, 2.0f);
}
// b = 1.5 takes the general pow() path of the weight (1024 x 1024, same segments, to stay under 2 s).
void BM_BeierNeelyMapPowB1024(benchmark::State& s) {
    mapBench(s, BeierNeelyVariant::Original, false, 1.5f, 1024);
}

void resampleBench(benchmark::State& state, io::SampleFilter interpolation, bool oneThread) {
    const BeierNeelyWarp warp(segments(kSize), {});
    std::vector<glm::vec2> map(static_cast<size_t>(kSize) * kSize);
    warp.mapPixelCentres(kSize, kSize, map);
    io::Image image(kSize, kSize, 3);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] = static_cast<float>(i % 251) / 250.0f;
    const int saved = omp_get_max_threads();
    if (oneThread) omp_set_num_threads(1);
    for (auto _ : state) {
        io::Image out = resampleImage(image, map, kSize, kSize, interpolation);
        benchmark::DoNotOptimize(out.pixels.data());
    }
    omp_set_num_threads(saved);
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(kSize) * kSize);
}

void BM_ResampleBilinear(benchmark::State& s) {
    resampleBench(s, io::SampleFilter::Bilinear, false);
}
void BM_ResampleBicubic(benchmark::State& s) {
    resampleBench(s, io::SampleFilter::Bicubic, false);
}
void BM_ResampleBicubic_1Thread(benchmark::State& s) {
    resampleBench(s, io::SampleFilter::Bicubic, true);
}

// Reference: the same warp through the generic engine (fields bound once, evaluate timed) on 256 x 256.
void BM_GenericEngine256(benchmark::State& state) {
    constexpr int32_t n = 256;
    std::vector<SegmentPair> pairs = segments(kSize);
    for (auto& s : pairs) {  // the same layout scaled to the small image
        const float k = static_cast<float>(n) / kSize;
        s.dstP *= k, s.dstQ *= k, s.srcP *= k, s.srcQ *= k;
    }
    BeierNeelyWarp warp(pairs, {});
    std::vector<glm::vec3> points;
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x)
            points.push_back({x + 0.5f, y + 0.5f, 0.0f});
    }
    SparseFields fields;
    warp.bind(points, fields);
    Transformations transforms;
    std::vector<glm::vec3> out(points.size());
    for (auto _ : state) {
        warp.transformations(transforms);
        evaluateWarp(points, fields, transforms, out);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n) * n * kSegments);
}

}  // namespace

BENCHMARK(BM_BeierNeelyMap)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BeierNeelyMap_1Thread)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BeierNeelyMapGlobal)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BeierNeelyMapGlobal_1Thread)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BeierNeelyMapPowB1024)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ResampleBilinear)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ResampleBicubic)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ResampleBicubic_1Thread)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_GenericEngine256)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
