// FFD (paper §4.1) against references written here: a direct Bernstein sum with local coordinates by
// Cramer's rule, and a Cox-de Boor B-spline over a lattice explicitly extended by phantom controls.
#include <catch2/catch.hpp>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/ffd.h"
#include "warp_test_support.h"

using namespace deformkit;
using namespace deformkit::warp;
using deformkit::test::maxError;
using deformkit::test::samplePoints;
using deformkit::test::viaEngine;

namespace {

// Painted weights in [0, 1], one per point.
std::vector<float> randomWeights(size_t count, std::mt19937& rng) {
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> weights(count);
    for (auto& w : weights)
        w = unit(rng);
    return weights;
}

// The rest points moved a little, as an upstream deformer's output.
std::vector<glm::vec3> shifted(const std::vector<glm::vec3>& rest) {
    std::vector<glm::vec3> out = rest;
    for (auto& p : out)
        p += glm::vec3(0.01f, -0.02f, 0.03f);
    return out;
}

// A skewed parallelepiped, not axis-aligned, not orthogonal.
Lattice skewLattice(glm::ivec3 divisions) {
    Lattice l;
    l.origin = {-0.7f, 0.3f, 1.1f};
    l.axes =
        glm::mat3(glm::vec3(2.0f, 0.3f, -0.2f), glm::vec3(0.4f, 1.5f, 0.1f), glm::vec3(-0.3f, 0.2f, 1.8f));
    l.divisions = divisions;
    return l;
}

// Local coordinates by Cramer's rule, in double.
glm::dvec3 cramer(const Lattice& l, const glm::vec3& p) {
    const glm::dvec3 x(l.axes[0]), y(l.axes[1]), z(l.axes[2]), r = glm::dvec3(p) - glm::dvec3(l.origin);
    const double det = glm::dot(x, glm::cross(y, z));
    return {glm::dot(r, glm::cross(y, z)) / det, glm::dot(x, glm::cross(r, z)) / det,
            glm::dot(x, glm::cross(y, r)) / det};
}

double choose(int n, int k) {
    double c = 1.0;
    for (int i = 0; i < k; ++i)
        c = c * (n - i) / (i + 1);
    return c;
}

double bernstein(int d, int i, double t) {
    return choose(d, i) * std::pow(t, i) * std::pow(1.0 - t, d - i);
}

glm::dvec3 controlRef(const Lattice& l, int i, int j, int k) {
    return glm::dvec3(l.origin) + glm::dvec3(l.axes[0]) * (double(i) / l.divisions.x) +
           glm::dvec3(l.axes[1]) * (double(j) / l.divisions.y) +
           glm::dvec3(l.axes[2]) * (double(k) / l.divisions.z);
}

// B_i beyond [0, 1] continued from the end with its value and derivative there, B_i(e) + (t - e) B_i'(e),
// B_i' = d (B^(d-1)_(i-1) - B^(d-1)_i) (FfdOutside::Extrapolate); B_i itself inside.
double bernsteinContinued(int d, int i, double t) {
    if (t >= 0.0 && t <= 1.0) return bernstein(d, i, t);
    const double e = t < 0.0 ? 0.0 : 1.0;
    const auto lower = [&](int k) { return k < 0 || k > d - 1 ? 0.0 : bernstein(d - 1, k, e); };
    return bernstein(d, i, e) + (t - e) * d * (lower(i - 1) - lower(i));
}

// Sederberg-Parry: X_ffd = sum_ijk B_i(s) B_j(t) B_k(u) P*_ijk, written as p + sum B (P* - P), with the
// basis continued beyond the lattice.
glm::vec3 bernsteinRef(const Lattice& l, const std::vector<glm::vec3>& target, const glm::vec3& p) {
    const glm::dvec3 s = cramer(l, p);
    const glm::ivec3 d = l.divisions;
    glm::dvec3 out(p);
    for (int i = 0; i <= d.x; ++i)
        for (int j = 0; j <= d.y; ++j)
            for (int k = 0; k <= d.z; ++k) {
                const double w = bernsteinContinued(d.x, i, s.x) * bernsteinContinued(d.y, j, s.y) *
                                 bernsteinContinued(d.z, k, s.z);
                out += w * (glm::dvec3(target[(i * (d.y + 1) + j) * (d.z + 1) + k]) - controlRef(l, i, j, k));
            }
    return glm::vec3(out);
}

// Cox-de Boor recursion on the integer knots.
double coxDeBoor(int i, int p, double x) {
    if (p == 0) return (x >= i && x < i + 1) ? 1.0 : 0.0;
    return (x - i) / p * coxDeBoor(i, p - 1, x) + (i + p + 1 - x) / p * coxDeBoor(i + 1, p - 1, x);
}

// The displacement of control (a, b, c), extended beyond the lattice linearly: T_-1 = 2 T_0 - T_1.
glm::dvec3 extendedDisplacement(const Lattice& l, const std::vector<glm::vec3>& target, int a, int b, int c) {
    const glm::ivec3 d = l.divisions;
    if (a < 0)
        return 2.0 * extendedDisplacement(l, target, 0, b, c) - extendedDisplacement(l, target, 1, b, c);
    if (a > d.x)
        return 2.0 * extendedDisplacement(l, target, d.x, b, c) -
               extendedDisplacement(l, target, d.x - 1, b, c);
    if (b < 0)
        return 2.0 * extendedDisplacement(l, target, a, 0, c) - extendedDisplacement(l, target, a, 1, c);
    if (b > d.y)
        return 2.0 * extendedDisplacement(l, target, a, d.y, c) -
               extendedDisplacement(l, target, a, d.y - 1, c);
    if (c < 0)
        return 2.0 * extendedDisplacement(l, target, a, b, 0) - extendedDisplacement(l, target, a, b, 1);
    if (c > d.z)
        return 2.0 * extendedDisplacement(l, target, a, b, d.z) -
               extendedDisplacement(l, target, a, b, d.z - 1);
    return glm::dvec3(target[(a * (d.y + 1) + b) * (d.z + 1) + c]) - controlRef(l, a, b, c);
}

// Uniform cubic B-spline volume over the extended controls -1 .. d + 1; basis of control a: N_{a-2,3}.
glm::vec3 bsplineRef(const Lattice& l, const std::vector<glm::vec3>& target, const glm::vec3& p) {
    const glm::dvec3 x = cramer(l, p) * glm::dvec3(l.divisions);
    const glm::ivec3 d = l.divisions;
    glm::dvec3 out(p);
    for (int a = -1; a <= d.x + 1; ++a)
        for (int b = -1; b <= d.y + 1; ++b)
            for (int c = -1; c <= d.z + 1; ++c) {
                const double w =
                    coxDeBoor(a - 2, 3, x.x) * coxDeBoor(b - 2, 3, x.y) * coxDeBoor(c - 2, 3, x.z);
                if (w != 0.0) out += w * extendedDisplacement(l, target, a, b, c);
            }
    return glm::vec3(out);
}

// The weight of control k (an index on the unbounded line of controls) at x (local coordinate times
// divisions) for the spline bases, written per basis in its textbook form: hat functions, Cox-de Boor, and
// the cardinal spline as a Hermite curve through controls span and span + 1 with tangents
// a (P_span+1 - P_span-1) and a (P_span+2 - P_span).
double splineRef(FfdBasis basis, int k, double x) {
    if (basis == FfdBasis::Linear) return std::max(0.0, 1.0 - std::abs(x - k));
    if (basis == FfdBasis::BSpline) return coxDeBoor(k - 2, 3, x);
    const double a = basis == FfdBasis::Cardinal ? 0.71 : 0.5;
    const double span = std::floor(x), u = x - span;
    const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u;
    const double h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
    if (k == span - 1) return -a * h10;
    if (k == span) return h00 - a * h11;
    if (k == span + 1) return h01 + a * h10;
    if (k == span + 2) return a * h11;
    return 0.0;
}

// Blender's Lattice modifier written out: the controls a span lacks beyond the ends are the end controls
// again (index k clamped to [0, d]), for points inside and outside alike; per-axis bases.
glm::vec3 repeatedEndsRef(const Lattice& l, const FfdBases& bases, const std::vector<glm::vec3>& target,
                          const glm::vec3& p) {
    const glm::dvec3 x = cramer(l, p) * glm::dvec3(l.divisions);
    const glm::ivec3 d = l.divisions;
    // Per axis: the weight of each real control, summed over the virtual indices that clamp to it.
    std::vector<double> w[3];
    for (int a = 0; a < 3; ++a) {
        w[a].assign(static_cast<size_t>(d[a]) + 1, 0.0);
        const int span = static_cast<int>(std::floor(x[a]));
        for (int k = span - 3; k <= span + 3; ++k)
            w[a][static_cast<size_t>(std::clamp(k, 0, d[a]))] += splineRef(bases[a], k, x[a]);
    }
    glm::dvec3 out(p);
    for (int i = 0; i <= d.x; ++i)
        for (int j = 0; j <= d.y; ++j)
            for (int k = 0; k <= d.z; ++k) {
                const double weight = w[0][i] * w[1][j] * w[2][k];
                out += weight *
                       (glm::dvec3(target[(i * (d.y + 1) + j) * (d.z + 1) + k]) - controlRef(l, i, j, k));
            }
    return glm::vec3(out);
}

constexpr FfdBasis kSplineBases[4] = {FfdBasis::BSpline, FfdBasis::Linear, FfdBasis::Cardinal,
                                      FfdBasis::CatmullRom};
constexpr FfdBasis kAllBases[5] = {FfdBasis::Bernstein, FfdBasis::BSpline, FfdBasis::Linear,
                                   FfdBasis::Cardinal, FfdBasis::CatmullRom};

std::vector<glm::vec3> randomTargets(const Lattice& l, std::mt19937& rng, float amount) {
    std::uniform_real_distribution<float> uni(-amount, amount);
    std::vector<glm::vec3> t = l.controlPoints();
    for (auto& p : t)
        p += glm::vec3(uni(rng), uni(rng), uni(rng));
    return t;
}

// The generic engine bound to rest and evaluated at upstream points.
std::vector<glm::vec3> viaEngineFrom(Warp& warp, const std::vector<glm::vec3>& rest,
                                     std::vector<glm::vec3> upstream, std::span<const float> weights,
                                     float envelope) {
    WarpDeformer deformer(warp);
    deformer.bind(rest);
    deformer.evaluate(upstream, weights, envelope);
    return upstream;
}

bool outsideUnit(const glm::dvec3& s) {
    for (int a = 0; a < 3; ++a)
        if (s[a] < 0.0 || s[a] > 1.0) return true;
    return false;
}

}  // namespace

