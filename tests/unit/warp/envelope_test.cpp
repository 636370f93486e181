// Every deformer's evaluate refuses a non-finite envelope or painted weight, naming it, before it writes a
// point: NaN or infinity would make every point it scales NaN.
#include <catch2/catch.hpp>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/engine.h"
#include "deformkit/warp/envelope.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/wires.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

std::vector<glm::vec3> gridPoints() {
    std::vector<glm::vec3> points;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j)
            points.emplace_back(0.2f * i, 0.2f * j, 0.1f * ((i + j) % 3));
    return points;
}

// evaluate(points, weights, envelope) of one deformer, bound to gridPoints(), deforming into `out`.
using Evaluate = std::function<void(std::span<const float>, float, std::vector<glm::vec3>&)>;

// Refused with the deformer's name, the envelope or the weight's point, and nothing written.
void checkRefusals(const std::string& name, const Evaluate& evaluate) {
    CAPTURE(name);
    const std::vector<glm::vec3> rest = gridPoints();
    std::vector<float> weights(rest.size(), 0.5f);
    std::vector<glm::vec3> out = rest;
    evaluate(weights, 1.0f, out);  // the valid call runs
    for (const float envelope : {kNaN, kInf, -kInf}) {
        out = rest;
        CHECK_THROWS_WITH(evaluate({}, envelope, out), Catch::Contains(name) &&
                                                           Catch::Contains("envelope: is") &&
                                                           Catch::Contains("expected a finite number"));
        CHECK(out == rest);
    }
    for (const float weight : {kNaN, kInf}) {
        weights[7] = weight;
        out = rest;
        CHECK_THROWS_WITH(evaluate(weights, 1.0f, out),
                          Catch::Contains(name) && Catch::Contains("painted weight of point 7: is"));
        CHECK(out == rest);
    }
}

}  // namespace

TEST_CASE("every deformer refuses a non-finite envelope or painted weight, naming it", "[warp][envelope]") {
    const std::vector<glm::vec3> rest = gridPoints();

    TwistWarp twist({{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}, ProfileCurve::constant(0.5f));
    twist.bind(rest);
    checkRefusals("twist", [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        twist.deform(rest, out, w, e);
    });
    checkRefusals("twist", [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        twist.deform(out, w, e);  // in place
    });

    Lattice lattice;
    lattice.origin = {-0.1f, -0.1f, -0.1f};
    lattice.axes = glm::mat3(1.2f);
    lattice.divisions = {3, 3, 3};
    Ffd ffd(lattice);
    std::vector<glm::vec3> targets(ffd.sourcePoints().begin(), ffd.sourcePoints().end());
    targets[5] += glm::vec3(0.1f);
    ffd.setTargets(targets);
    checkRefusals("FFD evaluate", [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        ffd.bindAndEvaluate(rest, rest, out, w, e);  // the unbound fast path
    });
    ffd.bind(rest);
    checkRefusals("FFD evaluate", [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        ffd.evaluate(rest, out, w, e);
    });
    WarpDeformer deformer(ffd);
    deformer.bind(rest);
    checkRefusals("warp evaluate", [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        deformer.evaluate(out, w, e);
    });

    Wire wire;
    wire.reference = {{0, 0.4f, 0}, {1, 0.4f, 0}};
    wire.wire = {{0, 0.5f, 0.1f}, {1, 0.5f, 0.1f}};
    wire.radius = 0.5f;
    for (const WiresVariant variant : {WiresVariant::Original, WiresVariant::Smooth}) {
        Wires wires({wire}, {variant});
        wires.bind(rest);
        checkRefusals("wires", [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
            wires.evaluate(out, w, e);
        });
    }
}

TEST_CASE("requireFiniteEnvelope takes large finite values and names the first bad weight",
          "[warp][envelope]") {
    std::vector<float> weights(100000, 1.0f);
    weights[99999] = std::numeric_limits<float>::max();
    weights[0] = -std::numeric_limits<float>::max();
    CHECK_NOTHROW(requireFiniteEnvelope("x", weights, 1e300));
    weights[70000] = kNaN;
    weights[90000] = kInf;
    CHECK_THROWS_WITH(requireFiniteEnvelope("x", weights, 1.0), Catch::Contains("point 70000: is nan"));
    CHECK_NOTHROW(requireFiniteEnvelope("x", {}, 0.0));
}
