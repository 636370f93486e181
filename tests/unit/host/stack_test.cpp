#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/slide/slider.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_dcc.h"
#include "deformkit/warp/ffd.h"
#include "host/host_test_support.h"
#include "slide/slide_test_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;
using host::DeformerStack;
using host::makeDeformer;

using test::flatten;
using test::maxError;
using test::restOf;

namespace {

bool sameBits(const glm::vec3& a, const glm::vec3& b) {
    return std::memcmp(&a, &b, sizeof(glm::vec3)) == 0;
}

// The scene of the comparison test: a 2 x 2 plane (n x n quads) at z = 0.1, a 2 x 2 x 1 lattice around
// it with two controls moved, a Maya twist about the x axis, a slide at the centre.
struct Scene {
    explicit Scene(int n = 8)
        : rest(test::planeGrid(n, n, 2.0f / n, glm::mat3(1.0f), glm::vec3(0, 0, 0.1f))) {
        lattice.divisions = {2, 2, 1};
        lattice.origin = {-0.1f, -0.1f, -0.5f};
        lattice.axes = glm::mat3(glm::vec3(2.2f, 0, 0), glm::vec3(0, 2.2f, 0), glm::vec3(0, 0, 1.2f));
        targets = lattice.controlPoints();
        targets[lattice.index(1, 1, 1)] += glm::vec3(0.2f, -0.1f, 0.4f);
        targets[lattice.index(2, 0, 0)] += glm::vec3(-0.1f, 0.3f, 0.1f);
        twist.handleOrigin = {1, 1, 0};
        twist.handleY = {1, 0, 0};
        twist.startAngle = -0.4;
        twist.endAngle = 0.7;
        centre = (n / 2) * (n + 1) + n / 2;
    }

    // The stack: ffd, twist, slide, set by name.
    void fill(DeformerStack& stack) const {
        stack.setRest(rest);
        auto ffd = makeDeformer("ffd", "lattice1");
        ffd->set("divisions", std::vector<double>{2, 2, 1});
        ffd->set("origin", std::vector<double>{lattice.origin.x, lattice.origin.y, lattice.origin.z});
        ffd->set("axes", std::vector<double>{2.2f, 0, 0, 0, 2.2f, 0, 0, 0, 1.2f});
        ffd->set("points", flatten(targets));
        stack.add(std::move(ffd));
        stack.add(makeDeformer("twist", "twist1"));
        stack.set(1, "handleOrigin", std::vector<double>{1, 1, 0});
        stack.set(1, "handleY", std::vector<double>{1, 0, 0});
        stack.set(1, "startAngle", -0.4);
        stack.set(1, "endAngle", 0.7);
        stack.add(makeDeformer("slide", "slide1"));
        stack.set(2, "vertex", static_cast<double>(centre));
        stack.set(2, "radius", 0.8);
        stack.set(2, "displacement", std::vector<double>{0.15, -0.1, 0.0});
    }

    // The same through the core APIs, in the same order; weights and envelope as given for each stage
    // (empty / 1 = none). The warps take Maya's rule through warp::applyEnvelope; the slide its own.
    std::vector<glm::vec3> direct(const std::vector<float>& weights = {}, float envelope = 1.0f) const {
        std::vector<glm::vec3> points = restOf(rest);
        warp::Ffd ffd(lattice);
        ffd.setTargets(targets);
        ffd.bind(rest.points());
        ffd.evaluate(points);
        const warp::AxialSetup setup = warp::fromMayaTwist(twist);
        warp::TwistWarp twistWarp(setup.frame, setup.profile);
        warp::SparseFields fields;
        twistWarp.bind(rest.points(), fields);
        std::vector<glm::vec3> twisted(points.size());
        twistWarp.evaluate(points, twisted);
        slide::Slider slider(rest, {{centre, 0.8}});
        const std::vector<slide::SlideDrive> drives{{glm::dvec3(0.15, -0.1, 0.0)}};
        slider.evaluate(drives, twisted, weights, envelope);
        return twisted;
    }

    geom::Mesh rest;
    warp::Lattice lattice;
    std::vector<glm::vec3> targets;
    warp::MayaTwist twist;
    int32_t centre = 0;
};

}  // namespace