TEST_CASE("ffd: Bernstein FFD equals a direct Bernstein sum", "[warp][ffd]") {
    std::mt19937 rng(11);
    for (glm::ivec3 div : {glm::ivec3(3, 3, 3), glm::ivec3(1, 2, 4), glm::ivec3(5, 1, 2)}) {
        const Lattice l = skewLattice(div);
        Ffd ffd(l);
        const auto target = randomTargets(l, rng, 0.4f);
        ffd.setTargets(target);
        const auto pts = samplePoints(l, rng, 500, 0.0f, 1.0f);
        std::vector<glm::vec3> ref(pts.size());
        for (size_t i = 0; i < pts.size(); ++i)
            ref[i] = bernsteinRef(l, target, pts[i]);
        CHECK(maxError(viaEngine(ffd, pts), ref) < 1e-5f);
        std::vector<glm::vec3> fast = pts;
        ffd.bind(pts);
        ffd.evaluate(fast);
        CHECK(maxError(fast, ref) < 1e-5f);
    }
}

TEST_CASE("ffd: identity when targets equal sources", "[warp][ffd]") {
    std::mt19937 rng(12);
    for (FfdBasis basis : kAllBases) {
        for (FfdOutside outside : {FfdOutside::None, FfdOutside::Extrapolate}) {
            for (FfdEnds ends : {FfdEnds::Extrapolate, FfdEnds::Repeat}) {
                const Lattice l = skewLattice({4, 3, 2});
                Ffd ffd(l, {basis, outside, FfdKernel::Auto, ends});
                ffd.setTargets(l.controlPoints());
                const auto pts = samplePoints(l, rng, 400, -0.3f, 1.3f);
                CHECK(maxError(viaEngine(ffd, pts), pts) < 1e-6f);
                std::vector<glm::vec3> fast = pts;
                ffd.bind(pts);
                ffd.evaluate(fast);
                CHECK(maxError(fast, pts) < 1e-6f);
            }
        }
    }
}

