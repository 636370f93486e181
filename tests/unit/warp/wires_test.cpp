#include <catch2/catch.hpp>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/warp/curve.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/wires.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Independent references written for the tests: the default falloff and Rodrigues' rotation.
double smoothstepFalloff(double t) {
    return t >= 1.0 ? 0.0 : 1.0 - 3.0 * t * t + 2.0 * t * t * t;
}

glm::dvec3 rotateZ(const glm::dvec3& v, double angle) {
    return {v.x * std::cos(angle) - v.y * std::sin(angle), v.x * std::sin(angle) + v.y * std::cos(angle),
            v.z};
}

std::vector<glm::vec3> line(glm::vec3 a, glm::vec3 b, int segments) {
    std::vector<glm::vec3> out;
    for (int i = 0; i <= segments; ++i)
        out.push_back(a + (b - a) * (static_cast<float>(i) / segments));
    return out;
}

std::vector<glm::vec3> translated(std::vector<glm::vec3> c, glm::vec3 t) {
    for (auto& p : c)
        p += t;
    return c;
}

std::vector<glm::vec3> randomPoints(int n, float lo, float hi, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(lo, hi);
    std::vector<glm::vec3> out(n);
    for (auto& p : out)
        p = {uni(rng), uni(rng), uni(rng)};
    return out;
}

// A bent 3-D reference curve and a wire that translates, bends, twists and stretches it.
Wire bentWire(float radius, float scale) {
    Wire w;
    std::vector<glm::vec3> controls{{0, 0, 0}, {0.5f, 0.3f, 0}, {1, 0, 0.2f}, {1.5f, -0.2f, 0.1f}, {2, 0, 0}};
    w.reference = sampleCurve(controls, CurveType::CatmullRom, 6);
    std::vector<glm::vec3> moved{
        {0, 0.1f, 0}, {0.6f, 0.6f, 0.1f}, {1, 0.2f, 0.6f}, {1.4f, -0.5f, 0.3f}, {2.2f, 0, -0.2f}};
    w.wire = sampleCurve(moved, CurveType::CatmullRom, 6);
    w.radius = radius;
    w.scale = scale;
    return w;
}

// A second, brute-force implementation of both variants in double, for one wire: every segment (original)
// or every arc-length sample (smooth) is visited, no grid; T(v) built from the documented conventions
// (vertex tangents = mean of adjacent unit segment directions, lerped and normalised; minimal rotation;
// composition-method scaling about C(v)); Eq. (3) with weights |d|^m (times f dv for the smooth variant).
glm::dvec3 referenceWires(const Wire& w, const glm::dvec3& p, bool smooth, double m, int K) {
    const size_t n = w.reference.size();
    auto unit = [](glm::dvec3 v) { return glm::length(v) > 0 ? v / glm::length(v) : glm::dvec3(0); };
    auto vertexTangent = [&](const std::vector<glm::vec3>& c, size_t j) {
        glm::dvec3 t(0);
        if (j > 0) t += unit(glm::dvec3(c[j]) - glm::dvec3(c[j - 1]));
        if (j + 1 < n) t += unit(glm::dvec3(c[j + 1]) - glm::dvec3(c[j]));
        return unit(t);
    };
    // (s . T(v))<p> - p at segment j, parameter t.
    auto displacement = [&](size_t j, double t, double s) {
        const glm::dvec3 c = glm::mix(glm::dvec3(w.reference[j]), glm::dvec3(w.reference[j + 1]), t);
        const glm::dvec3 cs = glm::mix(glm::dvec3(w.wire[j]), glm::dvec3(w.wire[j + 1]), t);
        const glm::dvec3 a =
            unit(glm::mix(vertexTangent(w.reference, j), vertexTangent(w.reference, j + 1), t));
        const glm::dvec3 b = unit(glm::mix(vertexTangent(w.wire, j), vertexTangent(w.wire, j + 1), t));
        const glm::dvec3 axis = unit(glm::cross(a, b));
        const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * s;
        glm::dvec3 q = (p - c) * (1.0 + s * (w.scale - 1.0));
        q = q * std::cos(angle) + glm::cross(axis, q) * std::sin(angle) +
            axis * glm::dot(axis, q) * (1 - std::cos(angle));
        return c + s * (cs - c) + q - p;
    };
    const double r = w.radius;
    if (!smooth) {
        double best = INFINITY, bestT = 0;
        size_t bestJ = 0;
        for (size_t j = 0; j + 1 < n; ++j) {
            const glm::dvec3 a(w.reference[j]), ab = glm::dvec3(w.reference[j + 1]) - a;
            const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
            const double d = glm::length(a + t * ab - p);
            if (d < best) best = d, bestJ = j, bestT = t;
        }
        if (best >= r) return p;
        const glm::dvec3 d = displacement(bestJ, bestT, smoothstepFalloff(best / r));
        return glm::length(d) > 0 || m == 0 ? p + d : p;
    }
    std::vector<double> cum{0.0};
    for (size_t j = 1; j < n; ++j)
        cum.push_back(cum.back() + glm::length(glm::dvec3(w.reference[j] - w.reference[j - 1])));
    glm::dvec3 num(0);
    double den = 0;
    for (int k = 0; k < K; ++k) {
        const double target = cum.back() * k / (K - 1);
        size_t j = 0;
        while (j + 2 < n && cum[j + 1] < target)
            ++j;
        const double t = std::clamp((target - cum[j]) / (cum[j + 1] - cum[j]), 0.0, 1.0);
        const double dist =
            glm::length(glm::mix(glm::dvec3(w.reference[j]), glm::dvec3(w.reference[j + 1]), t) - p);
        const double f = smoothstepFalloff(dist / r);
        if (f <= 0) continue;
        const glm::dvec3 d = displacement(j, t, f);
        const double weight = f * (k == 0 || k == K - 1 ? 0.5 : 1.0) * std::pow(glm::length(d), m);
        num += weight * d;
        den += weight;
    }
    return den > 0 ? p + num / den : p;
}

