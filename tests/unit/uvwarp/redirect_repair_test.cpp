#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/uvwarp/redirect_metrics.h"
#include "deformkit/uvwarp/redirect_repair.h"
#include "uvwarp/redirect_cells.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using namespace deformkit::uvwarp;

namespace {

glm::dvec2 centreOf(int32_t x, int32_t y, int32_t t) {
    return {(x + 0.5) / t, 1.0 - (y + 0.5) / t};
}

// A redirect map that is the identity outside the square [lo, hi]^2 and inside it, with (s, w) the square's
// own coordinates in [0, 1], r = q + a (hi - lo) (sin(pi s) sin(pi w), sin(pi s) sin(2 pi w)): fold-free for
// a <= 0.05 (its Jacobian's determinant stays above 0.4), and the square's texels show content inside it.
io::Image smoothMap(int32_t t, double a, double lo = 0.0, double hi = 1.0) {
    io::Image map(t, t, 2);
    for (int32_t y = 0; y < t; ++y) {
        for (int32_t x = 0; x < t; ++x) {
            const glm::dvec2 q = centreOf(x, y, t);
            const glm::dvec2 p = (q - lo) / (hi - lo);
            glm::dvec2 r = q;
            if (p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0) {
                r += a * (hi - lo) *
                     glm::dvec2(std::sin(M_PI * p.x) * std::sin(M_PI * p.y),
                                std::sin(M_PI * p.x) * std::sin(2.0 * M_PI * p.y));
            }
            map.at(x, y, 0) = static_cast<float>(r.x);
            map.at(x, y, 1) = static_cast<float>(r.y);
        }
    }
    return map;
}

// The inverted triangles of a map, written apart from the library's count: per cell of the texel-centre
// grid, the four triangles of its two splittings, each oriented as the identity's (corners counter-
// clockwise in uv, v up), inverted when the cross product of two of its edges is negative.
int64_t invertedReference(const io::Image& map) {
    const auto at = [&](int32_t x, int32_t y) { return glm::dvec2(map.at(x, y, 0), map.at(x, y, 1)); };
    const auto cross = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
        const glm::dvec2 e = b - a, f = c - a;
        return e.x * f.y - e.y * f.x;
    };
    int64_t inverted = 0;
    for (int32_t y = 0; y + 1 < map.height; ++y) {
        for (int32_t x = 0; x + 1 < map.width; ++x) {
            // In uv the row below (y + 1) is lower: bottom-left (x, y + 1), bottom-right (x + 1, y + 1),
            // top-right (x + 1, y), top-left (x, y); counter-clockwise triangles have positive cross
            // products.
            const glm::dvec2 bl = at(x, y + 1), br = at(x + 1, y + 1), tr = at(x + 1, y), tl = at(x, y);
            for (double c : {cross(bl, br, tr), cross(bl, tr, tl), cross(bl, br, tl), cross(br, tr, tl)})
                inverted += c < 0.0 ? 1 : 0;
        }
    }
    return inverted;
}

const ContentCheck kAnything = [](int32_t, int32_t, glm::dvec2) { return true; };

}  // namespace

TEST_CASE("the reference count and the library's agree on folded maps", "[uvwarp][repair]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> offset(-2.0, 2.0);
    for (int c = 0; c < 20; ++c) {
        io::Image map = smoothMap(32, 0.04);
        for (int k = 0; k < 6; ++k) {
            const int32_t x = 1 + static_cast<int32_t>(rng() % 30), y = 1 + static_cast<int32_t>(rng() % 30);
            map.at(x, y, 0) += static_cast<float>(offset(rng) / 32.0);
            map.at(x, y, 1) += static_cast<float>(offset(rng) / 32.0);
        }
        CHECK(countInvertedTriangles(map) == invertedReference(map));
    }
    CHECK(invertedReference(smoothMap(32, 0.05)) == 0);
}

