#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/warp/inversion.h"
#include "deformkit/warp/mesh_warp.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

bool near(const glm::vec3& a, const glm::vec3& b, float tol) {
    return glm::length(a - b) <= tol;
}

std::vector<glm::vec3> randomPoints(int n, float lo, float hi, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(lo, hi);
    std::vector<glm::vec3> p(n);
    for (auto& q : p)
        q = {uni(rng), uni(rng), uni(rng)};
    return p;
}

glm::vec3 rotate(const glm::vec3& v, const glm::vec3& axisAngle) {
    const float a = glm::length(axisAngle);
    const glm::vec3 k = axisAngle / a;
    return v * std::cos(a) + glm::cross(k, v) * std::sin(a) + k * glm::dot(k, v) * (1.0f - std::cos(a));
}

// A point-feature warp in the FFD mould: each feature translates by its offset, with a smooth radial
// weight and a strength falling off with distance, both spatial (so they change if the model moves).
// `linear` optionally makes each transformation a rotation about the feature (not a translation).
class PointWarp : public Warp {
  public:
    std::vector<glm::vec3> centres, offsets;
    float radius = 1.0f;
    float rotationAngle = 0.0f;  // radians about z, about each centre; 0 = translation-only

    void bind(std::span<const glm::vec3> rest, SparseFields& fields) override {
        for (const auto& p : rest) {
            for (size_t i = 0; i < centres.size(); ++i) {
                const float d = glm::length(p - centres[i]) / radius;
                if (d < 1.0f) fields.add(static_cast<int32_t>(i), 1.0f - 0.5f * d, (1.0f - d) * (1.0f - d));
            }
            fields.endPoint();
        }
    }
    void transformations(Transformations& out) const override {
        out.method = ScaleMethod::Displacement;
        out.affine.clear();
        for (size_t i = 0; i < centres.size(); ++i) {
            const float c = std::cos(rotationAngle), s = std::sin(rotationAngle);
            const glm::mat3 r(glm::vec3(c, s, 0), glm::vec3(-s, c, 0), glm::vec3(0, 0, 1));
            out.affine.push_back(Affine::translate(offsets[i]) * Affine::about(r, centres[i]));
        }
    }
};

PointWarp makePointWarp(unsigned seed, float offsetScale) {
    PointWarp w;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    for (int i = 0; i < 6; ++i) {
        w.centres.emplace_back(uni(rng), uni(rng), uni(rng));
        w.offsets.push_back(offsetScale * glm::vec3(uni(rng), uni(rng), uni(rng)));
    }
    w.radius = 1.2f;
    return w;
}

std::vector<glm::vec3> apply(Warp& warp, std::span<const glm::vec3> bindPoints,
                             std::span<const glm::vec3> points) {
    WarpDeformer d(warp);
    d.bind(bindPoints);
    std::vector<glm::vec3> out(points.begin(), points.end());
    d.evaluate(out);
    return out;
}

float maxDistance(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
    float worst = 0.0f;
    for (size_t u = 0; u < a.size(); ++u)
        worst = std::max(worst, glm::length(a[u] - b[u]));
    return worst;
}

}  // namespace

TEST_CASE("inversion: each transformation is inverted", "[mesh_warp][inversion]") {
    Transformations t;
    t.affine.push_back(Affine::translate({1, 2, 3}));
    t.affine.push_back(
        Affine{glm::mat3(glm::vec3(2, 0.5f, 0), glm::vec3(0, 1, 0.3f), glm::vec3(0.1f, 0, 3)), {1, -1, 2}});
    const Transformations inv = invertedTransformations(t);
    REQUIRE(inv.size() == 2);
    CHECK(near(inv.affine[0].translation, {-1, -2, -3}, 1e-6f));
    for (const glm::vec3& p : randomPoints(20, -3, 3, 1)) {
        for (int i = 0; i < 2; ++i)
            CHECK(near(inv.affine[i].apply(t.affine[i].apply(p)), p, 1e-5f));
    }
    // Composition method: a rotation about a pivot then a translation. The inverse about the image of
    // the pivot is the opposite rotation and the opposite translation, so it scales back symmetrically.
    Transformations c;
    c.method = ScaleMethod::Composition;
    Components k;
    k.pivot = {1, 0, 0};
    k.translation = {0, 2, 0};
    k.rotation = {0, 0, 0.6f};
    c.components.push_back(k);
    const Transformations ci = invertedTransformations(c);
    REQUIRE(ci.method == ScaleMethod::Composition);
    CHECK(near(ci.components[0].pivot, {1, 2, 0}, 1e-6f));
    CHECK(near(ci.components[0].translation, {0, -2, 0}, 1e-5f));
    CHECK(near(ci.components[0].rotation, {0, 0, -0.6f}, 1e-5f));
    CHECK(near(ci.components[0].scale, {1, 1, 1}, 1e-5f));
    const glm::vec3 p(0.3f, -0.7f, 1.1f);
    CHECK(near(toAffine(ci.components[0]).apply(toAffine(k).apply(p)), p, 1e-5f));

    Transformations singular;
    singular.affine = {Affine::identity(), Affine{glm::mat3(0.0f), glm::vec3(0.0f)}};
    CHECK_THROWS_WITH(invertedTransformations(singular),
                      Catch::Contains("transformation 1") && Catch::Contains("singular"));
}

