#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/engine.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

SegmentPair pair(glm::vec2 dp, glm::vec2 dq, glm::vec2 sp, glm::vec2 sq, float a = 1.0f, float b = 2.0f,
                 float p = 0.5f) {
    SegmentPair s;
    s.dstP = dp;
    s.dstQ = dq;
    s.srcP = sp;
    s.srcQ = sq;
    s.a = a;
    s.b = b;
    s.p = p;
    return s;
}

std::vector<SegmentPair> randomPairs(std::mt19937& rng, int n, float size) {
    std::uniform_real_distribution<float> pos(0.0f, size), jitter(-0.2f * size, 0.2f * size);
    std::vector<SegmentPair> pairs;
    for (int i = 0; i < n; ++i) {
        const glm::vec2 p(pos(rng), pos(rng)), q(pos(rng), pos(rng));
        pairs.push_back(pair(p, q, p + glm::vec2(jitter(rng), jitter(rng)),
                             q + glm::vec2(jitter(rng), jitter(rng)), 0.5f + 0.1f * i, 1.0f + 0.25f * (i % 5),
                             0.25f * (i % 4)));
    }
    return pairs;
}

std::vector<glm::vec2> pixelCentres(int w, int h) {
    std::vector<glm::vec2> out;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x)
            out.push_back({x + 0.5f, y + 0.5f});
    }
    return out;
}

// The L-shaped shear of Fig. 15 (docs/decisions.md, BN-5): a horizontal segment that stays
// put and a vertical segment above it whose source copy leans over by 1.1 rad about its foot.
std::vector<SegmentPair> shearCase() {
    const float tilt = 1.1f;
    const glm::vec2 top(32.0f + 28.0f * std::sin(tilt), 40.0f - 28.0f * std::cos(tilt));
    return {pair({12, 44}, {52, 44}, {12, 44}, {52, 44}), pair({32, 40}, {32, 12}, {32, 40}, top)};
}

// Minimum Jacobian determinant of a map over the pixel centres of a w x h grid, by central differences
// with step h written here independently of the warp.
double minJacobian(const BeierNeelyWarp& warp, int w, int h, float step, int* negatives) {
    const std::vector<glm::vec2> centres = pixelCentres(w, h);
    std::vector<glm::vec2> xp(centres), xm(centres), yp(centres), ym(centres);
    for (size_t i = 0; i < centres.size(); ++i) {
        xp[i].x += step;
        xm[i].x -= step;
        yp[i].y += step;
        ym[i].y -= step;
    }
    for (auto* v : {&xp, &xm, &yp, &ym})
        warp.mapPoints(*v, *v);
    double minDet = std::numeric_limits<double>::max();
    *negatives = 0;
    for (size_t i = 0; i < centres.size(); ++i) {
        const glm::dvec2 jx = glm::dvec2(xp[i] - xm[i]) / (2.0 * step);
        const glm::dvec2 jy = glm::dvec2(yp[i] - ym[i]) / (2.0 * step);
        const double det = jx.x * jy.y - jx.y * jy.x;
        minDet = std::min(minDet, det);
        if (det < 0.0) ++*negatives;
    }
    return minDet;
}

}  // namespace

TEST_CASE("Beier-Neely: identity when source and destination segments agree", "[warp][beier_neely]") {
    std::mt19937 rng(11);
    std::vector<SegmentPair> pairs = randomPairs(rng, 6, 64.0f);
    for (auto& s : pairs) {
        s.srcP = s.dstP;
        s.srcQ = s.dstQ;
    }
    for (auto variant : {BeierNeelyVariant::Original, BeierNeelyVariant::Global}) {
        const BeierNeelyWarp warp(pairs, {variant});
        const std::vector<glm::vec2> map = beierNeelyMap(64, 48, pairs, {variant});
        const std::vector<glm::vec2> centres = pixelCentres(64, 48);
        float worst = 0.0f;
        for (size_t i = 0; i < map.size(); ++i)
            worst = std::max(worst, glm::length(map[i] - centres[i]));
        CHECK(worst <= 1e-6f);

        // The generic engine path over 3-D points: x, y unchanged, z untouched.
        std::vector<glm::vec3> points{{3.5f, 7.25f, 2.0f}, {60, -10, -5}, {0, 0, 0}};
        WarpDeformer deformer(const_cast<BeierNeelyWarp&>(warp));
        deformer.bind(points);
        std::vector<glm::vec3> moved = points;
        deformer.evaluate(moved);
        for (size_t i = 0; i < points.size(); ++i)
            CHECK(glm::length(moved[i] - points[i]) <= 1e-6f);
    }
}