TEST_CASE("ffd: linear precision, an affine target lattice gives that affine map", "[warp][ffd]") {
    std::mt19937 rng(13);
    const glm::mat3 a(glm::vec3(1.2f, 0.3f, -0.1f), glm::vec3(-0.2f, 0.8f, 0.25f),
                      glm::vec3(0.1f, -0.3f, 1.4f));
    const glm::vec3 b(0.5f, -1.0f, 0.25f);
    // Not the cardinal spline of tension 0.71: its tangents are 1.42x the spacing of evenly spaced controls.
    for (FfdBasis basis : {FfdBasis::Bernstein, FfdBasis::BSpline, FfdBasis::Linear, FfdBasis::CatmullRom}) {
        for (glm::ivec3 div : {glm::ivec3(3, 3, 3), glm::ivec3(1, 4, 6)}) {
            const Lattice l = skewLattice(div);
            // Extrapolation continues the polynomials, and they reproduce linear functions everywhere.
            Ffd ffd(l, {basis, FfdOutside::Extrapolate});
            std::vector<glm::vec3> target = l.controlPoints();
            for (auto& p : target)
                p = a * p + b;
            ffd.setTargets(target);
            const auto pts = samplePoints(l, rng, 400, -0.2f, 1.2f);
            std::vector<glm::vec3> ref(pts.size());
            for (size_t i = 0; i < pts.size(); ++i)
                ref[i] = a * pts[i] + b;
            CHECK(maxError(viaEngine(ffd, pts), ref) < 1e-5f);
            std::vector<glm::vec3> fast = pts;
            ffd.bind(pts);
            ffd.evaluate(fast);
            CHECK(maxError(fast, ref) < 1e-5f);
        }
    }
}

TEST_CASE("ffd: weighting fields are a partition of unity, sparse and non-negative inside", "[warp][ffd]") {
    std::mt19937 rng(14);
    for (FfdBasis basis : kAllBases) {
        const Lattice l = skewLattice({6, 5, 4});
        FfdLattice lattice(l, {basis, FfdOutside::Extrapolate});
        auto pts = samplePoints(l, rng, 300, -0.25f, 1.25f);
        pts.push_back(l.origin);  // a corner: only the corner control, weight 1, for every basis
        lattice.bind(pts);
        SparseFields f;
        lattice.fields(f);
        REQUIRE(f.numPoints() == static_cast<int32_t>(pts.size()));
        for (int32_t u = 0; u < f.numPoints(); ++u) {
            double sum = 0.0;
            bool nonNegative = true;
            for (int32_t e = f.offsets[u]; e < f.offsets[u + 1]; ++e) {
                sum += f.weight[e];
                nonNegative = nonNegative && f.weight[e] > 0.0f;
                CHECK(f.strength[e] == 1.0f);
            }
            CHECK(sum == Approx(1.0).margin(1e-5));
            const int32_t count = f.offsets[u + 1] - f.offsets[u];
            if (basis != FfdBasis::Bernstein) CHECK(count <= 64);  // a point pays only for its 4x4x4 support
            if (basis == FfdBasis::Linear) CHECK(count <= 8);
            // The interpolating cubics have negative lobes.
            const bool positive = basis != FfdBasis::Cardinal && basis != FfdBasis::CatmullRom;
            if (positive && !outsideUnit(cramer(l, pts[u]))) CHECK(nonNegative);
        }
        const int32_t corner = f.numPoints() - 1;
        REQUIRE(f.offsets[corner + 1] - f.offsets[corner] == 1);
        CHECK(f.transform[f.offsets[corner]] == 0);
        CHECK(f.weight[f.offsets[corner]] == Approx(1.0f).margin(1e-6));
    }
}

TEST_CASE("ffd: outside points, unchanged or extrapolated", "[warp][ffd]") {
    std::mt19937 rng(15);
    const Lattice l = skewLattice({3, 2, 3});
    const auto target = randomTargets(l, rng, 0.3f);
    auto pts = samplePoints(l, rng, 400, -0.5f, 1.5f);
    int outside = 0;
    for (const auto& p : pts)
        outside += outsideUnit(cramer(l, p)) ? 1 : 0;
    REQUIRE(outside > 100);
    REQUIRE(outside < 400);

    Ffd none(l, {FfdBasis::Bernstein, FfdOutside::None});
    none.setTargets(target);
    Ffd extra(l, {FfdBasis::Bernstein, FfdOutside::Extrapolate});
    extra.setTargets(target);
    const auto outNone = viaEngine(none, pts), outExtra = viaEngine(extra, pts);
    std::vector<glm::vec3> fastNone = pts;
    none.bind(pts);
    none.evaluate(fastNone);
    for (size_t i = 0; i < pts.size(); ++i) {
        const glm::vec3 ref = bernsteinRef(l, target, pts[i]);
        if (outsideUnit(cramer(l, pts[i]))) {
            CHECK(outNone[i] == pts[i]);  // exactly, no entries at all
            CHECK(fastNone[i] == pts[i]);
        } else {
            CHECK(glm::length(outNone[i] - ref) < 1e-5f);
        }
        CHECK(glm::length(outExtra[i] - ref) < 2e-5f);  // continued from the faces beyond [0, 1]
    }
    SparseFields f;
    none.bind(pts, f);
    for (size_t i = 0; i < pts.size(); ++i) {
        if (outsideUnit(cramer(l, pts[i]))) CHECK(f.offsets[i + 1] == f.offsets[i]);
    }

    // B-spline extrapolation continues from the end face: continuous across it.
    Ffd bs(l, {FfdBasis::BSpline, FfdOutside::Extrapolate});
    bs.setTargets(target);
    const glm::vec3 onFace = l.origin + l.axes * glm::vec3(1.0f, 0.4f, 0.6f);
    const glm::vec3 step = l.axes[0] * 1e-4f;
    std::vector<glm::vec3> across{onFace - step, onFace + step};
    const auto moved = viaEngine(bs, across);
    const glm::vec3 jump = (moved[1] - across[1]) - (moved[0] - across[0]);
    CHECK(glm::length(jump) < 2e-3f);
}

