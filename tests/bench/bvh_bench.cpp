// BVH queries against the reference of testing every triangle (scripts/bench_table.py prints the ratios),
// BVH construction, and rasterising UV triangles. The input is the demo asset (makeCappedTube, 44,480
// triangles). The brute-force references use the same per-triangle tests as the BVH (Ericson's region
// method, Moller-Trumbore, in double), so the ratios measure the hierarchy alone.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/geom/bvh.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/geom/triangulation.h"
#include "geom/rasterize_triangle.h"

namespace {

using namespace deformkit::geom;

constexpr size_t kQueries = 1024;
constexpr int32_t kRasterSize = 2048;

struct Ray {
    glm::vec3 origin, direction;
};

struct Input {
    Mesh tube = makeCappedTube();
    std::vector<std::array<int32_t, 3>> triangles;
    std::vector<glm::vec3> queries;                   // within 0.1 of the surface (the tube's radius is 1)
    std::vector<Ray> rays;                            // from outside the tube towards a random surface point
    std::vector<glm::vec2> uvPositions;               // the tube's UVs in raster coordinates, tile 1001
    std::vector<std::array<int32_t, 3>> uvTriangles;  // UV index triples
};

const Input& input() {
    static const Input in = [] {
        Input in;
        const Triangulation tris = triangulate(in.tube);
        in.triangles = triangleVertices(in.tube, tris);
        std::mt19937 rng(20240601);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f), offset(-0.1f, 0.1f), wide(-3.0f, 3.0f);
        auto surfacePoint = [&] {
            const auto& t = in.triangles[rng() % in.triangles.size()];
            float b1 = unit(rng), b2 = unit(rng);
            if (b1 + b2 > 1.0f) {
                b1 = 1.0f - b1;
                b2 = 1.0f - b2;
            }
            const auto p = in.tube.points();
            return (1.0f - b1 - b2) * p[t[0]] + b1 * p[t[1]] + b2 * p[t[2]];
        };
        for (size_t q = 0; q < kQueries; ++q) {
            in.queries.push_back(surfacePoint() + glm::vec3(offset(rng), offset(rng), offset(rng)));
            const glm::vec3 origin(wide(rng), 2.0f + 2.0f * wide(rng), wide(rng));
            in.rays.push_back({origin, surfacePoint() - origin});
        }
        for (const glm::vec2& uv : in.tube.uvs())
            in.uvPositions.push_back(uv * static_cast<float>(kRasterSize));
        const auto uvIndices = in.tube.uvIndices();
        for (const auto& c : tris.corners)
            in.uvTriangles.push_back({uvIndices[c[0]], uvIndices[c[1]], uvIndices[c[2]]});
        return in;
    }();
    return in;
}

// Squared distance from p to triangle (a, b, c) by Ericson's region method (Real-Time Collision
// Detection, 5.1.5); the input has no degenerate triangles.
double distance2ToTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                           const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    auto at = [&p](const glm::dvec3& q) { return glm::dot(p - q, p - q); };
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return at(a);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return at(b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return at(a + d1 / (d1 - d3) * ab);
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return at(c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return at(a + d2 / (d2 - d6) * ac);
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
        return at(b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b));
    const double denom = 1.0 / (va + vb + vc);
    return at(a + vb * denom * ab + vc * denom * ac);
}

// Moller-Trumbore without culling; infinity on a miss.
double rayTriangle(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                   const glm::dvec3& c) {
    constexpr double kMiss = std::numeric_limits<double>::infinity();
    const glm::dvec3 e1 = b - a, e2 = c - a, pvec = glm::cross(d, e2);
    const double det = glm::dot(e1, pvec);
    if (det == 0.0) return kMiss;
    const double inv = 1.0 / det;
    const glm::dvec3 tvec = o - a;
    const double u = glm::dot(tvec, pvec) * inv;
    if (u < 0.0 || u > 1.0) return kMiss;
    const glm::dvec3 qvec = glm::cross(tvec, e1);
    const double v = glm::dot(d, qvec) * inv;
    if (v < 0.0 || u + v > 1.0) return kMiss;
    const double t = glm::dot(e2, qvec) * inv;
    return t >= 0.0 ? t : kMiss;
}

