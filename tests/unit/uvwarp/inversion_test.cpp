#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/uvwarp/inversion.h"
#include "uvwarp/raster_points.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using namespace deformkit::uvwarp;

namespace {

// A smooth bijection of the unit square onto itself that fixes its border:
//   W(u, v) = (u + a sin(pi u) sin(pi v), v + a sin(pi u) sin(2 pi v)).
// With a = 0.05 the Jacobian's diagonal stays >= 1 - 2 pi a > 0.68 and its off-diagonal product <= (2 pi a)^2
// / 2, so det J > 0.4 everywhere.
constexpr double kA = 0.05;
glm::dvec2 smoothWarp(double u, double v) {
    return {u + kA * std::sin(M_PI * u) * std::sin(M_PI * v),
            v + kA * std::sin(M_PI * u) * std::sin(2.0 * M_PI * v)};
}

// W^-1(target) by Newton's method from the target itself.
glm::dvec2 smoothInverse(const glm::dvec2& target) {
    glm::dvec2 p = target;
    for (int iteration = 0; iteration < 50; ++iteration) {
        const glm::dvec2 r = smoothWarp(p.x, p.y) - target;
        const double su = std::sin(M_PI * p.x), cu = std::cos(M_PI * p.x);
        const double a = 1.0 + kA * M_PI * cu * std::sin(M_PI * p.y),
                     b = kA * M_PI * su * std::cos(M_PI * p.y);
        const double c = kA * M_PI * cu * std::sin(2.0 * M_PI * p.y);
        const double d = 1.0 + 2.0 * kA * M_PI * su * std::cos(2.0 * M_PI * p.y);
        const double det = a * d - b * c;
        p -= glm::dvec2((d * r.x - b * r.y) / det, (a * r.y - c * r.x) / det);
        if (std::abs(r.x) + std::abs(r.y) < 1e-15) break;
    }
    return p;
}

glm::dvec2 texelCentre(int32_t x, int32_t y, int32_t texels) {
    return {(x + 0.5) / texels, 1.0 - (y + 0.5) / texels};
}

}  // namespace

TEST_CASE("the identity warp inverts to the identity redirect", "[uvwarp][inversion]") {
    for (const auto& [cells, texels] :
         {std::pair{64, 64}, std::pair{32, 64}, std::pair{64, 32}, std::pair{1, 8}}) {
        io::Image redirect;
        invertWarp(WarpGrid::identity(cells), texels, redirect);
        REQUIRE(redirect.width == texels);
        REQUIRE(redirect.height == texels);
        REQUIRE(redirect.channels == 2);
        double worst = 0.0;
        for (int32_t y = 0; y < texels; ++y) {
            for (int32_t x = 0; x < texels; ++x) {
                const glm::dvec2 c = texelCentre(x, y, texels);
                worst = std::max(
                    {worst, std::abs(redirect.at(x, y, 0) - c.x), std::abs(redirect.at(x, y, 1) - c.y)});
            }
        }
        INFO(cells << " cells, " << texels << " texels");
        // float32 barycentrics and uv: a few ulps of values <= 1.
        CHECK(worst < 1e-6);
    }
}

TEST_CASE("evaluating the warp is piecewise linear over the (i, j)-(i+1, j+1) split", "[uvwarp][inversion]") {
    // One cell whose corner (1, 1) moves by d: the weight of that corner is min(u, v) in both triangles of
    // this split (the other split would give max(0, u + v - 1)).
    WarpGrid one = WarpGrid::identity(1);
    const glm::dvec2 d(0.1, -0.2);
    one.u[3] += static_cast<float>(d.x);
    one.v[3] += static_cast<float>(d.y);
    for (const auto& uv : {glm::dvec2(0.6, 0.2), glm::dvec2(0.2, 0.6), glm::dvec2(0.9, 0.9),
                           glm::dvec2(0.0, 1.0), glm::dvec2(0.75, 0.25)}) {
        const glm::dvec2 expected = uv + std::min(uv.x, uv.y) * d;
        const glm::vec2 got = evaluateWarp(one, static_cast<float>(uv.x), static_cast<float>(uv.y));
        CHECK(got.x == Approx(expected.x).margin(1e-6));
        CHECK(got.y == Approx(expected.y).margin(1e-6));
    }
    // An affine warp is reproduced everywhere; arguments clamp to the unit square.
    const WarpGrid shear =
        test::warpFrom(8, [](double u, double v) { return glm::dvec2(0.8 * u + 0.1 * v + 0.05, 0.9 * v); });
    for (const auto& uv : {glm::dvec2(0.13, 0.77), glm::dvec2(0.5, 0.5), glm::dvec2(0.999, 0.01)}) {
        const glm::vec2 got = evaluateWarp(shear, static_cast<float>(uv.x), static_cast<float>(uv.y));
        CHECK(got.x == Approx(0.8 * uv.x + 0.1 * uv.y + 0.05).margin(1e-6));
        CHECK(got.y == Approx(0.9 * uv.y).margin(1e-6));
    }
    const glm::vec2 clamped = evaluateWarp(shear, 1.5f, -1.0f);
    CHECK(clamped.x == Approx(0.85).margin(1e-6));
    CHECK(clamped.y == Approx(0.0).margin(1e-6));
}