std::vector<glm::vec3> evaluateFast(Wires& wires, const std::vector<glm::vec3>& rest) {
    std::vector<glm::vec3> out = rest;
    wires.bind(rest);
    wires.evaluate(out);
    return out;
}

std::vector<glm::vec3> evaluateGeneric(Wires& wires, const std::vector<glm::vec3>& rest) {
    SparseFields fields;
    wires.bind(rest, fields);
    Transformations t;
    wires.transformations(t);
    std::vector<glm::vec3> out(rest.size());
    evaluateWarp(rest, fields, t, out, wires.engineOptions());
    return out;
}

float maxDistance(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    float worst = 0.0f;
    for (size_t i = 0; i < a.size(); ++i)
        worst = std::max(worst, glm::length(a[i] - b[i]));
    return worst;
}

}  // namespace

TEST_CASE("curve sampling: polyline, Catmull-Rom and Bezier", "[wires][curve]") {
    const std::vector<glm::vec3> c{{0, 0, 0}, {1, 1, 0}, {2, 0, 0}, {3, 1, 0}};
    CHECK(sampleCurve(c, CurveType::Polyline, 5) == c);
    const auto cr = sampleCurve(c, CurveType::CatmullRom, 4);
    REQUIRE(cr.size() == 13);
    for (int i = 0; i < 4; ++i)
        CHECK(glm::length(cr[4 * i] - c[i]) < 1e-6f);  // interpolates its controls
    // Middle span at t = 1/2: (-P0 + 9 P1 + 9 P2 - P3) / 16.
    CHECK(glm::length(cr[6] - (-c[0] + 9.0f * c[1] + 9.0f * c[2] - c[3]) / 16.0f) < 1e-6f);
    const auto bz = sampleCurve(c, CurveType::Bezier, 2);
    REQUIRE(bz.size() == 3);
    CHECK(glm::length(bz[1] - (c[0] + 3.0f * c[1] + 3.0f * c[2] + c[3]) / 8.0f) < 1e-6f);
    // A straight control polygon stays straight (reflected end phantoms).
    for (const auto& p : sampleCurve(line({0, 0, 0}, {3, 0, 0}, 3), CurveType::CatmullRom, 5))
        CHECK(p.y == 0.0f);
    CHECK_THROWS_WITH(sampleCurve(std::vector<glm::vec3>{{0, 0, 0}}, CurveType::CatmullRom, 4, "my curve"),
                      Catch::Contains("my curve") && Catch::Contains("at least 2"));
    CHECK_THROWS_WITH(
        sampleCurve(std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, CurveType::Bezier, 4),
        Catch::Contains("3k + 1"));
    std::vector<glm::vec3> bad = c;
    bad[2].y = NAN;
    CHECK_THROWS_WITH(sampleCurve(bad, CurveType::Polyline, 1, "c"), Catch::Contains("c point 2"));
}

