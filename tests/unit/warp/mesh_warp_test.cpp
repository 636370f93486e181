#include <catch2/catch.hpp>

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <set>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/warp/mesh_warp.h"
#include "mesh_support.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

bool near(const glm::vec3& a, const glm::vec3& b, float tol) {
    return glm::length(a - b) <= tol;
}

geom::Mesh makeMeshFrom(std::vector<glm::vec3> points, std::vector<std::vector<int32_t>> faces) {
    geom::Mesh::Data d;
    d.points = std::move(points);
    for (const auto& f : faces) {
        d.faceCounts.push_back(static_cast<int32_t>(f.size()));
        d.faceIndices.insert(d.faceIndices.end(), f.begin(), f.end());
    }
    return geom::Mesh(std::move(d), "test cage");
}

// Octahedron of radius 1: every star spans 3-space, and no vertex lies in another's support.
geom::Mesh octahedron() {
    return makeMeshFrom(
        {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
        {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

// Unit cube: three edges per corner, so E is square and A = E^-1 E*.
geom::Mesh cube() {
    std::vector<glm::vec3> p;
    for (int i = 0; i < 8; ++i)
        p.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    return makeMeshFrom(p,
                        {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
}

std::vector<glm::vec3> randomPoints(int n, float lo, float hi, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(lo, hi);
    std::vector<glm::vec3> p(n);
    for (auto& q : p)
        q = {uni(rng), uni(rng), uni(rng)};
    return p;
}

std::vector<glm::vec3> jitter(std::span<const glm::vec3> p, float amount, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(-amount, amount);
    std::vector<glm::vec3> out(p.begin(), p.end());
    for (auto& q : out)
        q += glm::vec3(uni(rng), uni(rng), uni(rng));
    return out;
}

// Rodrigues' formula, independent of the library.
glm::vec3 rotate(const glm::vec3& v, const glm::vec3& axisAngle) {
    const float a = glm::length(axisAngle);
    const glm::vec3 k = axisAngle / a;
    return v * std::cos(a) + glm::cross(k, v) * std::sin(a) + k * glm::dot(k, v) * (1.0f - std::cos(a));
}

// ---- An independent reference implementation of §6, written from the paper ----

using D3 = std::array<std::array<double, 3>, 3>;

D3 inverse3(const D3& m) {
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    D3 r;
    r[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
    r[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
    r[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
    r[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
    r[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    r[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
    r[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
    r[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
    r[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
    return r;
}

struct Reference {
    std::vector<glm::vec3> rest, target;
    std::vector<std::vector<int32_t>> nbrs;  // from the face list, ascending
    MeshWarpOptions o;

    Reference(const geom::Mesh& cage, std::span<const glm::vec3> tgt, const MeshWarpOptions& opt)
        : rest(cage.points().begin(), cage.points().end()), target(tgt.begin(), tgt.end()), o(opt) {
        std::vector<std::set<int32_t>> s(rest.size());
        for (int32_t f = 0; f < cage.numFaces(); ++f) {
            const auto fv = cage.face(f);
            for (size_t c = 0; c < fv.size(); ++c) {
                const int32_t a = fv[c], b = fv[(c + 1) % fv.size()];
                s[a].insert(b);
                s[b].insert(a);
            }
        }
        for (const auto& x : s)
            nbrs.emplace_back(x.begin(), x.end());
    }

    static double f(double t, double a, double b) {
        if (t <= a) return 1.0;
        if (t >= b) return 0.0;
        const double x = (t - a) / (b - a);
        return 1.0 - (3.0 * x * x - 2.0 * x * x * x);
    }

    double weight(size_t i, const glm::vec3& p) const {
        const glm::dvec3 d = glm::dvec3(p) - glm::dvec3(rest[i]);
        double longest = 0.0;
        for (int32_t j : nbrs[i])
            longest = std::max(longest, glm::length(glm::dvec3(rest[j]) - glm::dvec3(rest[i])));
        double w = f(glm::length(d) / longest, o.alpha, o.beta);
        for (int32_t j : nbrs[i]) {
            const glm::dvec3 e = glm::dvec3(rest[j]) - glm::dvec3(rest[i]);
            w *= f(glm::dot(d, e) / glm::dot(e, e), o.gamma, o.mu);
        }
        return w;
    }

    // A = (E^T E)^-1 E^T E* by the normal equations (full-rank stars only), as a column-vector map
    // L = A^T: L[r][c] with r the row.
    D3 linear(size_t i) const {
        D3 ete{}, ets{};
        for (int32_t j : nbrs[i]) {
            const glm::dvec3 e = glm::dvec3(rest[j]) - glm::dvec3(rest[i]);
            const glm::dvec3 s = glm::dvec3(target[j]) - glm::dvec3(target[i]);
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c) {
                    ete[r][c] += e[r] * e[c];
                    ets[r][c] += e[r] * s[c];
                }
            }
        }
        const D3 inv = inverse3(ete);
        D3 a{};
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
                for (int k = 0; k < 3; ++k)
                    a[r][c] += inv[r][k] * ets[k][c];
            }
        }
        D3 l;
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c)
                l[r][c] = a[c][r];
        }
        return l;
    }

    glm::vec3 deform(const glm::vec3& p) const {
        glm::dvec3 sum(0.0);
        double wsum = 0.0;
        for (size_t i = 0; i < rest.size(); ++i) {
            const double w = weight(i, p);
            if (w <= 0.0) continue;
            const D3 l = linear(i);
            const glm::dvec3 d = glm::dvec3(p) - glm::dvec3(rest[i]);
            glm::dvec3 q = glm::dvec3(target[i]);
            for (int r = 0; r < 3; ++r)
                q[r] += l[r][0] * d.x + l[r][1] * d.y + l[r][2] * d.z;
            sum += w * (q - glm::dvec3(p));
            wsum += w;
        }
        return wsum > 0.0 ? glm::vec3(glm::dvec3(p) + sum / wsum) : p;
    }
};

std::vector<glm::vec3> runWarp(MeshWarp& warp, std::span<const glm::vec3> rest) {
    WarpDeformer deformer(warp);
    deformer.bind(rest);
    std::vector<glm::vec3> out(rest.begin(), rest.end());
    deformer.evaluate(out);
    return out;
}

}  // namespace

TEST_CASE("mesh warp: falloff f_ab is the smoothstep cubic", "[mesh_warp]") {
    CHECK(meshWarpFalloff(-1.0f, 0.0f, 1.0f) == 1.0f);
    CHECK(meshWarpFalloff(0.0f, 0.0f, 1.0f) == 1.0f);
    CHECK(meshWarpFalloff(1.0f, 0.0f, 1.0f) == 0.0f);
    CHECK(meshWarpFalloff(0.5f, 0.0f, 1.0f) == Approx(0.5f).margin(1e-7));
    CHECK(meshWarpFalloff(0.25f, 0.0f, 1.0f) == Approx(0.84375f).margin(1e-7));  // 1 - (3/16 - 2/64)
    CHECK(meshWarpFalloff(1.5f, 1.0f, 3.0f) == Approx(0.84375f).margin(1e-7));
    // C1 at both ends: the slope vanishes.
    CHECK((1.0f - meshWarpFalloff(1e-3f, 0.0f, 1.0f)) / 1e-3f == Approx(0.0f).margin(4e-3));
    CHECK(meshWarpFalloff(1.0f - 1e-3f, 0.0f, 1.0f) / 1e-3f == Approx(0.0f).margin(4e-3));
}

TEST_CASE("mesh warp: identity when the target cage equals the rest cage", "[mesh_warp]") {
    const geom::Mesh cage = geom::makeSphere({1.0f, 8, 6});
    const auto rest = randomPoints(5000, -1.3f, 1.3f, 1);
    MeshWarp warp(cage);
    const auto out = runWarp(warp, rest);
    float worst = 0.0f;
    for (size_t u = 0; u < rest.size(); ++u)
        worst = std::max(worst, glm::length(out[u] - rest[u]));
    CHECK(worst <= 1e-6f);
    // Planar stars too (a grid cage, rank 2 everywhere).
    const geom::Mesh grid = geom::makeGrid({4, 4, 1.0f, 1.0f});
    MeshWarp flat(grid);
    const auto restFlat = randomPoints(2000, -0.2f, 1.2f, 2);
    const auto outFlat = runWarp(flat, restFlat);
    worst = 0.0f;
    for (size_t u = 0; u < restFlat.size(); ++u)
        worst = std::max(worst, glm::length(outFlat[u] - restFlat[u]));
    CHECK(worst <= 1e-6f);
}

TEST_CASE("mesh warp: A = E+ E* matches the normal equations for full-rank stars", "[mesh_warp]") {
    for (const geom::Mesh& cage : {octahedron(), cube(), geom::makeSphere({1.0f, 8, 6})}) {
        const auto target = jitter(cage.points(), 0.2f, 3);
        MeshWarp warp(cage);
        warp.setTarget(target);
        const Reference ref(cage, target, {});
        for (int32_t i = 0; i < warp.numControlVertices(); ++i) {
            REQUIRE(warp.starRank(i) == 3);
            const glm::mat3 l = warp.linearMap(i);
            const D3 r = ref.linear(i);
            for (int row = 0; row < 3; ++row) {
                for (int col = 0; col < 3; ++col)
                    CHECK(l[col][row] == Approx(r[row][col]).margin(1e-5));
            }
        }
    }
}

TEST_CASE("mesh warp: hand-worked planar star keeps its normal direction", "[mesh_warp]") {
    // 2x2 grid, centre vertex 4 at (0.5, 0.5, 0) with edges +-0.5 x, +-0.5 y: E^T E = diag(0.5, 0.5, 0).
    const geom::Mesh grid = geom::makeGrid({2, 2, 1.0f, 1.0f});
    REQUIRE(grid.points()[4] == glm::vec3(0.5f, 0.5f, 0.0f));
    MeshWarp warp(grid);
    CHECK(warp.starRank(4) == 2);
    std::vector<glm::vec3> target(grid.points().begin(), grid.points().end());
    // +x edge becomes (1, 0, 0.25) = L (0.5, 0, 0), -x edge its negative; y edges unchanged. By hand:
    // E+ (E* - E) has one non-zero row, x: (1, 0, 0.5), so L^T = I + that row, and L =
    // [[2,0,0],[0,1,0],[0.5,0,1]].
    target[5] = target[4] + glm::vec3(1.0f, 0.0f, 0.25f);
    target[3] = target[4] - glm::vec3(1.0f, 0.0f, 0.25f);
    warp.setTarget(target);
    const glm::mat3 l = warp.linearMap(4);
    CHECK(near(l[0], {2.0f, 0.0f, 0.5f}, 1e-6f));
    CHECK(near(l[1], {0.0f, 1.0f, 0.0f}, 1e-6f));
    CHECK(near(l[2], {0.0f, 0.0f, 1.0f}, 1e-6f));  // the unconstrained normal is left as it is
}

TEST_CASE("mesh warp: points at control vertices move exactly to their targets", "[mesh_warp]") {
    for (const geom::Mesh& cage :
         {octahedron(), cube(), geom::makeSphere({1.0f, 8, 6}), geom::makeGrid({3, 3})}) {
        const auto target = jitter(cage.points(), 0.25f, 4);
        MeshWarp warp(cage);
        warp.setTarget(target);
        std::vector<glm::vec3> rest(cage.points().begin(), cage.points().end());
        const auto out = runWarp(warp, rest);
        for (size_t i = 0; i < rest.size(); ++i)
            CHECK(near(out[i], target[i], 1e-5f));
    }
}

TEST_CASE("mesh warp: equals an independent implementation of paper §6", "[mesh_warp]") {
    for (const geom::Mesh& cage : {octahedron(), geom::makeSphere({1.0f, 8, 6})}) {
        const auto target = jitter(cage.points(), 0.2f, 5);
        MeshWarpOptions o;
        o.alpha = 0.2f;
        o.beta = 1.2f;
        o.gamma = -0.1f;
        o.mu = 0.9f;
        MeshWarp warp(cage, o);
        warp.setTarget(target);
        const auto rest = randomPoints(3000, -1.3f, 1.3f, 6);
        const auto out = runWarp(warp, rest);
        const Reference ref(cage, target, o);
        int moved = 0;
        for (size_t u = 0; u < rest.size(); ++u) {
            const glm::vec3 expected = ref.deform(rest[u]);
            double wsum = 0.0;
            for (size_t i = 0; i < ref.rest.size(); ++i)
                wsum += ref.weight(i, rest[u]);
            INFO("point " << u << " total weight " << wsum << " got " << out[u].x << " " << out[u].y
                          << " expected " << expected.x << " " << expected.y);
            CHECK(near(out[u], expected, 2e-5f));
            moved += glm::length(expected - rest[u]) > 1e-3f;
        }
        CHECK(moved > 500);  // the comparison covers deformed points, not just the identity
    }
}

TEST_CASE("mesh warp: sparse fields hold exactly the non-zero weights", "[mesh_warp]") {
    const geom::Mesh cage = geom::makeSphere({1.0f, 8, 6});
    const Reference ref(cage, cage.points(), {});
    MeshWarp warp(cage);
    const auto rest = randomPoints(3000, -1.5f, 1.5f, 7);
    SparseFields fields;
    warp.bind(rest, fields);
    REQUIRE(fields.numPoints() == static_cast<int32_t>(rest.size()));
    for (size_t u = 0; u < rest.size(); ++u) {
        std::vector<std::pair<int32_t, double>> expected;
        for (size_t i = 0; i < ref.rest.size(); ++i) {
            const double w = ref.weight(i, rest[u]);
            if (w > 1e-6) expected.emplace_back(static_cast<int32_t>(i), w);
        }
        std::vector<std::pair<int32_t, double>> got;
        for (int32_t e = fields.offsets[u]; e < fields.offsets[u + 1]; ++e) {
            CHECK(fields.strength[e] == 1.0f);
            if (fields.weight[e] > 1e-6f) got.emplace_back(fields.transform[e], fields.weight[e]);
            CHECK(fields.weight[e] == Approx(ref.weight(fields.transform[e], rest[u])).margin(1e-6));
        }
        REQUIRE(got.size() == expected.size());
        for (size_t k = 0; k < got.size(); ++k)
            CHECK(got[k].first == expected[k].first);
    }
}

TEST_CASE("mesh warp: a rigid motion of the whole cage moves the surface rigidly", "[mesh_warp]") {
    const glm::vec3 axisAngle = glm::normalize(glm::vec3(1, -2, 0.5f)) * 0.9f;
    const glm::vec3 shift(0.3f, -1.2f, 2.0f);
    for (const geom::Mesh& cage : {octahedron(), geom::makeSphere({1.0f, 8, 6})}) {
        std::vector<glm::vec3> target;
        for (const auto& p : cage.points())
            target.push_back(rotate(p, axisAngle) + shift);
        MeshWarp warp(cage);
        warp.setTarget(target);
        WarpDeformer deformer(warp);
        const auto rest = randomPoints(4000, -1.3f, 1.3f, 8);
        deformer.bind(rest);
        auto out = rest;
        deformer.evaluate(out);
        int influenced = 0;
        for (size_t u = 0; u < rest.size(); ++u) {
            const bool inside = deformer.fields().offsets[u + 1] > deformer.fields().offsets[u];
            if (inside) {
                ++influenced;
                CHECK(near(out[u], rotate(rest[u], axisAngle) + shift, 1e-5f));
            } else {
                CHECK(out[u] == rest[u]);
            }
        }
        CHECK(influenced > 1000);
    }
}

TEST_CASE("mesh warp: moving one control vertex has a local effect", "[mesh_warp]") {
    const geom::Mesh cage = geom::makeSphere({1.0f, 8, 6});
    MeshWarp warp(cage);
    const int32_t k = 12;
    std::vector<glm::vec3> target(cage.points().begin(), cage.points().end());
    target[k] += glm::vec3(0.2f, 0.1f, -0.15f);
    warp.setTarget(target);
    std::set<int32_t> affected{k};
    for (int32_t j : warp.neighbors(k))
        affected.insert(j);  // their edge maps change too
    auto rest = randomPoints(4000, -1.3f, 1.3f, 9);
    rest.push_back({10, 10, 10});  // far from the cage
    WarpDeformer deformer(warp);
    deformer.bind(rest);
    auto out = rest;
    deformer.evaluate(out);
    int unchanged = 0, moved = 0;
    for (size_t u = 0; u < rest.size(); ++u) {
        bool reached = false;
        const auto& f = deformer.fields();
        for (int32_t e = f.offsets[u]; e < f.offsets[u + 1]; ++e)
            reached |= affected.count(f.transform[e]) > 0;
        if (!reached) {
            CHECK(out[u] == rest[u]);
            ++unchanged;
        } else if (glm::length(out[u] - rest[u]) > 1e-4f) {
            ++moved;
        }
    }
    CHECK(out.back() == rest.back());
    CHECK(unchanged > 2000);
    CHECK(moved > 20);
}

TEST_CASE("mesh warp: bind once, evaluate with new targets, weights and envelope", "[mesh_warp]") {
    const geom::Mesh cage = octahedron();
    MeshWarp warp(cage);
    WarpDeformer deformer(warp);
    const auto rest = randomPoints(500, -1.0f, 1.0f, 10);
    deformer.bind(rest);
    const SparseFields fieldsAtBind = deformer.fields();
    const auto t1 = jitter(cage.points(), 0.2f, 11);
    warp.setTarget(t1);
    auto full = rest;
    deformer.evaluate(full);
    auto half = rest;
    std::vector<float> painted(rest.size(), 0.5f);
    deformer.evaluate(half, painted, 0.8f);
    for (size_t u = 0; u < rest.size(); ++u)
        CHECK(near(half[u], rest[u] + 0.4f * (full[u] - rest[u]), 1e-6f));
    CHECK(deformer.fields().offsets == fieldsAtBind.offsets);
    CHECK(deformer.fields().weight == fieldsAtBind.weight);
    // The one-off function gives the same result.
    auto oneOff = rest;
    meshWarp(oneOff, cage, t1, {}, painted, 0.8f);
    for (size_t u = 0; u < rest.size(); ++u)
        CHECK(near(oneOff[u], half[u], 1e-6f));
}

TEST_CASE("mesh warp: bit-identical for 1 and 2 threads", "[mesh_warp][determinism]") {
    const geom::Mesh cage = geom::makeSphere({1.0f, 12, 8});
    const auto target = jitter(cage.points(), 0.2f, 12);
    const auto rest = randomPoints(60000, -1.3f, 1.3f, 13);
    std::vector<glm::vec3> out[2];
    SparseFields fields[2];
    for (int threads = 1; threads <= 2; ++threads) {
        omp_set_num_threads(threads);
        MeshWarp warp(cage);
        warp.setTarget(target);
        WarpDeformer deformer(warp);
        deformer.bind(rest);
        fields[threads - 1] = deformer.fields();
        out[threads - 1] = rest;
        deformer.evaluate(out[threads - 1]);
    }
    omp_set_num_threads(omp_get_num_procs());
    CHECK(fields[0].offsets == fields[1].offsets);
    CHECK(fields[0].transform == fields[1].transform);
    CHECK(std::memcmp(fields[0].weight.data(), fields[1].weight.data(),
                      fields[0].weight.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(out[0].data(), out[1].data(), rest.size() * sizeof(glm::vec3)) == 0);
}

TEST_CASE("mesh warp: bad input names the element", "[mesh_warp][errors]") {
    CHECK_THROWS_WITH(MeshWarp(geom::Mesh()), Catch::Contains("cage") && Catch::Contains("no vertices"));
    // Three triangles on edge (0, 1).
    const geom::Mesh fin = makeMeshFrom({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                                        {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
    CHECK_THROWS_AS(MeshWarp(fin), TopologyError);
    CHECK_THROWS_WITH(MeshWarp(fin), Catch::Contains("edge (0, 1)"));
    const geom::Mesh isolated = makeMeshFrom({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}}, {{0, 1, 2}});
    CHECK_THROWS_WITH(MeshWarp(isolated), Catch::Contains("cage vertex 3") && Catch::Contains("no edges"));
    const geom::Mesh collapsed = makeMeshFrom({{0, 0, 0}, {1, 0, 0}, {1, 0, 0}}, {{0, 1, 2}});
    CHECK_THROWS_WITH(MeshWarp(collapsed),
                      Catch::Contains("cage edge (1, 2)") && Catch::Contains("zero length"));

    const geom::Mesh cage = octahedron();
    MeshWarpOptions o;
    o.alpha = 1.0f;
    o.beta = 1.0f;
    CHECK_THROWS_WITH(MeshWarp(cage, o), Catch::Contains("alpha") && Catch::Contains("alpha < beta"));
    o = {};
    o.alpha = -0.5f;
    CHECK_THROWS_WITH(MeshWarp(cage, o), Catch::Contains("alpha >= 0"));
    o = {};
    o.gamma = 2.0f;
    CHECK_THROWS_WITH(MeshWarp(cage, o), Catch::Contains("gamma") && Catch::Contains("gamma < mu"));
    o = {};
    o.mu = NAN;
    CHECK_THROWS_WITH(MeshWarp(cage, o), Catch::Contains(": mu: is nan (expected a finite number)"));
    o = {};
    o.beta = INFINITY;
    CHECK_THROWS_WITH(MeshWarp(cage, o), Catch::Contains(": beta: is inf (expected a finite number)"));
    o = {};
    o.alpha = -0.5f;
    CHECK_THROWS_WITH(MeshWarp(cage, o), Catch::Contains("alpha: is -0.5 (expected alpha >= 0)"));

    MeshWarp warp(cage);
    const std::vector<glm::vec3> three{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    CHECK_THROWS_WITH(warp.setTarget(three), Catch::Contains("target cage") &&
                                                 Catch::Contains("has 3 points") &&
                                                 Catch::Contains("6 points"));
    std::vector<glm::vec3> nanTarget(cage.points().begin(), cage.points().end());
    nanTarget[2].y = NAN;
    CHECK_THROWS_WITH(warp.setTarget(nanTarget), Catch::Contains("target cage point 2"));
    const std::vector<glm::vec3> nanRest{{0, 0, 0}, {NAN, 0, 0}};
    SparseFields f;
    CHECK_THROWS_WITH(warp.bind(nanRest, f), Catch::Contains("rest point 1"));
    // A beta whose supports overflow float: refused at bind (it once grew the support grid's cell forever).
    o = {};
    o.beta = 2e38f;
    MeshWarp huge(cage, o);
    const std::vector<glm::vec3> rest{{0, 0, 0}, {0.1f, 0, 0}};
    CHECK_THROWS_WITH(huge.bind(rest, f),
                      Catch::Contains("beta: is 2e+38") && Catch::Contains("no finite box"));
}

TEST_CASE("mesh warp: a cage with split vertices warps as the shared-vertex cage, bit for bit",
          "[mesh_warp][weld]") {
    const geom::Mesh cage = geom::makeSphere({});
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<glm::vec3> points(600);
    for (glm::vec3& p : points)
        p = glm::vec3(unit(rng), unit(rng), unit(rng)) * 0.8f;
    std::vector<glm::vec3> target(cage.points().begin(), cage.points().end());
    for (glm::vec3& p : target)
        p += glm::vec3(unit(rng), unit(rng), unit(rng)) * 0.1f;
    for (const bool perCorner : {false, true}) {
        CAPTURE(perCorner);
        std::vector<int32_t> original, newIndex;
        const geom::Mesh split = test::splitCopy(cage, perCorner, original);
        const geom::Mesh shared =
            test::renumbered(cage, test::firstCopyOrder(original, cage.numVertices()), newIndex);
        std::vector<glm::vec3> sharedTarget(target.size()), splitTarget;
        for (size_t v = 0; v < target.size(); ++v)
            sharedTarget[static_cast<size_t>(newIndex[v])] = target[v];
        for (int32_t v : original)
            splitTarget.push_back(target[static_cast<size_t>(v)]);
        std::vector<glm::vec3> want = points, got = points;
        warp::meshWarp(want, shared, sharedTarget);
        warp::meshWarp(got, split, splitTarget);
        CHECK(std::memcmp(got.data(), want.data(), got.size() * sizeof(glm::vec3)) == 0);
        CHECK(warp::MeshWarp(split).numControlVertices() == cage.numVertices());
        CHECK(warp::MeshWarp(split).numCageVertices() == split.numVertices());
        double moved = 0.0;
        for (size_t k = 0; k < points.size(); ++k)
            moved = std::max(moved, static_cast<double>(glm::length(got[k] - points[k])));
        CHECK(moved > 0.01);
    }
}

TEST_CASE(
    "mesh warp: a split vertex's copies move it by their mean; copies torn apart are refused, naming both",
    "[mesh_warp][weld]") {
    const geom::Mesh cage = geom::makeSphere({});
    std::vector<int32_t> original, newIndex;
    const geom::Mesh split = test::splitCopy(cage, true, original);
    const geom::Mesh shared =
        test::renumbered(cage, test::firstCopyOrder(original, cage.numVertices()), newIndex);
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<glm::vec3> points(400);
    for (glm::vec3& p : points)
        p = glm::vec3(unit(rng), unit(rng), unit(rng)) * 0.8f;
    // Each copy moved by a little noise of its own (a DCC's per-copy rounding), well within 1% of an edge.
    std::vector<glm::vec3> splitTarget;
    std::vector<glm::dvec3> sum(static_cast<size_t>(cage.numVertices()), glm::dvec3(0.0));
    std::vector<int32_t> count(sum.size(), 0);
    for (const int32_t v : original) {
        const glm::vec3 p = cage.points()[static_cast<size_t>(v)] + glm::vec3(0.05f, -0.02f, 0.03f) +
                            glm::vec3(unit(rng), unit(rng), unit(rng)) * 1e-5f;
        splitTarget.push_back(p);
        sum[static_cast<size_t>(v)] += glm::dvec3(p);
        ++count[static_cast<size_t>(v)];
    }
    std::vector<glm::vec3> sharedTarget(sum.size());
    for (size_t v = 0; v < sum.size(); ++v)
        sharedTarget[static_cast<size_t>(newIndex[v])] = glm::vec3(sum[v] / static_cast<double>(count[v]));
    std::vector<glm::vec3> want = points, got = points;
    warp::meshWarp(want, shared, sharedTarget);
    warp::meshWarp(got, split, splitTarget);
    CHECK(std::memcmp(got.data(), want.data(), got.size() * sizeof(glm::vec3)) == 0);

    // One copy of a vertex dragged alone (an edit to one side of a seam): refused, the target unchanged.
    warp::MeshWarp warp(split, {}, "cage.obj");
    warp.setTarget(splitTarget);
    const std::vector<glm::vec3> before(warp.targetCage().begin(), warp.targetCage().end());
    int32_t second = -1, firstOfIt = -1;
    for (size_t k = 0; k < original.size() && second < 0; ++k) {
        for (size_t j = 0; j < k; ++j) {
            if (original[j] == original[k]) {
                second = static_cast<int32_t>(k);
                firstOfIt = static_cast<int32_t>(j);
                break;
            }
        }
    }
    REQUIRE(second >= 0);
    std::vector<glm::vec3> torn = splitTarget;
    torn[static_cast<size_t>(second)] += glm::vec3(0.0f, 0.2f, 0.0f);
    CHECK_THROWS_WITH(warp.setTarget(torn),
                      Catch::Contains("cage.obj") &&
                          Catch::Contains("target cage point " + std::to_string(second)) &&
                          Catch::Contains("from point " + std::to_string(firstOfIt)) &&
                          Catch::Contains("copies of a split vertex moved together"));
    CHECK(std::equal(before.begin(), before.end(), warp.targetCage().begin()));
    // mu <= 0 would give every control vertex zero weight past itself: refused.
    warp::MeshWarpOptions o;
    o.gamma = -1.0f;
    o.mu = 0.0f;
    CHECK_THROWS_WITH(warp::MeshWarp(cage, o), Catch::Contains("mu") && Catch::Contains("mu > 0"));
}
