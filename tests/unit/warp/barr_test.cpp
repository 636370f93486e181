// Barr taper, twist and bend (paper §4.3): closed forms, the engine path against the direct path,
// host parameterisations against hand-worked cases, and bad input.
#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_dcc.h"
#include "deformkit/warp/engine.h"

using namespace deformkit;
using namespace deformkit::warp;
using Catch::Contains;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

float maxDistance(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    float m = 0.0f;
    for (size_t i = 0; i < a.size(); ++i)
        m = std::max(m, glm::length(a[i] - b[i]));
    return m;
}

// An axis frame for the tests, with its own perpendicular pair (e1, e2, axis) right-handed, chosen
// independently of the library's side/up.
struct TestFrame {
    glm::vec3 origin{1.0f, -2.0f, 0.5f};
    glm::vec3 axis = glm::normalize(glm::vec3(1.0f, 2.0f, 2.0f));  // (1,2,2)/3
    glm::vec3 e1 = glm::normalize(glm::vec3(2.0f, -1.0f, 0.0f));   // perpendicular to (1,2,2)
    glm::vec3 e2 = glm::cross(axis, e1);
    [[nodiscard]] glm::vec3 point(float a, float b, float z) const {
        return origin + a * e1 + b * e2 + z * axis;
    }
    [[nodiscard]] AxisFrame frame() const { return {origin, 3.0f * axis, e2}; }
};

std::vector<glm::vec3> randomPoints(int n, float extent, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(-extent, extent);
    std::vector<glm::vec3> p(n);
    for (auto& q : p)
        q = {uni(rng), uni(rng), uni(rng)};
    return p;
}

// Engine path: the warp's fields and per-point transformations through evaluateWarp (Eq. 3).
std::vector<glm::vec3> enginePath(AxialWarp& warp, const std::vector<glm::vec3>& rest,
                                  const std::vector<glm::vec3>& current) {
    SparseFields fields;
    warp.bind(rest, fields);
    Transformations t;
    warp.transformations(t);
    std::vector<glm::vec3> out(current.size());
    evaluateWarp(current, fields, t, out, warp.engineOptions());
    return out;
}

std::vector<glm::vec3> directPath(AxialWarp& warp, const std::vector<glm::vec3>& rest,
                                  const std::vector<glm::vec3>& current) {
    SparseFields fields;
    warp.bind(rest, fields);
    std::vector<glm::vec3> out(current.size());
    warp.evaluate(current, out);
    return out;
}

}  // namespace

TEST_CASE("profile curve: Fritsch-Carlson interpolation, linear precision, constant extension",
          "[barr][warp]") {
    // Samples on the line y = 2 - 0.5 z at uneven spacing: reproduced exactly in between.
    const ProfileCurve line({-2.0f, -0.5f, 1.0f, 4.0f}, {3.0f, 2.25f, 1.5f, 0.0f});
    for (float z = -2.0f; z <= 4.0f; z += 0.37f)
        CHECK(line(z) == Approx(2.0f - 0.5f * z).margin(1e-6));
    CHECK(line(-10.0f) == 3.0f);  // held outside
    CHECK(line(10.0f) == 0.0f);

    // Monotone data with a flat stretch: no overshoot anywhere (a Catmull-Rom spline overshoots here).
    const ProfileCurve step({0.0f, 1.0f, 2.0f, 3.0f}, {0.0f, 0.0f, 1.0f, 1.0f});
    float previous = -1.0f;
    for (float z = 0.0f; z <= 3.0f; z += 0.01f) {
        const float y = step(z);
        CHECK(y >= -1e-7f);
        CHECK(y <= 1.0f + 1e-7f);
        CHECK(y >= previous - 1e-7f);
        previous = y;
    }
    // Hermite interpolation of the middle interval with the limited tangents (0 at both ends):
    // smoothstep 3t^2 - 2t^3, written out.
    CHECK(step(1.25f) == Approx(3 * 0.0625f - 2 * 0.015625f).margin(1e-6));

    // C1 at an interior knot: one-sided difference quotients agree with each other and with the tangent.
    const ProfileCurve smooth({0.0f, 1.0f, 2.5f, 3.0f}, {1.0f, 1.5f, 1.8f, 2.0f});
    const float h = 1e-3f;
    const float left = (smooth(1.0f) - smooth(1.0f - h)) / h, right = (smooth(1.0f + h) - smooth(1.0f)) / h;
    CHECK(left == Approx(right).margin(2e-3));
    // Fritsch-Carlson tangent at knot 1: mean of the secants 0.5 and 0.2 (limiter inactive).
    CHECK(smooth.tangents()[1] == Approx(0.35f));
    CHECK(ProfileCurve::constant(0.7f)(123.0f) == 0.7f);
}

