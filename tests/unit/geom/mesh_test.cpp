#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "deformkit/error.h"
#include "deformkit/geom/mesh.h"

using deformkit::InvalidInput;
using deformkit::geom::Mesh;

namespace {

Mesh::Data quadAndTriangle() {
    Mesh::Data d;
    d.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}};
    d.faceCounts = {4, 3};
    d.faceIndices = {0, 1, 2, 3, 1, 4, 2};
    return d;
}

}  // namespace

TEST_CASE("mesh offsets and face spans follow the counts", "[geom][mesh]") {
    const Mesh m(quadAndTriangle());
    CHECK(m.numVertices() == 5);
    CHECK(m.numFaces() == 2);
    CHECK(m.numCorners() == 7);
    REQUIRE(m.faceOffsets().size() == 3);
    CHECK(m.faceOffsets()[1] == 4);
    CHECK(m.faceOffsets()[2] == 7);
    CHECK(m.face(1)[0] == 1);
    CHECK(m.face(1)[2] == 2);
    CHECK_FALSE(m.hasUVs());
    CHECK(m.faceUVIndices(0).empty());
    const auto box = m.bounds();
    CHECK(box.min.x == 0.0f);
    CHECK(box.max.x == 2.0f);
    CHECK(box.max.y == 1.0f);
}

TEST_CASE("mesh rejects bad connectivity and values, naming the element", "[geom][mesh][errors]") {
    SECTION("face with fewer than 3 vertices") {
        auto d = quadAndTriangle();
        d.faceCounts = {4, 2, 1};
        CHECK_THROWS_WITH(Mesh(d, "body.obj"), Catch::Contains("body.obj: face 1: has 2 vertices") &&
                                                   Catch::Contains("at least 3"));
    }
    SECTION("index out of range") {
        auto d = quadAndTriangle();
        d.faceIndices[5] = 9;
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("face 1 corner 1") && Catch::Contains("[0, 5)"));
    }
    SECTION("negative index") {
        auto d = quadAndTriangle();
        d.faceIndices[0] = -1;
        CHECK_THROWS_AS(Mesh(d), InvalidInput);
    }
    SECTION("face counts past the indices name their whole sum") {
        auto d = quadAndTriangle();
        d.faceCounts = {2147483647, 2147483647};
        CHECK_THROWS_WITH(Mesh(d),
                          Catch::Contains("count 7 does not match the face vertex counts, which sum to "
                                          "4294967294"));
    }
    SECTION("repeated vertex") {
        auto d = quadAndTriangle();
        d.faceIndices[6] = 1;
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("face 1: uses vertex 1 twice"));
    }
    SECTION("repeated vertex in a long polygon: the first corner that comes back, as pair by pair") {
        // 40 corners around a circle, corner 30 repeating corner 12's vertex and corner 35 corner 3's: the
        // error names vertex 12, the first repeat in corner order (the small faces' rule).
        Mesh::Data d;
        for (int i = 0; i < 40; ++i)
            d.points.emplace_back(std::cos(i * 0.157f), std::sin(i * 0.157f), 0.0f);
        d.faceCounts = {40};
        for (int i = 0; i < 40; ++i)
            d.faceIndices.push_back(i);
        CHECK_NOTHROW(Mesh(d));
        d.faceIndices[30] = 12;
        d.faceIndices[35] = 3;
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("face 0: uses vertex 12 twice"));
    }
    SECTION("NaN and infinite coordinates") {
        auto d = quadAndTriangle();
        d.points[3].y = std::numeric_limits<float>::quiet_NaN();
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("vertex 3") && Catch::Contains("NaN"));
        d = quadAndTriangle();
        d.points[4].z = std::numeric_limits<float>::infinity();
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("vertex 4"));
    }
    SECTION("index count does not match counts") {
        auto d = quadAndTriangle();
        d.faceIndices.pop_back();
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("sum to 7"));
    }
    SECTION("uv indices that do not cover every corner") {
        auto d = quadAndTriangle();
        d.uvs = {{0, 0}};
        d.uvIndices = {0, 0, 0};
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("uv indices"));
        d.uvIndices = {0, 0, 0, 0, 0, 0, 1};
        CHECK_THROWS_WITH(Mesh(d), Catch::Contains("face corner 6"));
    }
}

TEST_CASE("setPoints checks the count and finiteness and keeps connectivity", "[geom][mesh]") {
    Mesh m(quadAndTriangle());
    std::vector<glm::vec3> moved(m.points().begin(), m.points().end());
    for (auto& p : moved)
        p += glm::vec3(0, 0, 1);
    m.setPoints(moved);
    CHECK(m.points()[4].z == 1.0f);
    moved.pop_back();
    CHECK_THROWS_AS(m.setPoints(moved), InvalidInput);
    moved.push_back(glm::vec3(std::nanf("")));
    CHECK_THROWS_AS(m.setPoints(moved), InvalidInput);
    CHECK(m.points()[4].z == 1.0f);
}

TEST_CASE("UDIM tile numbers follow 1001 + floor(u) + 10 floor(v)", "[geom][mesh][udim]") {
    using deformkit::geom::udimTileOf;
    CHECK(udimTileOf({0.5f, 0.5f}) == 1001);
    CHECK(udimTileOf({1.0f, 0.0f}) == 1002);
    CHECK(udimTileOf({9.99f, 0.1f}) == 1010);
    CHECK(udimTileOf({0.2f, 1.5f}) == 1011);
    CHECK(udimTileOf({3.5f, 2.5f}) == 1024);
    // Off the tiles a number no tile has (a preview draws no texture there); huge and non-finite coordinates
    // stay defined (1e30 does not fit an int).
    CHECK(udimTileOf({-0.3f, 0.5f}) == 1000);
    CHECK(udimTileOf({0.5f, 1e30f}) == 1001 + 10000000);
    CHECK(udimTileOf({std::nanf(""), 1.5f}) == 0);
}