TEST_CASE("Beier-Neely: one segment pair gives the closed-form rotation-and-stretch map",
          "[warp][beier_neely]") {
    // Reference (Beier-Neely 1992 with u along the segment normalised by length^2 and v the unnormalised
    // perpendicular distance): X' = P* + R_theta (k (X - P)_par + (X - P)_perp), k = |L*| / |L|, theta the
    // angle from L to L*. For |L*| = |L| this is the rigid motion taking L onto L*.
    struct Case {
        glm::vec2 p, q, ps, qs;
    };
    const Case cases[] = {
        {{10, 20},
         {40, 25},
         {15, 10},
         {15 + 30 * std::cos(1.0f) - 5 * std::sin(1.0f),
          10 + 30 * std::sin(1.0f) + 5 * std::cos(1.0f)}},  // rigid
        {{30, 30}, {30, 10}, {5, 40}, {45, 70}},            // rotated, stretched x2.5
        {{50, 5}, {10, 40}, {50, 5}, {30, 22.5f}},          // same line, half length
    };
    for (auto variant : {BeierNeelyVariant::Original, BeierNeelyVariant::Global}) {
        for (const Case& c : cases) {
            const std::vector<SegmentPair> pairs{pair(c.p, c.q, c.ps, c.qs, 0.7f, 1.3f, 0.9f)};
            const glm::dvec2 d = glm::dvec2(c.q - c.p), e = glm::dvec2(c.qs - c.ps);
            const double theta = std::atan2(e.y, e.x) - std::atan2(d.y, d.x);
            const double k = glm::length(e) / glm::length(d);
            const glm::dvec2 dh = d / glm::length(d);
            const int w = 60, h = 50;
            const std::vector<glm::vec2> map = beierNeelyMap(w, h, pairs, {variant});
            double worst = 0.0;
            for (int y = 0; y < h; ++y) {
                for (int x = 0; x < w; ++x) {
                    const glm::dvec2 r = glm::dvec2(x + 0.5, y + 0.5) - glm::dvec2(c.p);
                    const glm::dvec2 par = glm::dot(r, dh) * dh, perp = r - par;
                    const glm::dvec2 local = k * par + perp;
                    const glm::dvec2 expected =
                        glm::dvec2(c.ps) + glm::dvec2(std::cos(theta) * local.x - std::sin(theta) * local.y,
                                                      std::sin(theta) * local.x + std::cos(theta) * local.y);
                    worst = std::max(worst, glm::length(glm::dvec2(map[y * w + x]) - expected));
                }
            }
            CHECK(worst <= 1e-4);  // pixel coordinates up to ~150: a few float ulps
        }
    }
    // A rigid single pair preserves distances between any two mapped pixel centres.
    const std::vector<SegmentPair> rigid{pair(cases[0].p, cases[0].q, cases[0].ps, cases[0].qs)};
    const std::vector<glm::vec2> m = beierNeelyMap(20, 20, rigid);
    CHECK(glm::length(m[0] - m[399]) == Approx(glm::length(glm::vec2(19, 19))).epsilon(1e-6));
}