TEST_CASE("the float filter of the fold scan misses no inverted cell", "[uvwarp][repair]") {
    // One-cell maps (2 x 2 texels) with corners near a line, so that areas sit at the edge of float rounding:
    // every cell with an inverted triangle (in double, as counted) must be a candidate.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), sign(-1.0f, 1.0f);
    int64_t inverted = 0, candidatesOnly = 0;
    for (int trial = 0; trial < 200000; ++trial) {
        io::Image cell(2, 2, 2);
        const glm::vec2 origin(unit(rng), unit(rng)), along(sign(rng), sign(rng));
        const float scale = std::ldexp(1.0f, -static_cast<int>(rng() % 40));  // 1 down to 1e-12
        for (int c = 0; c < 4; ++c) {
            const glm::vec2 p = origin + scale * (unit(rng) * along +
                                                  std::ldexp(sign(rng), -20) * glm::vec2(-along.y, along.x));
            cell.at(c & 1, c >> 1, 0) = p.x;
            cell.at(c & 1, c >> 1, 1) = p.y;
        }
        const bool isInverted = uvwarp::detail::invertedInCell(cell, 0, 0) > 0;
        const bool isCandidate = uvwarp::detail::foldCandidatesInRow(cell, 0) > 0;
        inverted += isInverted ? 1 : 0;
        candidatesOnly += isCandidate && !isInverted ? 1 : 0;
        if (isInverted) REQUIRE(isCandidate);
    }
    CHECK(inverted > 10000);  // the cases do probe the margin
    INFO("candidates that hold no inverted triangle: " << candidatesOnly);
    CHECK(candidatesOnly < inverted);  // and the filter still filters
}

TEST_CASE("a fold-free map is left as it is", "[uvwarp][repair]") {
    for (double a : {0.0, 0.03, 0.05}) {
        io::Image map = smoothMap(64, a);
        const std::vector<float> before = map.pixels;
        const FoldRepair r = repairFolds(map, kAnything);
        CHECK(map.pixels == before);
        CHECK(r.invertedFound == 0);
        CHECK(r.texelsMoved == 0);
        CHECK(r.passes == 0);
        CHECK(r.regionsScaled == 0);
        CHECK(r.smallestScale == 1.0);
    }
}

TEST_CASE("the repair ends every fold of random maps, near the folds, keeping content on its chart",
          "[uvwarp][repair]") {
    // A square "chart" [0.1, 0.9]^2, which the smooth map keeps its content in: its texels may only show
    // content inside it.
    const auto inChart = [](glm::dvec2 p) { return p.x > 0.1 && p.x < 0.9 && p.y > 0.1 && p.y < 0.9; };
    std::mt19937 rng(20261204);
    int64_t foldsMade = 0;
    double worstReturn = 0.0;
    for (int c = 0; c < 200; ++c) {
        const int32_t t = 16 << (c % 3);
        const ContentCheck mayShow = [&](int32_t x, int32_t y, glm::dvec2 r) {
            return !inChart(centreOf(x, y, t)) || inChart(r);
        };
        std::uniform_real_distribution<double> amplitude(0.0, 0.05), offset(-3.0, 3.0);
        const io::Image base = smoothMap(t, amplitude(rng), 0.1, 0.9);
        io::Image map = base;
        std::vector<std::pair<int32_t, int32_t>> spikes;
        const int spikeCount = 1 + static_cast<int>(rng() % 5);
        for (int k = 0; k < spikeCount; ++k) {
            const int32_t x = 2 + static_cast<int32_t>(rng() % (t - 4)),
                          y = 2 + static_cast<int32_t>(rng() % (t - 4));
            map.at(x, y, 0) += static_cast<float>(offset(rng) / t);
            map.at(x, y, 1) += static_cast<float>(offset(rng) / t);
            spikes.emplace_back(x, y);
        }
        const int64_t before = invertedReference(map);
        foldsMade += before;
        const io::Image given = map;
        const FoldRepair r = repairFolds(map, mayShow);
        INFO("case " << c << ", " << t << "^2, " << before << " inverted triangles");
        REQUIRE(invertedReference(map) == 0);
        CHECK(r.invertedFound == before);
        // Every texel that moved shows content its chart allows.
        for (int32_t y = 0; y < t; ++y) {
            for (int32_t x = 0; x < t; ++x) {
                if (map.at(x, y, 0) == given.at(x, y, 0) && map.at(x, y, 1) == given.at(x, y, 1)) continue;
                CHECK(mayShow(x, y, {map.at(x, y, 0), map.at(x, y, 1)}));
            }
        }
        if (before == 0) {
            CHECK(map.pixels == given.pixels);
            continue;
        }
        CHECK(r.regionsScaled == 0);  // smoothing alone ends folds this small
        // Texels farther than 2 from every spike keep their values: a spike's folds lie in its 4 cells, and
        // the smoothing moves their corners and, from the 16th pass on, a ring more every 16 passes.
        const int32_t reach = 2 + r.passes / 16;
        for (int32_t y = 0; y < t; ++y) {
            for (int32_t x = 0; x < t; ++x) {
                const bool near = std::any_of(spikes.begin(), spikes.end(), [&](const auto& s) {
                    return std::abs(s.first - x) <= reach && std::abs(s.second - y) <= reach;
                });
                if (!near) {
                    CHECK(map.at(x, y, 0) == given.at(x, y, 0));
                    CHECK(map.at(x, y, 1) == given.at(x, y, 1));
                }
            }
        }
        // The smooth base is locally almost affine, which the neighbour mean reproduces: a spiked texel goes
        // back near its base value (within 0.94 texel at worst in these cases, from up to 4.2 texels away).
        for (const auto& [x, y] : spikes) {
            const glm::dvec2 d(map.at(x, y, 0) - base.at(x, y, 0), map.at(x, y, 1) - base.at(x, y, 1));
            worstReturn = std::max(worstReturn, glm::length(d) * t);
        }
    }
    CHECK(foldsMade > 500);
    INFO("farthest a repaired spike stayed from the smooth map: " << worstReturn << " texels");
    CHECK(worstReturn < 1.5);
}