TEST_CASE("a smooth warp inverts to its closed-form inverse", "[uvwarp][inversion]") {
    const int32_t cells = 64, texels = 64;
    const WarpGrid warp = test::warpFrom(cells, smoothWarp);
    const io::Image redirect = invertWarp(warp, texels);
    double worst = 0.0, sum = 0.0;
    for (int32_t y = 0; y < texels; ++y) {
        for (int32_t x = 0; x < texels; ++x) {
            const glm::dvec2 expected = smoothInverse(texelCentre(x, y, texels));
            const double error =
                std::hypot(redirect.at(x, y, 0) - expected.x, redirect.at(x, y, 1) - expected.y) * texels;
            worst = std::max(worst, error);
            sum += error;
        }
    }
    INFO("max " << worst << " texels, mean " << sum / (texels * texels));
    // The grid interpolates W linearly: |W - W_h| <= h^2 max|D^2 W| / 2 = (1/64)^2 * 4 pi^2 a / 2 = 2.4e-4 uv
    // (0.015 texel); the inverse amplifies it by at most 1 / (smallest singular value of J) < 1.6, so 0.03
    // texel bounds the difference between W_h^-1 and W^-1.
    CHECK(worst < 0.03);

    const InversionError error = inversionError(warp, redirect);
    INFO("round trip max " << error.maxTexels << " mean " << error.meanTexels);
    CHECK(error.texels == texels * texels);
    // W_h(W_h^-1(uv)) = uv up to float32 rounding of uv and barycentrics (~1e-7 uv, ~1e-5 texel).
    CHECK(error.maxTexels < 1e-3);
    CHECK(error.meanTexels <= error.maxTexels);
}

TEST_CASE("inversion error of a wrong redirect, over a region", "[uvwarp][inversion]") {
    const int32_t texels = 32;
    const WarpGrid identity = WarpGrid::identity(16);
    io::Image redirect = invertWarp(identity, texels);
    // Shift the left half by 0.25 texel in u: the error is 0.25 texel there, 0 elsewhere.
    io::Image region(texels, texels, 1, 0.0f);
    for (int32_t y = 0; y < texels; ++y) {
        for (int32_t x = 0; x < texels / 2; ++x) {
            redirect.at(x, y, 0) += 0.25f / texels;
            region.at(x + texels / 2, y, 0) = 1.0f;
        }
    }
    const InversionError all = inversionError(identity, redirect);
    // float32 uv of size <= 1 in units of 1/32: ~1e-5 texel.
    CHECK(all.maxTexels == Approx(0.25).margin(1e-4));
    CHECK(all.meanTexels == Approx(0.125).margin(1e-4));
    const InversionError right = inversionError(identity, redirect, region);
    CHECK(right.texels == texels * texels / 2);
    CHECK(right.maxTexels < 1e-4);

    redirect.at(5, 7, 1) = std::numeric_limits<float>::infinity();
    CHECK_THROWS_WITH(inversionError(identity, redirect), Catch::Contains("redirect texel (5, 7)"));
    CHECK_THROWS_AS(inversionError(identity, io::Image(texels, texels / 2, 2)), InvalidInput);
    CHECK_THROWS_AS(inversionError(identity, invertWarp(identity, texels), io::Image(8, 8, 1)), InvalidInput);
}

