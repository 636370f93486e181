// FFD with coordinate-frame features (paper §5.1): equal to FFD for translation-only frames, and a local
// rotation about a control that plain FFD cannot make, against closed forms written here.
#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/ffd_frames.h"
#include "warp_test_support.h"

using namespace deformkit;
using namespace deformkit::warp;
using deformkit::test::maxError;
using deformkit::test::samplePoints;
using deformkit::test::viaEngine;

namespace {

Lattice boxLattice(glm::ivec3 divisions) {
    Lattice l;
    l.origin = {-1.0f, -1.0f, -1.0f};
    l.axes = glm::mat3(2.0f);
    l.divisions = divisions;
    return l;
}

Lattice skewLattice(glm::ivec3 divisions) {
    Lattice l;
    l.origin = {0.2f, -0.4f, 0.5f};
    l.axes =
        glm::mat3(glm::vec3(1.8f, 0.2f, 0.1f), glm::vec3(-0.3f, 1.2f, 0.2f), glm::vec3(0.1f, -0.2f, 1.6f));
    l.divisions = divisions;
    return l;
}

glm::mat3 rotationZ(float angle) {
    const float c = std::cos(angle), s = std::sin(angle);
    return glm::mat3(glm::vec3(c, s, 0), glm::vec3(-s, c, 0), glm::vec3(0, 0, 1));
}

}  // namespace

TEST_CASE("ffd frames: frameToFrame maps source frame to target frame", "[warp][ffd][frames]") {
    const Frame from{{1, 2, 3},
                     glm::mat3(glm::vec3(1, 0.2f, 0), glm::vec3(0, 2, 0.1f), glm::vec3(0.3f, 0, 1))};
    const Frame to{{-1, 0, 4}, glm::mat3(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0.5f), glm::vec3(0, 0, 3))};
    const Affine t = frameToFrame(from, to);
    CHECK(glm::length(t.apply(from.origin) - to.origin) < 1e-5f);
    for (int a = 0; a < 3; ++a) {
        // Each source basis vector's tip goes to the target's.
        CHECK(glm::length(t.apply(from.origin + from.basis[a]) - (to.origin + to.basis[a])) < 1e-5f);
    }
}

TEST_CASE("ffd frames: translation-only frames equal plain FFD", "[warp][ffd][frames]") {
    std::mt19937 rng(21);
    std::uniform_real_distribution<float> uni(-0.4f, 0.4f);
    for (FfdBasis basis : {FfdBasis::Bernstein, FfdBasis::BSpline}) {
        for (FfdOutside outside : {FfdOutside::None, FfdOutside::Extrapolate}) {
            const Lattice l = skewLattice({3, 2, 4});
            Ffd ffd(l, {basis, outside});
            FfdFrames frames(l, {basis, outside});
            std::vector<glm::vec3> target = l.controlPoints();
            std::vector<Frame> source(target.size()), moved(target.size());
            for (size_t c = 0; c < target.size(); ++c) {
                // Any invertible source basis, the same basis at the target: a pure translation.
                const glm::mat3 b(glm::vec3(1 + uni(rng), uni(rng), uni(rng)),
                                  glm::vec3(uni(rng), 1 + uni(rng), uni(rng)),
                                  glm::vec3(uni(rng), uni(rng), 1 + uni(rng)));
                source[c] = {target[c], b};
                target[c] += glm::vec3(uni(rng), uni(rng), uni(rng));
                moved[c] = {target[c], b};
            }
            ffd.setTargets(target);
            frames.setSourceFrames(source);
            frames.setTargetFrames(moved);
            const auto pts = samplePoints(l, rng, 1000, -0.2f, 1.2f);
            const auto plain = viaEngine(ffd, pts);
            CHECK(maxError(viaEngine(frames, pts), plain) < 1e-5f);
            std::vector<glm::vec3> fast = pts;
            frames.bind(pts);
            frames.evaluate(fast);
            CHECK(maxError(fast, plain) < 1e-5f);
            // Into another buffer: the in-place bytes.
            std::vector<glm::vec3> into(pts.size());
            frames.evaluate(pts, into, {}, 1.0f);
            CHECK(std::memcmp(into.data(), fast.data(), into.size() * sizeof(glm::vec3)) == 0);
        }
    }
}

