#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/normals.h"
#include "deformkit/geom/primitives.h"

using namespace deformkit::geom;

namespace {

Mesh fromFaces(std::vector<glm::vec3> points, const std::vector<std::vector<int32_t>>& faces) {
    Mesh::Data d;
    d.points = std::move(points);
    for (const auto& f : faces) {
        d.faceCounts.push_back(static_cast<int32_t>(f.size()));
        d.faceIndices.insert(d.faceIndices.end(), f.begin(), f.end());
    }
    return Mesh(std::move(d));
}

double angleBetween(const glm::vec3& a, const glm::vec3& b) {
    const glm::dvec3 x(a), y(b);
    return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
}

// Largest angle between a sphere's vertex normals and the radial direction.
double maxRadialError(const SphereOptions& options, NormalWeighting weighting) {
    const Mesh sphere = makeSphere(options);
    const auto normals = vertexNormals(sphere, {weighting});
    double worst = 0.0;
    for (int32_t v = 0; v < sphere.numVertices(); ++v)
        worst = std::max(worst, angleBetween(normals[v], sphere.points()[v]));
    return worst;
}

// Unit cube [0,1]^3 with outward faces. Each face is split into triangles: by one of its two diagonals
// (bit f of `diagonals`) or, when `centres` is set, as a fan around an off-centre interior vertex.
Mesh triangulatedCube(int diagonals, bool centres, std::mt19937& rng) {
    std::vector<glm::vec3> points;
    for (int i = 0; i < 8; ++i)
        points.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    // Outward-wound quads.
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    std::uniform_real_distribution<float> uni(0.15f, 0.85f);
    std::vector<std::vector<int32_t>> faces;
    for (int f = 0; f < 6; ++f) {
        const int* q = quads[f];
        if (centres) {
            // Bilinear point of the face at random (s, t): inside and coplanar.
            const float s = uni(rng), t = uni(rng);
            const glm::vec3 c = (1 - s) * (1 - t) * points[q[0]] + s * (1 - t) * points[q[1]] +
                                s * t * points[q[2]] + (1 - s) * t * points[q[3]];
            const auto centre = static_cast<int32_t>(points.size());
            points.push_back(c);
            for (int k = 0; k < 4; ++k)
                faces.push_back({q[k], q[(k + 1) % 4], centre});
        } else if (diagonals & (1 << f)) {
            faces.push_back({q[0], q[1], q[2]});
            faces.push_back({q[0], q[2], q[3]});
        } else {
            faces.push_back({q[1], q[2], q[3]});
            faces.push_back({q[1], q[3], q[0]});
        }
    }
    return fromFaces(std::move(points), faces);
}

}  // namespace

TEST_CASE("face normals: Newell's vector for planar and non-planar faces", "[geom][normals]") {
    const float h = 0.6f;
    // A unit square in z = 0, a triangle in x = 2 facing +x, and a quad with one corner lifted by h.
    const Mesh m =
        fromFaces({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}, {2, 0, 1}, {1, 1, h}},
                  {{0, 1, 2, 3}, {4, 5, 6}, {0, 1, 7, 3}});
    std::vector<glm::vec3> n(m.numFaces());
    computeFaceNormals(m, n);
    CHECK(n[0] == glm::vec3(0, 0, 1));
    CHECK(n[1] == glm::vec3(1, 0, 0));
    // Newell's vector of a quad is the cross product of its diagonals: (p2 - p0) x (p3 - p1) = (-h, -h, 2).
    const glm::vec3 expected = glm::normalize(glm::vec3(-h, -h, 2.0f));
    CHECK(n[2].x == Approx(expected.x).margin(1e-6));
    CHECK(n[2].y == Approx(expected.y).margin(1e-6));
    CHECK(n[2].z == Approx(expected.z).margin(1e-6));

    std::vector<glm::vec3> wrong(2);
    CHECK_THROWS_AS(computeFaceNormals(m, wrong), deformkit::InvalidInput);
}

TEST_CASE("flat grid: every normal is exactly +z", "[geom][normals]") {
    const Mesh grid = makeGrid({7, 5, 3.0f, 1.3f});
    for (const auto weighting : {NormalWeighting::Area, NormalWeighting::Angle}) {
        const auto normals = vertexNormals(grid, {weighting});
        REQUIRE(normals.size() == static_cast<size_t>(grid.numVertices()));
        for (const auto& n : normals)
            REQUIRE(n == glm::vec3(0.0f, 0.0f, 1.0f));
    }
    std::vector<glm::vec3> faceNormals(grid.numFaces());
    computeFaceNormals(grid, faceNormals);
    for (const auto& n : faceNormals)
        REQUIRE(n == glm::vec3(0.0f, 0.0f, 1.0f));
}