TEST_CASE("wires falloff: default cubic and user ramp", "[wires]") {
    const Falloff f;
    for (double t : {0.0, 0.1, 0.37, 0.5, 0.9, 0.999})
        CHECK(f(static_cast<float>(t)) == Approx(smoothstepFalloff(t)).margin(1e-6));
    CHECK(f(1.0f) == 0.0f);
    CHECK(f(2.0f) == 0.0f);
    // Ramp [1, 0.5, 0]: zero end slopes, interior slope -1 (harmonic mean of secants -1, -1); by the Hermite
    // basis on [0, 0.5] at u = 1/2: 0.5 * 1 + 0.5 * 0.5 - 0.125 * 0.5 * (-1) = 0.8125.
    const Falloff ramp = Falloff::fromSamples({1.0f, 0.5f, 0.0f});
    CHECK(ramp(0.0f) == 1.0f);
    CHECK(ramp(0.25f) == Approx(0.8125f).margin(1e-6));
    CHECK(ramp(0.5f) == Approx(0.5f).margin(1e-6));
    CHECK(ramp(0.75f) == Approx(0.1875f).margin(1e-6));
    CHECK(ramp(1.0f) == 0.0f);
    // f'(0) = f'(1) = 0: a one-sided difference is second order small.
    CHECK(std::abs(ramp(1e-3f) - 1.0f) < 1e-5f);
    CHECK(std::abs(ramp(1.0f - 1e-3f)) < 1e-5f);
    CHECK_THROWS_WITH(Falloff::fromSamples({1.0f, 0.2f}, "wire 0 falloff"),
                      Catch::Contains("wire 0 falloff") && Catch::Contains("f(1) = 0"));
    CHECK_THROWS_WITH(Falloff::fromSamples({1.0f, 1.5f, 0.0f}), Catch::Contains("sample 1"));
    CHECK_THROWS_WITH(Falloff::fromSamples({1.0f}), Catch::Contains("at least 2"));
}

TEST_CASE("wires: identity when the wire equals the reference", "[wires]") {
    const auto rest = randomPoints(3000, -0.5f, 2.5f, 1);
    for (auto variant : {WiresVariant::Original, WiresVariant::Smooth}) {
        Wire w = bentWire(0.8f, 1.0f);
        w.wire = w.reference;
        Wires wires({w}, {variant, 1.0f, 0});
        CHECK(maxDistance(evaluateFast(wires, rest), rest) <= 1e-6f);
        CHECK(maxDistance(evaluateGeneric(wires, rest), rest) <= 1e-6f);
        CHECK(wires.fields().offsets.back() > 300);  // the points really were within reach
    }
}

TEST_CASE("wires: points on the reference curve map onto the wire curve (original, §7.2)", "[wires]") {
    for (float scale : {1.0f, 1.7f}) {
        for (float m : {0.0f, 1.0f, 2.0f}) {
            const Wire w = bentWire(0.5f, scale);
            Wires wires({w}, {WiresVariant::Original, m, 0});
            // Points at vertices and inside segments (not the ends of the open curve's extension).
            std::vector<glm::vec3> rest, expected;
            for (size_t j = 0; j + 1 < w.reference.size(); ++j) {
                for (float t : {0.0f, 0.3f, 0.75f}) {
                    rest.push_back((1 - t) * w.reference[j] + t * w.reference[j + 1]);
                    expected.push_back((1 - t) * w.wire[j] + t * w.wire[j + 1]);
                }
            }
            CHECK(maxDistance(evaluateFast(wires, rest), expected) <= 1e-5f);
            CHECK(maxDistance(evaluateGeneric(wires, rest), expected) <= 1e-5f);
        }
    }
}

TEST_CASE("wires: a translated wire moves points by f(d / r) times the translation", "[wires]") {
    const glm::vec3 offset(0.1f, 0.3f, -0.2f);
    const float r = 0.6f;
    Wire w;
    w.reference = line({0, 0, 0}, {4, 0, 0}, 8);
    w.wire = translated(w.reference, offset);
    w.radius = r;
    std::vector<glm::vec3> rest;
    for (int i = 0; i <= 40; ++i)
        rest.push_back({1.3f + 0.01f * i, 0.02f * i, -0.01f * i});  // d up to 0.9 > r
    for (auto variant : {WiresVariant::Original, WiresVariant::Smooth}) {
        Wires wires({w}, {variant, 1.0f, 0});
        const auto out = evaluateFast(wires, rest);
        for (size_t i = 0; i < rest.size(); ++i) {
            const double d = std::hypot(rest[i].y, rest[i].z);
            // Closed form for the original (rotation 0, scale 1, one entry); the smooth variant's average
            // over samples is checked against its quadrature in the next test.
            if (variant == WiresVariant::Original) {
                const glm::dvec3 expected =
                    glm::dvec3(rest[i]) + smoothstepFalloff(d / r) * glm::dvec3(offset);
                CHECK(glm::length(glm::dvec3(out[i]) - expected) < 1e-6);
            }
            if (d >= r) CHECK(out[i] == rest[i]);  // beyond the dropoff radius: untouched, bit for bit
        }
    }
}