TEST_CASE("a stack of two warps and a slide equals the same core calls made directly", "[host][stack]") {
    const Scene scene;
    DeformerStack stack;
    scene.fill(stack);
    REQUIRE(stack.size() == 3);
    std::vector<glm::vec3> points = restOf(scene.rest);
    stack.evaluate(points);
    const std::vector<glm::vec3> expected = scene.direct();
    // Envelope 1 and no painted weights: each stage's output is its core deformer's, bit for bit (the blend
    // passes a weight of exactly 1 through untouched).
    CHECK(test::sameBits(points, expected));
    CHECK(maxError(points, restOf(scene.rest)) > 0.1f);  // every stage did something
    CHECK(stack.bindCount() == 3);

    // Evaluating again from the rest positions repeats the result bit for bit, without binding.
    std::vector<glm::vec3> again = restOf(scene.rest);
    stack.evaluate(again);
    CHECK(test::sameBits(again, expected));
    CHECK(stack.bindCount() == 3);

    // The slide takes weights and envelope itself (Native): equal to the Slider given them directly.
    std::vector<float> weights(scene.rest.numVertices());
    for (size_t u = 0; u < weights.size(); ++u)
        weights[u] = static_cast<float>(u % 5) / 4.0f;
    stack.setWeights(2, weights);
    stack.setEnvelope(2, 0.5);
    std::vector<glm::vec3> weighted = restOf(scene.rest);
    stack.evaluate(weighted);
    CHECK(test::sameBits(weighted, scene.direct(weights, 0.5f)));
    CHECK(stack.bindCount() == 3);
}

TEST_CASE("envelope and painted weights follow out = in + e w (d - in)", "[host][stack]") {
    const geom::Mesh rest = test::planeGrid(6, 6, 0.4f, glm::mat3(1.0f), glm::vec3(-1.2f, -1.2f, 0.3f));
    const double theta = 0.9;
    DeformerStack stack;
    stack.setRest(rest);
    stack.add(makeDeformer("twist", "tw"));
    stack.set(0, "startAngle", theta);  // a constant twist about +y through the origin
    stack.set(0, "endAngle", theta);
    std::vector<float> weights(rest.numVertices());
    for (size_t u = 0; u < weights.size(); ++u)
        weights[u] = static_cast<float>(u % 7) / 6.0f;  // 0, 1/6, ..., 1
    stack.setWeights(0, weights);
    const double envelope = 0.6;
    stack.set(0, "envelope", envelope);
    CHECK(stack.get(0, "envelope") == std::vector<double>{0.6});

    std::vector<glm::vec3> out = restOf(rest);
    stack.evaluate(out);
    // The full deformation, to blend by hand: the twist alone.
    std::vector<glm::vec3> full(out.size());
    stack.deformer(0).evaluate(restOf(rest), full);
    const auto in = rest.points();
    for (size_t u = 0; u < out.size(); ++u) {
        const glm::dvec3 p(in[u]);
        // Closed form of the twist: right-handed about +y by theta.
        const glm::dvec3 d(p.x * std::cos(theta) + p.z * std::sin(theta), p.y,
                           -p.x * std::sin(theta) + p.z * std::cos(theta));
        const double k = envelope * weights[u];
        const glm::dvec3 expected = p + k * (d - p);
        // Against the closed form: the twist's float trigonometry is off by a few float ulps of
        // coordinates below 2 (2^-22 each), so 2e-6.
        CHECK(glm::length(glm::dvec3(out[u]) - expected) < 2e-6);
        // Against the rule on the deformer's own float output, in double and rounded once: exact.
        const glm::vec3 rule(p + k * (glm::dvec3(full[u]) - p));
        CHECK(sameBits(out[u], rule));
    }
    // The weight-0 vertices did not move at all.
    CHECK(sameBits(out[0], in[0]));
    CHECK(sameBits(out[7], in[7]));

    // Envelope 1 and weight 1: exactly the deformed position.
    stack.setEnvelope(0, 1.0);
    std::vector<glm::vec3> full2 = restOf(rest);
    stack.evaluate(full2);
    CHECK(sameBits(full2[6], full[6]));

    // Envelope 0: bit-identical pass-through; all-zero weights too.
    stack.setEnvelope(0, 0.0);
    CHECK_FALSE(stack.isActive(0));
    std::vector<glm::vec3> off = restOf(rest);
    stack.evaluate(off);
    CHECK(test::sameBits(off, restOf(rest)));
    stack.setEnvelope(0, 1.0);
    stack.setWeights(0, std::vector<float>(rest.numVertices(), 0.0f));
    CHECK_FALSE(stack.isActive(0));
    std::vector<glm::vec3> zero = restOf(rest);
    stack.evaluate(zero);
    CHECK(test::sameBits(zero, restOf(rest)));
    // Envelope beyond 1 is not clamped: twice the displacement (0 + 2 (d - 0) on the twist's axis plane).
    stack.setWeights(0, {});
    stack.setEnvelope(0, 2.0);
    std::vector<glm::vec3> twice = restOf(rest);
    stack.evaluate(twice);
    const glm::dvec3 p(in[3]);
    const glm::dvec3 twiceExpected = p + 2.0 * (glm::dvec3(full[3]) - p);
    CHECK(glm::length(glm::dvec3(twice[3]) - twiceExpected) < 1e-6);  // float rounding of the output
}