void BM_BvhClosestPoint(benchmark::State& state) {
    const Input& in = input();
    const Bvh bvh(in.tube);
    size_t q = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(bvh.closestPoint(in.queries[q++ % kQueries]));
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
BENCHMARK(BM_BvhClosestPoint);

void BM_BruteForceClosestPoint(benchmark::State& state) {
    const Input& in = input();
    const auto points = in.tube.points();
    size_t q = 0;
    for (auto _ : state) {
        const glm::dvec3 p(in.queries[q++ % kQueries]);
        double best = std::numeric_limits<double>::infinity();
        for (const auto& t : in.triangles) {
            best = std::min(best, distance2ToTriangle(p, glm::dvec3(points[t[0]]), glm::dvec3(points[t[1]]),
                                                      glm::dvec3(points[t[2]])));
        }
        benchmark::DoNotOptimize(best);
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
// About 1 ms per query: a fixed count keeps the run short.
BENCHMARK(BM_BruteForceClosestPoint)->Iterations(400);

void BM_BvhRayCast(benchmark::State& state) {
    const Input& in = input();
    const Bvh bvh(in.tube);
    size_t q = 0;
    for (auto _ : state) {
        const Ray& r = in.rays[q++ % kQueries];
        benchmark::DoNotOptimize(bvh.intersectRay(r.origin, r.direction));
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
BENCHMARK(BM_BvhRayCast);

void BM_BruteForceRayCast(benchmark::State& state) {
    const Input& in = input();
    const auto points = in.tube.points();
    size_t q = 0;
    for (auto _ : state) {
        const Ray& r = in.rays[q++ % kQueries];
        const glm::dvec3 o(r.origin), d(r.direction);
        double best = std::numeric_limits<double>::infinity();
        for (const auto& t : in.triangles) {
            best = std::min(best, rayTriangle(o, d, glm::dvec3(points[t[0]]), glm::dvec3(points[t[1]]),
                                              glm::dvec3(points[t[2]])));
        }
        benchmark::DoNotOptimize(best);
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}
BENCHMARK(BM_BruteForceRayCast)->Iterations(1000);

void BM_BvhBuild(benchmark::State& state) {
    const Input& in = input();
    for (auto _ : state) {
        const Bvh bvh(in.tube.points(), in.triangles);
        benchmark::DoNotOptimize(bvh.bounds());
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * in.triangles.size()));
}
BENCHMARK(BM_BvhBuild)->Unit(benchmark::kMillisecond);

// Items are covered pixels. The side's UVs fill the 2048^2 tile; the caps (tile 1002) fall outside.
void BM_RasterizeTriangles(benchmark::State& state) {
    const Input& in = input();
    const RasterGrid grid{kRasterSize, kRasterSize};
    std::vector<int32_t> ids(static_cast<size_t>(kRasterSize) * kRasterSize, -1);
    int64_t pixels = 0;
    for (auto _ : state) {
        for (size_t t = 0; t < in.uvTriangles.size(); ++t) {
            const auto& tri = in.uvTriangles[t];
            rasterizeTriangle(grid, in.uvPositions[tri[0]], in.uvPositions[tri[1]], in.uvPositions[tri[2]],
                              [&](int32_t x, int32_t y, const glm::vec3&) {
                                  ids[static_cast<size_t>(y) * kRasterSize + x] = static_cast<int32_t>(t);
                                  ++pixels;
                              });
        }
        benchmark::DoNotOptimize(ids.data());
    }
    state.SetItemsProcessed(pixels);
}
BENCHMARK(BM_RasterizeTriangles)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
