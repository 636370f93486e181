#include <catch2/catch.hpp>

#include <cmath>
#include <functional>

#include "deformkit/error.h"
#include "deformkit/uvwarp/metrics.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using namespace deformkit::uvwarp;

namespace {

PointField field3(int32_t n, const std::function<glm::dvec3(double, double)>& f) {
    PointField out;
    out.cells = n;
    out.channels = 3;
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i) {
            const glm::dvec3 p = f(double(i) / n, double(j) / n);
            out.values.push_back(static_cast<float>(p.x));
            out.values.push_back(static_cast<float>(p.y));
            out.values.push_back(static_cast<float>(p.z));
        }
    }
    return out;
}

PointField field1(int32_t n, const std::function<double(int32_t, int32_t)>& f) {
    PointField out;
    out.cells = n;
    out.channels = 1;
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i)
            out.values.push_back(static_cast<float>(f(i, j)));
    }
    return out;
}

constexpr double kSize = 2.0;  // scene units of the unit square
const auto kRest = [](double u, double v) { return glm::dvec3(kSize * u, kSize * v, 0.0); };
const auto kStretched = [](double u, double v) { return glm::dvec3(1.5 * kSize * u, kSize * v, 0.0); };
// |l_def / l_org - 1| of a diagonal edge under a 1.5x stretch along u: sqrt(1.5^2 + 1) / sqrt(2) - 1.
const double kDiagonal = std::sqrt(3.25 / 2.0) - 1.0;

}  // namespace

TEST_CASE("stretch error of a uniform 1.5x stretch with the identity warp", "[uvwarp][metrics]") {
    const int32_t n = 16;
    const PointField rest = field3(n, kRest), deformed = field3(n, kStretched);
    const PointField rigid = field1(n, [](int32_t, int32_t) { return 1.0; });
    const PointField free = field1(n, [](int32_t, int32_t) { return 1.0; });
    const WarpMetrics m = measureWarp(WarpGrid::identity(n), rest, deformed, rigid, free);
    // Horizontal edges (n (n + 1)) stretch by 0.5, vertical ones (n (n + 1)) by 0, diagonals (2 n^2) by
    // kDiagonal.
    const double horizontal = n * (n + 1), vertical = n * (n + 1), diagonal = 2.0 * n * n;
    const double expected = (0.5 * horizontal + kDiagonal * diagonal) / (horizontal + vertical + diagonal);
    CHECK(m.rigidEdges == static_cast<int64_t>(horizontal + vertical + diagonal));
    CHECK(m.skippedEdges == 0);
    // float32 geometry images: relative rounding ~1e-7 per length.
    CHECK(m.identityStretchError == Approx(expected).margin(1e-6));
    CHECK(m.rigidStretchError == Approx(expected).margin(1e-6));
    CHECK(m.foldOvers == 0);
    CHECK(m.maxMaskedDisplacement == 0.0);
    CHECK(m.maxBorderDisplacement == 0.0);
    CHECK(m.pointsOutside == 0);

    // Below the rigidity threshold nothing is measured.
    const PointField soft = field1(n, [](int32_t, int32_t) { return 0.4; });
    const WarpMetrics none = measureWarp(WarpGrid::identity(n), rest, deformed, soft, free);
    CHECK(none.rigidEdges == 0);
    CHECK(none.rigidStretchError == 0.0);
}

TEST_CASE("a warp that shrinks a rigid band by 1 / 1.5 removes its stretch", "[uvwarp][metrics]") {
    // Rigidity 1 at columns 5..11 of n = 16 (u strictly inside (0.25, 0.75)). The warp maps u in [0.25, 0.75]
    // to 0.5 + (u - 0.5) / 1.5 and the two outer intervals linearly onto what is left; every rigid edge
    // has both ends in columns 4..12, where f_D(W(p)) = f_O(p) exactly for the 1.5x stretch.
    const int32_t n = 16;
    auto w = [](double u) {
        if (u <= 0.25) return u * (0.5 - 0.25 / 1.5) / 0.25;
        if (u >= 0.75) return 1.0 - (1.0 - u) * (0.5 - 0.25 / 1.5) / 0.25;
        return 0.5 + (u - 0.5) / 1.5;
    };
    const WarpGrid warp = test::warpFrom(n, [&](double u, double v) { return glm::dvec2(w(u), v); });
    const PointField rest = field3(n, kRest), deformed = field3(n, kStretched);
    const PointField rigidity = field1(n, [](int32_t i, int32_t) { return i >= 5 && i <= 11 ? 1.0 : 0.0; });
    const PointField mask = field1(n, [](int32_t i, int32_t) { return i <= 2 ? 0.0 : 1.0; });
    MetricsOptions options;
    options.texels = 32;
    const WarpMetrics m = measureWarp(warp, rest, deformed, rigidity, mask, options);

    // Edges with an end in columns 5..11: horizontal i in 4..11 (8 x 17 rows), vertical i in 5..11 (7 x 16),
    // each diagonal direction i in 4..11 (8 x 16).
    const double horizontal = 8 * 17, vertical = 7 * 16, diagonal = 2 * 8 * 16;
    CHECK(m.rigidEdges == static_cast<int64_t>(horizontal + vertical + diagonal));
    CHECK(
        m.identityStretchError ==
        Approx((0.5 * horizontal + kDiagonal * diagonal) / (horizontal + vertical + diagonal)).margin(1e-6));
    // float32 warp and geometry: ratios exact to ~1e-6.
    CHECK(m.rigidStretchError < 1e-5);
    CHECK(m.foldOvers == 0);
    CHECK(m.pointsOutside == 0);
    // The border rows slide along u: the largest |W(u) - u| is at u = 0.25 and 0.75, 1/12, i.e. 32 / 12
    // texels.
    CHECK(m.maxBorderDisplacement == Approx(32.0 / 12.0).margin(1e-4));
    // Masked columns 0..2: W(u) = 4u / 3 there, the largest move at u = 2/16 is 1/24, i.e. 32 / 24 texels.
    CHECK(m.maxMaskedDisplacement == Approx(32.0 / 24.0).margin(1e-4));

    // Thread count does not change a bit of the result.
    const auto run = [&] {
        const WarpMetrics r = measureWarp(warp, rest, deformed, rigidity, mask, options);
        return std::vector<double>{r.rigidStretchError, r.identityStretchError, r.maxBorderDisplacement};
    };
    CHECK(test::withThreads(1, run) == test::withThreads(2, run));
}