TEST_CASE("ffd: extrapolated, an affine lattice stays affine up to float rounding, every basis and degree",
          "[warp][ffd]") {
    // Targets an affine map of the controls (A p + b, A a shear and scale): the FFD of any basis but the
    // cardinal spline (not linearly precise) reproduces it inside, and the continuation from the faces does
    // beyond them, at any degree. Evaluated as polynomials, Bernstein of degree 20 sent a point one box out
    // to half its place, degree 64 to 1e21 or NaN: float rounding amplified by (2 |s| + 1)^degree.
    const glm::mat3 shear(glm::vec3(2.0f, 0.1f, 0.0f), glm::vec3(0.2f, 1.5f, -0.1f),
                          glm::vec3(0.0f, 0.3f, 0.8f));
    const glm::vec3 move(0.5f, -1.0f, 2.0f);
    const auto affine = [&](glm::vec3 p) { return shear * p + move; };
    std::mt19937 rng(1207);
    std::uniform_real_distribution<float> far(-100.0f, 101.0f), near(-2.0f, 3.0f);
    struct Case {
        FfdBasis basis;
        int32_t divisions;
    };
    for (const Case c :
         {Case{FfdBasis::Bernstein, 3}, Case{FfdBasis::Bernstein, 20}, Case{FfdBasis::Bernstein, 64},
          Case{FfdBasis::BSpline, 64}, Case{FfdBasis::BSpline, 3}, Case{FfdBasis::CatmullRom, 7},
          Case{FfdBasis::Linear, 5}}) {
        Lattice l = skewLattice({c.divisions, 2, 3});
        std::vector<glm::vec3> target = l.controlPoints();
        for (glm::vec3& p : target)
            p = affine(p);
        std::vector<glm::vec3> pts;
        for (int k = 0; k < 400; ++k) {
            auto& dist = k % 2 == 0 ? far : near;
            pts.push_back(l.origin + l.axes * glm::vec3(dist(rng), dist(rng), dist(rng)));
        }
        for (FfdKernel kernel : {FfdKernel::Auto, FfdKernel::PerPoint}) {
            Ffd ffd(l, {FfdBases(c.basis), FfdOutside::Extrapolate, kernel});
            ffd.setTargets(target);
            std::vector<glm::vec3> oneOff, bound = pts;
            oneOff = pts;
            ffd.bindAndEvaluate(pts, oneOff);
            ffd.bind(pts);
            ffd.evaluate(bound);
            const auto engine = viaEngine(ffd, pts);
            // Float: the sum rounds each weight's share, so its error is bounded by a few float epsilons of
            // sum |w| max |T|, sum |w| = prod over axes of (1 + 2 k d_a g_a), g_a the distance outside in box
            // lengths (the continuation's weights 1 + k e and -k e, e = d_a g_a), and the engine's generic
            // path rounds each share's (P + T) - P at P's size too. The bound grows with the distance, not
            // the degree; the polynomials' grew as (2 |s| + 1)^degree.
            double maxT = 0.0;
            for (size_t k = 0; k < target.size(); ++k)
                maxT = std::max(maxT, static_cast<double>(glm::length(target[k] - l.controlPoints()[k])));
            double worst = 0.0;
            for (size_t u = 0; u < pts.size(); ++u) {
                const glm::dvec3 s = cramer(l, pts[u]);
                double weightSum = 1.0;
                for (int a = 0; a < 3; ++a) {
                    const double outside = std::max({0.0, -s[a], s[a] - 1.0});
                    weightSum *= 1.0 + 2.0 * l.divisions[a] * outside;
                }
                const double size = glm::length(pts[u]);
                const double allowed = 4.0 * 6e-8 * weightSum * (maxT + size) + 1e-6 * (1.0 + size);
                const glm::vec3 expected = affine(pts[u]);
                for (const glm::vec3& got : {oneOff[u], bound[u], engine[u]})
                    worst = std::max(worst, glm::length(glm::dvec3(got) - glm::dvec3(expected)) / allowed);
            }
            INFO("basis " << static_cast<int>(c.basis) << ", " << c.divisions << " divisions");
            CHECK(worst < 1.0);  // the error within its float bound
        }
    }
}

