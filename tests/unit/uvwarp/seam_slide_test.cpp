#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/io/obj.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/redirect_metrics.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/solver.h"
#include "deformkit/uvwarp/tile_warp.h"
#include "uvwarp/seam_slide.h"
#include "uvwarp/tile_uvs.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using uvwarp::detail::SeamSlide;

namespace {

// A seam cylinder (uvwarp_test_support.h) laid out so that each edge along the seam spans a whole number
// of texels: 256^2 texels, UVs [0.25, 0.75] x [0.125, 0.875], 32 segments around and 12 rows of 16 texels
// along its height of 3. Its seam (angle 0) runs along v at u = 0.25 on one side and u = 0.75 on the other.
constexpr int32_t kTexels = 256;
constexpr int kRows = 12;
constexpr float kHeight = 3.0f;
geom::Mesh cylinder() {
    return test::seamCylinder(32, kRows, kHeight, {0.25f, 0.125f}, {0.75f, 0.875f});
}

// Rigid (1) within 20 texels of the seam on both sides, between rows 4 and 8 (v in [0.375, 0.625]).
io::Image rigidAlongSeam() {
    io::Image map(kTexels, kTexels, 1);
    for (int32_t y = 0; y < kTexels; ++y)
        for (int32_t x = 0; x < kTexels; ++x) {
            const float u = (static_cast<float>(x) + 0.5f) / kTexels,
                        v = 1.0f - (static_cast<float>(y) + 0.5f) / kTexels;
            const bool nearSeam =
                (u > 0.25f && u < 0.25f + 20.0f / kTexels) || (u < 0.75f && u > 0.75f - 20.0f / kTexels);
            if (nearSeam && v > 0.375f && v < 0.625f) map.at(x, y, 0) = 1.0f;
        }
    return map;
}

// Row r of the cylinder's height lifted to stretched(r): rows 3 to 8 stretched to 1.5 times their height.
float stretchedHeight(float y) {
    const float row = kHeight / kRows;
    const auto stretch = [&](float r) {
        return r <= 3.0f ? r : (r <= 9.0f ? 3.0f + 1.5f * (r - 3.0f) : 12.0f + (r - 9.0f));
    };
    return stretch(y / row) * row;
}

std::vector<glm::vec3> stretchedCylinder(const geom::Mesh& rest) {
    std::vector<glm::vec3> points(rest.points().begin(), rest.points().end());
    for (glm::vec3& p : points)
        p.y = stretchedHeight(p.y);
    return points;
}

}  // namespace

TEST_CASE("seam slide: one chain along the cylinder's seam, between its open borders", "[uvwarp][seam]") {
    const geom::Mesh mesh = cylinder();
    const uvwarp::detail::TileUVs uvs = uvwarp::detail::collectTileUVs(mesh, 1001, "cylinder");
    const SeamSlide slide(mesh, uvs, rigidAlongSeam());
    REQUIRE(slide.chains() == 1);
    const auto points = slide.chainPoints(0);
    REQUIRE(points.size() == kRows + 1);
    // The seam's points (angle 0: x = 1, z = 0), one per row, in order from one open border to the other.
    for (size_t k = 0; k < points.size(); ++k) {
        const glm::vec3 p = mesh.points()[points[k]];
        CHECK(p.x == Approx(1.0f));
        CHECK(p.z == Approx(0.0f).margin(1e-6));
        CHECK(std::abs(p.y - mesh.points()[points[0]].y) == Approx(kHeight * static_cast<float>(k) / kRows));
    }
}