TEST_CASE("raster points in vector-friendly float arithmetic equal the double rounding",
          "[uvwarp][inversion]") {
    using detail::snap;
    using detail::snapFloat;
    // The float rounding against the double one: every 499th float up to the clamp (both signs), every float
    // within 3 ulps of the halves k / 256 + 1 / 512 for |k| <= 2^16 and of the clamp itself. (All 2.5e9
    // floats of the range agree; too slow for a unit test.)
    const auto limitBits = std::bit_cast<uint32_t>(detail::kRasterLimit);
    int64_t checked = 0, mismatches = 0;
    const auto check = [&](float x) {
        for (const float s : {x, -x}) {
            ++checked;
            if (snap(s) != static_cast<int64_t>(snapFloat(s))) {
                if (++mismatches <= 5) INFO("x = " << s << ": " << snap(s) << " vs " << snapFloat(s));
                CHECK(snap(s) == static_cast<int64_t>(snapFloat(s)));
            }
        }
    };
    for (uint32_t bits = 0; bits <= limitBits; bits += 499)
        check(std::bit_cast<float>(bits));
    const auto around = [&](float centre) {
        float x = centre;
        for (int step = 0; step < 3; ++step)
            x = std::nextafter(x, 0.0f);
        for (int step = 0; step < 7; ++step, x = std::nextafter(x, detail::kRasterLimit))
            if (std::abs(x) <= detail::kRasterLimit) check(x);
    };
    for (int32_t k = -65536; k <= 65536; ++k)
        around((static_cast<float>(k) + 0.5f) / 256.0f);
    around(detail::kRasterLimit);
    CHECK(mismatches == 0);
    CHECK(checked > 5000000);

    // A row of points, far-off and negative ones included, against the clamp and the double rounding.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> near(-0.2f, 1.2f), far(-3000.0f, 3000.0f);
    detail::RasterRow<65> row;
    for (int round = 0; round < 50; ++round) {
        std::array<float, 65> u{}, v{};
        for (size_t m = 0; m < u.size(); ++m) {
            u[m] = m % 7 == 3 ? far(rng) : near(rng);
            v[m] = m % 11 == 5 ? far(rng) : near(rng);
        }
        const float t = round % 2 == 0 ? 1024.0f : 4096.0f;
        row.compute(u.data(), v.data(), 65, t);
        for (int32_t m = 0; m < 65; ++m) {
            const float limit = detail::kRasterLimit;
            const float x = std::clamp(u[m] * t, -limit, limit),
                        y = std::clamp((1.0f - v[m]) * t, -limit, limit);
            const detail::RasterPoint got = row.point(m);
            REQUIRE(got.x == x);
            REQUIRE(got.y == y);
            REQUIRE(got.sx == snap(x));
            REQUIRE(got.sy == snap(y));
        }
    }
}

