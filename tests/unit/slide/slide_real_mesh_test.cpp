#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include <omp.h>
#include <glm/geometric.hpp>

#include "deformkit/geom/bvh.h"
#include "deformkit/io/obj.h"
#include "deformkit/slide/slider.h"
#include "slide_real_meshes.h"

// The slide on a real model: Keenan Crane's "Spot" (tests/data/README.md), a quad mesh with creases,
// concave dimples and thin parts (ears, horns, legs). Invariants that hold for any handle and drag:
// a vertex travels |d_P| over the surface, so it moves at most |d| falloff(|P - P0| / r) in space; it lands
// on a triangle of the surface; nothing is NaN.

using namespace deformkit;
using slide::Falloff;
using slide::SlideDrive;
using slide::SlideHandle;
using slide::SlideLanding;
using slide::SlideResult;
using test::bob;
using test::diagonal;
using test::spot;

namespace {

// The rest surface as a BVH, for the distance of a slid vertex to it measured apart from the landings;
// the last one built is kept while the same points come again.
const geom::Bvh& bvhOf(const geom::Mesh& mesh) {
    static std::vector<glm::vec3> points;
    static std::unique_ptr<geom::Bvh> bvh;
    if (!bvh || !std::equal(points.begin(), points.end(), mesh.points().begin(), mesh.points().end())) {
        points.assign(mesh.points().begin(), mesh.points().end());
        bvh = std::make_unique<geom::Bvh>(mesh);
    }
    return *bvh;
}

struct Worst {
    double travelRatio = 0.0;   // largest |moved| / (|d| falloff) over moved vertices
    double offSurface = 0.0;    // largest distance between a moved vertex and its landing point
    double offMesh = 0.0;       // largest distance between a moved vertex and the rest surface (BVH)
    double negativeBary = 0.0;  // most negative barycentric coordinate of a landing
    int walkLimitStopped = 0;
    bool finite = true;
};

// One slide of `mesh` by `d` at `handle`, checked vertex by vertex against the bound |d| falloff(dist / r).
void check(const geom::Mesh& mesh, int32_t handle, const glm::dvec3& d, double radius, Worst& worst,
           slide::RegionMetric region = slide::RegionMetric::Euclidean) {
    const SlideDrive drive{d, Falloff::smooth()};
    SlideResult result;
    const std::vector<glm::vec3> out = slide::slide(mesh, std::vector<SlideHandle>{{handle, radius, region}},
                                                    {&drive, 1}, {}, 1.0f, {}, &result);
    const auto rest = mesh.points();
    const glm::dvec3 p0(rest[handle]);
    const double scale = diagonal(mesh.points());
    for (size_t v = 0; v < out.size(); ++v) {
        worst.finite =
            worst.finite && std::isfinite(out[v].x) && std::isfinite(out[v].y) && std::isfinite(out[v].z);
        const double moved = glm::length(glm::dvec3(out[v]) - glm::dvec3(rest[v]));
        const double bound =
            glm::length(d) * Falloff::smooth()(glm::length(glm::dvec3(rest[v]) - p0) / radius);
        // float positions: a few ulps of the model's size on top of the bound
        if (moved > 1e-6 * scale)
            worst.travelRatio = std::max(worst.travelRatio, (moved - 1e-6 * scale) / bound);
    }
    for (const SlideLanding& l : result.landings) {
        glm::dvec3 at(0.0);
        for (int k = 0; k < 3; ++k) {
            at += l.barycentric[k] * glm::dvec3(rest[l.triangle[k]]);
            worst.negativeBary = std::min(worst.negativeBary, l.barycentric[k]);
        }
        worst.offSurface = std::max(worst.offSurface, glm::length(at - glm::dvec3(out[l.vertex])) / scale);
    }
    worst.walkLimitStopped += result.walkLimitStopped;
    const geom::Bvh& bvh = bvhOf(mesh);
    for (const SlideLanding& l : result.landings) {
        const glm::vec3 p = out[l.vertex];
        worst.offMesh = std::max(worst.offMesh, static_cast<double>(bvh.closestPoint(p).distance) / scale);
    }
}

// The invariants of every case: finite, within the travel bound, on the surface, no walk at its limit.
void checkInvariants(const Worst& worst) {
    CHECK(worst.finite);
    CHECK(worst.travelRatio <= 1.0);
    CHECK(worst.offSurface < 1e-6);
    CHECK(worst.offMesh < 1e-6);  // float positions and a float BVH query: a few ulps of the model's size
    CHECK(worst.negativeBary >= 0.0);
    CHECK(worst.walkLimitStopped == 0);
}

}  // namespace

TEST_CASE("slide on Spot: the tail-dimple drag moves no vertex farther than the drag", "[slide][real]") {
    // The case that tore the mesh when far vertices were read from their normal-curve maps: vertex 1848
    // moved 0.68 (8.8 |d|) and five walks ran into the walk limit.
    Worst worst;
    check(spot(), 1858, glm::dvec3(0.0283, 0.0717, -0.0088), 0.2588, worst);
    checkInvariants(worst);
}

TEST_CASE("slide on Spot: random drags keep travel, stay on the surface, stay finite", "[slide][real]") {
    // Drags of 3% of the bounding-box diagonal with radius 10%, as a rigger would set them up, at random
    // handles in random directions (fixed seed).
    const geom::Mesh& mesh = spot();
    const double scale = diagonal(mesh.points());
    std::mt19937 rng(2026);
    std::uniform_int_distribution<int32_t> vertex(0, mesh.numVertices() - 1);
    std::normal_distribution<double> gauss;
    Worst worst;
    constexpr int kCases = 60;
    for (int c = 0; c < kCases; ++c) {
        const int32_t handle = vertex(rng);
        glm::dvec3 d(gauss(rng), gauss(rng), gauss(rng));
        d *= 0.03 * scale / glm::length(d);
        check(mesh, handle, d, 0.1 * scale, worst);
    }
    INFO("largest travel / (|d| falloff) " << worst.travelRatio << ", off surface " << worst.offSurface);
    checkInvariants(worst);
}