TEST_CASE("seam slide: phi minimises the chain's energy, as a dense solve of it finds", "[uvwarp][seam]") {
    // The energy of seam_slide.h written out again and minimised by Eigen's dense LDLT: sub-segments of one
    // texel (16 an edge), rigidity 1 on the 4 rows painted and 0 elsewhere (the map's texels are whole
    // there), rest length a_j and deformed length d_j of each; rigid ones ask for a_j (weight 1), elastic
    // ones for d_j (weight kElasticWeight); mu = kElasticWeight / kReach^2 holds each end near the identity.
    const geom::Mesh mesh = cylinder();
    const uvwarp::detail::TileUVs uvs = uvwarp::detail::collectTileUVs(mesh, 1001, "cylinder");
    SeamSlide slide(mesh, uvs, rigidAlongSeam());
    const std::vector<glm::vec3> deformed = stretchedCylinder(mesh);
    slide.update(deformed);

    const auto points = slide.chainPoints(0);
    const bool upwards = mesh.points()[points[0]].y < mesh.points()[points[1]].y;
    constexpr int kSubs = 16, n = kRows * kSubs;
    const float row = kHeight / kRows;
    std::vector<double> a(n), d(n), w(n), c(n);
    for (int j = 0; j < n; ++j) {
        const int r = upwards ? j / kSubs : kRows - 1 - j / kSubs;  // the row sub-segment j lies in
        a[j] = row / kSubs;
        d[j] = (stretchedHeight(row * static_cast<float>(r + 1)) -
                stretchedHeight(row * static_cast<float>(r))) /
               kSubs;
        const bool rigid = r >= 4 && r < 8;
        w[j] = rigid ? 1.0 : SeamSlide::kElasticWeight;
        c[j] = rigid ? a[j] - d[j] : 0.0;
    }
    const double mu = SeamSlide::kElasticWeight / (SeamSlide::kReach * SeamSlide::kReach);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n - 1, n - 1);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n - 1);
    for (int j = 0; j < n; ++j) {  // w_j (y_{j+1} - y_j - c_j)^2, unknowns y_1 .. y_{n-1} at rows 0 .. n-2
        const int lo = j - 1, hi = j;
        if (lo >= 0) h(lo, lo) += w[j];
        if (hi < n - 1) h(hi, hi) += w[j];
        if (lo >= 0 && hi < n - 1) {
            h(lo, hi) -= w[j];
            h(hi, lo) -= w[j];
        }
        if (hi < n - 1) g(hi) += w[j] * c[j];
        if (lo >= 0) g(lo) -= w[j] * c[j];
    }
    h.diagonal().array() += mu;
    const Eigen::VectorXd y = h.ldlt().solve(g);
    // End b is shown where the deformed arc length reaches its identity's plus y_b: as a chain parameter.
    double arc = 0.0;
    for (int b = 1; b < n; ++b) {
        arc += d[b - 1];
        const double shown = arc + y(b - 1);
        double before = 0.0, parameter = 0.0;
        for (int e = 0; e < kRows; ++e) {
            const double length = d[e * kSubs] * kSubs;
            if (shown <= before + length || e == kRows - 1) {
                parameter = e + (shown - before) / length;
                break;
            }
            before += length;
        }
        const float t = static_cast<float>(b) / kSubs;
        CHECK(slide.shownAt(0, t) == Approx(parameter).margin(2e-4));
    }
    // The rigid rows, stretched to 1.5 times their rest length, are shown over nearly their rest length: the
    // slide undoes at least 90% of their stretch along the seam.
    const float lo = slide.shownAt(0, upwards ? 4.0f : 8.0f), hi = slide.shownAt(0, upwards ? 8.0f : 4.0f);
    const auto heightAt = [&](float t) {
        const float rowOf = upwards ? t : static_cast<float>(kRows) - t;
        return stretchedHeight(row * rowOf);
    };
    const float shownLength = std::abs(heightAt(hi) - heightAt(lo));
    const float restLength = 4.0f * row, stretchedLength = 1.5f * restLength;
    CHECK(shownLength - restLength < 0.1f * (stretchedLength - restLength));
    CHECK(shownLength > restLength * 0.99f);
}