TEST_CASE("the slide's own weighting equals Maya's rule on a plane", "[host][stack][slide]") {
    // On a plane the slide is a translation by falloff x weight x envelope x displacement, which is
    // also what out = in + e w (d - in) gives: the two agree to the walk's rounding (1e-6 at unit scale).
    const geom::Mesh rest = test::planeGrid(10, 10, 0.2f);
    DeformerStack stack;
    stack.setRest(rest);
    stack.add(makeDeformer("slide", "s"));
    stack.set(0, "vertex", 60.0);  // (5, 5), the centre (1, 1)
    stack.set(0, "radius", 0.9);
    stack.set(0, "displacement", std::vector<double>{0.3, 0.2, 0.0});
    std::vector<glm::vec3> full = restOf(rest);
    stack.evaluate(full);
    std::vector<float> weights(rest.numVertices());
    for (size_t u = 0; u < weights.size(); ++u)
        weights[u] = static_cast<float>(u % 3) / 2.0f;
    stack.setWeights(0, weights);
    stack.setEnvelope(0, 0.7);
    std::vector<glm::vec3> out = restOf(rest);
    stack.evaluate(out);
    const auto in = rest.points();
    for (size_t u = 0; u < out.size(); ++u) {
        const glm::dvec3 p(in[u]);
        const glm::dvec3 expected = p + 0.7 * weights[u] * (glm::dvec3(full[u]) - p);
        CHECK(glm::length(glm::dvec3(out[u]) - expected) < 1e-6);
    }
    CHECK(glm::length(full[60] - glm::vec3(1.3f, 1.2f, 0.0f)) < 1e-6f);
}

namespace {

// A deformer whose binding uses the painted weights: it lifts every point by the sum of the weights it
// was bound with. Shows that a studio's own deformer plugs into the stack, and that weights rebind it.
class WeightSumLift final : public host::Deformer {
  public:
    WeightSumLift() : Deformer("lift", "lift1") {
        gain_ = addParameter({.name = "gain", .doc = "multiplies the lift"}, {1.0});
    }
    [[nodiscard]] bool weightsAffectBinding() const override { return true; }

  protected:
    void bindRest(const geom::Mesh& rest, std::span<const float> weights) override {
        sum_ = 0.0;
        for (float w : weights)
            sum_ += w;
        if (weights.empty()) sum_ = rest.numVertices();
    }
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out) override {
        for (size_t u = 0; u < in.size(); ++u)
            out[u] = in[u] + glm::vec3(0.0f, 0.0f, static_cast<float>(value(gain_)[0] * sum_));
    }

  private:
    size_t gain_;
    double sum_ = 0.0;
};

}  // namespace

