#include <cmath>

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include "deformkit/slide/exp_map.h"
#include "slide_test_support.h"

using namespace deformkit;

TEST_CASE("exp map of a plane is the plane itself", "[slide]") {
    // On a plane the normal curve is the straight segment: |alpha_pq| = |pq|, and the map is an isometry.
    const geom::Mesh mesh = test::planeGrid(12, 12, 0.1f);
    const slide::SlideSurface surface(mesh);
    const int p = 6 * 13 + 6;
    for (int q = 0; q < mesh.numVertices(); ++q) {
        if (q == p) continue;
        const glm::dvec3 pq = surface.point(q) - surface.point(p);
        const auto length = slide::normalCurveLength(surface, p, q);
        REQUIRE(length.has_value());
        CHECK(*length == Approx(glm::length(pq)).epsilon(1e-12));
        const glm::dvec2 image = slide::expMap(surface, p, q);
        const glm::dvec2 expected(glm::dot(pq, surface.tangent1(p)), glm::dot(pq, surface.tangent2(p)));
        CHECK(glm::length(image - expected) < 1e-12);
    }
}

TEST_CASE("normal curve around a cylinder follows the ring polygon", "[slide]") {
    // p's normal is radial, so the plane through p and a vertex q of the same ring is the ring's plane:
    // the cut is the ring polygon, k chords long for q k steps away.
    const int around = 48;
    const geom::Mesh mesh = test::cylinder(around, 6, 2.0f, 1.0f);
    const slide::SlideSurface surface(mesh);
    const int p = 3 * around;
    const double chord = 2.0 * 2.0 * std::sin(M_PI / around);
    for (int k = 1; k <= 10; ++k) {
        const auto length = slide::normalCurveLength(surface, p, p + k);
        REQUIRE(length.has_value());
        CHECK(*length == Approx(k * chord).epsilon(1e-6));
        // Its image lies on p's circumferential tangent line at distance k chords.
        const glm::dvec2 image = slide::expMap(surface, p, p + k);
        CHECK(glm::length(image) == Approx(k * chord).epsilon(1e-6));
    }
}

TEST_CASE("normal curve on a sphere approximates the great-circle distance", "[slide]") {
    // Inscribed polylines are shorter than arcs by O(h^2): 1% covers edges ~0.07 of the radius.
    const geom::Mesh mesh = test::icosphere(4, 1.0f);
    const slide::SlideSurface surface(mesh);
    const int p = 17;
    int checked = 0;
    for (int q = 0; q < mesh.numVertices(); ++q) {
        const glm::dvec3 a = glm::normalize(surface.point(p)), b = glm::normalize(surface.point(q));
        const double arc = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        if (q == p || arc > 0.5) continue;
        const auto length = slide::normalCurveLength(surface, p, q);
        REQUIRE(length.has_value());
        CHECK(*length == Approx(arc).epsilon(0.01));
        ++checked;
    }
    CHECK(checked > 100);
}