TEST_CASE("sphere: vertex normals converge to the radial direction", "[geom][normals]") {
    // Faces span h = 2 pi / segments in longitude and latitude. Angle weighting is second order in h.
    // Area weighting is only first order at the rings next to the poles, where the polar triangle fans
    // (half the area of the quads on the other side) pull the normal towards the pole by about h / 4.
    struct Expectation {
        NormalWeighting weighting;
        double boundOverSpacing;  // max error < bound * h
        double refinementRatio;   // error(h / 2) < ratio * error(h)
    };
    for (const auto& e :
         {Expectation{NormalWeighting::Angle, 0.06, 0.3}, Expectation{NormalWeighting::Area, 0.26, 0.55}}) {
        double previous = 0.0;
        for (const int32_t segments : {16, 32, 64, 128}) {
            const double error = maxRadialError({1.7f, segments, segments / 2}, e.weighting);
            const double spacing = 2.0 * std::numbers::pi / segments;
            INFO("weighting " << static_cast<int>(e.weighting) << ", segments " << segments << ": max angle "
                              << error);
            CHECK(error < e.boundOverSpacing * spacing);
            if (previous > 0.0) CHECK(error < e.refinementRatio * previous);
            previous = error;
        }
    }
}

TEST_CASE("cube corner: angle weighting gives (1,1,1)/sqrt 3 for any triangulation", "[geom][normals]") {
    std::mt19937 rng(11);
    const glm::dvec3 diagonal = glm::normalize(glm::dvec3(1.0));
    bool areaDiffers = false;
    for (int variant = 0; variant <= 64; ++variant) {
        const Mesh cube = triangulatedCube(variant, variant == 64, rng);
        const auto angle = vertexNormals(cube, {NormalWeighting::Angle});
        const auto area = vertexNormals(cube, {NormalWeighting::Area});
        for (int32_t v = 0; v < 8; ++v) {
            const glm::dvec3 outward = glm::dvec3(cube.points()[v]) * 2.0 - 1.0;
            const glm::dvec3 expected = outward * diagonal.x;
            for (int i = 0; i < 3; ++i)
                REQUIRE(angle[v][i] == Approx(expected[i]).margin(1e-6));
            if (glm::length(glm::dvec3(area[v]) - expected) > 1e-3) areaDiffers = true;
        }
    }
    // Area weighting depends on how the faces are split: the property is specific to angle weighting.
    CHECK(areaDiffers);
}

TEST_CASE("degenerate faces and unused vertices get zero normals", "[geom][normals]") {
    // Face 0 is a regular triangle; face 1 has collinear corners 3, 4, 5; vertex 6 is unused.
    const Mesh m = fromFaces({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 2}, {2, 2, 3}, {5, 5, 5}},
                             {{0, 1, 2}, {3, 4, 5}, {0, 1, 4}});
    std::vector<glm::vec3> faceNormals(m.numFaces());
    computeFaceNormals(m, faceNormals);
    CHECK(faceNormals[0] == glm::vec3(0, 0, 1));
    CHECK(faceNormals[1] == glm::vec3(0.0f));
    for (const auto weighting : {NormalWeighting::Area, NormalWeighting::Angle}) {
        std::vector<glm::vec3> n(m.numVertices(), glm::vec3(9.0f));
        computeVertexNormals(m, n, {weighting});
        CHECK(n[3] == glm::vec3(0.0f));  // only the degenerate face
        CHECK(n[5] == glm::vec3(0.0f));
        CHECK(n[6] == glm::vec3(0.0f));  // no face
        CHECK(n[2] == glm::vec3(0, 0, 1));
        // Vertex 4 sees face 2 only (face 1 is degenerate): its unit normal.
        CHECK(glm::length(n[4]) == Approx(1.0f));
        CHECK(glm::dot(n[4], faceNormals[2]) == Approx(1.0f));
    }
    std::vector<glm::vec3> tooShort(3);
    CHECK_THROWS_WITH(computeVertexNormals(m, tooShort), Catch::Contains("7, one per vertex"));
}