TEST_CASE("dirty tracking: controls never rebind, rest and bind-time inputs do", "[host][stack]") {
    const Scene scene;
    DeformerStack stack;
    scene.fill(stack);  // ffd 0, twist 1, slide 2
    stack.add(makeDeformer("bend", "bend1"));
    stack.add(makeDeformer("taper", "taper1"));
    stack.add(makeDeformer("wires", "wires1"));
    stack.set(5, "restCurve", std::vector<double>{0, 1, 0.1, 2, 1, 0.1});
    stack.set(3, "handleX", std::vector<double>{0, 0, 1});
    stack.set(3, "handleY", std::vector<double>{1, 0, 0});
    const auto bindCounts = [&] {
        std::vector<int64_t> counts;
        for (size_t i = 0; i < stack.size(); ++i)
            counts.push_back(stack.bindCount(i));
        return counts;
    };
    std::vector<glm::vec3> points = restOf(scene.rest);
    stack.evaluate(points);
    CHECK(bindCounts() == std::vector<int64_t>{1, 1, 1, 1, 1, 1});
    CHECK(stack.bindCount() == 6);
    const std::vector<glm::vec3> first = points;

    // Every animatable control of every type, the envelopes and the weights: no bind, and the result moves.
    std::vector<double> moved = flatten(scene.targets);
    moved[0] += 0.25;
    stack.set(0, "points", moved);
    stack.set(1, "endAngle", 1.1);
    stack.set(2, "displacement", std::vector<double>{0.05, 0.2, 0.0});
    stack.set(2, "falloff", 1.0);
    stack.set(3, "curvature", 0.4);
    stack.set(4, "endScale", 1.3);
    stack.set(5, "curve", std::vector<double>{0, 1, 0.1, 2, 1.2, 0.4});
    stack.set(4, "envelope", 0.5);
    stack.setWeights(1, std::vector<float>(scene.rest.numVertices(), 0.5f));
    for (size_t i = 0; i < stack.size(); ++i) {
        INFO("entry " << i);
        CHECK_FALSE(stack.deformer(i).needsBind());
    }
    points = restOf(scene.rest);
    stack.evaluate(points);
    CHECK(bindCounts() == std::vector<int64_t>{1, 1, 1, 1, 1, 1});
    CHECK(stack.bindCount() == 6);
    CHECK(maxError(points, first) > 0.05f);

    // A bind-time parameter of one entry rebinds that entry only.
    stack.set(0, "origin", std::vector<double>{-0.2, -0.1, -0.5});
    stack.set(2, "radius", 0.6);
    CHECK(stack.deformer(0).needsBind());
    CHECK_FALSE(stack.deformer(1).needsBind());
    stack.evaluate(points);
    CHECK(bindCounts() == std::vector<int64_t>{2, 1, 2, 1, 1, 1});
    CHECK(stack.bindCount() == 8);

    // Setting a bind-time parameter to the value it has changes nothing.
    stack.set(0, "origin", std::vector<double>{-0.2, -0.1, -0.5});
    stack.set(3, "handleY", std::vector<double>{1, 0, 0});
    stack.evaluate(points);
    CHECK(stack.bindCount() == 8);

    // A new rest mesh rebinds every entry once.
    stack.setRest(scene.rest);
    stack.evaluate(points);
    stack.evaluate(points);
    CHECK(bindCounts() == std::vector<int64_t>{3, 2, 3, 2, 2, 2});
    CHECK(stack.bindCount() == 14);

    // A skipped entry (envelope 0) is not bound until it runs again.
    stack.setEnvelope(3, 0.0);
    stack.set(3, "handleOrigin", std::vector<double>{0.5, 1, 0});
    stack.evaluate(points);
    CHECK(stack.bindCount(3) == 2);
    stack.setEnvelope(3, 1.0);
    stack.evaluate(points);
    CHECK(stack.bindCount(3) == 3);
    CHECK(stack.bindCount() == 15);

    // bind() binds what needs it, whether active or not.
    stack.setEnvelope(3, 0.0);
    stack.set(3, "handleOrigin", std::vector<double>{0.6, 1, 0});
    stack.bind();
    CHECK(stack.bindCount(3) == 4);
    stack.bind();
    CHECK(stack.bindCount() == 16);
}

TEST_CASE("a deformer whose binding uses the weights is rebound by a weight change only", "[host][stack]") {
    const geom::Mesh rest = test::planeGrid(2, 2, 1.0f);  // 9 vertices
    DeformerStack stack;
    stack.setRest(rest);
    stack.add(std::make_unique<WeightSumLift>());
    // The default lattice (the unit cube, points at rest) moves nothing, bit for bit: every translation is 0.
    stack.add(makeDeformer("ffd", "identity"));
    std::vector<glm::vec3> points = restOf(rest);
    stack.evaluate(points);
    CHECK(points[4].z == 9.0f);  // no weights: a sum of nine 1s; the blend with weight 1 is exact
    CHECK(stack.bindCount(0) == 1);

    stack.set(0, "gain", 2.0);  // a control: no bind
    std::vector<float> weights(9, 0.0f);
    weights[4] = 1.0f;
    weights[8] = 0.5f;
    stack.setWeights(1, weights);  // the lattice's binding does not use weights
    points = restOf(rest);
    stack.evaluate(points);
    CHECK(stack.bindCount(0) == 1);
    CHECK(stack.bindCount(1) == 1);
    CHECK(points[4].z == 18.0f);

    stack.setWeights(0, weights);  // now bound with a sum of 1.5
    CHECK(stack.deformer(0).needsBind());
    points = restOf(rest);
    stack.evaluate(points);
    CHECK(stack.bindCount(0) == 2);
    CHECK(stack.bindCount(1) == 1);
    // Vertex 4: weight 1 of a 2 x 1.5 lift; vertex 8: weight 0.5 of it; vertex 0: weight 0, unmoved.
    // Dyadic values: exact.
    CHECK(points[4].z == 3.0f);
    CHECK(points[8].z == 1.5f);
    CHECK(points[0].z == 0.0f);
}