TEST_CASE("Beier-Neely: a rigid motion of every segment moves the image rigidly", "[warp][beier_neely]") {
    std::mt19937 rng(3);
    std::vector<SegmentPair> pairs = randomPairs(rng, 5, 64.0f);
    const float angle = 0.6f;
    const glm::vec2 shift(7.0f, -3.0f);
    auto motion = [&](glm::vec2 x) {
        return glm::vec2(std::cos(angle) * x.x - std::sin(angle) * x.y,
                         std::sin(angle) * x.x + std::cos(angle) * x.y) +
               shift;
    };
    for (auto& s : pairs) {
        s.srcP = motion(s.dstP);
        s.srcQ = motion(s.dstQ);
    }
    for (auto variant : {BeierNeelyVariant::Original, BeierNeelyVariant::Global}) {
        const std::vector<glm::vec2> map = beierNeelyMap(64, 64, pairs, {variant});
        float worst = 0.0f;
        for (int y = 0; y < 64; ++y) {
            for (int x = 0; x < 64; ++x) {
                worst = std::max(worst, glm::length(map[y * 64 + x] - motion({x + 0.5f, y + 0.5f})));
            }
        }
        CHECK(worst <= 1e-4f);
    }
}

TEST_CASE("Beier-Neely: global variant target basis matches the reconstructed Sec. 5.2 weights",
          "[warp][beier_neely]") {
    // Independent evaluation of the documented reconstruction for the two-segment shear case:
    // N*_0 = normalise(sum_j w_0j R_j N_0), w_0j = (len_j^p / ((a + dist_0j)(a + |d_0 . d_j| / len_0)))^b.
    const std::vector<SegmentPair> pairs = shearCase();
    const double a = 1.0, b = 2.0, p = 0.5;
    const double len0 = 40.0, len1 = 28.0;
    const double dist01 = 4.0;  // foot of the vertical segment (32, 40) to the horizontal one at y = 44
    const double w00 = std::pow(std::pow(len0, p) / (a * (a + len0)), b);
    const double w01 = std::pow(std::pow(len1, p) / ((a + dist01) * a), b);  // perpendicular: dot = 0
    const glm::dvec2 n0(0.0, 1.0);                                           // perp(40, 0) / 40
    const double tilt = 1.1;
    // R_1 rotates (0, -1) onto (sin t, -cos t): a counter-clockwise turn by t in these coordinates.
    const glm::dvec2 r1n0(-std::sin(tilt) * n0.y, std::cos(tilt) * n0.y);
    glm::dvec2 expected = (w00 * n0 + w01 * r1n0) / (w00 + w01);
    expected /= glm::length(expected);

    const std::vector<Affine> t = beierNeelyTransformations(pairs, {BeierNeelyVariant::Global});
    const glm::vec3 got = t[0].linear * glm::vec3(0, 1, 0);
    CHECK(got.x == Approx(expected.x).margin(1e-6));
    CHECK(got.y == Approx(expected.y).margin(1e-6));
    CHECK(got.z == 0.0f);
    // Along the segment the frame still maps Q - P onto Q* - P*.
    const glm::vec3 along = t[0].linear * glm::vec3(40, 0, 0);
    CHECK(along.x == Approx(40.0f));
    CHECK(along.y == Approx(0.0f).margin(1e-5));
    // The original keeps the perpendicular.
    const std::vector<Affine> o = beierNeelyTransformations(pairs);
    CHECK(glm::length(o[0].linear * glm::vec3(0, 1, 0) - glm::vec3(0, 1, 0)) <= 1e-7f);
}