TEST_CASE("profile curve: bad samples are named", "[barr][warp][errors]") {
    CHECK_THROWS_WITH(ProfileCurve({0.0f, 2.0f, 1.0f}, {1.0f, 1.0f, 1.0f}, "taper profile"),
                      Contains("taper profile") && Contains("z_samples[2]") && Contains("ascending"));
    CHECK_THROWS_WITH(ProfileCurve({0.0f, 0.0f}, {1.0f, 1.0f}), Contains("z_samples[1]"));
    CHECK_THROWS_WITH(ProfileCurve({0.0f, 1.0f}, {1.0f}), Contains("value_samples") && Contains("2 entries"));
    CHECK_THROWS_WITH(ProfileCurve({0.0f, 1.0f}, {1.0f, std::nanf("")}), Contains("value_samples[1]"));
    CHECK_THROWS_WITH(ProfileCurve({std::nanf(""), 1.0f}, {1.0f, 1.0f}), Contains("z_samples[0]"));
    CHECK_THROWS_WITH(ProfileCurve({}, {}), Contains("z_samples") && Contains("empty"));
}

TEST_CASE("axis frame: orthonormal, right-handed, bad axes named", "[barr][warp][errors]") {
    const OrthoFrame f = orthonormalFrame({{0, 0, 0}, {0, 0, 5}, {1, 1, 3}}, true, "bend");
    CHECK(glm::length(f.axis - glm::vec3(0, 0, 1)) < 1e-7f);
    CHECK(glm::length(f.up - glm::normalize(glm::vec3(1, 1, 0))) < 1e-6f);
    CHECK(glm::length(glm::cross(f.side, f.up) - f.axis) < 1e-6f);
    CHECK_THROWS_WITH(orthonormalFrame({{0, 0, 0}, {0, 0, 0}, {0, 1, 0}}, false, "taper"),
                      Contains("taper") && Contains("axis_dir") && Contains("zero"));
    // Too short to give a direction, but not zero: said as it is, not as "the zero vector".
    CHECK_THROWS_WITH(orthonormalFrame({{0, 0, 0}, {0, 1e-30f, 0}, {0, 1, 0}}, false, "twist"),
                      Contains("twist: axis_dir: is (0, 1e-30, 0), of length ") &&
                          Contains("(expected a direction longer than 1e-12)"));
    CHECK_THROWS_WITH(orthonormalFrame({{0, 0, 0}, {0, 2, 0}, {0, -3, 0}}, true, "bend"),
                      Contains("up_dir") && Contains("parallel"));
    CHECK_THROWS_WITH(orthonormalFrame({{std::nanf(""), 0, 0}, {0, 0, 1}, {0, 1, 0}}, true, "bend"),
                      Contains("axis_origin"));
    CHECK_THROWS_WITH(orthonormalFrame({{0, 0, 0}, {0, std::numeric_limits<float>::infinity(), 1}, {0, 1, 0}},
                                       true, "bend"),
                      Contains("axis_dir"));
    // Taper and twist accept an up parallel to the axis (they do not use it).
    CHECK_NOTHROW(TaperWarp(AxisFrame{{0, 0, 0}, {0, 1, 0}, {0, 1, 0}}));
    CHECK_THROWS_WITH(BendWarp(AxisFrame{{0, 0, 0}, {0, 1, 0}, {0, 1, 0}}, {}), Contains("up_dir"));
}