TEST_CASE("ffd: extrapolated, continuous with its slope across the faces", "[warp][ffd]") {
    // Random lattices of every basis: across a face (1e-3 of the box each side) the displacement and its
    // derivative along the face normal direction agree on both sides (the continuation takes the end face's
    // value and slope), within the finite difference's own error.
    std::mt19937 rng(31);
    for (FfdBasis basis : {FfdBasis::Bernstein, FfdBasis::BSpline, FfdBasis::CatmullRom, FfdBasis::Cardinal,
                           FfdBasis::Linear}) {
        const Lattice l = skewLattice({4, 3, 5});
        Ffd ffd(l, {FfdBases(basis), FfdOutside::Extrapolate});
        ffd.setTargets(randomTargets(l, rng, 0.3f));
        const float h = 1e-3f;
        std::vector<glm::vec3> pts;
        for (float face : {0.0f, 1.0f}) {
            for (float at : {0.3f, 0.55f}) {
                const glm::vec3 on = l.origin + l.axes * glm::vec3(face, at, 0.4f);
                for (float k : {-2.0f, -1.0f, 1.0f, 2.0f})
                    pts.push_back(on + k * h * l.axes[0]);
            }
        }
        const auto moved = viaEngine(ffd, pts);
        for (size_t g = 0; g < pts.size(); g += 4) {
            glm::vec3 d[4];
            for (int k = 0; k < 4; ++k)
                d[k] = moved[g + k] - pts[g + k];
            const glm::vec3 slopeIn = (d[1] - d[0]) / h, slopeOut = (d[3] - d[2]) / h;
            const glm::vec3 across = d[2] - d[1];
            INFO("basis " << static_cast<int>(basis) << ", group " << g / 4);
            // No step: the change across the face is the slope's over 2 h, to second order (curvature h^2).
            CHECK(glm::length(across - h * (slopeIn + slopeOut)) < 2e-4f);
            CHECK(glm::length(slopeIn - slopeOut) < 0.05f * (1.0f + glm::length(slopeIn)));
        }
    }
}

TEST_CASE("ffd: B-spline variant equals a Cox-de Boor evaluation over phantom controls", "[warp][ffd]") {
    std::mt19937 rng(16);
    for (glm::ivec3 div : {glm::ivec3(5, 4, 6), glm::ivec3(1, 2, 3), glm::ivec3(3, 3, 3)}) {
        const Lattice l = skewLattice(div);
        Ffd ffd(l, {FfdBasis::BSpline, FfdOutside::None});
        const auto target = randomTargets(l, rng, 0.4f);
        ffd.setTargets(target);
        const auto pts = samplePoints(l, rng, 300, 0.001f, 0.999f);
        std::vector<glm::vec3> ref(pts.size());
        for (size_t i = 0; i < pts.size(); ++i)
            ref[i] = bsplineRef(l, target, pts[i]);
        CHECK(maxError(viaEngine(ffd, pts), ref) < 1e-5f);
        std::vector<glm::vec3> fast = pts;
        ffd.bind(pts);
        ffd.evaluate(fast);
        CHECK(maxError(fast, ref) < 1e-5f);
        // The choice of end handling makes lattice corners interpolate their control.
        const glm::vec3 corner = l.controlPoint(div.x, 0, div.z);
        std::vector<glm::vec3> c{corner};
        CHECK(glm::length(viaEngine(ffd, c)[0] - target[l.index(div.x, 0, div.z)]) < 1e-5f);
    }
    // For 3 divisions the B-spline is not the Bernstein cubic: a real local variant.
    const Lattice l = skewLattice({3, 3, 3});
    const auto target = randomTargets(l, rng, 0.4f);
    const glm::vec3 p = l.origin + l.axes * glm::vec3(0.3f, 0.5f, 0.7f);
    CHECK(glm::length(bsplineRef(l, target, p) - bernsteinRef(l, target, p)) > 1e-3f);
}

TEST_CASE("ffd: B-spline is local, a control moves only points in its support", "[warp][ffd]") {
    std::mt19937 rng(17);
    const Lattice l = skewLattice({8, 8, 8});
    Ffd ffd(l, {FfdBasis::BSpline});
    const auto pts = samplePoints(l, rng, 2000, 0.0f, 1.0f);
    ffd.bind(pts);
    auto target = l.controlPoints();
    target[l.index(4, 4, 4)] += glm::vec3(0.5f, 0.0f, 0.0f);
    ffd.setTargets(target);  // no re-bind: moving a control redoes no bind work
    std::vector<glm::vec3> out = pts;
    ffd.evaluate(out);
    int moved = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        const glm::dvec3 x = cramer(l, pts[i]) * 8.0;
        const bool inSupport = std::abs(x.x - 4) < 2 && std::abs(x.y - 4) < 2 && std::abs(x.z - 4) < 2;
        if (!inSupport) CHECK(out[i] == pts[i]);
        moved += out[i] != pts[i] ? 1 : 0;
        CHECK(glm::length(out[i] - bsplineRef(l, target, pts[i])) < 1e-5f);
    }
    CHECK(moved > 50);
}

TEST_CASE("ffd: fast path equals the generic engine with painted weights and envelope", "[warp][ffd]") {
    std::mt19937 rng(18);
    for (FfdBasis basis : kAllBases) {
        for (FfdOutside outside : {FfdOutside::None, FfdOutside::Extrapolate}) {
            const Lattice l = skewLattice({4, 3, 5});
            const FfdEnds ends = basis == FfdBasis::Cardinal ? FfdEnds::Repeat : FfdEnds::Extrapolate;
            Ffd ffd(l, {basis, outside, FfdKernel::Auto, ends});
            ffd.setTargets(randomTargets(l, rng, 0.5f));
            const auto rest = samplePoints(l, rng, 3000, -0.2f, 1.2f);
            const std::vector<float> weights = randomWeights(rest.size(), rng);
            // Evaluate at upstream points that differ from the rest points, as a deformer stack would.
            const std::vector<glm::vec3> upstream = shifted(rest);
            WarpDeformer deformer(ffd);
            deformer.bind(rest);
            std::vector<glm::vec3> generic = upstream;
            deformer.evaluate(generic, weights, 0.7f);
            ffd.bind(rest);
            std::vector<glm::vec3> fast = upstream;
            ffd.evaluate(fast, weights, 0.7f);
            CHECK(maxError(generic, fast) < 1e-5f);
        }
    }
}