TEST_CASE("seam slide: without rigid content phi is the identity", "[uvwarp][seam]") {
    const geom::Mesh mesh = cylinder();
    const uvwarp::detail::TileUVs uvs = uvwarp::detail::collectTileUVs(mesh, 1001, "cylinder");
    SeamSlide slide(mesh, uvs, io::Image(kTexels, kTexels, 1));
    slide.update(stretchedCylinder(mesh));
    for (int b = 0; b <= kRows * 16; ++b) {
        const float t = static_cast<float>(b) / 16.0f;
        CHECK(slide.shownAt(0, t) == Approx(t).margin(1e-5));
    }
}

TEST_CASE("seam slide: both sides of the seam show the same content in the delivered maps",
          "[uvwarp][seam]") {
    // The texels next to the seam on either side (columns 64 and 191: u just inside 0.25 and 0.75) show the
    // same rest v, the same point of the cylinder, with the slide; and the slide moves that content several
    // texels along the seam, where the identity (the slide off) leaves it where it is.
    const geom::Mesh mesh = cylinder();
    const std::vector<glm::vec3> deformed = stretchedCylinder(mesh);
    uvwarp::TileWarpOptions options = uvwarp::shotOptions();
    REQUIRE(options.seamSlide);
    options.cells = kTexels;
    float largestSlide = 0.0f, largestGap = 0.0f, largestOff = 0.0f;
    for (bool on : {true, false}) {
        options.seamSlide = on;
        uvwarp::TileWarp warp(mesh, 1001, rigidAlongSeam(), {}, options);
        warp.solve(deformed);
        io::Image redirect;
        const uvwarp::FoldRepair repair = warp.redirect(redirect);
        (void)repair;
        const uvwarp::DeliveredMetrics figures = warp.measure(redirect);
        CHECK(figures.invertedTriangles == 0);
        CHECK(figures.offChartTexels == 0);
        for (int32_t y = 32; y < kTexels - 32; ++y) {
            const float v = 1.0f - (static_cast<float>(y) + 0.5f) / kTexels;
            const float left = redirect.at(64, y, 1), right = redirect.at(191, y, 1);
            if (on) {
                largestGap = std::max(largestGap, std::abs(left - right) * kTexels);
                largestSlide = std::max(largestSlide, std::abs(left - v) * kTexels);
            } else {
                largestOff =
                    std::max({largestOff, std::abs(left - v) * kTexels, std::abs(right - v) * kTexels});
            }
        }
    }
    CHECK(largestSlide > 4.0f);
    CHECK(largestGap < 0.5f);
    CHECK(largestOff < 0.5f);
}

TEST_CASE("seam slide: the points placed fold no grid cell, over random poses of the Fox", "[uvwarp][seam]") {
    // The Fox's rest mesh (tests/data/fox) with rigid detail along every seam, its points moved at random
    // (each scaled about the mesh's centre by a random factor in [0.6, 1.6] per axis, smooth over the mesh):
    // whatever the chains ask for, the placement is fold-free and finite.
    const geom::Mesh fox = io::readObj(DEFORMKIT_TEST_DATA "/fox/rest.obj").mesh;
    const uvwarp::detail::TileUVs uvs = uvwarp::detail::collectTileUVs(fox, 1001, "fox");
    io::Image rigidity(kTexels, kTexels, 1);
    for (int32_t y = 0; y < kTexels; ++y)
        for (int32_t x = 0; x < kTexels; ++x)
            rigidity.at(x, y, 0) = ((x / 8 + y / 8) % 3 == 0) ? 1.0f : 0.0f;
    SeamSlide slide(fox, uvs, rigidity);
    REQUIRE(slide.chains() > 10);
    const int id = slide.addGrid(kTexels);
    std::mt19937 random(20261206);
    std::uniform_real_distribution<float> factor(0.6f, 1.6f), phase(0.0f, 6.2831853f);
    int64_t placed = 0;
    float farthest = 0.0f;
    for (int pose = 0; pose < 40; ++pose) {
        const glm::vec3 scale{factor(random), factor(random), factor(random)};
        const glm::vec3 wave{phase(random), phase(random), phase(random)};
        std::vector<glm::vec3> points(fox.points().begin(), fox.points().end());
        for (glm::vec3& p : points)
            p = p * (scale + 0.3f * glm::vec3(std::sin(p.y * 0.05f + wave.x), std::sin(p.z * 0.05f + wave.y),
                                              std::sin(p.x * 0.05f + wave.z)));
        slide.update(points);
        const uvwarp::detail::SlidPoints& s = slide.points(id);
        uvwarp::WarpGrid grid = uvwarp::WarpGrid::identity(kTexels);
        for (size_t k = 0; k < s.index.size(); ++k) {
            REQUIRE(std::isfinite(s.u[k]));
            REQUIRE(std::isfinite(s.v[k]));
            grid.u[s.index[k]] = s.u[k];
            grid.v[s.index[k]] = s.v[k];
            const auto i = static_cast<float>(s.index[k] % (kTexels + 1)),
                       j = static_cast<float>(s.index[k] / (kTexels + 1));
            farthest = std::max(farthest, std::hypot(s.u[k] * kTexels - i, s.v[k] * kTexels - j));
        }
        placed += static_cast<int64_t>(s.index.size());
        CHECK(uvwarp::countFolds(grid) == 0);
    }
    CHECK(placed > 0);
    CHECK(farthest > 1.0f);  // the poses do slide content
}