TEST_CASE("ffd frames: identity when target frames equal source frames", "[warp][ffd][frames]") {
    std::mt19937 rng(22);
    const Lattice l = skewLattice({2, 3, 2});
    FfdFrames frames(l, {FfdBasis::Bernstein, FfdOutside::Extrapolate});
    std::vector<Frame> source(l.numControls());
    const auto cp = l.controlPoints();
    for (size_t c = 0; c < source.size(); ++c)
        source[c] = {cp[c], rotationZ(0.1f * c) * glm::mat3(1.5f)};
    frames.setSourceFrames(source);
    frames.setTargetFrames(source);
    const auto pts = samplePoints(l, rng, 500, -0.3f, 1.3f);
    CHECK(maxError(viaEngine(frames, pts), pts) < 1e-6f);
    std::vector<glm::vec3> fast = pts;
    frames.bind(pts);
    frames.evaluate(fast);
    CHECK(maxError(fast, pts) < 1e-6f);
}

TEST_CASE("ffd frames: rotating the centre frame rotates the model about that control",
          "[warp][ffd][frames]") {
    // Divisions (2, 2, 2) over [-1, 1]^3: the centre control (1, 1, 1) sits at the origin, with Bernstein
    // weight (2 s (1 - s))^3 in each local coordinate s = (x + 1) / 2.
    const Lattice l = boxLattice({2, 2, 2});
    const float angle = std::numbers::pi_v<float> / 3.0f;
    const glm::mat3 r = rotationZ(angle);
    FfdFrames frames(l);
    std::vector<Frame> target(frames.targetFrames().begin(), frames.targetFrames().end());
    const int32_t centre = l.index(1, 1, 1);
    REQUIRE(glm::length(target[centre].origin) < 1e-7f);
    target[centre].basis = r;
    frames.setTargetFrames(target);

    const int samples = 24;
    const float radius = 0.2f;
    std::vector<glm::vec3> ring(samples);
    for (int s = 0; s < samples; ++s) {
        const float a = 2.0f * std::numbers::pi_v<float> * s / samples;
        ring[s] = {radius * std::cos(a), radius * std::sin(a), 0.05f};
    }
    ring.push_back(glm::vec3(0.0f));  // the centre control itself does not move
    const auto out = viaEngine(frames, ring);
    std::vector<glm::vec3> fast = ring;
    frames.bind(ring);
    frames.evaluate(fast);
    CHECK(maxError(out, fast) < 1e-5f);
    CHECK(glm::length(out[samples]) < 1e-6f);
    float circulation = 0.0f;
    for (int s = 0; s < samples; ++s) {
        const glm::vec3 p = ring[s];
        float wc = 1.0f;  // B^2_1(s) B^2_1(t) B^2_1(u), B^2_1(s) = 2 s (1 - s)
        for (int a = 0; a < 3; ++a) {
            const float t = (p[a] + 1.0f) / 2.0f;
            wc *= 2.0f * t * (1.0f - t);
        }
        // Closed form: p + w_c (R p - p), the other controls' transformations being the identity.
        const glm::vec3 expected = p + wc * (r * p - p);
        CHECK(glm::length(out[s] - expected) < 1e-5f);
        const glm::vec3 d = out[s] - p, tangent = glm::normalize(glm::vec3(-p.y, p.x, 0.0f));
        CHECK(glm::dot(d, tangent) > 0.0f);  // every point turns the same way about the control
        circulation += glm::dot(d, tangent);
    }
    // Each point turns by about w_c r sin(angle) with w_c >= (1/8)(1 - r^2)^2 (1 - z^2) on this ring.
    CHECK(circulation >
          0.9f * samples * radius * std::sin(angle) * 0.125f * (1 - radius * radius) * (1 - radius * radius));

    // Plain FFD moving the centre control point (its only freedom there) cannot turn the ring: the
    // displacements near the control are nearly parallel and their circulation vanishes.
    Ffd ffd(l);
    std::vector<glm::vec3> points = l.controlPoints();
    points[centre] += glm::vec3(0.3f, 0.2f, 0.0f);
    ffd.setTargets(points);
    const auto plain = viaEngine(ffd, std::vector<glm::vec3>(ring.begin(), ring.end() - 1));
    float plainCirculation = 0.0f;
    for (int s = 0; s < samples; ++s) {
        const glm::vec3 p = ring[s];
        plainCirculation += glm::dot(plain[s] - p, glm::normalize(glm::vec3(-p.y, p.x, 0.0f)));
    }
    CHECK(std::abs(plainCirculation) < 1e-4f * samples);
    CHECK(circulation > 100.0f * std::abs(plainCirculation));
}