TEST_CASE("wires: smooth variant of a translated wire, against its quadrature written out", "[wires]") {
    // With a pure translation t every sample's transformation is t: Eq. (3) with weights
    // f_k dv_k |f_k t|^m and displacements f_k t, f_k = f(|P - C(v_k)| / r), trapezoidal dv_k.
    const glm::vec3 offset(0, 0.2f, 0);
    Wire w;
    w.reference = line({0, 0, 0}, {2, 0, 0}, 4);
    w.wire = translated(w.reference, offset);
    w.radius = 0.5f;
    const int K = 41;
    const double m = 1.5;
    Wires wires({w}, {WiresVariant::Smooth, static_cast<float>(m), K});
    const std::vector<glm::vec3> rest{
        {1.03f, 0.1f, 0.05f}, {0.1f, -0.2f, 0}, {1.9f, 0.3f, 0.1f}, {1.0f, 0.0f, 0.0f}};
    const auto out = evaluateFast(wires, rest);
    for (size_t i = 0; i < rest.size(); ++i) {
        double num = 0, den = 0;
        for (int k = 0; k < K; ++k) {
            const double x = 2.0 * k / (K - 1);
            const double d = glm::length(glm::dvec3(rest[i]) - glm::dvec3(x, 0, 0));
            const double f = smoothstepFalloff(d / 0.5);
            if (f <= 0) continue;
            const double dv = 2.0 / (K - 1) * (k == 0 || k == K - 1 ? 0.5 : 1.0);
            const double weight = f * dv * std::pow(f * glm::length(glm::dvec3(offset)), m);
            num += weight * f;
            den += weight;
        }
        const glm::dvec3 expected = glm::dvec3(rest[i]) + (num / den) * glm::dvec3(offset);
        CHECK(glm::length(glm::dvec3(out[i]) - expected) < 1e-6);
    }
    // On the curve the smooth variant only approximately interpolates (§5.3): less than the full offset.
    CHECK(out[3].y < 0.2f);
    CHECK(out[3].y > 0.15f);
}

TEST_CASE("wires: rotation and scale of T(v) = X . R . S, composition method", "[wires]") {
    // The whole wire rotated by alpha about z through the origin: tangents rotate by alpha, so R(v) is the
    // same rotation and T(v)<P> = C*(v) + R (P - C(v)) with S = x about C(v).
    const double alpha = 0.6, x = 1.4, r = 0.8;
    Wire w;
    w.reference = line({1, 0, 0}, {3, 0, 0}, 4);
    for (const auto& p : w.reference)
        w.wire.push_back(glm::vec3(rotateZ(glm::dvec3(p), alpha)));
    w.radius = static_cast<float>(r);
    w.scale = static_cast<float>(x);
    Wires wires({w}, {WiresVariant::Original, 1.0f, 0});
    const std::vector<glm::vec3> rest{{2.2f, 0.3f, 0.1f}, {1.5f, -0.4f, 0.0f}, {2.9f, 0.0f, 0.5f}};
    const auto out = evaluateFast(wires, rest);
    for (size_t i = 0; i < rest.size(); ++i) {
        const glm::dvec3 p(rest[i]), c(p.x, 0, 0);
        const double s = smoothstepFalloff(glm::length(p - c) / r);
        // s . T by composition: translation s (C* - C), angle s alpha, scale 1 + s (x - 1), about C.
        const glm::dvec3 cStar = rotateZ(c, alpha);
        const glm::dvec3 expected = c + s * (cStar - c) + rotateZ((p - c) * (1.0 + s * (x - 1.0)), s * alpha);
        CHECK(glm::length(glm::dvec3(out[i]) - expected) < 2e-6);
    }
}