TEST_CASE("ffd: bit-identical output for 1 and 2 threads", "[warp][ffd][determinism]") {
    std::mt19937 rng(19);
    for (FfdBasis basis : kAllBases) {
        const Lattice l = skewLattice({3, 4, 5});
        Ffd ffd(l, {basis, FfdOutside::Extrapolate, FfdKernel::Auto, FfdEnds::Repeat});
        ffd.setTargets(randomTargets(l, rng, 0.5f));
        const auto rest = samplePoints(l, rng, 20000, -0.2f, 1.2f);
        std::vector<glm::vec3> one = rest, two = rest, engineOne, engineTwo;
        omp_set_num_threads(1);
        ffd.bind(rest);
        ffd.evaluate(one);
        engineOne = viaEngine(ffd, rest);
        omp_set_num_threads(2);
        ffd.bind(rest);
        ffd.evaluate(two);
        engineTwo = viaEngine(ffd, rest);
        CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec3)) == 0);
        CHECK(std::memcmp(engineOne.data(), engineTwo.data(), one.size() * sizeof(glm::vec3)) == 0);
    }
    omp_set_num_threads(omp_get_num_procs());
}

TEST_CASE("ffd: the AVX2 and portable Bernstein 4x4x4 kernels give the same bytes", "[warp][ffd][simd]") {
    // Divisions (3, 3, 3) take the SoA kernels; a point count that is not a multiple of the 8-point block,
    // points outside the lattice, painted weights and an envelope exercise the block tails and the mask.
    // No kernel uses fused multiply-add, so a farm of mixed CPUs writes the same bytes. Without AVX2 on this
    // CPU (or with DEFORMKIT_SIMD=baseline) both runs take the portable kernel and the comparison is
    // trivially exact.
    INFO("AVX2 kernel available: " << ffdHasAvx2Kernel());
    std::mt19937 rng(23);
    for (FfdOutside outside : {FfdOutside::None, FfdOutside::Extrapolate}) {
        const Lattice l = skewLattice({3, 3, 3});
        const auto target = randomTargets(l, rng, 0.5f);
        const auto rest = samplePoints(l, rng, 10001, -0.2f, 1.2f);
        const std::vector<float> weights = randomWeights(rest.size(), rng);
        const std::vector<glm::vec3> upstream = shifted(rest);
        Ffd fast(l, {FfdBasis::Bernstein, outside, FfdKernel::Auto});
        Ffd portable(l, {FfdBasis::Bernstein, outside, FfdKernel::Portable});
        std::vector<glm::vec3> a = upstream, b = upstream;
        for (Ffd* ffd : {&fast, &portable}) {
            ffd->setTargets(target);
            ffd->bind(rest);
        }
        fast.evaluate(a, weights, 0.7f);
        portable.evaluate(b, weights, 0.7f);
        CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0);
        // Both against the generic engine, as the fast path test does for other divisions.
        const auto generic = viaEngineFrom(portable, rest, upstream, weights, 0.7f);
        CHECK(maxError(a, generic) < 1e-5f);
        CHECK(maxError(b, generic) < 1e-5f);
        // And each kernel alone is bit-identical for 1 and 2 threads.
        for (Ffd* ffd : {&fast, &portable}) {
            std::vector<glm::vec3> one = upstream, two = upstream;
            omp_set_num_threads(1);
            ffd->evaluate(one, weights, 0.7f);
            omp_set_num_threads(2);
            ffd->evaluate(two, weights, 0.7f);
            CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec3)) == 0);
        }
        omp_set_num_threads(omp_get_num_procs());
    }
}

TEST_CASE("ffd: every basis on the 4x4x4 lattice takes the block kernels, bit for bit the per-point path",
          "[warp][ffd][simd]") {
    // The block kernels sum each point's per-point weights in the per-point path's order: every basis and end
    // rule, mixed bases, points outside the lattice (deformed, or left as they are), block tails, painted
    // weights, 1 and 2 threads.
    std::mt19937 rng(41);
    const FfdBasis bases[] = {FfdBasis::BSpline, FfdBasis::CatmullRom, FfdBasis::Cardinal,
                              FfdBasis::Linear,  FfdBasis::Bernstein,  FfdBasis::Bernstein};
    int cases = 0;
    for (const auto& [ends, outside] : {std::pair{FfdEnds::Extrapolate, FfdOutside::Extrapolate},
                                        std::pair{FfdEnds::Repeat, FfdOutside::Extrapolate},
                                        std::pair{FfdEnds::Extrapolate, FfdOutside::None}}) {
        for (int combo = 0; combo < 6; ++combo) {
            FfdBases basis = bases[combo];
            if (combo == 5) basis = FfdBases{FfdBasis::BSpline, FfdBasis::Bernstein, FfdBasis::CatmullRom};
            const Lattice l = skewLattice({3, 3, 3});
            const auto target = randomTargets(l, rng, 0.5f);
            auto rest = samplePoints(l, rng, 4099, -0.2f, 1.2f);
            // Far outside too: thousands of lattice widths away, and beyond 2^23 lattice units.
            for (const float far : {-3.0e3f, 2.5e3f, -1.0e8f, 4.0e8f})
                rest.push_back(l.origin + far * l.axes[0] + 0.5f * l.axes[1] - 0.25f * far * l.axes[2]);
            const std::vector<float> weights = randomWeights(rest.size(), rng);
            std::vector<glm::vec3> reference = rest;
            Ffd perPoint(l, {basis, outside, FfdKernel::PerPoint, ends});
            perPoint.setTargets(target);
            perPoint.bind(rest);
            perPoint.evaluate(reference, weights, 0.7f);
            for (FfdKernel kernel : {FfdKernel::Auto, FfdKernel::Portable}) {
                Ffd ffd(l, {basis, outside, kernel, ends});
                ffd.setTargets(target);
                ffd.bind(rest);
                for (int threads : {1, 2, 1}) {  // weights computed, kept, read back
                    omp_set_num_threads(threads);
                    std::vector<glm::vec3> got = rest;
                    ffd.evaluate(got, weights, 0.7f);
                    CHECK(std::memcmp(got.data(), reference.data(), got.size() * sizeof(glm::vec3)) == 0);
                }
            }
            omp_set_num_threads(omp_get_num_procs());
            CHECK(maxError(reference, rest) > 1e-3f);  // the lattice moves the points
            ++cases;
        }
    }
    CHECK(cases == 18);
}

