#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/primitives.h"
#include "demo_assets.h"

using namespace deformkit;

namespace {

double meanOf(const io::Image& img) {
    double sum = 0.0;
    for (float v : img.pixels)
        sum += v;
    return sum / static_cast<double>(img.pixels.size());
}

}  // namespace

TEST_CASE("demo assets: a 22k-vertex tube over two UDIM tiles with a map of each kind per tile",
          "[harness][demo]") {
    const harness::DemoAssets a = harness::makeDemoAssets({128, 2});
    CHECK(a.mesh.numVertices() == 22242);
    CHECK(a.mesh.udimTiles() == std::vector<int>{1001, 1002});
    for (int tile : {1001, 1002}) {
        REQUIRE(a.rigidity.count(tile) == 1);
        REQUIRE(a.mask.count(tile) == 1);
        REQUIRE(a.albedo.count(tile) == 1);
        CHECK(a.rigidity.at(tile).channels == 1);
        CHECK(a.mask.at(tile).channels == 1);
        CHECK(a.albedo.at(tile).channels == 3);
        for (float v : a.rigidity.at(tile).pixels)
            REQUIRE((v >= 0.0f && v <= 1.0f));
    }
    CHECK_THROWS_AS(harness::makeDemoAssets({8, 2}), InvalidInput);
}

TEST_CASE("demo rigidity: rigid band and features on an elastic background", "[harness][demo]") {
    const int32_t n = 512;
    const io::Image side = harness::demoRigidity(1001, n);
    // Image row y samples v = 1 - (y + 0.5) / n. The band spans v in [0.45, 0.52]: rigid along a whole row.
    const int32_t bandRow = static_cast<int32_t>((1.0f - 0.485f) * n);
    for (int32_t x = 0; x < n; ++x)
        REQUIRE(side.at(x, bandRow, 0) == 1.0f);
    // Below the disks (v < 0.05) and away from the band, the skin is fully elastic.
    const int32_t skinRow = n - 5;
    for (int32_t x = 0; x < n; ++x)
        REQUIRE(side.at(x, skinRow, 0) == 0.0f);
    // Rigid fraction: at least the band (0.07 of the tile), clearly less than half.
    const double rigid = meanOf(side);
    CHECK(rigid > 0.07);
    CHECK(rigid < 0.5);

    const io::Image caps = harness::demoRigidity(1002, n);
    // Each cap: a ring of width 0.036 at radius 0.165 and a boss of radius 0.05. Closed-form area.
    const double ring = 2.0 * std::numbers::pi * 0.165 * 0.036, boss = std::numbers::pi * 0.05 * 0.05;
    CHECK(meanOf(caps) == Approx(2.0 * (ring + boss)).epsilon(0.02));
    CHECK_THROWS_AS(harness::demoRigidity(1003, n), InvalidInput);
}

TEST_CASE("chart warp mask: charts minus a border, zero outside", "[harness][demo]") {
    const geom::Mesh tube = geom::makeCappedTube();
    const int32_t n = 256, border = 2;
    // The side chart covers all of tile 1001: only the outer border ring is masked out.
    const io::Image side = harness::chartWarpMask(tube, 1001, n, border);
    double ones = 0.0;
    for (float v : side.pixels)
        ones += v;
    CHECK(ones == static_cast<double>((n - 2 * border) * (n - 2 * border)));
    CHECK(side.at(border - 1, n / 2, 0) == 0.0f);
    CHECK(side.at(border, n / 2, 0) == 1.0f);

    // The caps are two disks of radius R = 0.24 tiles. Eroding by a square of half-width b leaves a
    // shape between the disks of radius R - b sqrt(2) and R - b; allow one texel for discretisation.
    const io::Image caps = harness::chartWarpMask(tube, 1002, n, border);
    const double R = 0.24 * n;
    auto twoDisks = [](double radius) { return 2.0 * std::numbers::pi * radius * radius; };
    double capOnes = 0.0;
    for (float v : caps.pixels)
        capOnes += v;
    CHECK(capOnes > twoDisks(R - border * std::sqrt(2.0) - 1.0));
    CHECK(capOnes < twoDisks(R - border + 1.0));
    CHECK(caps.at(n / 4, n / 2, 0) == 1.0f);  // a cap centre
    CHECK(caps.at(n / 2, 2, 0) == 0.0f);      // between the disks
}
