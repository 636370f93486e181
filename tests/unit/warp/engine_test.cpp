#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/engine.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

// Rodrigues' formula, written independently of the library's Eigen path.
glm::vec3 rotateAbout(const glm::vec3& v, const glm::vec3& axisAngle) {
    const float a = glm::length(axisAngle);
    if (a == 0.0f) return v;
    const glm::vec3 k = axisAngle / a;
    return v * std::cos(a) + glm::cross(k, v) * std::sin(a) + k * glm::dot(k, v) * (1.0f - std::cos(a));
}

bool near(const glm::vec3& a, const glm::vec3& b, float tol) {
    return glm::length(a - b) <= tol;
}

// The engine's result at the origin for two translations by `a` and `b`, weights 1 and 1, with the
// displacement-weight exponent `m`.
glm::vec3 meanOfTwo(const glm::vec3& a, const glm::vec3& b, float m) {
    const std::vector<glm::vec3> points{{0, 0, 0}};
    Transformations t;
    t.affine = {Affine::translate(a), Affine::translate(b)};
    SparseFields f;
    f.add(0, 1.0f, 1.0f);
    f.add(1, 1.0f, 1.0f);
    f.endPoint();
    std::vector<glm::vec3> out(1);
    evaluateWarp(points, f, t, out, {m});
    return out[0];
}

}  // namespace

TEST_CASE("transform components recompose and decompose", "[warp][transform]") {
    Components c;
    c.pivot = {1, 2, 3};
    c.translation = {0.5f, -1, 2};
    c.rotation = glm::normalize(glm::vec3(1, 2, -1)) * 0.7f;
    c.scale = {2, 0.5f, 1.5f};
    c.shear = {0.3f, -0.2f, 0.1f};
    const Affine t = toAffine(c);
    // Reference: apply shear, scale, rotation about the pivot, then translate, step by step.
    const glm::vec3 p(0.3f, -0.8f, 2.2f);
    glm::vec3 q = p - c.pivot;
    q = {q.x + c.shear.x * q.y + c.shear.y * q.z, q.y + c.shear.z * q.z, q.z};
    q *= c.scale;
    q = rotateAbout(q, c.rotation) + c.pivot + c.translation;
    CHECK(near(t.apply(p), q, 1e-5f));

    const Components d = decompose(t, c.pivot);
    CHECK(near(d.rotation, c.rotation, 1e-5f));
    CHECK(near(d.scale, c.scale, 1e-5f));
    CHECK(near(d.shear, c.shear, 1e-5f));
    CHECK(near(d.translation, c.translation, 1e-5f));
    CHECK(near(toAffine(d).apply(p), t.apply(p), 1e-5f));

    const Affine inv = inverse(t);
    CHECK(near(inv.apply(t.apply(p)), p, 1e-5f));
    CHECK_THROWS_AS(inverse(Affine{glm::mat3(0.0f), glm::vec3(0.0f)}), InvalidInput);
}

TEST_CASE("scalar times transformation: displacement and composition methods", "[warp][transform]") {
    Components c;
    c.rotation = {0, 0, std::numbers::pi_v<float> / 2};
    const Affine t = toAffine(c);
    const glm::vec3 p(1, 0, 0);
    // Displacement method: half of the displacement (1,0,0) -> (0,1,0).
    CHECK(near(scaleByDisplacement(t, 0.5f).apply(p), glm::vec3(0.5f, 0.5f, 0), 1e-6f));
    // Composition method: half the angle, so the point stays on the unit circle.
    CHECK(near(toAffine(scaleByComposition(c, 0.5f)).apply(p), glm::vec3(std::sqrt(0.5f), std::sqrt(0.5f), 0),
               1e-6f));
    CHECK(near(toAffine(scaleByComposition(c, 0.0f)).apply(p), p, 0.0f));
    Components s;
    s.scale = {3, 3, 3};
    CHECK(toAffine(scaleByComposition(s, 0.5f)).linear[0][0] == Approx(2.0f));
}

TEST_CASE("engine: Eq. 3 weighted average of scaled transformations", "[warp][engine]") {
    const std::vector<glm::vec3> points{{0, 0, 0}, {1, 0, 0}, {5, 5, 5}};
    Transformations t;
    t.affine = {Affine::translate({1, 0, 0}), Affine::translate({0, 2, 0})};
    SparseFields f;
    f.add(0, 1.0f, 1.0f);  // point 0: both, weights 1 and 3
    f.add(1, 1.0f, 3.0f);
    f.endPoint();
    f.add(0, 0.5f, 2.0f);  // point 1: one, half strength
    f.endPoint();
    f.add(1, 1.0f, 0.0f);  // point 2: zero weight -> identity
    f.endPoint();
    std::vector<glm::vec3> out(3);
    evaluateWarp(points, f, t, out);
    CHECK(near(out[0], glm::vec3(0.25f, 1.5f, 0), 1e-6f));
    CHECK(near(out[1], glm::vec3(1.5f, 0, 0), 1e-6f));
    CHECK(out[2] == points[2]);

    f.transform[0] = 7;
    CHECK_THROWS_WITH(evaluateWarp(points, f, t, out),
                      Catch::Contains("field entry 0") && Catch::Contains("[0, 2)"));
    std::vector<glm::vec3> wrong(2);
    CHECK_THROWS_AS(evaluateWarp(points, f, t, wrong), InvalidInput);
}