TEST_CASE("ffd: a one-off without the bind cache gives bind + evaluate's bytes", "[warp][ffd][simd]") {
    std::mt19937 rng(61);
    for (const auto& [divisions, basis] :  // the fused paths (Bernstein, B-spline), the fallback
         {std::pair{glm::ivec3(3), FfdBasis::Bernstein}, std::pair{glm::ivec3(3), FfdBasis::BSpline},
          std::pair{glm::ivec3(3, 2, 4), FfdBasis::Bernstein}}) {
        for (FfdOutside outside : {FfdOutside::None, FfdOutside::Extrapolate}) {
            const Lattice l = skewLattice(divisions);
            const auto target = randomTargets(l, rng, 0.5f);
            const auto rest = samplePoints(l, rng, 5003, -0.2f, 1.2f);
            const std::vector<float> weights = randomWeights(rest.size(), rng);
            const std::vector<glm::vec3> upstream = shifted(rest);
            Ffd bound(l, {basis, outside});
            bound.setTargets(target);
            bound.bind(rest);
            std::vector<glm::vec3> want = upstream, got = upstream;
            bound.evaluate(want, weights, 0.7f);
            Ffd once(l, {basis, outside});
            once.setTargets(target);
            once.bindAndEvaluate(rest, got, weights, 0.7f);
            CHECK(std::memcmp(got.data(), want.data(), got.size() * sizeof(glm::vec3)) == 0);
            CHECK(maxError(want, upstream) > 1e-3f);
        }
    }
    // The bind's error, from either path.
    const Lattice l = skewLattice({3, 3, 3});
    std::vector<glm::vec3> rest(20, glm::vec3(0.5f));
    rest[13].y = std::numeric_limits<float>::quiet_NaN();
    std::vector<glm::vec3> points = rest;
    Ffd once(l);
    CHECK_THROWS_WITH(once.bindAndEvaluate(rest, points),
                      Catch::Contains("FFD bind: point 13: is not finite"));
}

TEST_CASE("ffd: evaluating into another buffer gives the in-place bytes on every path", "[warp][ffd][simd]") {
    // The Bernstein blocks, spline weights computed then kept, the per-point path (a 3 x 2 x 4 lattice), the
    // one-off without the bind cache; points outside an FfdOutside::None lattice are copied unchanged.
    std::mt19937 rng(71);
    int cases = 0;
    for (const glm::ivec3 divisions : {glm::ivec3(3), glm::ivec3(3, 2, 4)}) {
        for (FfdBasis basis : {FfdBasis::Bernstein, FfdBasis::BSpline}) {
            const Lattice l = skewLattice(divisions);
            const auto target = randomTargets(l, rng, 0.5f);
            const auto rest = samplePoints(l, rng, 4099, -0.2f, 1.2f);
            const std::vector<float> weights = randomWeights(rest.size(), rng);
            const std::vector<glm::vec3> upstream = shifted(rest);
            Ffd ffd(l, {basis, FfdOutside::None});
            ffd.setTargets(target);
            ffd.bind(rest);
            for (int round = 0; round < 3; ++round) {  // spline weights computed, kept, read back
                std::vector<glm::vec3> inPlace = upstream, out(upstream.size(), glm::vec3(-7.0f));
                ffd.evaluate(inPlace, weights, 0.7f);
                ffd.evaluate(upstream, out, weights, 0.7f);
                CHECK(std::memcmp(out.data(), inPlace.data(), out.size() * sizeof(glm::vec3)) == 0);
            }
            Ffd once(l, {basis, FfdOutside::None});
            once.setTargets(target);
            std::vector<glm::vec3> inPlace = upstream, out(upstream.size(), glm::vec3(-7.0f));
            ffd.evaluate(inPlace, weights, 0.7f);
            once.bindAndEvaluate(rest, upstream, out, weights, 0.7f);
            CHECK(std::memcmp(out.data(), inPlace.data(), out.size() * sizeof(glm::vec3)) == 0);
            CHECK(maxError(inPlace, upstream) > 1e-3f);
            ++cases;
        }
    }
    CHECK(cases == 4);
    const Lattice l = skewLattice({3, 3, 3});
    Ffd ffd(l);
    const std::vector<glm::vec3> rest(10, glm::vec3(0.5f));
    ffd.bind(rest);
    std::vector<glm::vec3> shortOut(9);
    CHECK_THROWS_WITH(ffd.evaluate(rest, shortOut, {}, 1.0f),
                      Catch::Contains("output: has 9 points") && Catch::Contains("10 points, as bound"));
}