TEST_CASE("taper with a linear profile gives the analytic positions", "[barr][warp]") {
    const TestFrame tf;
    // f(z) = 1 + 0.25 z on [-2, 2] (three collinear samples), held outside.
    TaperWarp taper(tf.frame(), ProfileCurve({-2.0f, 0.5f, 2.0f}, {0.5f, 1.125f, 1.5f}));
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> uni(-3.0f, 3.0f);
    std::vector<glm::vec3> rest, expected;
    for (int i = 0; i < 500; ++i) {
        const float a = uni(rng), b = uni(rng), z = uni(rng);
        const float f = 1.0f + 0.25f * std::clamp(z, -2.0f, 2.0f);
        rest.push_back(tf.point(a, b, z));
        expected.push_back(tf.point(f * a, f * b, z));
    }
    CHECK(maxDistance(directPath(taper, rest, rest), expected) < 2e-5f);
    CHECK(maxDistance(enginePath(taper, rest, rest), expected) < 2e-5f);
}

TEST_CASE("twist with theta = c z gives the rotated closed form", "[barr][warp]") {
    const TestFrame tf;
    const float c = 0.8f;  // radians per unit
    TwistWarp twist(tf.frame(), ProfileCurve({-4.0f, 4.0f}, {-4.0f * c, 4.0f * c}));
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> uni(-3.0f, 3.0f);
    std::vector<glm::vec3> rest, expected;
    for (int i = 0; i < 500; ++i) {
        const float a = uni(rng), b = uni(rng), z = uni(rng);
        const float t = c * z;
        rest.push_back(tf.point(a, b, z));
        expected.push_back(tf.point(a * std::cos(t) - b * std::sin(t), a * std::sin(t) + b * std::cos(t), z));
    }
    CHECK(maxDistance(directPath(twist, rest, rest), expected) < 2e-5f);
    CHECK(maxDistance(enginePath(twist, rest, rest), expected) < 2e-5f);
}

TEST_CASE("bend maps the axis segment in range onto the arc of radius 1/k", "[barr][warp]") {
    const TestFrame tf;
    const float k = 0.7f, z0 = 0.5f, lo = -1.5f, hi = 2.0f;
    // up = e2, so the library's up and the test's e2 agree and the centre of curvature is at
    // origin + z0 axis + e2 / k.
    BendWarp bend(tf.frame(), {k, z0, lo, hi});
    const glm::vec3 centre = tf.point(0.0f, 1.0f / k, z0);
    std::vector<glm::vec3> rest;
    const int n = 71;
    for (int i = 0; i < n; ++i)
        rest.push_back(tf.point(0.0f, 0.0f, lo + (hi - lo) * i / (n - 1)));
    for (const auto& out : {directPath(bend, rest, rest), enginePath(bend, rest, rest)}) {
        for (int i = 0; i < n; ++i)
            CHECK(glm::length(out[i] - centre) == Approx(1.0f / k).margin(1e-5));
        // Arc length preserved: the angle subtended between neighbours is spacing * k.
        const float spacing = (hi - lo) / (n - 1);
        for (int i = 0; i + 1 < n; ++i) {
            const glm::vec3 u = glm::normalize(out[i] - centre), v = glm::normalize(out[i + 1] - centre);
            const float angle = std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v));
            CHECK(angle == Approx(spacing * k).margin(2e-5));
        }
        // The centre point is fixed; the start of the range has turned by k (lo - z0).
        CHECK(glm::length(out[(n - 1) * 4 / 7] - rest[(n - 1) * 4 / 7]) < 1e-5f);  // z = 0.5
        const float t = k * (lo - z0);
        CHECK(glm::length(out[0] - tf.point(0.0f, (1.0f - std::cos(t)) / k, z0 + std::sin(t) / k)) < 1e-5f);
    }
    // Off-axis points in range stay at in-plane distance |1/k - y| from the centre (concentric arcs).
    const std::vector<glm::vec3> off{tf.point(0.3f, 0.4f, 1.2f), tf.point(-1.0f, -0.6f, -1.0f)};
    const auto out = directPath(bend, off, off);
    const auto inPlane = [&](const glm::vec3& v) { return v - glm::dot(v, tf.e1) * tf.e1; };
    CHECK(glm::length(inPlane(out[0] - centre)) == Approx(1.0f / k - 0.4f).margin(1e-5));
    CHECK(glm::length(inPlane(out[1] - centre)) == Approx(1.0f / k + 0.6f).margin(1e-5));
    CHECK(glm::dot(out[0] - tf.origin, tf.e1) == Approx(0.3f).margin(1e-5));  // side coordinate kept
}