TEST_CASE("inversion draws what geom::rasterizeAttributes draws", "[uvwarp][inversion]") {
    // Reference: the library's general rasteriser over the warped triangles in (j, i, lower, upper) order,
    // carrying the rest uv; where triangles overlap the later one wins in both.
    auto compare = [](const WarpGrid& warp, int32_t texels, int& covered) {
        const int32_t cells = warp.cells, side = cells + 1;
        std::vector<glm::vec2> positions;
        std::vector<float> attributes;
        for (int32_t j = 0; j <= cells; ++j) {
            for (int32_t i = 0; i <= cells; ++i) {
                const size_t k = static_cast<size_t>(j) * side + i;
                positions.emplace_back(warp.u[k] * texels, (1.0f - warp.v[k]) * texels);
                attributes.push_back(static_cast<float>(i) / cells);
                attributes.push_back(static_cast<float>(j) / cells);
            }
        }
        std::vector<std::array<int32_t, 3>> triangles;
        for (int32_t j = 0; j < cells; ++j) {
            for (int32_t i = 0; i < cells; ++i) {
                const int32_t k = j * side + i;
                triangles.push_back({k, k + 1, k + side + 1});
                triangles.push_back({k, k + side + 1, k + side});
            }
        }
        geom::AttributeRaster reference;
        geom::rasterizeAttributes({texels, texels}, positions, triangles, attributes, 2, reference);
        const io::Image redirect = invertWarp(warp, texels);
        covered = 0;
        double worst = 0.0;
        for (int32_t y = 0; y < texels; ++y) {
            for (int32_t x = 0; x < texels; ++x) {
                const size_t p = static_cast<size_t>(y) * texels + x;
                glm::dvec2 expected = texelCentre(x, y, texels);
                if (reference.triangle[p] >= 0) {
                    ++covered;
                    expected = {reference.values[2 * p], reference.values[2 * p + 1]};
                }
                worst = std::max({worst, std::abs(redirect.at(x, y, 0) - expected.x),
                                  std::abs(redirect.at(x, y, 1) - expected.y)});
            }
        }
        return worst;
    };
    int covered = 0;

    SECTION("a jittered warp with folds and points off the tile") {
        const int32_t cells = 128, texels = 160;  // several chunks of cells per row
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> jitter(-0.45, 0.45);
        WarpGrid warp = test::warpFrom(cells, smoothWarp);
        for (size_t k = 0; k < warp.u.size(); ++k) {
            warp.u[k] += static_cast<float>(jitter(rng) / cells);
            warp.v[k] += static_cast<float>(jitter(rng) / cells);
        }
        const int32_t side = cells + 1;
        warp.u[10 * side + 12] += 2.5f / cells;
        warp.v[20 * side + 3] -= 1.7f / cells;
        warp.u[100 * side + 90] += 1.5f / cells;
        // Same coverage and winner; values agree to float32 rounding of barycentric blends of uv <= 1.
        CHECK(compare(warp, texels, covered) < 1e-6);
        CHECK(covered > texels * texels * 9 / 10);
    }
    SECTION("cells left at the identity beside moved and folded ones") {
        // Most of a real tile is fixed by its warp mask: those cells are drawn as rectangles of texels when
        // a cell is a power-of-two number of texels wide, as the centre on one corner when a texel is a
        // power-of-two number of cells wide (a refined grid's 1/2 texel: 32 texels; 1/4, 1/8), and rasterised
        // otherwise (3 texels per cell). Moved points, some pushed across their neighbours so that moved
        // cells fold over still ones drawn before and after them, must give the reference's coverage and
        // winners.
        for (const int32_t texels : {8, 16, 32, 64, 128, 192, 256}) {
            const int32_t cells = 64, side = cells + 1;
            std::mt19937 rng(11);
            std::uniform_real_distribution<double> jitter(-0.45, 0.45);
            WarpGrid warp = WarpGrid::identity(cells);
            for (int32_t j = 1; j < cells; ++j) {
                for (int32_t i = 1; i < cells; ++i) {
                    if ((i / 8 + j / 8) % 2 == 0) continue;  // a checkerboard of still and moved blocks
                    const size_t k = static_cast<size_t>(j) * side + i;
                    warp.u[k] += static_cast<float>(jitter(rng) / cells);
                    warp.v[k] += static_cast<float>(jitter(rng) / cells);
                }
            }
            // Moved points pushed over still cells drawn after theirs (to the right, above) and before
            // (to the left).
            warp.u[12 * side + 23] += 2.5f / cells;
            warp.v[23 * side + 9] += 2.5f / cells;
            warp.u[12 * side + 17] -= 2.5f / cells;
            CHECK(compare(warp, texels, covered) < 1e-6);
            CHECK(covered > texels * texels * 9 / 10);
            if (texels == 192) continue;
            // Texels whose centres lie in the still cells (33..38, 33..38), away from the folds: the
            // identity's values, exactly.
            const io::Image redirect = invertWarp(warp, texels);
            int still = 0;
            for (int32_t y = 0; y < texels; ++y) {
                for (int32_t x = 0; x < texels; ++x) {
                    const double gi = (x + 0.5) * cells / texels, gj = cells - (y + 0.5) * cells / texels;
                    if (gi < 33 || gi >= 39 || gj < 33 || gj >= 39) continue;
                    ++still;
                    CHECK(redirect.at(x, y, 0) ==
                          (static_cast<float>(x) + 0.5f) / static_cast<float>(texels));
                    CHECK(redirect.at(x, y, 1) ==
                          1.0f - (static_cast<float>(y) + 0.5f) / static_cast<float>(texels));
                }
            }
            // Centres in [33, 39) per axis: 6 per cell at 1 cell a texel and more; 33, 35, 37 at 2 cells a
            // texel (centres on odd points); 34, 38 at 4 (2 mod 4); 36 at 8 (4 mod 8).
            const int32_t perAxis = texels >= cells ? 6 * (texels / cells)
                                    : texels == 32  ? 3
                                    : texels == 16  ? 2
                                                    : 1;
            CHECK(still == perAxis * perAxis);
        }
    }
    SECTION("a grid finer than the map, moved cells folding over still ones on every side") {
        // Where a fold covers a texel centre on a still point, which cell draws it last decides its value:
        // a still cell must draw exactly the centre the rasteriser gives it, in its turn.
        const int32_t cells = 64, side = cells + 1;
        for (const int32_t texels : {32, 16}) {
            for (uint32_t seed = 1; seed <= 12; ++seed) {
                std::mt19937 rng(seed);
                std::uniform_real_distribution<double> jitter(-1.5, 1.5);
                std::bernoulli_distribution moved(0.15);
                WarpGrid warp = WarpGrid::identity(cells);
                for (int32_t j = 1; j < cells; ++j) {
                    for (int32_t i = 1; i < cells; ++i) {
                        if (!moved(rng)) continue;
                        const size_t k = static_cast<size_t>(j) * side + i;
                        warp.u[k] += static_cast<float>(jitter(rng) / cells);
                        warp.v[k] += static_cast<float>(jitter(rng) / cells);
                    }
                }
                CAPTURE(texels, seed);
                CHECK(compare(warp, texels, covered) < 1e-6);
                CHECK(covered == texels * texels);
            }
        }
    }
    SECTION("a row of points that snapping moves onto texel centres at a band border") {
        // Point row 112 of 128 moved up by 0.499 texel: raster y 15.501 snaps to 15.5, the centre of texel
        // row 15, which only the cells below that row (raster y > 15.5) own by the top-left rule.
        const int32_t cells = 128, texels = 128, side = cells + 1;
        WarpGrid warp = WarpGrid::identity(cells);
        for (int32_t i = 0; i <= cells; ++i)
            warp.v[112 * side + i] += 0.499f / texels;
        CHECK(compare(warp, texels, covered) < 1e-6);
        CHECK(covered == texels * texels);
    }
}