TEST_CASE("bad inputs are reported with the entry and the parameter", "[host][stack][errors]") {
    const Scene scene;
    DeformerStack stack;
    CHECK_THROWS_WITH(stack.evaluate(std::span<glm::vec3>()), Contains("rest mesh: is not set"));
    scene.fill(stack);
    const size_t n = scene.rest.numVertices();

    CHECK_THROWS_AS(stack.set(1, "startangle", 1.0), InvalidInput);
    CHECK_THROWS_WITH(stack.set(1, "startangle", 1.0),
                      Contains("stack entry 1 (twist 'twist1'): parameter 'startangle': does not exist") &&
                          Contains("envelope, handleOrigin, handleY, startAngle"));
    CHECK_THROWS_WITH(
        stack.set(0, "points", std::vector<double>{1, 2}),
        Contains("stack entry 0 (ffd 'lattice1'): parameter 'points': has 2 values (expected 54 "
                 "values)"));
    CHECK_THROWS_WITH(stack.set(2, "displacement", std::vector<double>{0, std::nan(""), 0}),
                      Contains("stack entry 2 (slide 'slide1'): parameter 'displacement': value 1 is nan"));
    CHECK_THROWS_WITH(stack.set(2, "envelope", std::numeric_limits<double>::infinity()),
                      Contains("stack entry 2 (slide 'slide1'): parameter 'envelope': is inf"));
    CHECK_THROWS_WITH(
        stack.set(2, "envelope", 1e39),
        Contains("stack entry 2 (slide 'slide1'): parameter 'envelope': is 1e+39 (expected a finite "
                 "number within float range, usually in [0, 1])"));
    CHECK_THROWS_WITH(stack.set(2, "envelope", std::vector<double>{1, 1}),
                      Contains("parameter 'envelope': has 2 values"));
    CHECK_THROWS_WITH(stack.setWeights(0, std::vector<float>(n - 1, 1.0f)),
                      Contains("stack entry 0 (ffd 'lattice1'): weights: has 80 values (expected 81, one per "
                               "rest vertex)"));
    std::vector<float> nan(n, 1.0f);
    nan[3] = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(stack.setWeights(1, nan),
                      Contains("stack entry 1 (twist 'twist1'): weight of vertex 3: is nan"));
    CHECK(stack.weights(1).empty());  // rejected weights are not kept
    CHECK_THROWS_WITH(stack.deformer(7),
                      Contains("stack: entry 7: does not exist (expected an index below 3)"));
    CHECK_THROWS_WITH(stack.find("twist2"),
                      Contains("deformer 'twist2'") && Contains("'lattice1', 'twist1'"));
    CHECK(stack.find("slide1") == 2);
    CHECK_THROWS_WITH(
        stack.add(makeDeformer("bend", "twist1")),
        Contains("stack entry 3: label 'twist1': is already used by stack entry 1 (twist 'twist1')"));
    CHECK_THROWS_WITH(stack.add(nullptr), Contains("deformer: is null"));
    CHECK(stack.size() == 3);

    std::vector<glm::vec3> wrongCount(n + 1);
    CHECK_THROWS_WITH(stack.evaluate(wrongCount), Contains("points: has 82 positions (expected 81"));

    // A failure during evaluation names the entry and leaves the points as they were.
    stack.set(1, "lowBound", 5.0);
    std::vector<glm::vec3> points = restOf(scene.rest);
    CHECK_THROWS_WITH(stack.evaluate(points),
                      Contains("stack entry 1 (twist 'twist1'): parameter 'lowBound': is 5"));
    CHECK(test::sameBits(points, restOf(scene.rest)));
    stack.set(1, "lowBound", -1.0);
    // A failed bind names the entry, and the entry stays unbound until it succeeds.
    stack.set(2, "vertex", 1000.0);
    CHECK_THROWS_WITH(stack.evaluate(points),
                      Contains("stack entry 2 (slide 'slide1'): parameter 'vertex': is 1000"));
    CHECK(stack.deformer(2).needsBind());
    CHECK(test::sameBits(points, restOf(scene.rest)));
    stack.set(2, "vertex", static_cast<double>(scene.centre));
    stack.evaluate(points);
    CHECK(test::sameBits(points, scene.direct()));

    // Weights painted for another mesh are caught when the rest mesh changes under them.
    stack.setWeights(0, std::vector<float>(n, 0.5f));
    stack.setRest(test::planeGrid(4, 4, 0.5f));
    std::vector<glm::vec3> smaller = restOf(stack.rest());
    CHECK_THROWS_WITH(stack.evaluate(smaller),
                      Contains("stack entry 0 (ffd 'lattice1'): weights: has 81 values (expected 25"));
}