TEST_CASE("Solver::placePoints: fixed points stay placed, movable ones start there", "[uvwarp][seam]") {
    // A 16-cell grid, fixed in its left half: point (4, 8) fixed, placed 0.3 cells up; point (12, 8) movable,
    // placed 0.3 cells right. With nothing to do (f_D = f_O), the fixed point stays where it is put through
    // solves, a reset and a start from a coarser warp; the movable one starts there after a reset.
    const auto restGeometry = test::pointField(16, 3, [](float u, float v, float* out) {
        out[0] = u;
        out[1] = v;
        out[2] = 0.0f;
    });
    const auto mask =
        test::pointField(16, 1, [](float u, float, float* out) { out[0] = u < 0.5f ? 0.0f : 1.0f; });
    uvwarp::SolverOptions options;
    options.warmStart = false;
    uvwarp::Solver solver(restGeometry,
                          test::pointField(16, 1, [](float, float, float* out) { out[0] = 0.0f; }), mask,
                          options);
    const int64_t fixedPoint = 8 * 17 + 4, movablePoint = 8 * 17 + 12;
    const std::vector<int64_t> index{fixedPoint, movablePoint};
    const std::vector<float> u{4.0f / 16, 12.3f / 16}, v{8.3f / 16, 8.0f / 16};
    solver.placePoints(index, u, v);
    CHECK(solver.warp().u[fixedPoint] == u[0]);
    CHECK(solver.warp().v[fixedPoint] == v[0]);
    CHECK(solver.warp().u[movablePoint] == u[1]);  // the next solve starts from the identity: placed now
    solver.solve(restGeometry);
    CHECK(solver.warp().v[fixedPoint] == v[0]);
    solver.reset();
    CHECK(solver.warp().v[fixedPoint] == v[0]);
    CHECK(solver.warp().u[movablePoint] == u[1]);
    solver.startFrom(uvwarp::WarpGrid::identity(8));
    CHECK(solver.warp().v[fixedPoint] == v[0]);
    CHECK(solver.warp().u[movablePoint] ==
          Approx(12.0f / 16));  // a movable point starts from the coarser warp
    // An empty list puts the fixed point back at rest.
    solver.placePoints({}, {}, {});
    CHECK(solver.warp().v[fixedPoint] == 8.0f / 16);
    // Bad lists: lengths, order, range, NaN.
    const std::vector<float> one{0.5f};
    CHECK_THROWS_AS(solver.placePoints(index, one, one), InvalidInput);
    const std::vector<int64_t> backwards{movablePoint, fixedPoint}, outside{17 * 17};
    CHECK_THROWS_AS(solver.placePoints(backwards, u, v), InvalidInput);
    CHECK_THROWS_AS(solver.placePoints(outside, one, one), InvalidInput);
    const std::vector<float> nan{std::nanf("")};
    CHECK_THROWS_AS(solver.placePoints(std::vector<int64_t>{fixedPoint}, nan, one), InvalidInput);
}