TEST_CASE("ffd frames: bit-identical output for 1 and 2 threads", "[warp][ffd][frames][determinism]") {
    std::mt19937 rng(23);
    const Lattice l = skewLattice({3, 3, 3});
    FfdFrames frames(l, {FfdBasis::BSpline, FfdOutside::Extrapolate});
    std::vector<Frame> target(frames.targetFrames().begin(), frames.targetFrames().end());
    for (size_t c = 0; c < target.size(); ++c) {
        target[c].basis = rotationZ(0.05f * static_cast<float>(c));
        target[c].origin += glm::vec3(0.01f * c, 0.0f, -0.02f);
    }
    frames.setTargetFrames(target);
    const auto rest = samplePoints(l, rng, 20000, -0.2f, 1.2f);
    std::vector<glm::vec3> one = rest, two = rest;
    omp_set_num_threads(1);
    frames.bind(rest);
    frames.evaluate(one);
    omp_set_num_threads(2);
    frames.bind(rest);
    frames.evaluate(two);
    omp_set_num_threads(omp_get_num_procs());
    CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec3)) == 0);
    CHECK(maxError(one, viaEngine(frames, rest)) < 1e-5f);
}

TEST_CASE("ffd frames: bad input names the control", "[warp][ffd][frames][errors]") {
    const Lattice l = skewLattice({2, 2, 2});
    FfdFrames frames(l);
    std::vector<Frame> f(frames.sourceFrames().begin(), frames.sourceFrames().end());
    f[l.index(2, 1, 0)].basis[1] = f[l.index(2, 1, 0)].basis[0];
    CHECK_THROWS_AS(frames.setSourceFrames(f), InvalidInput);
    CHECK_THROWS_WITH(frames.setSourceFrames(f), Catch::Contains("control 21 (i=2, j=1, k=0)") &&
                                                     Catch::Contains("singular source basis"));
    // A well-conditioned basis 1e-39 long (a denormal scale) maps onto a unit target by 1e39 (NaN points),
    // one 1e-38 long by 1e38 (finite, but infinite once extrapolated): refused at any control, the origin's
    // too.
    for (const size_t c : {l.index(1, 1, 1), l.index(0, 0, 0)}) {
        for (const float scale : {1e-39f, 1e-38f, 1e-19f}) {
            f = {frames.sourceFrames().begin(), frames.sourceFrames().end()};
            f[c].basis = glm::mat3(scale);
            CHECK_THROWS_WITH(frames.setSourceFrames(f), Catch::Contains("control " + std::to_string(c)) &&
                                                             Catch::Contains("with a scale beyond 1e18"));
        }
    }
    // A scale of 1e6 (a basis 1e-6 long) is a frame, if an extreme one.
    f = {frames.sourceFrames().begin(), frames.sourceFrames().end()};
    f[l.index(1, 1, 1)].basis = glm::mat3(1e-6f);
    CHECK_NOTHROW(frames.setSourceFrames(f));
    f = {frames.sourceFrames().begin(), frames.sourceFrames().end()};
    f[5].origin.y = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(frames.setTargetFrames(f),
                      Catch::Contains("target frame of control 5") && Catch::Contains("not finite"));
    f.pop_back();
    CHECK_THROWS_WITH(frames.setTargetFrames(f), Catch::Contains("target frames") &&
                                                     Catch::Contains("26 frames") &&
                                                     Catch::Contains("27 frames"));
    CHECK(frames.targetFrames()[5].origin == l.controlPoint(0, 1, 2));  // nothing changed

    // Targets refused at the last control (a scale beyond 1e18) leave every control as it was: the same
    // deformation as before the call, not the first controls' new targets.
    const std::vector<glm::vec3> points = {l.origin + 0.3f * l.axes[0] + 0.6f * l.axes[1] + 0.4f * l.axes[2],
                                           l.origin + 0.9f * l.axes[0] + 0.1f * l.axes[1] + 0.8f * l.axes[2]};
    frames.setSourceFrames(std::vector<Frame>(frames.targetFrames().begin(), frames.targetFrames().end()));
    frames.bind(points);
    std::vector<glm::vec3> before = points, after = points;
    frames.evaluate(before);
    f = {frames.targetFrames().begin(), frames.targetFrames().end()};
    for (Frame& frame : f)
        frame.origin += glm::vec3(0.2f);
    f.back().basis *= 1e19f;
    CHECK_THROWS_WITH(frames.setTargetFrames(f),
                      Catch::Contains("control 26") && Catch::Contains("with a scale beyond 1e18"));
    frames.evaluate(after);
    CHECK(after == before);
    CHECK(frames.targetFrames()[0].origin == l.controlPoint(0, 0, 0));
}