TEST_CASE("wires: two wires combine through the engine's normalised weights", "[wires]") {
    const glm::vec3 t1(0, 0, 0.3f), t2(0, 0, -0.1f);
    Wire a, b;
    a.reference = line({0, 0, 0}, {2, 0, 0}, 4);
    a.wire = translated(a.reference, t1);
    b.reference = line({0, 1, 0}, {2, 1, 0}, 4);
    b.wire = translated(b.reference, t2);
    a.radius = 0.9f;
    b.radius = 0.8f;
    for (double m : {0.0, 1.0, 3.0}) {
        Wires wires({a, b}, {WiresVariant::Original, static_cast<float>(m), 0});
        std::vector<glm::vec3> rest;
        for (int i = 0; i <= 20; ++i)
            rest.push_back({1.0f, 0.05f * i, 0.0f});
        const auto out = evaluateFast(wires, rest);
        CHECK(maxDistance(out, evaluateGeneric(wires, rest)) <= 1e-6f);
        for (size_t i = 0; i < rest.size(); ++i) {
            const double y = rest[i].y;
            const double s1 = smoothstepFalloff(y / 0.9), s2 = smoothstepFalloff((1.0 - y) / 0.8);
            const glm::dvec3 d1 = s1 * glm::dvec3(t1), d2 = s2 * glm::dvec3(t2);
            // Only wires that reach the point have a weight; m = 0 gives weight 1 to each.
            const double w1 = s1 > 0 ? std::pow(glm::length(d1), m) : 0.0,
                         w2 = s2 > 0 ? std::pow(glm::length(d2), m) : 0.0;
            const glm::dvec3 expected = glm::dvec3(rest[i]) + (w1 * d1 + w2 * d2) / (w1 + w2);
            CHECK(glm::length(glm::dvec3(out[i]) - expected) < 1e-6);
        }
    }
}

TEST_CASE("wires: on a tie the nearest point with the smallest parameter wins (original)", "[wires]") {
    // A V: (0, 1, 0) is exactly 1/sqrt(2) from both arms (the arithmetic is exact in float and double).
    Wire w;
    w.reference = {{-1, 1, 0}, {0, 0, 0}, {1, 1, 0}};
    w.wire = {{-1, 1, 0.4f}, {0, 0, 0}, {1, 1, -0.4f}};  // arm midpoints move by +-0.2 in z
    w.radius = 2.0f;
    Wires wires({w}, {WiresVariant::Original, 1.0f, 0});
    const auto out = evaluateFast(wires, {{0, 1, 0}, {-1e-4f, 1, 0}, {1e-4f, 1, 0}});
    CHECK(wires.fields().offsets.back() == 3);
    CHECK(out[0].z > 0.05f);                      // the first arm (smaller parameter) wins
    CHECK(glm::length(out[0] - out[1]) < 1e-3f);  // as for a point just on the first arm's side
    CHECK(out[2].z < -0.05f);                     // the other side follows the second arm
}

TEST_CASE("wires: the original jumps across the medial set, the smooth variant is continuous (§5.3)",
          "[wires]") {
    // A U: left arm x = -1 from y = 2 down to 0, lower half circle of radius 1, right arm x = +1 back up.
    // The wire lifts the left arm by +delta in z and lowers the right arm by -delta (the arc in between
    // tilts linearly), so on the medial line x = 0 (y > 0) the two arms compete.
    const float delta = 0.5f;
    std::vector<glm::vec3> ref;
    for (int i = 0; i < 8; ++i)
        ref.push_back({-1, 2 - 0.25f * i, 0});
    for (int i = 0; i <= 32; ++i) {
        const float a = kPi + kPi * i / 32;  // from (-1, 0) under the centre to (1, 0)
        ref.push_back({std::cos(a), std::sin(a), 0});
    }
    for (int i = 1; i <= 8; ++i)
        ref.push_back({1, 0.25f * i, 0});
    Wire w;
    w.reference = ref;
    for (const auto& p : ref)
        w.wire.push_back(p + glm::vec3(0, 0, -delta * std::clamp(p.x, -1.0f, 1.0f)));
    w.radius = 1.5f;
    // Points on y = 0.7 crossing x = 0, 1e-3 apart, the crossing between two of them.
    std::vector<glm::vec3> rest;
    for (int i = 0; i < 400; ++i)
        rest.push_back({-0.2f + 0.0005f + 1e-3f * i, 0.7f, 0});
    Wires original({w}, {WiresVariant::Original, 1.0f, 0});
    Wires smooth({w}, {WiresVariant::Smooth, 1.0f, 0});
    const auto a = evaluateFast(original, rest), b = evaluateFast(smooth, rest);
    float jumpA = 0, jumpB = 0;
    for (size_t i = 0; i + 1 < rest.size(); ++i) {
        jumpA = std::max(jumpA, glm::length(a[i + 1] - a[i]));
        jumpB = std::max(jumpB, glm::length(b[i + 1] - b[i]));
    }
    // Original: s = f(1 / 1.5) = 0.2593 on either side of x = 0, displacement +-0.2593 delta in z.
    const double s = smoothstepFalloff(1.0 / 1.5);
    CHECK(jumpA == Approx(2 * s * delta).margin(2e-3));
    CHECK(jumpA > 0.2f);
    // Smooth: a Lipschitz warp, so neighbours 1e-3 apart stay O(1e-3) apart (including the 1e-3 spacing).
    CHECK(jumpB < 3e-3f);
    // and symmetric: the point on the medial line does not move in z.
    CHECK(std::abs(b[200].z) < 2e-3f);
}

