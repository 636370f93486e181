#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/warp/mesh_warp.h"
#include "deformkit/warp/morph.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

bool near(const glm::vec3& a, const glm::vec3& b, float tol) {
    return glm::length(a - b) <= tol;
}

float maxDistance(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
    float worst = 0.0f;
    for (size_t u = 0; u < a.size(); ++u)
        worst = std::max(worst, glm::length(a[u] - b[u]));
    return worst;
}

struct Setup {
    geom::Mesh cage = geom::makeSphere({1.0f, 8, 6});
    std::vector<glm::vec3> rest, target;
    SparseFields fields;
    Transformations transforms;

    Setup() {
        std::mt19937 rng(21);
        std::uniform_real_distribution<float> uni(-1.3f, 1.3f), small(-0.25f, 0.25f);
        for (int i = 0; i < 4000; ++i)
            rest.emplace_back(uni(rng), uni(rng), uni(rng));
        target.assign(cage.points().begin(), cage.points().end());
        for (auto& p : target)
            p += glm::vec3(small(rng), small(rng), small(rng));
        MeshWarp warp(cage);
        warp.setTarget(target);
        warp.bind(rest, fields);
        warp.transformations(transforms);
    }
    std::vector<glm::vec3> eval(const SparseFields& f, const Transformations& t) const {
        std::vector<glm::vec3> out(rest.size());
        evaluateWarp(rest, f, t, out);
        return out;
    }
};

}  // namespace

TEST_CASE("morph: t = 0 is the identity and t = 1 the full warp, all three ways", "[mesh_warp][morph]") {
    const Setup s;
    const auto full = s.eval(s.fields, s.transforms);
    REQUIRE(maxDistance(full, s.rest) > 0.1f);
    for (const float t : {0.0f, 1.0f}) {
        const auto& expected = t == 0.0f ? s.rest : full;
        std::vector<glm::vec3> env(s.rest.size());
        morphByEnvelope(s.rest, full, t, env);
        CHECK(maxDistance(env, expected) <= 1e-6f);
        Transformations tt;
        morphTransformations(s.transforms, std::vector<float>{t}, tt);
        CHECK(maxDistance(s.eval(s.fields, tt), expected) <= 1e-6f);
        SparseFields ff;
        morphStrengths(s.fields, t, ff);
        CHECK(maxDistance(s.eval(ff, s.transforms), expected) <= 1e-6f);
    }
}

TEST_CASE("morph: with the displacement method all three ways agree with the envelope blend",
          "[mesh_warp][morph]") {
    const Setup s;
    const auto full = s.eval(s.fields, s.transforms);
    for (const float t : {0.25f, 0.6f}) {
        std::vector<glm::vec3> reference(s.rest.size());
        for (size_t u = 0; u < s.rest.size(); ++u)
            reference[u] = s.rest[u] + t * (full[u] - s.rest[u]);
        std::vector<glm::vec3> env(s.rest.size());
        morphByEnvelope(s.rest, full, t, env);
        CHECK(maxDistance(env, reference) <= 1e-6f);
        Transformations tt;
        morphTransformations(s.transforms, std::vector<float>{t}, tt);
        CHECK(maxDistance(s.eval(s.fields, tt), reference) <= 1e-5f);
        SparseFields ff;
        morphStrengths(s.fields, t, ff);
        CHECK(maxDistance(s.eval(ff, s.transforms), reference) <= 1e-5f);
    }
}

