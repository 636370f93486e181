#include <catch2/catch.hpp>

#include <glm/geometric.hpp>
#include <numbers>

#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/primitives.h"

using namespace deformkit::geom;

namespace {

// Signed volume by the divergence theorem over fan-triangulated faces: positive iff outward oriented.
double signedVolume(const Mesh& m) {
    double vol = 0.0;
    const auto p = m.points();
    for (int32_t f = 0; f < m.numFaces(); ++f) {
        const auto c = m.face(f);
        for (size_t k = 1; k + 1 < c.size(); ++k) {
            vol +=
                glm::dot(glm::dvec3(p[c[0]]), glm::cross(glm::dvec3(p[c[k]]), glm::dvec3(p[c[k + 1]]))) / 6.0;
        }
    }
    return vol;
}

// Signed area of the UV polygons (shoelace): positive iff the UV layout is not mirrored.
double uvArea(const Mesh& m, int32_t f) {
    const auto t = m.faceUVIndices(f);
    double a = 0.0;
    for (size_t k = 0; k < t.size(); ++k) {
        const glm::dvec2 p = m.uvs()[t[k]], q = m.uvs()[t[(k + 1) % t.size()]];
        a += 0.5 * (p.x * q.y - q.x * p.y);
    }
    return a;
}

}  // namespace

TEST_CASE("grid: counts, extent and UVs", "[geom][primitives]") {
    const Mesh g = makeGrid({8, 4, 2.0f, 1.0f});
    CHECK(g.numVertices() == 9 * 5);
    CHECK(g.numFaces() == 32);
    CHECK(g.bounds().max.x == Approx(2.0f));
    CHECK(g.udimTiles() == std::vector<int>{1001});
    for (int32_t f = 0; f < g.numFaces(); ++f)
        CHECK(uvArea(g, f) > 0.0);
    // A grid whose face corners would not fit int32 indices is refused at once (it took minutes and all
    // memory before failing).
    CHECK_THROWS_WITH(makeGrid({50000, 50000}),
                      Catch::Contains("cellsX x cellsY: is 50000 x 50000, 10000000000 face corners") &&
                          Catch::Contains("at most 2147483647"));
}

TEST_CASE("sphere volume converges to 4/3 pi r^3 and is outward oriented", "[geom][primitives]") {
    const double r = 1.5;
    const Mesh coarse = makeSphere({static_cast<float>(r), 32, 16});
    const Mesh fine = makeSphere({static_cast<float>(r), 128, 64});
    const double exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    const double errCoarse = exact - signedVolume(coarse), errFine = exact - signedVolume(fine);
    CHECK(errCoarse > 0.0);  // inscribed polyhedron: slightly smaller
    CHECK(errFine > 0.0);
    CHECK(errFine / exact < 2e-3);
    CHECK(errFine < errCoarse / 10.0);  // second-order convergence: ~16x for 4x resolution
    for (int32_t f = 0; f < fine.numFaces(); ++f)
        REQUIRE(uvArea(fine, f) > 0.0);
}

TEST_CASE("capped tube: closed, outward, two UDIM tiles, demo size", "[geom][primitives]") {
    const Mesh tube = makeCappedTube();
    CHECK(tube.numVertices() == 160 * 121 + 2 * (9 * 160 + 1));
    CHECK(tube.halfEdges().report().isClosed());
    CHECK(tube.halfEdges().report().isManifold());
    CHECK(tube.udimTiles() == std::vector<int>{1001, 1002});
    // Volume of a cylinder r = 1, h = 4, approximated by a 160-gon prism: n/2 sin(2pi/n) r^2 h.
    const double prism = 80.0 * std::sin(2.0 * std::numbers::pi / 160.0) * 4.0;
    CHECK(signedVolume(tube) == Approx(prism).epsilon(1e-5));
    for (int32_t f = 0; f < tube.numFaces(); ++f)
        REQUIRE(uvArea(tube, f) > 0.0);
}