TEST_CASE("Beier-Neely: the global variant's weights keep their ratios below double's range",
          "[warp][beier_neely]") {
    // The shear case with a = 10, b = 400: w_00 = (40^0.5 / (10 * 50))^400 ~ 1e-1139 and w_01 = (28^0.5 /
    // (14 * 10))^400 ~ 1e-569 both underflow in double, which left N*_0 its own perpendicular; their ratio
    // (1e570 for w_01) makes N*_0 the turned one. Reference in long double (range to 1e-4951).
    std::vector<SegmentPair> pairs = shearCase();
    for (SegmentPair& s : pairs) {
        s.a = 10.0f;
        s.b = 400.0f;
    }
    const long double w00 = std::pow(std::sqrt(40.0L) / (10.0L * 50.0L), 400.0L);
    const long double w01 = std::pow(std::sqrt(28.0L) / (14.0L * 10.0L), 400.0L);
    REQUIRE(w00 > 0.0L);
    REQUIRE(static_cast<double>(w01) == 0.0);  // below double's range
    const long double tilt = 1.1L;
    const long double x = (w01 * -std::sin(tilt)) / (w00 + w01),
                      y = (w00 + w01 * std::cos(tilt)) / (w00 + w01);
    const long double norm = std::sqrt(x * x + y * y);
    const std::vector<Affine> t = beierNeelyTransformations(pairs, {BeierNeelyVariant::Global});
    const glm::vec3 got = t[0].linear * glm::vec3(0, 1, 0);
    CHECK(got.x == Approx(static_cast<double>(x / norm)).margin(1e-6));
    CHECK(got.y == Approx(static_cast<double>(y / norm)).margin(1e-6));
}

TEST_CASE("Beier-Neely: the global variant removes the fold-over of the Fig. 15 shear",
          "[warp][beier_neely]") {
    const std::vector<SegmentPair> pairs = shearCase();
    int negOriginal = 0, negGlobal = 0;
    const double original =
        minJacobian(BeierNeelyWarp(pairs, {BeierNeelyVariant::Original}), 64, 64, 0.25f, &negOriginal);
    const double global =
        minJacobian(BeierNeelyWarp(pairs, {BeierNeelyVariant::Global}), 64, 64, 0.25f, &negGlobal);
    INFO("original min det " << original << " (" << negOriginal << " pixels), global min det " << global);
    CHECK(original < -0.03);  // the original folds the plane back on itself...
    CHECK(negOriginal > 50);
    CHECK(global > 0.05);  // ...the global variant does not, anywhere on the grid
    CHECK(negGlobal == 0);
}

TEST_CASE("Beier-Neely: a rigid motion moves pixels rigidly however far from the features",
          "[warp][beier_neely]") {
    // Eq. (3) is a weighted mean, so a pure translation of every segment translates every point, whatever a,
    // b and p. Far from the features the float weights (1 / (a + dist))^b fall below float's range (a = 10,
    // b = 30: every pixel past 52 from them; b = 12, a = 1: past 1,000) and must not leave pixels in place.
    // Random features and parameters with a fixed seed, 16 features apart by different b too, on a strip
    // 8,192 wide; every path: the map, mapPoints, and bind with the engine.
    std::mt19937 rng(1207);
    std::uniform_real_distribution<float> at(0.0f, 64.0f), aOf(0.5f, 10.0f), bOf(6.0f, 40.0f),
        pOf(0.0f, 1.0f);
    for (int c = 0; c < 12; ++c) {
        const glm::vec2 shift(at(rng) - 32.0f, at(rng) / 8.0f);
        std::vector<SegmentPair> pairs;
        const int count = 1 + c % 4;
        for (int i = 0; i < count; ++i) {
            const glm::vec2 p(at(rng), at(rng) / 4.0f),
                q = p + glm::vec2(4.0f + at(rng) / 4.0f, at(rng) / 16.0f);
            pairs.push_back(pair(p, q, p + shift, q + shift, aOf(rng), bOf(rng), pOf(rng)));
        }
        const int32_t width = 8192, height = 4;
        for (auto variant : {BeierNeelyVariant::Original, BeierNeelyVariant::Global}) {
            INFO("case " << c << ", variant " << static_cast<int>(variant));
            BeierNeelyWarp warp(pairs, {variant});
            std::vector<glm::vec2> map(static_cast<size_t>(width) * height);
            warp.mapPixelCentres(width, height, map);
            std::vector<glm::vec2> centres = pixelCentres(width, height);
            std::vector<glm::vec2> mapped(centres.size());
            warp.mapPoints(centres, mapped);
            std::vector<glm::vec3> points, generic(centres.size());
            for (const glm::vec2& x : centres)
                points.emplace_back(x, 0.0f);
            SparseFields fields;
            warp.bind(points, fields);
            Transformations transforms;
            warp.transformations(transforms);
            evaluateWarp(points, fields, transforms, generic);
            float worst = 0.0f;
            for (size_t k = 0; k < centres.size(); ++k) {
                const glm::vec2 expected = centres[k] + shift;
                worst = std::max({worst, glm::length(map[k] - expected), glm::length(mapped[k] - expected),
                                  glm::length(glm::vec2(generic[k]) - expected)});
            }
            // Float: positions near 8,192 lie 9.8e-4 apart and are rounded three times (T<x>, the
            // displacement, the sum), and each T's linear part is 1 to within 6e-8 (5e-4 at 8,192). Left in
            // place, a pixel would be off by the whole shift.
            CHECK(worst <= 4e-3f);
        }
    }
}

