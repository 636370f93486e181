#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "deformkit/geom/primitives.h"
#include "demo_warps.h"

using namespace deformkit;

TEST_CASE("demo warps: every warp visibly deforms the tube and keeps it finite", "[harness][demo]") {
    const geom::Mesh tube = geom::makeCappedTube({1.0f, 4.0f, 32, 24, 3});
    const auto warps = harness::makeDemoWarps(tube);
    REQUIRE(warps.size() == 8);
    for (const auto& w : warps) {
        INFO(w.name);
        float maxMove = 0.0f;
        for (int32_t v = 0; v < tube.numVertices(); ++v) {
            const glm::vec3 p = w.mesh.points()[v];
            REQUIRE(std::isfinite(p.x + p.y + p.z));
            maxMove = std::max(maxMove, glm::length(p - tube.points()[v]));
        }
        CHECK(maxMove > 0.2f);
        CHECK(maxMove < 5.0f);
    }
}

TEST_CASE("demo twist: the top ring turns a quarter turn about +y, the bottom stays", "[harness][demo]") {
    const geom::Mesh tube = geom::makeCappedTube({1.0f, 4.0f, 32, 24, 3});
    const auto warps = harness::makeDemoWarps(tube);
    const geom::Mesh& twist = warps[3].mesh;
    REQUIRE(warps[3].name == "twist");
    for (int32_t v = 0; v < tube.numVertices(); ++v) {
        const glm::vec3 p = tube.points()[v];
        // theta(y) = (pi/2) y / 4, right-handed about +y: (x, z) -> (x cos + z sin, -x sin + z cos).
        const float t = std::numbers::pi_v<float> / 2 * p.y / 4.0f;
        const glm::vec3 expected(p.x * std::cos(t) + p.z * std::sin(t), p.y,
                                 -p.x * std::sin(t) + p.z * std::cos(t));
        REQUIRE(glm::length(twist.points()[v] - expected) < 1e-4f);
    }
}