TEST_CASE("wires: both variants against a brute-force reference implementation", "[wires]") {
    const auto rest = randomPoints(4000, -0.5f, 2.5f, 11);
    const Wire w = bentWire(0.6f, 1.3f);
    for (bool smooth : {false, true}) {
        for (double m : {0.0, 1.0, 2.5}) {
            Wires wires({w},
                        {smooth ? WiresVariant::Smooth : WiresVariant::Original, static_cast<float>(m), 0});
            const auto out = evaluateFast(wires, rest);
            double worst = 0;
            int moved = 0;
            for (size_t i = 0; i < rest.size(); ++i) {
                const glm::dvec3 expected =
                    referenceWires(w, glm::dvec3(rest[i]), smooth, m, wires.smoothSamples(0));
                worst = std::max(worst, glm::length(glm::dvec3(out[i]) - expected));
                moved += glm::length(expected - glm::dvec3(rest[i])) > 1e-3;
            }
            CHECK(worst < 1e-5);
            CHECK(moved > 300);
        }
    }
}

TEST_CASE("wires: fast path equals the generic engine and WarpDeformer", "[wires]") {
    const auto rest = randomPoints(5000, -0.5f, 2.5f, 7);
    Wire second;
    second.reference = line({0, 1, 0}, {2, 1.5f, 0.5f}, 5);
    second.wire = line({0, 1.2f, 0.2f}, {2.3f, 1.0f, 0.9f}, 5);
    second.radius = 0.7f;
    second.scale = 0.8f;
    second.falloff = Falloff::fromSamples({1, 0.9f, 0.4f, 0.1f, 0});
    for (auto variant : {WiresVariant::Original, WiresVariant::Smooth}) {
        Wires wires({bentWire(0.6f, 1.3f), second}, {variant, 1.0f, 0});
        const auto fast = evaluateFast(wires, rest);
        const auto generic = evaluateGeneric(wires, rest);
        CHECK(maxDistance(fast, generic) <= 1e-5f);
        CHECK(maxDistance(fast, rest) > 0.1f);
        // Painted weights and envelope as WarpDeformer applies them.
        std::vector<float> painted(rest.size());
        for (size_t i = 0; i < painted.size(); ++i)
            painted[i] = static_cast<float>(i % 5) / 4.0f;
        WarpDeformer deformer(wires);
        deformer.bind(rest);
        auto viaDeformer = rest;
        deformer.evaluate(viaDeformer, painted, 0.7f);
        auto viaFast = rest;
        wires.bind(rest);
        wires.evaluate(viaFast, painted, 0.7f);
        CHECK(maxDistance(viaDeformer, viaFast) <= 1e-5f);
        // Moving a wire after bind: the cached fields are reused (no rebind) and both paths still agree.
        auto moved = wires.wire(0).wire;
        for (auto& p : moved)
            p.z += 0.3f * p.x;
        wires.setWire(0, moved);
        auto again = rest;
        wires.evaluate(again);
        Transformations t;
        wires.transformations(t);
        std::vector<glm::vec3> engine(rest.size());
        evaluateWarp(rest, wires.fields(), t, engine, wires.engineOptions());
        CHECK(maxDistance(again, engine) <= 1e-5f);
        CHECK(maxDistance(again, fast) > 0.05f);
    }
}