TEST_CASE("inversion: translation warp then its inverse with rest-computed fields is the identity",
          "[mesh_warp][inversion]") {
    PointWarp forward = makePointWarp(2, 0.4f);
    const auto rest = randomPoints(5000, -1.5f, 1.5f, 3);
    const auto deformed = apply(forward, rest, rest);
    REQUIRE(maxDistance(deformed, rest) > 0.1f);  // the warp does something

    InvertedWarp inverse(forward);
    const auto back = apply(inverse, rest, deformed);  // fields precomputed on the undeformed model
    CHECK(maxDistance(back, rest) <= 1e-5f);

    // §7.4's caveat: fields re-evaluated on the deformed model break the inverse.
    const auto naive = apply(inverse, deformed, deformed);
    CHECK(maxDistance(naive, rest) > 1e-2f);
}

TEST_CASE("inversion: mesh warp inverse by feature swap", "[mesh_warp][inversion]") {
    const geom::Mesh cage = geom::makeSphere({1.0f, 8, 6});
    const auto rest = randomPoints(4000, -1.3f, 1.3f, 4);

    SECTION("a rigid motion of the whole cage is undone exactly") {
        std::vector<glm::vec3> target;
        const glm::vec3 aa = glm::normalize(glm::vec3(0.2f, 1, -0.4f)) * 0.8f;
        for (const auto& p : cage.points())
            target.push_back(rotate(p, aa) + glm::vec3(0.5f, 0.1f, -0.3f));
        MeshWarp forward(cage);
        forward.setTarget(target);
        const auto deformed = apply(forward, rest, rest);
        REQUIRE(maxDistance(deformed, rest) > 0.5f);
        InvertedWarp inverse(forward);
        CHECK(maxDistance(apply(inverse, rest, deformed), rest) <= 1e-5f);
    }
    SECTION("a general edit is undone exactly at control vertices, approximately elsewhere") {
        std::mt19937 rng(5);
        std::uniform_real_distribution<float> uni(-0.15f, 0.15f);
        std::vector<glm::vec3> target(cage.points().begin(), cage.points().end());
        for (auto& p : target)
            p += glm::vec3(uni(rng), uni(rng), uni(rng));
        MeshWarp forward(cage);
        forward.setTarget(target);
        std::vector<glm::vec3> pts(cage.points().begin(), cage.points().end());
        pts.insert(pts.end(), rest.begin(), rest.end());
        const auto deformed = apply(forward, pts, pts);
        InvertedWarp inverse(forward);
        const auto back = apply(inverse, pts, deformed);
        for (int32_t i = 0; i < cage.numVertices(); ++i)
            CHECK(near(back[i], pts[i], 1e-5f));
        // Between control vertices the average of inverses is not the inverse of the average: the
        // documented limit of §7.4 for non-translation transformations.
        CHECK(maxDistance(back, pts) > 1e-4f);
    }
}

TEST_CASE("commutativity: translation-only warps with precomputed deforming functions commute",
          "[mesh_warp][inversion]") {
    PointWarp a = makePointWarp(6, 0.5f), b = makePointWarp(7, 0.5f);
    const auto rest = randomPoints(5000, -1.5f, 1.5f, 8);
    // Fields (deforming functions) precomputed on the model M for both warps (§7.1).
    SparseFields fa, fb;
    a.bind(rest, fa);
    b.bind(rest, fb);
    Transformations ta, tb;
    a.transformations(ta);
    b.transformations(tb);
    std::vector<glm::vec3> ab(rest.size()), ba(rest.size()), tmp(rest.size());
    evaluateWarp(rest, fa, ta, tmp);
    evaluateWarp(tmp, fb, tb, ab);
    evaluateWarp(rest, fb, tb, tmp);
    evaluateWarp(tmp, fa, ta, ba);
    REQUIRE(maxDistance(ab, rest) > 0.1f);
    CHECK(maxDistance(ab, ba) <= 1e-6f);
    // Reference: with translations and rest fields each point just gets both displacements added.
    std::vector<glm::vec3> da(rest.size()), db(rest.size());
    evaluateWarp(rest, fa, ta, da);
    evaluateWarp(rest, fb, tb, db);
    for (size_t u = 0; u < rest.size(); ++u)
        CHECK(near(ab[u], da[u] + db[u] - rest[u], 1e-5f));

    // Either condition dropped, the warps no longer commute: fields recomputed on the warped model ...
    SparseFields fbAfterA;
    b.bind(std::vector<glm::vec3>(da), fbAfterA);
    std::vector<glm::vec3> abLive(rest.size());
    evaluateWarp(da, fbAfterA, tb, abLive);
    CHECK(maxDistance(abLive, ba) > 1e-2f);
    // ... or transformations that are not translations.
    a.rotationAngle = 0.5f;
    b.rotationAngle = -0.3f;
    a.transformations(ta);
    b.transformations(tb);
    evaluateWarp(rest, fa, ta, tmp);
    evaluateWarp(tmp, fb, tb, ab);
    evaluateWarp(rest, fb, tb, tmp);
    evaluateWarp(tmp, fa, ta, ba);
    CHECK(maxDistance(ab, ba) > 1e-2f);
}