TEST_CASE("ffd: bad input names the element", "[warp][ffd][errors]") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    Lattice l = skewLattice({3, 0, 3});
    CHECK_THROWS_AS(Ffd(l), InvalidInput);
    CHECK_THROWS_WITH(Ffd(l), Catch::Contains("divisions[1] (m)") && Catch::Contains("is 0"));
    l.divisions = {-2, 3, 3};
    CHECK_THROWS_WITH(Ffd(l), Catch::Contains("divisions[0] (l)") && Catch::Contains("is -2"));
    l.divisions = {3, 3, 100};
    CHECK_THROWS_WITH(Ffd(l), Catch::Contains("divisions[2] (n)") && Catch::Contains("B-spline"));
    CHECK_NOTHROW(Ffd(l, {FfdBasis::BSpline}));
    l.divisions = {3, 3, 100000};
    CHECK_THROWS_WITH(Ffd(l, {FfdBasis::BSpline}),
                      Catch::Contains("divisions[2] (n)") && Catch::Contains("1024"));

    l = skewLattice({3, 3, 3});
    l.axes[1] = glm::vec3(0.0f);
    CHECK_THROWS_WITH(Ffd(l), Catch::Contains("axis Y") && Catch::Contains("zero length"));
    l = skewLattice({3, 3, 3});
    l.axes[2] = l.axes[0] * 0.5f + l.axes[1] * 2.0f;  // coplanar: zero volume
    CHECK_THROWS_WITH(Ffd(l), Catch::Contains("coplanar"));
    l = skewLattice({3, 3, 3});
    l.axes[0].y = nan;
    CHECK_THROWS_WITH(Ffd(l), Catch::Contains("axis X") && Catch::Contains("not finite"));
    l = skewLattice({3, 3, 3});
    l.origin.z = std::numeric_limits<float>::infinity();
    CHECK_THROWS_WITH(Ffd(l), Catch::Contains("origin"));

    l = skewLattice({3, 3, 3});
    Ffd ffd(l);
    std::vector<glm::vec3> target = l.controlPoints();
    target.pop_back();
    CHECK_THROWS_WITH(ffd.setTargets(target), Catch::Contains("targets") && Catch::Contains("63 points") &&
                                                  Catch::Contains("= 64 points"));
    target = l.controlPoints();
    target[l.index(1, 2, 3)].x = nan;
    CHECK_THROWS_WITH(ffd.setTargets(target),
                      Catch::Contains("target 27 (i=1, j=2, k=3)") && Catch::Contains("not finite"));
    CHECK(ffd.targets()[27] == l.controlPoint(1, 2, 3));  // nothing changed

    std::vector<glm::vec3> pts{{0, 0, 0}, {1, 1, 1}};
    CHECK_THROWS_WITH(ffd.evaluate(pts), Catch::Contains("before bind"));
    pts[1].y = nan;
    CHECK_THROWS_WITH(ffd.bind(pts), Catch::Contains("point 1") && Catch::Contains("not finite"));
    pts[1].y = 1.0f;
    ffd.bind(pts);
    std::vector<glm::vec3> three(3);
    CHECK_THROWS_WITH(ffd.evaluate(three), Catch::Contains("3 points") && Catch::Contains("2 points"));
    std::vector<float> w(5, 1.0f);
    CHECK_THROWS_WITH(ffd.evaluate(pts, w), Catch::Contains("painted weights"));
}

TEST_CASE("ffd: Blender's lattice interpolations with repeated end controls equal a second implementation",
          "[warp][ffd][blender]") {
    // Random lattices (1 to 5 divisions an axis), a random basis per axis, random moved controls, points
    // inside and up to a lattice width outside: Blender deforms every point, so outside = Extrapolate.
    std::mt19937 rng(31);
    std::uniform_int_distribution<int> divisions(1, 5), pick(0, 3);
    double worst = 0.0;
    for (int trial = 0; trial < 40; ++trial) {
        const Lattice l = skewLattice({divisions(rng), divisions(rng), divisions(rng)});
        const FfdBases bases(kSplineBases[pick(rng)], kSplineBases[pick(rng)], kSplineBases[pick(rng)]);
        Ffd ffd(l, {bases, FfdOutside::Extrapolate, FfdKernel::Auto, FfdEnds::Repeat});
        const auto target = randomTargets(l, rng, 0.4f);
        ffd.setTargets(target);
        const auto pts = samplePoints(l, rng, 300, -1.0f, 2.0f);
        std::vector<glm::vec3> ref(pts.size());
        for (size_t i = 0; i < pts.size(); ++i)
            ref[i] = repeatedEndsRef(l, bases, target, pts[i]);
        std::vector<glm::vec3> fast = pts;
        ffd.bind(pts);
        ffd.evaluate(fast);
        worst = std::max<double>(worst, maxError(fast, ref));
        CHECK(maxError(viaEngine(ffd, pts), ref) < 1e-5f);
    }
    CHECK(worst < 1e-5);
}

TEST_CASE("ffd: repeated end controls, closed forms at the ends and beyond", "[warp][ffd][blender]") {
    // One cell along each axis would hide the difference; 3 divisions along X, 1 along Y and Z, and only
    // the X end controls moved.
    const Lattice l = skewLattice({3, 1, 1});
    std::vector<glm::vec3> target = l.controlPoints();
    const glm::vec3 d0(0.3f, 0.0f, 0.0f), d1(0.0f, 0.2f, 0.0f);
    for (int j = 0; j <= 1; ++j)
        for (int k = 0; k <= 1; ++k) {
            target[l.index(0, j, k)] += d0;
            target[l.index(1, j, k)] += d1;
        }
    const glm::vec3 onEndFace = l.origin + l.axes * glm::vec3(0.0f, 0.5f, 0.5f);
    const glm::vec3 farOutside = l.origin + l.axes * glm::vec3(-2.0f, 0.5f, 0.5f);
    struct Case {
        FfdBasis basis;
        glm::vec3 endFace;  // the displacement at x = 0
    };
    // The B-spline at a knot weights its controls 1/6, 4/6, 1/6: controls -1 and 0 are both control 0, so
    // the end face moves by 5/6 d0 + 1/6 d1 (with extrapolated ends it would move by d0 exactly). The
    // interpolating bases move it by d0.
    for (const Case& c :
         {Case{FfdBasis::BSpline, 5.0f / 6.0f * d0 + 1.0f / 6.0f * d1}, Case{FfdBasis::Linear, d0},
          Case{FfdBasis::Cardinal, d0}, Case{FfdBasis::CatmullRom, d0}}) {
        INFO("basis " << static_cast<int>(c.basis));
        Ffd ffd(l, {c.basis, FfdOutside::Extrapolate, FfdKernel::Auto, FfdEnds::Repeat});
        ffd.setTargets(target);
        std::vector<glm::vec3> pts = {onEndFace, farOutside};
        ffd.bind(pts);
        ffd.evaluate(pts);
        CHECK(maxError({pts[0]}, {onEndFace + c.endFace}) < 1e-6f);
        // Two lattice widths out every tap is control 0: the point moves by d0, rigidly.
        CHECK(maxError({pts[1]}, {farOutside + d0}) < 1e-6f);
    }
    Ffd extrapolated(l, {FfdBasis::BSpline, FfdOutside::Extrapolate});
    extrapolated.setTargets(target);
    std::vector<glm::vec3> pts = {onEndFace};
    extrapolated.bind(pts);
    extrapolated.evaluate(pts);
    CHECK(maxError(pts, {onEndFace + d0}) < 1e-6f);
}