TEST_CASE("wires: an exponent whose weights leave double's range still moves every point it reaches",
          "[wires]") {
    // |d|^400 overflows double for displacements over ~6.3 and underflows for those under ~0.17: the
    // fast path and the engine take such weights relative to the longest displacement, so points move
    // (finite, every point the plain exponent moves) and both paths agree.
    const auto rest = randomPoints(2000, -0.5f, 2.5f, 11);
    for (const float lift : {0.05f, 20.0f}) {
        Wire first = bentWire(0.6f, 1.3f), second;
        second.reference = line({0, 1, 0}, {2, 1.5f, 0.5f}, 5);
        second.wire = line({0, 1, lift}, {2, 1.5f, 0.5f + 1.5f * lift}, 5);
        second.radius = 0.7f;
        for (auto& p : first.wire)
            p.z += lift;
        for (auto variant : {WiresVariant::Original, WiresVariant::Smooth}) {
            CAPTURE(lift, static_cast<int>(variant));
            Wires plain({first, second}, {variant, 1.0f, 0}), steep({first, second}, {variant, 400.0f, 0});
            const auto moved = evaluateFast(plain, rest);
            const auto fast = evaluateFast(steep, rest);
            const auto generic = evaluateGeneric(steep, rest);
            CHECK(maxDistance(fast, generic) <= 1e-5f * std::max(1.0f, lift));
            size_t movedPlain = 0, movedSteep = 0, bad = 0;
            for (size_t i = 0; i < rest.size(); ++i) {
                bad += geom::isFinite(fast[i]) ? 0 : 1;
                movedPlain += moved[i] != rest[i] ? 1 : 0;
                movedSteep += fast[i] != rest[i] ? 1 : 0;
            }
            CHECK(bad == 0);
            CHECK(movedPlain > 100);
            CHECK(movedSteep == movedPlain);
        }
    }
}

TEST_CASE("wires: displacements whose squared length overflows float still move the points", "[wires]") {
    // A scale of 1e21 moves points ~1e20 away: |d|^2 beyond float's range made every weight inf / inf and
    // left the points unmoved. Against the brute-force reference in double, within 1e-7 of the scale: float's
    // precision of the largest displacements (near the dropoff's edge the falloff of a point's float
    // distance differs from the double one by more than 1e-5 of that point's own, small, travel).
    const auto rest = randomPoints(500, -0.5f, 2.5f, 5);
    Wire wire = bentWire(0.6f, 1.3f);
    wire.scale = 1e21f;
    for (bool smooth : {false, true}) {
        CAPTURE(smooth);
        Wires wires({wire}, {smooth ? WiresVariant::Smooth : WiresVariant::Original, 1.0f, 0});
        const auto got = evaluateFast(wires, rest);
        size_t far = 0;
        for (size_t i = 0; i < rest.size(); ++i) {
            CAPTURE(i);
            const glm::dvec3 expected =
                referenceWires(wire, glm::dvec3(rest[i]), smooth, 1.0, wires.smoothSamples(0));
            const double travel = glm::length(expected - glm::dvec3(rest[i]));
            REQUIRE(geom::isFinite(got[i]));
            CHECK(glm::length(glm::dvec3(got[i]) - expected) <= 1e-7 * 1e21);
            far += travel > 1.9e19 ? 1 : 0;
        }
        CHECK(far > 10);  // the case that overflowed is there
        CHECK(maxDistance(evaluateGeneric(wires, rest), got) <= 1e-5f * 1e21f);
    }
}

TEST_CASE("wires: bit-identical for 1 and 2 threads", "[wires][determinism]") {
    const auto rest = randomPoints(40000, -0.5f, 2.5f, 3);
    for (auto variant : {WiresVariant::Original, WiresVariant::Smooth}) {
        Wires wires({bentWire(0.7f, 1.2f)}, {variant, 1.0f, 0});
        omp_set_num_threads(1);
        const auto one = evaluateFast(wires, rest);
        const SparseFields f1 = wires.fields();
        omp_set_num_threads(2);
        const auto two = evaluateFast(wires, rest);
        const SparseFields& f2 = wires.fields();
        CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec3)) == 0);
        REQUIRE(f1.offsets == f2.offsets);
        CHECK(std::memcmp(f1.strength.data(), f2.strength.data(), f1.strength.size() * sizeof(float)) == 0);
        CHECK(f1.transform == f2.transform);
    }
    omp_set_num_threads(omp_get_num_procs());
}

TEST_CASE("wires: smooth sample count, automatic and given", "[wires]") {
    Wire w;
    w.reference = line({0, 0, 0}, {3, 0, 0}, 3);
    w.wire = w.reference;
    w.radius = 0.5f;
    CHECK(Wires({w}).smoothSamples(0) == 49);  // ceil(8 * 3 / 0.5) + 1
    w.radius = 10.0f;
    CHECK(Wires({w}).smoothSamples(0) == 16);  // the floor
    CHECK(Wires({w}, {WiresVariant::Smooth, 1.0f, 7}).smoothSamples(0) == 7);
}