TEST_CASE("Beier-Neely: fast 2-D path equals the generic engine path", "[warp][beier_neely]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(-10.0f, 74.0f);
    for (auto variant : {BeierNeelyVariant::Original, BeierNeelyVariant::Global}) {
        const std::vector<SegmentPair> pairs = randomPairs(rng, 7, 64.0f);
        BeierNeelyWarp warp(pairs, {variant});
        std::vector<glm::vec3> points(3000);
        for (auto& p : points)
            p = {uni(rng), uni(rng), uni(rng)};
        SparseFields fields;
        warp.bind(points, fields);
        REQUIRE(fields.numPoints() == 3000);
        Transformations transforms;
        warp.transformations(transforms);
        std::vector<glm::vec3> generic(points.size());
        evaluateWarp(points, fields, transforms, generic);

        std::vector<glm::vec2> flat(points.size());
        for (size_t i = 0; i < points.size(); ++i)
            flat[i] = glm::vec2(points[i]);
        warp.mapPoints(flat, flat);
        float worst = 0.0f;
        for (size_t i = 0; i < points.size(); ++i) {
            worst = std::max(worst, glm::length(glm::vec2(generic[i]) - flat[i]));
            REQUIRE(generic[i].z == points[i].z);  // z untouched
        }
        CHECK(worst <= 1e-5f);
        // mapPixelCentres is mapPoints at (x + 0.5, y + 0.5).
        std::vector<glm::vec2> map(31 * 17), centres = pixelCentres(31, 17);
        warp.mapPixelCentres(31, 17, map);
        warp.mapPoints(centres, centres);
        CHECK(std::memcmp(map.data(), centres.data(), map.size() * sizeof(glm::vec2)) == 0);
    }
}

TEST_CASE("Beier-Neely: moving source segments needs no rebind", "[warp][beier_neely]") {
    std::mt19937 rng(19);
    std::vector<SegmentPair> pairs = randomPairs(rng, 4, 64.0f);
    std::uniform_real_distribution<float> uni(0.0f, 64.0f);
    std::vector<glm::vec3> rest(500);
    for (auto& p : rest)
        p = {uni(rng), uni(rng), 1.0f};
    for (auto variant : {BeierNeelyVariant::Original, BeierNeelyVariant::Global}) {
        BeierNeelyWarp warp(pairs, {variant});
        WarpDeformer deformer(warp);
        deformer.bind(rest);
        std::vector<glm::vec2> ends;
        for (const auto& s : pairs) {
            ends.push_back(s.srcP + glm::vec2(3, -2));
            ends.push_back(s.srcQ * 1.1f);
        }
        warp.setSourceSegments(ends);
        std::vector<glm::vec3> moved = rest;
        deformer.evaluate(moved);

        std::vector<SegmentPair> fresh = pairs;
        for (size_t i = 0; i < fresh.size(); ++i) {
            fresh[i].srcP = ends[2 * i];
            fresh[i].srcQ = ends[2 * i + 1];
        }
        BeierNeelyWarp reference(fresh, {variant});
        std::vector<glm::vec2> flat(rest.size());
        for (size_t i = 0; i < rest.size(); ++i)
            flat[i] = glm::vec2(rest[i]);
        reference.mapPoints(flat, flat);
        float worst = 0.0f;
        for (size_t i = 0; i < rest.size(); ++i)
            worst = std::max(worst, glm::length(glm::vec2(moved[i]) - flat[i]));
        CHECK(worst <= 1e-5f);

        CHECK_THROWS_WITH(warp.setSourceSegments(std::span(ends).first(3)),
                          Catch::Contains("source segments") && Catch::Contains("has 3 endpoints") &&
                              Catch::Contains("8 (two per segment pair)"));
    }
}

