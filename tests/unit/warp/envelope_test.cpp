// Every deformer's evaluate refuses a non-finite envelope or painted weight, naming it, before it writes a
// point: NaN or infinity would make every point it scales NaN. And it refuses a result beyond float range,
// naming the first point.
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
#include "deformkit/warp/morph.h"
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
    WarpDeformer deformer(ffd, "engine FFD");
    deformer.bind(rest);
    checkRefusals("engine FFD", [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
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

namespace {

// 20,003 points between radius 1 and 2 about the z axis, z in [0, 1]: not a whole number of blocks or runs.
std::vector<glm::vec3> ringPoints() {
    std::vector<glm::vec3> points;
    for (int i = 0; i < 20003; ++i) {
        const float a = 0.01f * static_cast<float>(i), r = 1.0f + static_cast<float>(i % 97) / 97.0f;
        points.emplace_back(r * std::cos(a), r * std::sin(a), static_cast<float>(i % 89) / 89.0f);
    }
    return points;
}

// A deformer that moves every point by more than 1 (evaluate(weights, envelope, out)), given painted
// weights 0 below point `first` and 1 from it on and an envelope of 3e38, takes points `first` on beyond
// float range: it is refused naming point `first` (whatever the threads' schedule), as deformed from its
// input when the input is still there (`from`), by its result alone when the output overwrote it. First
// points 12345 (inside a run) and 20000 (in the last, partial, run).
void checkOverflow(const std::string& name, bool from, const Evaluate& evaluate) {
    CAPTURE(name);
    const std::vector<glm::vec3> rest = ringPoints();
    for (const int first : {12345, 20000}) {
        CAPTURE(first);
        std::vector<float> weights(rest.size(), 0.0f);
        std::fill(weights.begin() + first, weights.end(), 1.0f);
        std::vector<glm::vec3> out = rest;
        CHECK_NOTHROW(evaluate(weights, 1e30f, out));  // within range
        out = rest;
        const std::string point = name + ": point " + std::to_string(first) + ": is ";
        if (from) {
            CHECK_THROWS_WITH(evaluate(weights, 3e38f, out),
                              Catch::Contains(point + "deformed from (") && Catch::Contains("inf") &&
                                  Catch::Contains("expected finite positions: parameters that keep the "
                                                  "deformation within float range"));
        } else {
            CHECK_THROWS_WITH(
                evaluate(weights, 3e38f, out),
                Catch::Contains(point + "(") && Catch::Contains("inf") &&
                    Catch::Contains(") once deformed (expected finite points, and parameters that "
                                    "keep the deformation within float range"));
        }
    }
}

}  // namespace

TEST_CASE("every deformer refuses a result beyond float range, naming the first point", "[warp][envelope]") {
    const std::vector<glm::vec3> rest = ringPoints();

    TaperWarp taper({{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}, ProfileCurve::constant(5.0f));
    taper.bind(rest);
    checkOverflow("taper", true, [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        taper.deform(rest, out, w, e);
    });
    checkOverflow("taper", false, [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        taper.deform(out, w, e);  // in place
    });
    // With the envelope at 1, the factor alone: 3e38 at radius 1 to 2.
    TaperWarp huge({{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}, ProfileCurve::constant(3e38f));
    huge.bind(rest);
    std::vector<glm::vec3> out(rest.size());
    CHECK_THROWS_WITH(huge.deform(rest, out, {}, 1.0f),
                      Catch::Contains("taper: point ") && Catch::Contains(": is deformed from ("));
    out = rest;
    CHECK_THROWS_WITH(huge.deform(out, {}, 1.0f),
                      Catch::Contains("taper: point ") && Catch::Contains(") once deformed"));
    // Where the envelope is 0 the input stands, whatever the warp gave there.
    std::vector<float> none(rest.size(), 0.0f);
    CHECK_NOTHROW(huge.deform(rest, out, none, 1.0f));
    CHECK(out == rest);

    for (const glm::ivec3 divisions :
         {glm::ivec3(3), glm::ivec3(2)}) {  // the 4x4x4 blocks, the per-point path
        Lattice lattice;
        lattice.origin = {-2.5f, -2.5f, -0.5f};
        lattice.axes = glm::mat3(5.0f);
        lattice.divisions = divisions;
        for (const FfdBasis basis : {FfdBasis::Bernstein, FfdBasis::BSpline}) {
            if (basis == FfdBasis::BSpline && divisions != glm::ivec3(3)) continue;
            FfdOptions options;
            options.basis = basis;
            Ffd ffd(lattice, options);
            std::vector<glm::vec3> targets(ffd.sourcePoints().begin(), ffd.sourcePoints().end());
            for (glm::vec3& t : targets)
                t += glm::vec3(2.0f, 0.0f, 0.0f);
            ffd.setTargets(targets);
            if (divisions == glm::ivec3(3)) {
                checkOverflow("FFD evaluate", true,
                              [&](std::span<const float> w, float e, std::vector<glm::vec3>& o) {
                                  ffd.bindAndEvaluate(rest, rest, o, w, e);  // the unbound fast path
                              });
            }
            ffd.bind(rest);
            checkOverflow("FFD evaluate", true,
                          [&](std::span<const float> w, float e, std::vector<glm::vec3>& o) {
                              ffd.evaluate(rest, o, w, e);
                          });
            WarpDeformer deformer(ffd, "engine FFD");
            deformer.bind(rest);
            // The input is kept until the blend is checked: a point refused is named with where it came from.
            checkOverflow("engine FFD", true,
                          [&](std::span<const float> w, float e, std::vector<glm::vec3>& o) {
                              deformer.evaluate(o, w, e);
                          });
        }
    }

    Wire wire;
    wire.reference = {{-3, 0, 0.5f}, {3, 0, 0.5f}};
    wire.wire = {{-3, 2, 0.5f}, {3, 2, 0.5f}};
    wire.radius = 100.0f;
    Wires wires({wire}, {WiresVariant::Original});
    wires.bind(rest);
    checkOverflow("wires", false, [&](std::span<const float> w, float e, std::vector<glm::vec3>& out) {
        wires.evaluate(out, w, e);
    });
}

TEST_CASE("applyEnvelope returns the first point whose result is not finite", "[warp][envelope]") {
    const std::vector<glm::vec3> in(100000, glm::vec3(1.0f));
    std::vector<glm::vec3> deformed(in.size(), glm::vec3(3.0f)), out(in.size());
    std::vector<float> weights(in.size(), 0.0f);
    CHECK(applyEnvelope(in, deformed, weights, 1e38, out) == 100000);
    weights[70001] = 1.0f;
    weights[99999] = 1.0f;
    CHECK(applyEnvelope(in, deformed, weights, 1e38, out) == 100000);  // 1 + 2e38: within range
    CHECK(applyEnvelope(in, deformed, weights, 3e38, out) == 70001);
    CHECK(out[70001].x == std::numeric_limits<float>::infinity());
    CHECK(out[70000] == in[70000]);
    weights[20001] = 1.0f;  // in the first half: another thread's part than 70001's
    CHECK(applyEnvelope(in, deformed, weights, 3e38, out) == 20001);
    weights[20001] = 0.0f;
    deformed[5].y = kNaN;  // k = 0 there: the input is taken as it is, finite
    CHECK(applyEnvelope(in, deformed, weights, 3e38, out) == 70001);
    weights[5] = 1.0f;
    CHECK(applyEnvelope(in, deformed, weights, 1.0, out) == 5);
    CHECK_THROWS_WITH(requireFiniteResult("x", in, out, 5),
                      Catch::Contains("x: point 5: is deformed from (1, 1, 1) to (3, nan, 3)"));
    CHECK_THROWS_WITH(requireFiniteResult("x", {}, out, 5),
                      Catch::Contains("x: point 5: is (3, nan, 3) once deformed"));
    std::vector<glm::vec3> blend(in.size());
    CHECK_THROWS_WITH(morphByEnvelope(in, deformed, 3e38f, blend),
                      Catch::Contains("morph: point 0: is deformed from"));
    CHECK_NOTHROW(morphByEnvelope(in, std::vector<glm::vec3>(in.size(), glm::vec3(3.0f)), 0.5f, blend));
    CHECK(blend[5] == glm::vec3(2.0f));
    std::vector<glm::vec3> bad = in;
    bad[5].z = kInf;
    CHECK_THROWS_WITH(requireFiniteResult("x", bad, out, 5),
                      Catch::Contains("x: point 5: is (1, 1, inf) (expected finite coordinates)"));
    CHECK_NOTHROW(requireFiniteResult("x", in, out, static_cast<int64_t>(out.size())));
}