TEST_CASE("wires: bad input names the element", "[wires][errors]") {
    Wire good;
    good.reference = line({0, 0, 0}, {1, 0, 0}, 2);
    good.wire = good.reference;
    auto make = [&](auto edit, WiresOptions o = {}) {
        Wire bad = good;
        edit(bad);
        return Wires({good, bad}, o);
    };
    CHECK_THROWS_WITH(make([](Wire& w) { w.wire.pop_back(); }), Catch::Contains("wire 1 wire curve") &&
                                                                    Catch::Contains("2 points") &&
                                                                    Catch::Contains("3 points"));
    CHECK_THROWS_WITH(make([](Wire& w) {
                          w.reference.resize(1);
                          w.wire.resize(1);
                      }),
                      Catch::Contains("wire 1 reference curve") && Catch::Contains("at least 2"));
    CHECK_THROWS_WITH(make([](Wire& w) { w.radius = 0.0f; }),
                      Catch::Contains("wire 1 radius") && Catch::Contains("> 0"));
    CHECK_THROWS_WITH(make([](Wire& w) { w.radius = -1.0f; }), Catch::Contains("wire 1 radius"));
    CHECK_THROWS_WITH(make([](Wire& w) { w.radius = NAN; }), Catch::Contains("wire 1 radius"));
    CHECK_THROWS_WITH(make([](Wire& w) { w.scale = 0.0f; }), Catch::Contains("wire 1 scale"));
    CHECK_THROWS_WITH(make([](Wire& w) { w.wire[1].y = NAN; }), Catch::Contains("wire 1 wire curve point 1"));
    CHECK_THROWS_WITH(make([](Wire& w) { w.reference[2].x = INFINITY; }),
                      Catch::Contains("wire 1 reference curve point 2"));
    CHECK_THROWS_WITH(make([](Wire& w) { w.reference.assign(3, glm::vec3(1.0f)); }),
                      Catch::Contains("length 0"));
    CHECK_THROWS_WITH(make([](Wire&) {}, {WiresVariant::Original, -1.0f, 0}), Catch::Contains("exponent m"));
    CHECK_THROWS_WITH(make([](Wire&) {}, {WiresVariant::Original, NAN, 0}), Catch::Contains("exponent m"));
    CHECK_THROWS_WITH(make([](Wire&) {}, {WiresVariant::Smooth, 1.0f, 1}), Catch::Contains("smooth samples"));

    Wires wires({good, good});
    CHECK_THROWS_WITH(wires.setWire(1, std::vector<glm::vec3>(2)), Catch::Contains("wire 1 wire curve"));
    CHECK_THROWS_WITH(wires.setWire(2, good.wire), Catch::Contains("wire index 2"));
    std::vector<glm::vec3> nanCurve = good.wire;
    nanCurve[0].z = NAN;
    CHECK_THROWS_WITH(wires.setWire(0, nanCurve), Catch::Contains("wire 0 wire curve point 0"));
    CHECK(wires.wire(0).wire == good.wire);  // a rejected curve changes nothing

    // Beyond +-1e15 squared distances near float's limit (past 1.8e19 they overflowed, and the points were
    // left unmoved without a word): refused with the coordinates.
    std::vector<glm::vec3> farCurve = good.wire;
    farCurve[1].x = 2e19f;
    CHECK_THROWS_WITH(wires.setWire(0, farCurve),
                      Catch::Contains("wire 0 wire curve point 1: is (2e+19, ") &&
                          Catch::Contains("(expected finite coordinates within +-1e15"));
    CHECK(wires.wire(0).wire == good.wire);

    std::vector<glm::vec3> pts{{0, 0, 0}, {0.5f, NAN, 0}};
    CHECK_THROWS_WITH(wires.bind(pts), Catch::Contains("rest point 1"));
    pts[1] = {0.5f, 0.0f, -3e19f};
    CHECK_THROWS_WITH(wires.bind(pts), Catch::Contains("rest point 1: is (0.5, 0, -3e+19)"));
    std::vector<glm::vec3> three(3);
    CHECK_THROWS_WITH(wires.evaluate(three), Catch::Contains("before bind"));
    wires.bind(std::vector<glm::vec3>(2));
    CHECK_THROWS_WITH(wires.evaluate(three), Catch::Contains("points") && Catch::Contains("2 entries"));
    std::vector<glm::vec3> two(2);
    CHECK_THROWS_WITH(wires.evaluate(two, std::vector<float>(5)), Catch::Contains("painted weights"));
}