TEST_CASE("seam slide: the Fox's delivered maps, any thread count; a painted mask keeps seams fixed",
          "[uvwarp][seam]") {
    // The Fox's frame 18 at 256² (its skinning's hip squash), 2 refinement sweeps, each solve from the
    // identity: with the slide, points the derived mask fixes move (along seams) but none on the tile border,
    // the delivered grid and map fold nowhere and show nothing off the charts, and the warp is the same bytes
    // on 1 and 2 threads. Given the derived mask as a painted one, the slide stops: the warp is the one of a
    // tile bound without the slide.
    const geom::Mesh fox = io::readObj(DEFORMKIT_TEST_DATA "/fox/rest.obj").mesh;
    const geom::Mesh posed = io::readObj(DEFORMKIT_TEST_DATA "/fox/anim.0018.obj").mesh;
    const std::vector<glm::vec3> points(posed.points().begin(), posed.points().end());
    constexpr int32_t t = 256;
    io::Image rigidity(t, t, 1);  // disks of radius 0.025 on a 0.1 lattice, a texel inside the derived mask
    const io::Image derived = uvwarp::deriveWarpMask(fox, 1001, t);
    for (int32_t y = 0; y < t; ++y)
        for (int32_t x = 0; x < t; ++x) {
            const double u = (x + 0.5) / t, v = 1.0 - (y + 0.5) / t;
            bool rigid = std::hypot(u - (std::floor(u * 10.0) + 0.5) / 10.0,
                                    v - (std::floor(v * 10.0) + 0.5) / 10.0) < 0.025;
            for (int32_t dy = -1; dy <= 1 && rigid; ++dy)
                for (int32_t dx = -1; dx <= 1 && rigid; ++dx)
                    rigid = derived.at(std::clamp(x + dx, 0, t - 1), std::clamp(y + dy, 0, t - 1), 0) >= 0.5f;
            rigidity.at(x, y, 0) = rigid ? 1.0f : 0.0f;
        }
    uvwarp::TileWarpOptions options;
    options.solver.warmStart = false;
    options.refinementSweeps = 2;
    options.seamSlide = true;
    const auto run = [&] {
        uvwarp::TileWarp warp(fox, 1001, rigidity, {}, options);
        const uvwarp::WarpGrid grid = warp.solve(points);
        const uvwarp::DeliveredMetrics delivered = warp.deliveredMetrics();
        CHECK(delivered.invertedTriangles == 0);
        CHECK(delivered.offChartTexels == 0);
        CHECK(uvwarp::countFolds(grid) == 0);
        const uvwarp::WarpMetrics figures = warp.metrics();
        CHECK(figures.maxMaskedDisplacement > 0.5);  // texels: border content slid along its seam
        CHECK(figures.maxBorderDisplacement == 0.0);
        return grid;
    };
    const uvwarp::WarpGrid one = test::withThreads(1, run), two = test::withThreads(2, run);
    CHECK(one.u == two.u);
    CHECK(one.v == two.v);

    // The same tile given the derived mask as a painted one after a solve with the slide, then its derived
    // mask again.
    uvwarp::TileWarp painted(fox, 1001, rigidity, {}, options);
    painted.solve(points);
    painted.setMaps(rigidity, derived);
    const uvwarp::WarpGrid still = painted.solve(points);
    uvwarp::TileWarpOptions fixed = options;
    fixed.seamSlide = false;
    uvwarp::TileWarp reference(fox, 1001, rigidity, derived, fixed);
    const uvwarp::WarpGrid expected = reference.solve(points);
    CHECK(still.u == expected.u);
    CHECK(still.v == expected.v);
    CHECK(still.u != one.u);
    painted.setMaps(rigidity);
    const uvwarp::WarpGrid again = painted.solve(points);
    CHECK(again.u == one.u);
    CHECK(again.v == one.v);
}