TEST_CASE("ffd frames: the 4x4x4 lattice takes the block kernels, bit for bit the per-point path",
          "[warp][ffd][frames][simd]") {
    // Random frames (rotations, scales, shears), every basis, points outside, block tails, painted weights.
    std::mt19937 rng(57);
    std::uniform_real_distribution<float> uni(-0.4f, 0.4f), unit(0.0f, 1.0f);
    for (FfdBasis basis : {FfdBasis::Bernstein, FfdBasis::BSpline, FfdBasis::CatmullRom, FfdBasis::Linear}) {
        CAPTURE(static_cast<int>(basis));
        const Lattice l = skewLattice({3, 3, 3});
        std::vector<glm::vec3> points = l.controlPoints();
        std::vector<Frame> source(points.size()), moved(points.size());
        for (size_t c = 0; c < points.size(); ++c) {
            const glm::mat3 a(glm::vec3(1 + uni(rng), uni(rng), uni(rng)),
                              glm::vec3(uni(rng), 1 + uni(rng), uni(rng)),
                              glm::vec3(uni(rng), uni(rng), 1 + uni(rng)));
            const glm::mat3 b(glm::vec3(1 + uni(rng), uni(rng), uni(rng)),
                              glm::vec3(uni(rng), 1 + uni(rng), uni(rng)),
                              glm::vec3(uni(rng), uni(rng), 1 + uni(rng)));
            source[c] = {points[c], a};
            moved[c] = {points[c] + glm::vec3(uni(rng), uni(rng), uni(rng)), b};
        }
        const auto rest = samplePoints(l, rng, 4099, -0.2f, 1.2f);
        std::vector<float> weights(rest.size());
        for (auto& w : weights)
            w = unit(rng);
        std::vector<glm::vec3> reference = rest;
        {
            FfdFrames perPoint(l, {basis, FfdOutside::Extrapolate, FfdKernel::PerPoint});
            perPoint.setSourceFrames(source);
            perPoint.setTargetFrames(moved);
            perPoint.bind(rest);
            perPoint.evaluate(reference, weights, 0.6f);
        }
        for (FfdKernel kernel : {FfdKernel::Auto, FfdKernel::Portable}) {
            FfdFrames frames(l, {basis, FfdOutside::Extrapolate, kernel});
            frames.setSourceFrames(source);
            frames.setTargetFrames(moved);
            frames.bind(rest);
            for (int threads : {1, 2, 1}) {  // weights computed, kept, read back
                omp_set_num_threads(threads);
                std::vector<glm::vec3> got = rest;
                frames.evaluate(got, weights, 0.6f);
                CHECK(std::memcmp(got.data(), reference.data(), got.size() * sizeof(glm::vec3)) == 0);
            }
        }
        omp_set_num_threads(omp_get_num_procs());
        CHECK(maxError(reference, rest) > 1e-2f);
    }
}