TEST_CASE("the stack gives bit-identical output for 1 and 2 threads", "[host][stack][determinism]") {
    // 101 x 101 vertices: more than one OpenMP chunk in every stage (the Barr warps use chunks of 4096).
    const Scene scene(100);
    DeformerStack stack;
    scene.fill(stack);
    stack.add(makeDeformer("bend", "bend1"));
    stack.set(3, "handleOrigin", std::vector<double>{1, 1, 0});
    stack.set(3, "handleX", std::vector<double>{0, 0, 1});
    stack.set(3, "handleY", std::vector<double>{1, 0, 0});
    stack.set(3, "curvature", 0.6);
    std::vector<float> weights(scene.rest.numVertices());
    for (size_t u = 0; u < weights.size(); ++u)
        weights[u] = static_cast<float>(u % 11) / 10.0f;
    stack.setWeights(0, weights);
    stack.setWeights(2, weights);
    stack.setEnvelope(1, 0.7);
    stack.setEnvelope(3, 0.45);
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    std::vector<glm::vec3> one = restOf(scene.rest);
    stack.evaluate(one);
    omp_set_num_threads(2);
    std::vector<glm::vec3> two = restOf(scene.rest);
    stack.evaluate(two);
    omp_set_num_threads(threads);
    CHECK(test::sameBits(one, two));
    CHECK(maxError(one, restOf(scene.rest)) > 0.1f);
}

TEST_CASE("evaluate(in, out) gives the in-place result for 0 to 3 active entries", "[host][stack]") {
    const Scene scene;
    DeformerStack stack;
    scene.fill(stack);
    const std::vector<glm::vec3> input = restOf(scene.rest);
    // Entries switched on and off by their envelope: every count of active entries, first and last
    // positions of the chain included.
    for (int mask = 0; mask < 8; ++mask) {
        for (size_t i = 0; i < 3; ++i)
            stack.setEnvelope(i, (mask >> i) & 1 ? 1.0 : 0.0);
        CAPTURE(mask);
        std::vector<glm::vec3> inPlace = input;
        stack.evaluate(inPlace);
        std::vector<glm::vec3> out(input.size(), glm::vec3(7.0f));
        stack.evaluate(input, out);
        CHECK(test::sameBits(out, inPlace));
        if (mask == 7)
            CHECK(test::sameBits(out, scene.direct()));  // the reference: the core calls made directly
        if (mask == 0) CHECK(test::sameBits(out, input));
    }
    // A non-finite input point is found before any work: out untouched, the point named.
    std::vector<glm::vec3> bad = input;
    bad[5].y = std::numeric_limits<float>::quiet_NaN();
    std::vector<glm::vec3> out(input.size(), glm::vec3(7.0f));
    CHECK_THROWS_WITH(stack.evaluate(bad, out), Contains("point 5: is not finite"));
    CHECK(test::sameBits(out, std::vector<glm::vec3>(input.size(), glm::vec3(7.0f))));
    bad[5].y = std::numeric_limits<float>::infinity();
    CHECK_THROWS_WITH(stack.evaluate(bad), Contains("point 5: is not finite"));
}