TEST_CASE("bend continues rigidly and tangentially outside [lo, hi]", "[barr][warp]") {
    const TestFrame tf;
    const float k = -1.1f, z0 = 0.0f, lo = -1.0f, hi = 1.5f;
    BendWarp bend(tf.frame(), {k, z0, lo, hi});
    const float h = 1e-3f;
    std::vector<glm::vec3> rest;
    for (float z : {hi - h, hi, hi + h, hi + 2.0f, lo + h, lo, lo - h, lo - 3.0f})
        rest.push_back(tf.point(0, 0, z));
    const auto out = directPath(bend, rest, rest);
    for (int side = 0; side < 2; ++side) {
        const float edge = side == 0 ? hi : lo, beyond = side == 0 ? 2.0f : -3.0f;
        const glm::vec3 inside = out[4 * side], at = out[4 * side + 1], outside = out[4 * side + 2];
        // Value: continuous; tangent: one-sided difference quotients agree and equal the arc's unit
        // tangent cos(t) axis + sin(t) up at t = k (edge - z0).
        CHECK(glm::length(outside - at) == Approx(h).margin(2e-6));
        const glm::vec3 dIn = (at - inside) / (side == 0 ? h : -h),
                        dOut = (outside - at) / (side == 0 ? h : -h);
        const float t = k * (edge - z0);
        const glm::vec3 tangent = std::cos(t) * tf.axis + std::sin(t) * tf.e2;
        CHECK(glm::length(dIn - tangent) < 2e-3f);
        CHECK(glm::length(dOut - tangent) < 2e-3f);
        // Far outside: exactly on the tangent line, at the rest distance from the range end.
        CHECK(glm::length(out[4 * side + 3] - (at + beyond * tangent)) < 2e-5f);
    }
}

TEST_CASE("Barr identity: f = 1, theta = 0, k = 0", "[barr][warp]") {
    const auto rest = randomPoints(2000, 3.0f, 11);
    const TestFrame tf;
    TaperWarp taper(tf.frame(), ProfileCurve({-1.0f, 0.0f, 2.0f}, {1.0f, 1.0f, 1.0f}));
    TwistWarp twist(tf.frame(), ProfileCurve({-1.0f, 2.0f}, {0.0f, 0.0f}));
    BendWarp bend(tf.frame(), {0.0f, 0.3f, -1.0f, 1.0f});
    for (AxialWarp* w :
         {static_cast<AxialWarp*>(&taper), static_cast<AxialWarp*>(&twist), static_cast<AxialWarp*>(&bend)}) {
        CHECK(maxDistance(directPath(*w, rest, rest), rest) < 1e-6f);
        CHECK(maxDistance(enginePath(*w, rest, rest), rest) < 1e-6f);
    }
    // A tiny non-zero rate is close to the identity too (the k -> 0 form has no 1/k blow-up).
    bend.setParams({1e-30f, 0.3f, -1.0f, 1.0f});
    CHECK(maxDistance(directPath(bend, rest, rest), rest) < 1e-6f);
    CHECK(maxDistance(enginePath(bend, rest, rest), rest) < 1e-6f);
}