TEST_CASE("slide on Spot: large drags and geodesic regions keep the travel bound", "[slide][real]") {
    // Drags up to two thirds of the radius (where the smooth falloff starts to fold the texture) and radii
    // from 5% to 25% of the diagonal, with both region metrics. A geodesic distance is at least the 3D
    // one, so the falloff of the 3D distance bounds the travel in both cases.
    const geom::Mesh& mesh = spot();
    const double scale = diagonal(mesh.points());
    std::mt19937 rng(18);
    std::uniform_int_distribution<int32_t> vertex(0, mesh.numVertices() - 1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> gauss;
    Worst worst;
    constexpr int kCases = 40;
    for (int c = 0; c < kCases; ++c) {
        const int32_t handle = vertex(rng);
        const double radius = (0.05 + 0.2 * unit(rng)) * scale;
        glm::dvec3 d(gauss(rng), gauss(rng), gauss(rng));
        d *= (0.05 + 0.6 * unit(rng)) * radius / glm::length(d);
        check(mesh, handle, d, radius, worst,
              c % 2 ? slide::RegionMetric::Geodesic : slide::RegionMetric::Euclidean);
    }
    INFO("largest travel / (|d| falloff) " << worst.travelRatio << ", off surface " << worst.offSurface);
    checkInvariants(worst);
}

TEST_CASE("slide on Spot gives the same bytes for 1 and 2 threads", "[slide][real]") {
    const geom::Mesh& mesh = spot();
    const std::vector<SlideHandle> handles = {{1858, 0.3}, {400, 0.25, slide::RegionMetric::Geodesic}};
    const std::vector<SlideDrive> drives = {{glm::dvec3(0.05, 0.1, -0.02)}, {glm::dvec3(-0.04, 0.02, 0.06)}};
    const int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    const std::vector<glm::vec3> one = slide::slide(mesh, handles, drives);
    omp_set_num_threads(2);
    const std::vector<glm::vec3> two = slide::slide(mesh, handles, drives);
    omp_set_num_threads(saved);
    REQUIRE(one.size() == two.size());
    CHECK(one != std::vector<glm::vec3>(mesh.points().begin(), mesh.points().end()));
    CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec3)) == 0);
}

TEST_CASE("slide on Bob (triangles): random drags keep travel, stay on the surface, stay finite",
          "[slide][real]") {
    // As on Spot: drags of 3% of the diagonal at radius 10%, then drags up to two thirds of radii from 5% to
    // 25%, both region metrics (fixed seeds).
    const geom::Mesh& mesh = bob();
    const double scale = diagonal(mesh.points());
    std::mt19937 rng(1858);
    std::uniform_int_distribution<int32_t> vertex(0, mesh.numVertices() - 1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> gauss;
    Worst worst;
    for (int c = 0; c < 80; ++c) {
        const bool large = c >= 40;
        const double radius = large ? (0.05 + 0.2 * unit(rng)) * scale : 0.1 * scale;
        glm::dvec3 d(gauss(rng), gauss(rng), gauss(rng));
        d *= (large ? (0.05 + 0.6 * unit(rng)) * radius : 0.03 * scale) / glm::length(d);
        check(mesh, vertex(rng), d, radius, worst,
              c % 2 ? slide::RegionMetric::Geodesic : slide::RegionMetric::Euclidean);
    }
    INFO("largest travel / (|d| falloff) " << worst.travelRatio << ", off surface " << worst.offSurface
                                           << ", off the mesh " << worst.offMesh);
    checkInvariants(worst);
}

TEST_CASE("slide on crumpled sheets: invariants where one-ring maps fold", "[slide]") {
    // Random heights up to 4 edge lengths crumple 30 x 30 grids of quads: non-planar quads whose fan
    // triangles overlap in the tangent plane, so some one-ring maps fold and leave directions in no
    // sector, as on scanned meshes. (Before the walk started strictly inside a sector, such starts could
    // walk through triangles the line never meets: here 1.16 |d| falloff, on a 32k-vertex scan 73.)
    const int n = 30;
    Worst worst;
    std::mt19937 rng(73);
    for (int sheetIndex = 0; sheetIndex < 12; ++sheetIndex) {
        geom::Mesh::Data data;
        std::uniform_real_distribution<double> noise(-4.0, 4.0);
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i)
                data.points.emplace_back(i, j, noise(rng));
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const int a = j * (n + 1) + i;
                data.faceCounts.push_back(4);
                data.faceIndices.insert(data.faceIndices.end(), {a, a + 1, a + n + 2, a + n + 1});
            }
        const geom::Mesh sheet(std::move(data), "crumpled sheet");
        std::uniform_int_distribution<int32_t> row(8, n - 8);
        std::normal_distribution<double> gauss;
        for (int c = 0; c < 20; ++c) {
            const int32_t handle = row(rng) * (n + 1) + row(rng);
            glm::dvec3 d(gauss(rng), gauss(rng), gauss(rng));
            d *= 1.5 / glm::length(d);
            check(sheet, handle, d, 5.0, worst);
        }
    }
    INFO("largest travel / (|d| falloff) " << worst.travelRatio << ", off the mesh " << worst.offMesh);
    CHECK(worst.finite);
    CHECK(worst.travelRatio <= 1.0);
    CHECK(worst.offMesh < 1e-6);
    CHECK(worst.negativeBary >= 0.0);
}