TEST_CASE("a deformation beyond float range is refused, naming the entry and the point", "[host][stack]") {
    // Every parameter within float range, the result not: a taper tripling the width, applied with an
    // envelope of 1e38 (out = in + envelope (deformed - in): 2 x 1e38 x for the plane's x up to 2), and a
    // bend of 3e38 radians a unit over 2 units of its axis (an infinite angle).
    const Scene scene;
    const std::vector<glm::vec3> input = restOf(scene.rest);
    {
        DeformerStack stack;
        stack.setRest(scene.rest);
        stack.add(makeDeformer("taper", "taper1"));
        stack.set(0, "startScale", 3.0);
        stack.set(0, "endScale", 3.0);
        stack.setEnvelope(0, 1e38);
        std::vector<glm::vec3> points = input;
        CHECK_THROWS_WITH(stack.evaluate(points), Contains("stack entry 0 (taper 'taper1'): point ") &&
                                                      Contains("expected finite positions"));
        CHECK(test::sameBits(points, input));  // in place: untouched when an entry throws
        stack.setEnvelope(0, 1.0);
        CHECK_NOTHROW(stack.evaluate(points));
    }
    {
        DeformerStack stack;
        stack.setRest(scene.rest);
        stack.add(makeDeformer("bend", "bend1"));
        stack.set(0, "curvature", 3e38);
        stack.set(0, "highBound", 2.0);
        std::vector<glm::vec3> out(input.size());
        CHECK_THROWS_WITH(stack.evaluate(input, out),
                          Contains("stack entry 0 (bend 'bend1'): point ") && Contains("nan"));
    }
}

TEST_CASE("ffd after a twist: lattice coordinates at rest, or at the incoming points (evaluateAt)",
          "[host][stack][ffd]") {
    // Maya's and Blender's lattices take each point where the deformers above left it; DeformKit's FFD binds
    // at rest unless evaluateAt is 1. Both against the core: the twist alone, then a warp::Ffd bound to the
    // rest points or to the twisted ones.
    const Scene scene;
    for (const double at : {0.0, 1.0}) {
        DeformerStack stack;
        stack.setRest(scene.rest);
        stack.add(makeDeformer("twist", "twist1"));
        stack.set(0, "handleOrigin", std::vector<double>{1, 1, 0});
        stack.set(0, "handleY", std::vector<double>{1, 0, 0});
        stack.set(0, "startAngle", -0.4);
        stack.set(0, "endAngle", 0.7);
        auto ffd = makeDeformer("ffd", "lattice1");
        ffd->set("divisions", std::vector<double>{2, 2, 1});
        ffd->set("origin",
                 std::vector<double>{scene.lattice.origin.x, scene.lattice.origin.y, scene.lattice.origin.z});
        ffd->set("axes", std::vector<double>{2.2f, 0, 0, 0, 2.2f, 0, 0, 0, 1.2f});
        ffd->set("points", flatten(scene.targets));
        ffd->set("evaluateAt", at);
        stack.add(std::move(ffd));
        std::vector<glm::vec3> points = restOf(scene.rest);
        stack.evaluate(points);

        const warp::AxialSetup setup = warp::fromMayaTwist(scene.twist);
        warp::TwistWarp twistWarp(setup.frame, setup.profile);
        warp::SparseFields fields;
        twistWarp.bind(scene.rest.points(), fields);
        std::vector<glm::vec3> twisted(points.size());
        twistWarp.evaluate(restOf(scene.rest), twisted);
        warp::Ffd direct(scene.lattice);
        direct.setTargets(scene.targets);
        if (at == 1.0) {
            direct.bind(twisted);
        } else {
            direct.bind(scene.rest.points());
        }
        std::vector<glm::vec3> expected = twisted;
        direct.evaluate(expected);
        INFO("evaluateAt " << at);
        CHECK(test::sameBits(points, expected));
        // Switched to the other setting (as an animated evaluateAt does between frames), the stack gives
        // what the other setting gives from the start: a frame's result does not depend on the frames before.
        stack.set(1, "evaluateAt", 1.0 - at);
        std::vector<glm::vec3> switched = restOf(scene.rest);
        stack.evaluate(switched);
        expected = twisted;
        warp::Ffd other(scene.lattice);
        other.setTargets(scene.targets);
        if (at == 1.0) {
            other.bind(scene.rest.points());
        } else {
            other.bind(twisted);
        }
        other.evaluate(expected);
        CHECK(test::sameBits(switched, expected));
    }
}