TEST_CASE("twist: block sine and cosine over every quadrant and beyond their range", "[barr][warp]") {
    // The direct twist and bend paths take sin/cos of blocks of angles with their own reduction and
    // polynomials (barr.cpp); here against double std::cos/std::sin of the same float angle, with constant
    // profiles so the angle is exactly the sample. Half-steps from -60 to 60 rad, angles just either side of
    // multiples of pi/4 (the quadrant switches), and two beyond the block range (the std:: fallback).
    std::vector<float> angles;
    for (int i = -120; i <= 120; ++i)
        angles.push_back(0.5f * static_cast<float>(i));
    for (int k = -16; k <= 16; ++k) {
        const float at = static_cast<float>(k) * kPi / 4.0f;
        angles.push_back(std::nextafter(at, -1e9f));
        angles.push_back(std::nextafter(at, 1e9f));
    }
    angles.push_back(10000.5f);
    angles.push_back(-9000.25f);
    const std::vector<glm::vec3> rest = {{1.0f, 0.0f, 0.3f}, {0.0f, 1.0f, -2.0f}, {0.6f, -0.8f, 5.0f}};
    float worst = 0.0f;
    for (const float theta : angles) {
        TwistWarp twist({{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}, ProfileCurve::constant(theta));
        const auto out = directPath(twist, rest, rest);
        const double c = std::cos(static_cast<double>(theta)), s = std::sin(static_cast<double>(theta));
        for (size_t i = 0; i < rest.size(); ++i) {
            const glm::dvec3 p(rest[i]);
            const glm::dvec3 expected(c * p.x - s * p.y, s * p.x + c * p.y, p.z);
            worst = std::max(worst, static_cast<float>(glm::length(glm::dvec3(out[i]) - expected)));
        }
    }
    INFO("largest error " << worst);
    CHECK(worst < 1e-6f);
}

TEST_CASE("Barr: the direct path equals the engine path, also on moved points", "[barr][warp]") {
    const auto rest = randomPoints(5000, 2.5f, 12);
    auto moved = rest;
    for (size_t i = 0; i < moved.size(); ++i)
        moved[i] += glm::vec3(0.1f * std::sin(float(i)), 0.05f, -0.02f);
    const TestFrame tf;
    TaperWarp taper(tf.frame(), ProfileCurve({-2.0f, -0.5f, 1.0f, 2.0f}, {0.3f, 1.4f, 0.9f, 2.0f}));
    TwistWarp twist(tf.frame(), ProfileCurve({-2.0f, 0.0f, 2.0f}, {-1.0f, 0.5f, 3.0f}));
    BendWarp bend(tf.frame(), {1.3f, 0.2f, -1.0f, 1.5f});
    for (AxialWarp* w :
         {static_cast<AxialWarp*>(&taper), static_cast<AxialWarp*>(&twist), static_cast<AxialWarp*>(&bend)}) {
        const auto engine = enginePath(*w, rest, moved), direct = directPath(*w, rest, moved);
        CHECK(maxDistance(engine, direct) < 1e-5f);
        CHECK(maxDistance(direct, moved) > 0.1f);  // the warp does something here
    }
}

TEST_CASE("Barr: bind once, change controls, evaluate; weights and envelope", "[barr][warp]") {
    const geom::Mesh grid = geom::makeGrid({20, 20, 2.0f, 2.0f});
    const std::vector<glm::vec3> rest(grid.points().begin(), grid.points().end());
    TwistWarp twist(AxisFrame{{1, 1, 0}, {1, 0, 0}, {0, 0, 1}});
    SparseFields fields;
    twist.bind(rest, fields);
    const auto z = twist.restZ();
    twist.setProfile(ProfileCurve({-1.0f, 1.0f}, {-0.5f, 0.5f}));
    CHECK(twist.restZ() == z);  // a control change does not touch bind data
    std::vector<glm::vec3> full = rest, half = rest;
    twist.deform(full);
    std::vector<float> weights(rest.size(), 1.0f);
    weights[0] = 0.0f;
    twist.deform(half, weights, 0.5f);
    CHECK(half[0] == rest[0]);
    for (size_t i = 1; i < rest.size(); ++i) {
        CHECK(glm::length(half[i] - (rest[i] + 0.5f * (full[i] - rest[i]))) < 1e-6f);
    }
    // The generic deformer over the same warp agrees.
    WarpDeformer deformer(twist);
    deformer.bind(rest);
    std::vector<glm::vec3> generic = rest;
    deformer.evaluate(generic);
    CHECK(maxDistance(generic, full) < 1e-5f);
}

TEST_CASE("Barr: bit-identical output for 1 and 2 threads", "[barr][warp][determinism]") {
    const auto rest = randomPoints(40000, 2.0f, 13);
    const TestFrame tf;
    TaperWarp taper(tf.frame(), ProfileCurve({-2.0f, 0.0f, 2.0f}, {0.5f, 1.5f, 0.8f}));
    TwistWarp twist(tf.frame(), ProfileCurve({-2.0f, 2.0f}, {-2.0f, 2.0f}));
    BendWarp bend(tf.frame(), {0.9f, 0.0f, -1.0f, 1.0f});
    for (AxialWarp* w :
         {static_cast<AxialWarp*>(&taper), static_cast<AxialWarp*>(&twist), static_cast<AxialWarp*>(&bend)}) {
        omp_set_num_threads(1);
        const auto d1 = directPath(*w, rest, rest), e1 = enginePath(*w, rest, rest);
        omp_set_num_threads(2);
        const auto d2 = directPath(*w, rest, rest), e2 = enginePath(*w, rest, rest);
        CHECK(std::memcmp(d1.data(), d2.data(), d1.size() * sizeof(glm::vec3)) == 0);
        CHECK(std::memcmp(e1.data(), e2.data(), e1.size() * sizeof(glm::vec3)) == 0);
    }
    omp_set_num_threads(omp_get_num_procs());
}

TEST_CASE("Barr: bad input is named", "[barr][warp][errors]") {
    const TestFrame tf;
    CHECK_THROWS_WITH(BendWarp(tf.frame(), {1.0f, 0.0f, 2.0f, 1.0f}),
                      Contains("bend") && Contains("lo") && Contains("lo <= hi"));
    CHECK_THROWS_WITH(BendWarp(tf.frame(), {std::nanf(""), 0.0f, -1.0f, 1.0f}), Contains("rate"));
    CHECK_THROWS_WITH(BendWarp(tf.frame(), {1.0f, std::nanf(""), -1.0f, 1.0f}), Contains("centre"));
    BendWarp bend(tf.frame(), {1.0f, 0.0f, -1.0f, 1.0f});
    std::vector<glm::vec3> pts{{0, 0, 0}, {0, std::nanf(""), 0}};
    SparseFields fields;
    CHECK_THROWS_WITH(bend.bind(pts, fields), Contains("bend") && Contains("rest point 1"));
    std::vector<glm::vec3> out(2);
    CHECK_THROWS_WITH(bend.evaluate(pts, out), Contains("before bind"));
    pts[1] = {1, 1, 1};
    bend.bind(pts, fields);
    std::vector<glm::vec3> three(3);
    CHECK_THROWS_WITH(bend.evaluate(pts, three),
                      Contains("output points") && Contains("3 entries") && Contains("2 entries"));
    pts[0].x = std::numeric_limits<float>::infinity();
    CHECK_THROWS_WITH(bend.deform(pts), Contains("point 0"));
    // Moving the frame needs a new bind.
    bend.setFrame({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    CHECK_FALSE(bend.isBound());
}

TEST_CASE("Barr: deform into another buffer names a non-finite input point as it writes",
          "[barr][warp][errors]") {
    // Many blocks, so the parallel pass sees the bad points in several threads; the first one is named, and
    // a finite input gives the in-place deform's bytes.
    const TestFrame tf;
    std::vector<glm::vec3> rest(200000);
    for (size_t u = 0; u < rest.size(); ++u)
        rest[u] = {std::sin(0.001f * u), std::cos(0.0013f * u), -1.0f + 2.0f * u / rest.size()};
    TaperWarp taper(tf.frame(), ProfileCurve({-1.0f, 1.0f}, {0.5f, 1.5f}));
    TwistWarp twist(tf.frame(), ProfileCurve({-1.0f, 1.0f}, {-1.0f, 2.0f}));
    BendWarp bend(tf.frame(), {0.8f, 0.0f, -0.5f, 0.5f});
    BendWarp straight(tf.frame(), {0.0f, 0.0f, -0.5f, 0.5f});
    for (AxialWarp* w : std::initializer_list<AxialWarp*>{&taper, &twist, &bend, &straight}) {
        w->bind(rest);
        std::vector<glm::vec3> out(rest.size()), inPlace = rest;
        w->deform(rest, out, {}, 1.0f);
        w->deform(inPlace);
        CHECK(out == inPlace);
        std::vector<glm::vec3> bad = rest;
        bad[150000].y = std::numeric_limits<float>::infinity();
        bad[70001].z = std::nanf("");
        CHECK_THROWS_WITH(w->deform(bad, out, {}, 0.5f),
                          Contains("point 70001") && Contains("nan") && Contains("finite coordinates"));
    }
}

TEST_CASE("host: Maya bend maps onto Barr's bend (hand-worked)", "[barr][warp][host]") {
    MayaBend maya;
    maya.handleOrigin = {1, 0, 0};
    maya.handleX = {0, 0, 2};  // handle scaled by 2, rotated so its X points along world z
    maya.handleY = {0, 2, 0};
    maya.curvature = 0.5;
    maya.lowBound = -1.0;
    maya.highBound = 2.0;
    const BendSetup s = fromMayaBend(maya);
    CHECK(s.params.rate == Approx(0.25f));
    CHECK(s.params.lo == Approx(-2.0f));
    CHECK(s.params.hi == Approx(4.0f));
    CHECK(s.params.centre == 0.0f);
    // World point (1, 2, 0) is handle y = 1: arc angle 0.25 * 2 = 0.5 rad on radius 4, bending to +z:
    // (1, 4 sin 0.5, 4 (1 - cos 0.5)) = (1, 1.917702, 0.489670).
    BendWarp bend(s.frame, s.params);
    const std::vector<glm::vec3> p{{1, 2, 0}};
    const auto out = directPath(bend, p, p);
    CHECK(glm::length(out[0] - glm::vec3(1.0f, 1.917702f, 0.489670f)) < 1e-5f);
    maya.handleX = {0, 0, 3};
    CHECK_THROWS_WITH(fromMayaBend(maya), Contains("handle scale"));
    maya.handleX = {0, 0, 2};
    maya.lowBound = 3.0;
    CHECK_THROWS_WITH(fromMayaBend(maya), Contains("lowBound"));
    // Values that leave float32's range once scaled to world units (0.5e39 / 2, and 2 * 2e38) are named by
    // what the Maya user typed, not as an inf rate refused later by the bend.
    maya.lowBound = -1.0;
    maya.curvature = 1e39;
    CHECK_THROWS_WITH(fromMayaBend(maya),
                      Contains("Maya bend: rate (curvature over the handle's scale): is 5e+38, "
                               "beyond float32's range"));
    maya.curvature = 0.5;
    maya.highBound = 2e38;
    CHECK_THROWS_WITH(
        fromMayaBend(maya),
        Contains("Maya bend: highBound times the handle's scale: is 4e+38, beyond float32's range"));
}

TEST_CASE("host: Blender SimpleDeform twist, taper, bend (hand-worked)", "[barr][warp][host]") {
    SECTION("twist, deform axis Z, limits [0.25, 0.75] of z in [0, 4]") {
        BlenderSimpleDeform b;
        b.angle = kPi / 2;
        b.lowerLimit = 0.25;
        b.upperLimit = 0.75;
        const std::vector<glm::vec3> mesh{{0, 0, 0}, {0, 0, 4}};
        const AxialSetup s = fromBlenderTwist(b, mesh);
        // Limited range [1, 3], theta(z) = pi/4 clamp(z, 1, 3).
        TwistWarp twist(s.frame, s.profile);
        const std::vector<glm::vec3> p{{1, 0, 2}, {1, 0, 4}, {1, 0, 0}};
        const auto out = directPath(twist, p, p);
        const float r = std::sqrt(0.5f);
        CHECK(glm::length(out[0] - glm::vec3(0, 1, 2)) < 1e-6f);
        CHECK(glm::length(out[1] - glm::vec3(-r, r, 4)) < 1e-6f);
        CHECK(glm::length(out[2] - glm::vec3(r, r, 0)) < 1e-6f);
        b.lowerLimit = 0.8;
        CHECK_THROWS_WITH(fromBlenderTwist(b, mesh), Contains("limits"));
    }
    SECTION("taper, deform axis Z, factor 0.5 over z in [0, 2]") {
        BlenderSimpleDeform b;
        b.factor = 0.5;
        const std::vector<glm::vec3> mesh{{0, 0, 0}, {0, 0, 2}};
        const AxialSetup s = fromBlenderTaper(b, mesh);
        TaperWarp taper(s.frame, s.profile);  // f(z) = 1 + 0.25 clamp(z, 0, 2)
        const std::vector<glm::vec3> p{{2, 1, 1}, {2, 1, 3}};
        const auto out = directPath(taper, p, p);
        CHECK(glm::length(out[0] - glm::vec3(2.5f, 1.25f, 1)) < 1e-6f);
        CHECK(glm::length(out[1] - glm::vec3(3.0f, 1.5f, 3)) < 1e-6f);
    }
    SECTION("bend, deform axis Z: along x towards y") {
        BlenderSimpleDeform b;
        b.angle = kPi;
        const std::vector<glm::vec3> mesh{{-1, 0, 0}, {1, 0, 0}};
        const BendSetup s = fromBlenderBend(b, mesh);  // k = pi / 2 on [-1, 1]
        BendWarp bend(s.frame, s.params);
        const std::vector<glm::vec3> p{{1, 0, 0.3f}, {2, 0, 0}, {-1, 0, 0}};
        const auto out = directPath(bend, p, p);
        const float r = 2.0f / kPi;
        CHECK(glm::length(out[0] - glm::vec3(r, r, 0.3f)) < 1e-6f);
        CHECK(glm::length(out[1] - glm::vec3(r, r + 1.0f, 0)) < 1e-6f);
        CHECK(glm::length(out[2] - glm::vec3(-r, r, 0)) < 1e-6f);
    }
    SECTION("bend, deform axis X: along z towards y") {
        BlenderSimpleDeform b;
        b.angle = kPi / 2;
        b.deformAxis = BlenderAxis::X;
        const std::vector<glm::vec3> mesh{{0, 0, 0}, {0, 0, 2}};
        const BendSetup s = fromBlenderBend(b, mesh);  // k = pi / 4 on [0, 2]
        BendWarp bend(s.frame, s.params);
        const std::vector<glm::vec3> p{{0.5f, 0, 2}};
        const auto out = directPath(bend, p, p);
        CHECK(glm::length(out[0] - glm::vec3(0.5f, 4.0f / kPi, 4.0f / kPi)) < 1e-6f);
        const std::vector<glm::vec3> flat{{0, 0, 1}, {0, 0, 1}};
        CHECK_THROWS_WITH(fromBlenderBend(b, flat), Contains("zero length"));
    }
    SECTION("angles and factors whose rate or values leave float32's range") {
        // Over z in [0, 2]: rate 1e300 / 2; twist values 0 and 1e300; taper 1 + 1e39 (limits whole).
        const std::vector<glm::vec3> mesh{{0, 0, 0}, {0, 0, 2}};
        BlenderSimpleDeform b;
        b.angle = 1e300;
        b.deformAxis = BlenderAxis::X;
        CHECK_THROWS_WITH(fromBlenderBend(b, mesh),
                          Contains("Blender bend: rate (angle over the limited length): is 5e+299, beyond"));
        b.deformAxis = BlenderAxis::Z;
        CHECK_THROWS_WITH(
            fromBlenderTwist(b, mesh),
            Contains("Blender twist: value at the upper limit: is 1e+300, beyond float32's range "
                     "(expected an angle giving a value within float32's range)"));
        b.factor = 2e39;
        CHECK_THROWS_WITH(fromBlenderTaper(b, mesh),
                          Contains("Blender taper: value at the upper limit: is 2e+39"));
    }
}