TEST_CASE("edges of zero rest length are skipped", "[uvwarp][metrics]") {
    // f_O collapses v: vertical edges have l_org = 0 and are left out (n (n + 1) of them).
    const int32_t n = 8;
    const PointField rest = field3(n, [](double u, double) { return glm::dvec3(u, 0.0, 0.0); });
    const PointField deformed = field3(n, [](double u, double v) { return glm::dvec3(2.0 * u, v, 0.0); });
    const PointField ones = field1(n, [](int32_t, int32_t) { return 1.0; });
    const WarpMetrics m = measureWarp(WarpGrid::identity(n), rest, deformed, ones, ones);
    CHECK(m.skippedEdges == n * (n + 1));
    CHECK(m.rigidEdges == n * (n + 1) + 2 * n * n);
    // Horizontal: ratio 2 (error 1). Diagonals: l_org = 1/n, l_def = sqrt(4 + 1) / n, error sqrt(5) - 1.
    const double expected =
        (n * (n + 1) * 1.0 + 2.0 * n * n * (std::sqrt(5.0) - 1.0)) / (n * (n + 1) + 2.0 * n * n);
    CHECK(m.identityStretchError == Approx(expected).margin(1e-5));
}

TEST_CASE("fold-overs count both splittings of every cell", "[uvwarp][metrics]") {
    const PointField rest = field3(1, kRest);
    const PointField ones = field1(1, [](int32_t, int32_t) { return 1.0; });
    WarpGrid cell = WarpGrid::identity(1);
    // Corner (1, 1) pulled to (0.25, 0.25): the quad is concave; of the four triangles only
    // (1,0)-(1,1)-(0,1) of the other splitting turns clockwise.
    cell.u[3] = 0.25f;
    cell.v[3] = 0.25f;
    CHECK(measureWarp(cell, rest, rest, ones, ones).foldOvers == 1);
    // Corner (1, 1) pushed to (-0.5, -0.5), outside: three triangles turn, only (0,0)-(1,0)-(0,1) does not.
    cell.u[3] = -0.5f;
    cell.v[3] = -0.5f;
    const WarpMetrics out = measureWarp(cell, rest, rest, ones, ones);
    CHECK(out.foldOvers == 3);
    CHECK(out.pointsOutside == 1);
    // Corner (1, 1) on the other diagonal: (1,0)-(1,1)-(0,1) has zero area and counts.
    cell.u[3] = 0.5f;
    cell.v[3] = 0.5f;
    CHECK(measureWarp(cell, rest, rest, ones, ones).foldOvers == 1);
    // Corner (1, 1) collapsed onto (1, 0): both triangles holding the two are degenerate.
    cell.u[3] = 1.0f;
    cell.v[3] = 0.0f;
    CHECK(measureWarp(cell, rest, rest, ones, ones).foldOvers == 2);

    // A mirrored grid turns every triangle: 4 per cell.
    const int32_t n = 4;
    const WarpGrid mirrored = test::warpFrom(n, [](double u, double v) { return glm::dvec2(1.0 - u, v); });
    const PointField rest4 = field3(n, kRest);
    const PointField ones4 = field1(n, [](int32_t, int32_t) { return 1.0; });
    const WarpMetrics m = measureWarp(mirrored, rest4, rest4, ones4, ones4, {});
    CHECK(m.foldOvers == 4 * n * n);
    // Border point (0, j) moved to u = 1: one unit square side, n = 4 cells.
    CHECK(m.maxBorderDisplacement == Approx(4.0));
}

TEST_CASE("metrics bad input", "[uvwarp][metrics]") {
    const int32_t n = 4;
    const PointField rest = field3(n, kRest);
    const PointField ones = field1(n, [](int32_t, int32_t) { return 1.0; });
    const PointField coarse = field1(2, [](int32_t, int32_t) { return 1.0; });
    CHECK_THROWS_WITH(measureWarp(WarpGrid::identity(n), rest, rest, coarse, ones),
                      Catch::Contains("rigidity") && Catch::Contains("4 cells"));
    CHECK_THROWS_WITH(measureWarp(WarpGrid::identity(n), rest, ones, ones, ones),
                      Catch::Contains("deformed geometry image"));
    CHECK_THROWS_AS(measureWarp(WarpGrid::identity(2), rest, rest, ones, ones), InvalidInput);
}