TEST_CASE("inversion is bit-identical for 1 and 2 threads, folds included", "[uvwarp][inversion]") {
    WarpGrid folded = test::warpFrom(64, smoothWarp);
    // Fold a patch: push a point across two of its neighbours, so triangles overlap.
    const size_t k = 20 * 65 + 30;
    folded.u[k] += 3.0f / 64.0f;
    folded.v[k] -= 2.0f / 64.0f;
    const auto run = [&] { return invertWarp(folded, 128).pixels; };
    const std::vector<float> one = test::withThreads(1, run);
    const std::vector<float> two = test::withThreads(2, run);
    CHECK(one == two);
    // Still cells (drawn as rectangles) beside the fold.
    WarpGrid still = WarpGrid::identity(64);
    for (size_t p = 18 * 65 + 25; p < 18 * 65 + 35; ++p) {
        still.u[p] = folded.u[p];
        still.v[p] = folded.v[p];
    }
    still.u[k] = folded.u[k];
    still.v[k] = folded.v[k];
    const auto runStill = [&] { return invertWarp(still, 128).pixels; };
    CHECK(test::withThreads(1, runStill) == test::withThreads(2, runStill));
}

TEST_CASE("inversion bad input", "[uvwarp][inversion]") {
    WarpGrid warp = WarpGrid::identity(8);
    CHECK_THROWS_WITH(invertWarp(warp, 0), Catch::Contains("texels"));
    warp.v[3 * 9 + 4] = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(invertWarp(warp, 16), Catch::Contains("point (4, 3)") && Catch::Contains("not finite"));
    // Any point, u or v, the last one included; the caller's image is left as it was.
    for (const size_t k : {size_t{0}, size_t{40}, size_t{80}}) {
        for (const bool inU : {true, false}) {
            WarpGrid bad = WarpGrid::identity(8);
            (inU ? bad.u : bad.v)[k] = inU ? std::numeric_limits<float>::infinity() : std::nanf("");
            io::Image kept(4, 4, 2, 0.5f);
            CHECK_THROWS_WITH(invertWarp(bad, 16, kept), Catch::Contains("point (" + std::to_string(k % 9) +
                                                                         ", " + std::to_string(k / 9) + ")"));
            CHECK(kept.width == 4);
            CHECK(kept.pixels == std::vector<float>(32, 0.5f));
        }
    }
    WarpGrid odd = WarpGrid::identity(6);
    CHECK_THROWS_WITH(invertWarp(odd, 16), Catch::Contains("power of two"));
    WarpGrid shortGrid = WarpGrid::identity(8);
    shortGrid.u.pop_back();
    CHECK_THROWS_WITH(validateWarpGrid(shortGrid, "tile 1001"),
                      Catch::Contains("tile 1001") && Catch::Contains("81"));
}
