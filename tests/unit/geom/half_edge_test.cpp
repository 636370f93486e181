#include <catch2/catch.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/geom/primitives.h"

using namespace deformkit::geom;

namespace {

Mesh fromFaces(int32_t numVerts, std::vector<std::vector<int32_t>> faces) {
    Mesh::Data d;
    for (int32_t v = 0; v < numVerts; ++v)
        d.points.emplace_back(static_cast<float>(v), static_cast<float>(v * v % 7), 0.0f);
    for (const auto& f : faces) {
        d.faceCounts.push_back(static_cast<int32_t>(f.size()));
        d.faceIndices.insert(d.faceIndices.end(), f.begin(), f.end());
    }
    return Mesh(std::move(d));
}

}  // namespace

TEST_CASE("closed meshes satisfy Euler's formula and every half-edge has a twin", "[geom][half_edge]") {
    // Independent reference: V - E + F = 2 for a sphere-like closed surface.
    for (const Mesh& m : {makeSphere({1.0f, 12, 7}), makeCappedTube({1.0f, 2.0f, 16, 5, 3})}) {
        const HalfEdgeMesh& he = m.halfEdges();
        CHECK(m.numVertices() - he.numEdges() + m.numFaces() == 2);
        CHECK(he.report().isManifold());
        CHECK(he.report().isClosed());
        CHECK(he.report().components == 1);
        for (int32_t h = 0; h < he.numHalfEdges(); ++h) {
            REQUIRE(he.twin(h) >= 0);
            CHECK(he.twin(he.twin(h)) == h);
            CHECK(he.tail(he.twin(h)) == he.head(h));
            CHECK(he.next(he.prev(h)) == h);
            CHECK(he.face(he.next(h)) == he.face(h));
        }
        CHECK(&m.halfEdges() == &he);  // cached
    }
}

TEST_CASE("grid boundary: edges and vertices on the border", "[geom][half_edge]") {
    const Mesh grid = makeGrid({4, 3});
    const HalfEdgeMesh& he = grid.halfEdges();
    // Closed forms for an nx x ny quad grid.
    CHECK(he.numEdges() == 4 * 4 + 5 * 3);
    CHECK(he.report().boundaryEdges == 2 * (4 + 3));
    int32_t boundaryVerts = 0;
    for (int32_t v = 0; v < grid.numVertices(); ++v)
        boundaryVerts += he.isBoundaryVertex(v) ? 1 : 0;
    CHECK(boundaryVerts == 2 * (4 + 3));
    CHECK(he.report().isManifold());
    // Interior vertex (1,1) = index 6 has four neighbours: 1, 5, 7, 11.
    const auto ring = he.vertexNeighbors(6);
    REQUIRE(ring.size() == 4);
    CHECK(ring[0] == 1);
    CHECK(ring[1] == 5);
    CHECK(ring[2] == 7);
    CHECK(ring[3] == 11);
    CHECK(he.vertexHalfEdges(6).size() == 4);
}

TEST_CASE("non-manifold edges, flipped faces and bow-tie vertices are reported",
          "[geom][half_edge][errors]") {
    SECTION("three faces on one edge") {
        const Mesh m = fromFaces(5, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
        const auto& r = m.halfEdges().report();
        REQUIRE(r.nonManifoldEdges.size() == 1);
        CHECK(m.halfEdges().edgeVertices(r.nonManifoldEdges[0]) == std::array<int32_t, 2>{0, 1});
        CHECK_FALSE(r.isManifold());
        CHECK_THROWS_WITH(requireManifold(m, "fin.obj"),
                          Catch::Contains("fin.obj: edge (0, 1): is shared by 3 faces"));
    }
    SECTION("two faces with opposite orientation") {
        const Mesh m = fromFaces(4, {{0, 1, 2}, {0, 1, 3}});
        const auto& r = m.halfEdges().report();
        CHECK(r.inconsistentEdges.size() == 1);
        CHECK_THROWS_AS(requireManifold(m, "flip"), deformkit::TopologyError);
    }
    SECTION("two fans touching at one vertex") {
        const Mesh m = fromFaces(5, {{0, 1, 2}, {0, 3, 4}});
        const auto& r = m.halfEdges().report();
        REQUIRE(r.nonManifoldVertices.size() == 1);
        CHECK(r.nonManifoldVertices[0] == 0);
        CHECK(r.nonManifoldEdges.empty());
        CHECK(r.components == 1);
        CHECK_THROWS_WITH(requireManifold(m, "bowtie"), Catch::Contains("vertex 0"));
    }
    SECTION("isolated vertices and separate components") {
        const Mesh m = fromFaces(7, {{0, 1, 2}, {3, 4, 5}});
        const auto& r = m.halfEdges().report();
        CHECK(r.isolatedVertices == std::vector<int32_t>{6});
        CHECK(r.components == 2);
        CHECK(r.isManifold());
        CHECK_NOTHROW(requireManifold(m, "ok"));
    }
}