TEST_CASE("engine: displacement-weight exponent (Wires weighting)", "[warp][engine]") {
    // Weights 1^2 and 3^2: (1 * 1 + 9 * 3) / 10.
    CHECK(meanOfTwo({1, 0, 0}, {3, 0, 0}, 2.0f).x == Approx(2.8f));
}

TEST_CASE("engine: a displacement-weight exponent beyond double's range gives the same mean",
          "[warp][engine]") {
    // Two translations along x and y, lengths L and 1.002 L, weights 1 and 1, exponent 400: the weights
    // (L)^400 and (1.002 L)^400 overflow double for L = 10 and underflow it for L = 0.1, but their ratio
    // r = 1.002^400 does not. The mean: (d1 + r d2) / (1 + r), r computed here in log space.
    const double r = std::exp(400.0 * std::log(1.002));
    for (const float length : {10.0f, 0.1f, 1.0f}) {
        const glm::vec3 a(length, 0, 0), b(0, 1.002f * length, 0);
        const glm::vec3 out = meanOfTwo(a, b, 400.0f);
        // The lengths as float holds them, in the ratio's place.
        const double l1 = length, l2 = static_cast<double>(1.002f * length);
        const double ratio = std::exp(400.0 * std::log(l2 / l1));
        CHECK(ratio == Approx(r).epsilon(1e-3));
        CAPTURE(length);
        CHECK(std::isfinite(out.x));
        CHECK(out.x == Approx(l1 / (1.0 + ratio)).epsilon(1e-5));
        CHECK(out.y == Approx(ratio * l2 / (1.0 + ratio)).epsilon(1e-5));
        CHECK(out.z == 0.0f);
        // An entry of weight 0 changes nothing, even one whose |d|^400 overflows (0 inf was NaN).
        const std::vector<glm::vec3> points{{0, 0, 0}};
        Transformations t;
        t.affine = {Affine::translate(a), Affine::translate(b), Affine::translate({0, 0, 100.0f})};
        SparseFields g;
        g.add(0, 1.0f, 1.0f);
        g.add(2, 1.0f, 0.0f);
        g.add(1, 1.0f, 1.0f);
        g.endPoint();
        std::vector<glm::vec3> with(1);
        evaluateWarp(points, g, t, with, {400.0f});
        CHECK(with[0] == out);
    }
}

TEST_CASE("engine: bit-identical for 1 and 2 threads", "[warp][engine][determinism]") {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    const int n = 20000, k = 16;
    std::vector<glm::vec3> points(n);
    for (auto& p : points)
        p = {uni(rng), uni(rng), uni(rng)};
    Transformations t;
    t.method = ScaleMethod::Composition;
    for (int i = 0; i < k; ++i) {
        Components c;
        c.pivot = {uni(rng), uni(rng), uni(rng)};
        c.rotation = {uni(rng), uni(rng), uni(rng)};
        c.translation = {uni(rng), uni(rng), uni(rng)};
        c.scale = glm::vec3(1.2f);
        t.components.push_back(c);
    }
    SparseFields f;
    for (int u = 0; u < n; ++u) {
        for (int i = u % 3; i < k; i += 3)
            f.add(i, 0.5f + 0.5f * uni(rng), 1.0f + uni(rng));
        f.endPoint();
    }
    std::vector<glm::vec3> one(n), two(n);
    omp_set_num_threads(1);
    evaluateWarp(points, f, t, one);
    omp_set_num_threads(2);
    evaluateWarp(points, f, t, two);
    CHECK(std::memcmp(one.data(), two.data(), n * sizeof(glm::vec3)) == 0);
}

namespace {

// A studio warp: translate everything within `radius` of `centre` by `offset`, fading linearly.
class PushWarp : public Warp {
  public:
    glm::vec3 centre{0.0f}, offset{0.0f};
    float radius = 1.0f;
    void bind(std::span<const glm::vec3> rest, SparseFields& fields) override {
        for (const auto& p : rest) {
            const float d = glm::length(p - centre);
            if (d < radius) fields.add(0, 1.0f - d / radius, 1.0f);
            fields.endPoint();
        }
    }
    void transformations(Transformations& out) const override {
        out.method = ScaleMethod::Displacement;
        out.affine.assign(1, Affine::translate(offset));
    }
};

}  // namespace

TEST_CASE("a custom warp plugs into the deformer: bind once, evaluate with weights and envelope",
          "[warp][engine]") {
    PushWarp push;
    push.offset = {0, 1, 0};
    WarpDeformer deformer(push);
    std::vector<glm::vec3> pts{{0, 0, 0}, {0.5f, 0, 0}, {2, 0, 0}};
    CHECK_THROWS_AS(deformer.evaluate(pts), InvalidInput);
    deformer.bind(pts);
    const std::vector<glm::vec3> rest = pts;
    deformer.evaluate(pts, std::vector<float>{1.0f, 1.0f, 1.0f}, 1.0f);
    CHECK(pts[0].y == Approx(1.0f));
    CHECK(pts[1].y == Approx(0.5f));
    CHECK(pts[2].y == 0.0f);
    pts = rest;
    deformer.evaluate(pts, std::vector<float>{0.5f, 1.0f, 1.0f}, 0.5f);
    CHECK(pts[0].y == Approx(0.25f));
    CHECK(pts[1].y == Approx(0.25f));
    push.offset = {0, 0, 0};  // targets equal sources: identity
    pts = rest;
    deformer.evaluate(pts);
    CHECK(pts == rest);
}
