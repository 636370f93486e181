#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/geom/triangulation.h"

using namespace deformkit::geom;

namespace {

// One polygon per entry, vertices listed face by face (no sharing).
Mesh polygons(const std::vector<std::vector<glm::vec3>>& polys) {
    Mesh::Data d;
    for (const auto& poly : polys) {
        d.faceCounts.push_back(static_cast<int32_t>(poly.size()));
        for (const auto& p : poly) {
            d.faceIndices.push_back(static_cast<int32_t>(d.points.size()));
            d.points.push_back(p);
        }
    }
    return Mesh(std::move(d));
}

// A regular n-gon of circumradius r in the plane through `centre` spanned by orthonormal (e1, e2).
std::vector<glm::vec3> regularPolygon(int n, double r, const glm::dvec3& centre, const glm::dvec3& e1,
                                      const glm::dvec3& e2, double phase) {
    std::vector<glm::vec3> out;
    for (int k = 0; k < n; ++k) {
        const double a = phase + 2.0 * std::numbers::pi * k / n;
        out.emplace_back(centre + r * std::cos(a) * e1 + r * std::sin(a) * e2);
    }
    return out;
}

double triangleArea(const Mesh& m, const std::array<int32_t, 3>& corners) {
    const auto idx = m.faceIndices();
    const glm::dvec3 a(m.points()[idx[corners[0]]]), b(m.points()[idx[corners[1]]]),
        c(m.points()[idx[corners[2]]]);
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

}  // namespace

TEST_CASE("triangulate: n - 2 triangles per face, fanned from the first corner", "[geom][triangulation]") {
    const glm::dvec3 o(0.0), x(1, 0, 0), y(0, 1, 0);
    const Mesh m = polygons({regularPolygon(3, 1, o, x, y, 0), regularPolygon(4, 1, o, x, y, 0),
                             regularPolygon(5, 1, o, x, y, 0), regularPolygon(6, 1, o, x, y, 0)});
    const Triangulation t = triangulate(m);
    REQUIRE(t.size() == 1 + 2 + 3 + 4);
    REQUIRE(t.corners.size() == t.face.size());
    CHECK(t.face == std::vector<int32_t>{0, 1, 1, 2, 2, 2, 3, 3, 3, 3});
    for (int32_t i = 0; i < t.size(); ++i) {
        const int32_t first = m.faceOffsets()[t.face[i]];
        CHECK(t.corners[i][0] == first);
        CHECK(t.corners[i][1] > first);
        CHECK(t.corners[i][2] == t.corners[i][1] + 1);
        CHECK(t.corners[i][2] < m.faceOffsets()[t.face[i] + 1]);
    }
    // The hexagon's last triangle uses its last three corners.
    CHECK(t.corners.back() == std::array<int32_t, 3>{12, 16, 17});

    const Mesh tube = makeCappedTube();
    // 160 x 120 side quads, per cap 9 x 160 quads and a 160-triangle fan.
    CHECK(triangulate(tube).size() == 2 * 160 * 120 + 2 * (2 * 9 * 160 + 160));
}

TEST_CASE("triangle areas sum to the area of convex polygons", "[geom][triangulation]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    for (int n = 3; n <= 16; ++n) {
        // A tilted plane, so no coordinate axis lines up with the polygon.
        const glm::dvec3 normal = glm::normalize(glm::dvec3(uni(rng), uni(rng), uni(rng)));
        const glm::dvec3 e1 = glm::normalize(glm::cross(normal, glm::dvec3(0.3, 0.5, 0.8)));
        const glm::dvec3 e2 = glm::cross(normal, e1);
        const double r = 0.5 + uni(rng) * 0.25;
        const glm::dvec3 centre(uni(rng), uni(rng), uni(rng));
        const Mesh m = polygons({regularPolygon(n, r, centre, e1, e2, uni(rng))});
        const Triangulation t = triangulate(m);
        REQUIRE(t.size() == n - 2);
        double sum = 0.0;
        for (const auto& c : t.corners)
            sum += triangleArea(m, c);
        // Closed form of a regular n-gon's area.
        CHECK(sum == Approx(0.5 * n * r * r * std::sin(2.0 * std::numbers::pi / n)).epsilon(1e-6));
    }
    // Irregular convex polygons: points on an ellipse at sorted random angles; area by the shoelace formula.
    for (int trial = 0; trial < 20; ++trial) {
        const int n = 3 + trial % 9;
        std::vector<double> angles(n);
        for (auto& a : angles)
            a = std::numbers::pi * (uni(rng) + 1.0);
        std::sort(angles.begin(), angles.end());
        std::vector<glm::vec3> poly;
        for (const double a : angles)
            poly.emplace_back(2.0 * std::cos(a), 0.7 * std::sin(a), 0.0f);
        double shoelace = 0.0;
        for (int k = 0; k < n; ++k) {
            const glm::dvec3 p(poly[k]), q(poly[(k + 1) % n]);
            shoelace += 0.5 * (p.x * q.y - q.x * p.y);
        }
        const Mesh m = polygons({poly});
        double sum = 0.0;
        for (const auto& c : triangulate(m).corners)
            sum += triangleArea(m, c);
        CHECK(sum == Approx(shoelace).epsilon(1e-6));
    }
}

TEST_CASE("triangleVertices maps corners to vertices and keeps the winding", "[geom][triangulation]") {
    const Mesh grid = makeGrid({3, 2});
    const Triangulation t = triangulate(grid);
    const auto verts = triangleVertices(grid, t);
    REQUIRE(verts.size() == t.corners.size());
    for (size_t i = 0; i < verts.size(); ++i) {
        for (int k = 0; k < 3; ++k)
            CHECK(verts[i][k] == grid.faceIndices()[t.corners[i][k]]);
        const glm::vec3 a = grid.points()[verts[i][0]], b = grid.points()[verts[i][1]],
                        c = grid.points()[verts[i][2]];
        CHECK(glm::cross(b - a, c - a).z > 0.0f);  // the grid faces +z
    }
    Triangulation foreign = t;
    foreign.corners[1][2] = grid.numCorners();
    CHECK_THROWS_WITH(triangleVertices(grid, foreign),
                      Catch::Contains("triangle 1 corner 2") && Catch::Contains("[0, 24)"));
}