TEST_CASE("Beier-Neely: bit-identical for 1 and 2 threads", "[warp][beier_neely][determinism]") {
    std::mt19937 rng(23);
    const std::vector<SegmentPair> pairs = randomPairs(rng, 9, 200.0f);
    for (auto variant : {BeierNeelyVariant::Original, BeierNeelyVariant::Global}) {
        const BeierNeelyWarp warp(pairs, {variant});
        std::vector<glm::vec2> one(211 * 173), two(211 * 173);
        const int saved = omp_get_max_threads();
        omp_set_num_threads(1);
        warp.mapPixelCentres(211, 173, one);
        omp_set_num_threads(2);
        warp.mapPixelCentres(211, 173, two);
        omp_set_num_threads(saved);
        CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec2)) == 0);
    }
}

TEST_CASE("Beier-Neely: bad input names the segment pair", "[warp][beier_neely][errors]") {
    const SegmentPair good = pair({0, 0}, {10, 0}, {1, 1}, {11, 1});
    auto withSecond = [&](SegmentPair bad) { return std::vector<SegmentPair>{good, bad}; };
    const float nan = std::numeric_limits<float>::quiet_NaN();

    SegmentPair zeroDst = good;
    zeroDst.dstQ = zeroDst.dstP;
    CHECK_THROWS_WITH(
        beierNeelyTransformations(withSecond(zeroDst)),
        Catch::Contains("segment pair 1") && Catch::Contains("destination segment has zero length"));
    SegmentPair zeroSrc = good;
    zeroSrc.srcP = zeroSrc.srcQ;
    CHECK_THROWS_WITH(BeierNeelyWarp(withSecond(zeroSrc)),
                      Catch::Contains("segment pair 1") && Catch::Contains("source segment has zero length"));
    SegmentPair shortDst = good;
    shortDst.dstQ = shortDst.dstP + glm::vec2(1e-6f, 0.0f);
    CHECK_THROWS_WITH(
        beierNeelyMap(8, 8, withSecond(shortDst)),
        Catch::Contains("segment pair 1: destination segment is 1e-06 long (P = (0, 0), Q = (1e-06, 0))") &&
            Catch::Contains("longer than 1e-06"));
    SegmentPair nanEnd = good;
    nanEnd.dstP.y = nan;
    CHECK_THROWS_WITH(beierNeelyMap(8, 8, withSecond(nanEnd)),
                      Catch::Contains("segment pair 1") && Catch::Contains("non-finite endpoint"));
    // Endpoints near float's largest: the length overflowed, the map was inf and the weight message "nan".
    SegmentPair farEnd = good;
    farEnd.srcP = glm::vec2(-3e38f, 0.0f);
    farEnd.srcQ = glm::vec2(3e38f, 0.0f);
    CHECK_THROWS_WITH(beierNeelyMap(8, 8, withSecond(farEnd)),
                      Catch::Contains("segment pair 1: source segment has an endpoint beyond +-1e15") &&
                          Catch::Contains("(expected pixel coordinates within +-1e15"));
    for (float a : {0.0f, -1.0f, nan}) {
        SegmentPair bad = good;
        bad.a = a;
        CHECK_THROWS_WITH(beierNeelyTransformations(withSecond(bad)), Catch::Contains("segment pair 1") &&
                                                                          Catch::Contains("has a = ") &&
                                                                          Catch::Contains("a > 0"));
    }
    SegmentPair badB = good;
    badB.b = -0.5f;
    CHECK_THROWS_WITH(beierNeelyTransformations(withSecond(badB)),
                      Catch::Contains("segment pair 1") && Catch::Contains("b >= 0"));
    SegmentPair badP = good;
    badP.p = nan;
    CHECK_THROWS_WITH(beierNeelyTransformations(withSecond(badP)),
                      Catch::Contains("segment pair 1") && Catch::Contains("p >= 0"));
    CHECK_THROWS_AS(beierNeelyTransformations(withSecond(badP)), InvalidInput);
    // A weight that overflows float on its segment: (10^0 / 0.001)^40 = 1e120. A point on the segment got
    // inf / inf (NaN). Just within float range, (1 / 1e-19)^2 = 1e38, is accepted even over 4 pairs (the
    // sums are in double): a point on the segment maps as one pair maps it; (1 / 1e-20)^2 = 1e40 is not.
    SegmentPair steep = good;
    steep.p = 0.0f;
    steep.a = 0.001f;
    steep.b = 40.0f;
    CHECK_THROWS_WITH(beierNeelyTransformations(withSecond(steep)),
                      Catch::Contains("segment pair 1") &&
                          Catch::Contains("has a weight of inf on its segment") &&
                          Catch::Contains("a larger a, or a smaller p or b"));
    SegmentPair edge = good;
    edge.p = 0.0f;
    edge.a = 1e-19f;
    edge.b = 2.0f;
    const std::vector<glm::vec2> onSegment{{5.0f, 0.0f}};
    std::vector<glm::vec2> four(1), one(1);
    BeierNeelyWarp(std::vector<SegmentPair>{edge, edge, edge, edge}).mapPoints(onSegment, four);
    BeierNeelyWarp(std::vector<SegmentPair>{edge}).mapPoints(onSegment, one);
    CHECK(std::isfinite(four[0].x));
    CHECK(four[0] == one[0]);
    edge.a = 1e-20f;
    CHECK_THROWS_WITH(beierNeelyTransformations(std::vector<SegmentPair>{edge}),
                      Catch::Contains("segment pair 0") && Catch::Contains("has a weight of inf"));

    const BeierNeelyWarp warp({good});
    std::vector<glm::vec2> small(10);
    CHECK_THROWS_WITH(warp.mapPixelCentres(4, 4, small),
                      Catch::Contains("output map") && Catch::Contains("16"));
    CHECK_THROWS_WITH(warp.mapPixelCentres(0, 4, small), Catch::Contains("image size"));
    std::vector<glm::vec3> rest{{0, 0, 0}, {nan, 0, 0}};
    SparseFields fields;
    BeierNeelyWarp w2({good});
    CHECK_THROWS_WITH(w2.bind(rest, fields), Catch::Contains("rest point 1"));
}

TEST_CASE("Beier-Neely: weighting field is (length^p / (a + dist))^b", "[warp][beier_neely]") {
    const SegmentPair s = pair({10, 10}, {30, 10}, {0, 0}, {1, 0}, 2.0f, 1.5f, 0.75f);
    // Beside the middle (dist 5), past the end Q (dist |(35, 14) - (30, 10)|), on the segment (dist 0).
    CHECK(beierNeelyWeight(s, {20, 15}) == Approx(std::pow(std::pow(20.0, 0.75) / 7.0, 1.5)).epsilon(1e-6));
    CHECK(beierNeelyWeight(s, {35, 14}) ==
          Approx(std::pow(std::pow(20.0, 0.75) / (2.0 + std::sqrt(41.0)), 1.5)).epsilon(1e-6));
    CHECK(beierNeelyWeight(s, {12, 10}) == Approx(std::pow(std::pow(20.0, 0.75) / 2.0, 1.5)).epsilon(1e-6));
}