TEST_CASE("a fold the smoothing cannot end is scaled back around it, or with its region",
          "[uvwarp][repair]") {
    const int32_t t = 32;
    SECTION("no content allowed but a texel's own centre") {
        io::Image map = smoothMap(t, 0.04);
        map.at(10, 12, 0) += 3.0f / t;  // folds the cells around texel (10, 12)
        const ContentCheck nothing = [](int32_t, int32_t, glm::dvec2) { return false; };
        REQUIRE(invertedReference(map) > 0);
        int64_t displaced = 0;
        for (int32_t y = 0; y < t; ++y)
            for (int32_t x = 0; x < t; ++x)
                displaced += map.at(x, y, 0) != centreOf(x, y, t).x || map.at(x, y, 1) != centreOf(x, y, t).y;
        const FoldRepair r = repairFolds(map, nothing);
        CHECK(invertedReference(map) == 0);
        // Every displaced texel shows refused content: each goes back to its own centre before any smoothing.
        CHECK(r.offChartFound == displaced);
        CHECK(r.texelsMoved == 0);
        CHECK(r.regionsScaled == 0);
        // The map is the identity, the one state accepted without asking.
        for (int32_t y = 0; y < t; ++y) {
            for (int32_t x = 0; x < t; ++x) {
                CHECK(map.at(x, y, 0) == static_cast<float>((x + 0.5f) / static_cast<float>(t)));
                CHECK(map.at(x, y, 1) == 1.0f - (y + 0.5f) / static_cast<float>(t));
            }
        }
    }
    SECTION("a fold pinned by a texel on the tile border, which the smoothing never moves") {
        // The smooth map displaces every interior texel; border texel (0, 16) is pulled 6 texels inwards,
        // past its row's interior texels. The displacement is scaled back around the fold only: texels more
        // than a window's reach from it keep their values, where scaling the region back would have scaled
        // the whole tile's warp.
        io::Image map = smoothMap(t, 0.04);
        map.at(0, 16, 0) += 6.0f / t;
        REQUIRE(invertedReference(map) > 0);
        const io::Image given = map;
        const FoldRepair r = repairFolds(map, kAnything);
        CHECK(invertedReference(map) == 0);
        CHECK(r.regionsScaledLocally == 1);
        CHECK(r.regionsScaled == 0);
        CHECK(r.smallestScale < 1.0);
        int64_t kept = 0, far = 0;
        for (int32_t y = 0; y < t; ++y) {
            for (int32_t x = 0; x < t; ++x) {
                if (std::max(x, std::abs(y - 16)) <= 16) continue;
                ++far;
                kept += map.at(x, y, 0) == given.at(x, y, 0) && map.at(x, y, 1) == given.at(x, y, 1);
            }
        }
        CHECK(kept == far);
        CHECK(far > 0);
    }
    SECTION("the guarantee, where no window around the fold can end it") {
        // Content allowed: a texel's own centre or what it was given, nothing in between; on a tile wider
        // than twice the largest window, the windows' ramps always ask for something in between. The region
        // is scaled back to the identity.
        const int32_t wide = 1024;
        io::Image map = smoothMap(wide, 0.04);
        map.at(0, 512, 0) += 6.0f / wide;
        const io::Image given = map;
        const ContentCheck givenOrCentre = [&](int32_t x, int32_t y, glm::dvec2 r) {
            const glm::vec2 stored(r), q(centreOf(x, y, wide));
            return stored == q || (stored.x == given.at(x, y, 0) && stored.y == given.at(x, y, 1));
        };
        REQUIRE(invertedReference(map) > 0);
        const FoldRepair r = repairFolds(map, givenOrCentre);
        CHECK(invertedReference(map) == 0);
        CHECK(r.regionsScaledLocally == 0);
        CHECK(r.regionsScaled == 1);
        CHECK(r.smallestScale == 0.0);
    }
}