TEST_CASE("morph: a per-transformation schedule morphs parts of the model at their own rates",
          "[mesh_warp][morph]") {
    const Setup s;
    const int32_t n = s.transforms.size();
    std::vector<float> start(n), end(n), ti(n);
    for (int32_t i = 0; i < n; ++i) {
        start[i] = 0.1f * static_cast<float>(i % 5);
        end[i] = start[i] + 1.0f;
    }
    morphSchedule(0.3f, start, end, ti);
    CHECK(ti[0] == Approx(0.3f));
    CHECK(ti[3] == Approx(0.0f));
    CHECK(ti[1] == Approx(0.2f));
    morphSchedule(5.0f, start, end, ti);
    CHECK(ti[4] == 1.0f);
    morphSchedule(0.35f, start, end, ti);
    Transformations tt;
    morphTransformations(s.transforms, ti, tt);
    const auto out = s.eval(s.fields, tt);
    const auto full = s.eval(s.fields, s.transforms);
    // Reference: each point's displacement is the weighted average of its transformations' full
    // displacements scaled by their own t_i (Eq. 3 with t_i . T_i).
    for (size_t u = 0; u < s.rest.size(); ++u) {
        glm::dvec3 sum(0.0);
        double wsum = 0.0;
        for (int32_t e = s.fields.offsets[u]; e < s.fields.offsets[u + 1]; ++e) {
            const int32_t i = s.fields.transform[e];
            sum += double(s.fields.weight[e]) * double(ti[i]) *
                   glm::dvec3(s.transforms.affine[i].apply(s.rest[u]) - s.rest[u]);
            wsum += s.fields.weight[e];
        }
        const glm::vec3 expected = wsum > 0 ? s.rest[u] + glm::vec3(sum / wsum) : s.rest[u];
        CHECK(near(out[u], expected, 1e-5f));
    }
    CHECK(maxDistance(out, full) > 1e-2f);
    std::vector<float> badEnd = end;
    badEnd[1] = start[1];
    CHECK_THROWS_WITH(morphSchedule(0.0f, start, badEnd, ti), Catch::Contains("schedule entry 1"));
    CHECK_THROWS_WITH(morphTransformations(s.transforms, std::vector<float>{0.1f, 0.2f}, tt),
                      Catch::Contains("morph parameters t") && Catch::Contains("has 2 entries"));
    CHECK_THROWS_WITH(morphTransformations(s.transforms, std::vector<float>{NAN}, tt),
                      Catch::Contains("t[0]"));
    std::vector<glm::vec3> out2(s.rest.size());
    CHECK_THROWS_AS(morphByEnvelope(s.rest, out, NAN, out2), InvalidInput);
}

TEST_CASE("morph: the composition method swings through the arc, unlike the envelope blend",
          "[mesh_warp][morph]") {
    Transformations t;
    t.method = ScaleMethod::Composition;
    Components c;
    c.rotation = {0, 0, std::numbers::pi_v<float> / 2};
    t.components.push_back(c);
    SparseFields f;
    f.add(0, 1.0f, 1.0f);
    f.endPoint();
    const std::vector<glm::vec3> p{{1, 0, 0}};
    std::vector<glm::vec3> full(1), half(1), env(1);
    evaluateWarp(p, f, t, full);
    Transformations th;
    morphTransformations(t, std::vector<float>{0.5f}, th);
    evaluateWarp(p, f, th, half);
    morphByEnvelope(p, full, 0.5f, env);
    CHECK(near(half[0], {std::sqrt(0.5f), std::sqrt(0.5f), 0}, 1e-6f));
    CHECK(near(env[0], {0.5f, 0.5f, 0}, 1e-6f));
}

TEST_CASE("morph: animating the target features (the fourth way)", "[mesh_warp][morph]") {
    const Setup s;
    std::vector<glm::vec3> mid(s.target.size());
    MeshWarp warp(s.cage);
    WarpDeformer deformer(warp);
    deformer.bind(s.rest);
    for (const float t : {0.0f, 1.0f}) {
        morphTargets(s.cage.points(), s.target, t, mid);
        warp.setTarget(mid);
        auto out = s.rest;
        deformer.evaluate(out);
        CHECK(maxDistance(out, t == 0.0f ? s.rest : s.eval(s.fields, s.transforms)) <= 1e-6f);
    }
    morphTargets(s.cage.points(), s.target, 0.5f, mid);
    CHECK(near(mid[3], 0.5f * (s.cage.points()[3] + s.target[3]), 1e-6f));
}