TEST_CASE("held texels at their centres never move, and the folds next to them still end",
          "[uvwarp][repair]") {
    // The smooth warp on the square [0.4, 0.9]^2 of the tile, the identity elsewhere; the tile's left third
    // (x < t / 3, at the identity) held. Spikes a texel or two right of the held band fold cells whose
    // corners are held: the repair ends every fold without moving a held texel, by smoothing the others or
    // scaling their displacement back.
    std::mt19937 rng(1207);
    std::uniform_real_distribution<double> amplitude(0.0, 0.05), offset(-3.0, 3.0);
    int64_t foldsMade = 0, heldMovers = 0;
    for (int c = 0; c < 100; ++c) {
        const int32_t t = 48 << (c % 2), band = t / 3;
        io::Image map = smoothMap(t, amplitude(rng), 0.4, 0.9);
        for (int32_t y = 0; y < t; ++y) {
            for (int32_t x = 0; x < band; ++x) {  // the identity as the inversion writes it, in float
                map.at(x, y, 0) = (x + 0.5f) / static_cast<float>(t);
                map.at(x, y, 1) = 1.0f - (y + 0.5f) / static_cast<float>(t);
            }
        }
        for (int k = 0; k < 3; ++k) {
            const int32_t x = band + static_cast<int32_t>(rng() % 2),
                          y = 2 + static_cast<int32_t>(rng() % (t - 4));
            map.at(x, y, 0) += static_cast<float>(offset(rng) / t);
            map.at(x, y, 1) += static_cast<float>(offset(rng) / t);
        }
        const io::Image given = map;
        const TexelCheck held = [band](int32_t x, int32_t) { return x < band; };
        foldsMade += invertedReference(map);
        INFO("case " << c);
        (void)repairFolds(map, kAnything, {}, held);
        CHECK(invertedReference(map) == 0);
        for (int32_t y = 0; y < t; ++y) {
            for (int32_t x = 0; x < band; ++x) {
                CHECK(map.at(x, y, 0) == given.at(x, y, 0));
                CHECK(map.at(x, y, 1) == given.at(x, y, 1));
            }
        }
        // Without the held band, the smoothing moves some of those texels.
        io::Image free = given;
        (void)repairFolds(free, kAnything);
        for (int32_t y = 0; y < t; ++y)
            for (int32_t x = 0; x < band; ++x)
                heldMovers += free.at(x, y, 0) != given.at(x, y, 0) || free.at(x, y, 1) != given.at(x, y, 1);
    }
    CHECK(foldsMade > 300);
    CHECK(heldMovers > 100);
}

TEST_CASE("the repair is bit-identical for 1 and 2 threads", "[uvwarp][repair]") {
    std::mt19937 rng(3);
    io::Image map = smoothMap(128, 0.05);
    for (int k = 0; k < 40; ++k) {
        const int32_t x = 1 + static_cast<int32_t>(rng() % 126), y = 1 + static_cast<int32_t>(rng() % 126);
        map.at(x, y, 0) += static_cast<float>((static_cast<double>(rng() % 600) / 100.0 - 3.0) / 128.0);
    }
    const auto run = [&] {
        io::Image copy = map;
        (void)repairFolds(copy, kAnything);
        return copy.pixels;
    };
    CHECK(test::withThreads(1, run) == test::withThreads(2, run));
}

TEST_CASE("fold repair bad input", "[uvwarp][repair]") {
    io::Image oneChannel(8, 8, 1);
    CHECK_THROWS_WITH(repairFolds(oneChannel, kAnything),
                      Catch::Contains("redirect map") && Catch::Contains("2 channels"));
    io::Image wide(8, 4, 2);
    CHECK_THROWS_AS(repairFolds(wide, kAnything), InvalidInput);
}
