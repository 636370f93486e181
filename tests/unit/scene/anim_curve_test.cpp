#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/scene/anim_curve.h"

using deformkit::scene::AnimCurve;
using deformkit::scene::Interpolation;
using deformkit::scene::Key;
using deformkit::scene::TangentMode;

namespace {

// Every expected value below is a short sum of dyadic fractions, computed by hand; the library's few
// multiply-adds are off by a few ulps at most, so 1e-12 relative (plus 1e-12 absolute for values near 0)
// leaves room for rounding while any wrong coefficient or slope misses by far more.
Approx near(double expected) {
    return Approx(expected).epsilon(1e-12).margin(1e-12);
}

Key key(double time, double value, Interpolation interpolation = Interpolation::Bezier,
        TangentMode tangent = TangentMode::Auto) {
    return Key{.time = time, .value = value, .interpolation = interpolation, .tangent = tangent};
}

}  // namespace

TEST_CASE("a linear segment is a straight line and the curve holds its end values outside the keys",
          "[host]") {
    // From (2, 1) to (6, -3): v(t) = 1 - (t - 2), slope -1.
    const AnimCurve curve({key(2.0, 1.0, Interpolation::Linear), key(6.0, -3.0)});
    CHECK(curve.evaluate(3.0) == near(0.0));   // quarter: 1 - 1
    CHECK(curve.evaluate(4.0) == near(-1.0));  // midpoint: 1 - 2
    CHECK(curve.evaluate(5.0) == near(-2.0));  // three quarters: 1 - 3
    CHECK(curve.evaluate(2.0) == 1.0);
    CHECK(curve.evaluate(6.0) == -3.0);
    // Constant extrapolation on both sides, exactly the end values.
    CHECK(curve.evaluate(-10.0) == 1.0);
    CHECK(curve.evaluate(1.999) == 1.0);
    CHECK(curve.evaluate(6.001) == -3.0);
    CHECK(curve.evaluate(1e9) == -3.0);
    CHECK(curve.evaluate(-std::numeric_limits<double>::infinity()) == 1.0);
    CHECK(curve.evaluate(std::numeric_limits<double>::infinity()) == -3.0);
    CHECK(std::isnan(curve.evaluate(std::nan(""))));
    CHECK(curve.size() == 2);
    CHECK_FALSE(curve.isConstant());
}

TEST_CASE("a constant segment holds its key's value up to but not including the next key's time", "[host]") {
    const AnimCurve curve(
        {key(0.0, 1.0, Interpolation::Constant), key(10.0, 5.0, Interpolation::Constant), key(20.0, -2.0)});
    CHECK(curve.evaluate(0.0) == 1.0);
    CHECK(curve.evaluate(5.0) == 1.0);
    CHECK(curve.evaluate(std::nextafter(10.0, 0.0)) == 1.0);  // the last double before the next key
    CHECK(curve.evaluate(10.0) == 5.0);                       // exactly at the next key: its value
    CHECK(curve.evaluate(15.0) == 5.0);
    CHECK(curve.evaluate(std::nextafter(20.0, 0.0)) == 5.0);
    CHECK(curve.evaluate(20.0) == -2.0);
    CHECK(curve.evaluate(25.0) == -2.0);
    CHECK(curve.evaluate(-5.0) == 1.0);
}

TEST_CASE("a bezier segment with flat tangents is the smoothstep between its keys", "[host]") {
    // Slopes 0 at both ends: v(s) = h01(s) * 10 = 10 (3s^2 - 2s^3), s = t / 10.
    for (TangentMode tangent : {TangentMode::Flat, TangentMode::Auto}) {  // Auto end keys are flat too
        const AnimCurve curve({key(0.0, 0.0, Interpolation::Bezier, tangent), key(10.0, 10.0)});
        CHECK(curve.evaluate(2.5) == near(1.5625));  // 10 (3 * 0.0625 - 2 * 0.015625) = 10 * 0.15625
        CHECK(curve.evaluate(5.0) == near(5.0));     // 10 (0.75 - 0.25)
        CHECK(curve.evaluate(7.5) == near(8.4375));  // 10 (3 * 0.5625 - 2 * 0.421875) = 10 * 0.84375
        CHECK(curve.outSlope(0) == 0.0);
        CHECK(curve.inSlope(1) == 0.0);
    }
}

TEST_CASE("a bezier segment with explicit slopes follows the cubic hermite in time", "[host]") {
    Key first = key(1.0, 2.0, Interpolation::Bezier, TangentMode::Explicit);
    first.inSlope = 7.0;  // before the first key: not used
    first.outSlope = 3.0;
    Key last = key(5.0, 4.0, Interpolation::Bezier, TangentMode::Explicit);
    last.inSlope = -1.0;
    last.outSlope = 9.0;  // after the last key: not used
    const AnimCurve curve({first, last});
    CHECK(curve.outSlope(0) == 3.0);
    CHECK(curve.inSlope(1) == -1.0);

    // dt = 4, v0 = 2, m0 = 3, v1 = 4, m1 = -1.
    // t = 2, s = 0.25: s^2 = 0.0625, s^3 = 0.015625;
    //   h00 = 0.03125 - 0.1875 + 1 = 0.84375, h10 = 0.015625 - 0.125 + 0.25 = 0.140625,
    //   h01 = -0.03125 + 0.1875 = 0.15625, h11 = 0.015625 - 0.0625 = -0.046875;
    //   v = 0.84375 * 2 + 0.140625 * 4 * 3 + 0.15625 * 4 + (-0.046875) * 4 * (-1)
    //     = 1.6875 + 1.6875 + 0.625 + 0.1875 = 4.1875.
    CHECK(curve.evaluate(2.0) == near(4.1875));
    // t = 3, s = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125;
    //   v = 1 + 0.125 * 12 + 2 + (-0.125) * (-4) = 1 + 1.5 + 2 + 0.5 = 5.
    CHECK(curve.evaluate(3.0) == near(5.0));

    // The same curve as a cubic Bezier with handles at one third of the interval: control values
    // 2, 2 + 3 * 4/3 = 6, 4 - (-1) * 4/3 = 16/3, 4 (times 1, 7/3, 11/3, 5: evenly spaced, so t = 1 + 4s).
    //   s = 0.5: (2 + 3 * 6 + 3 * 16/3 + 4) / 8 = 40 / 8 = 5.
    //   s = 0.25: 0.421875 * 2 + 3 * 0.5625 * 0.25 * 6 + 3 * 0.75 * 0.0625 * 16/3 + 0.015625 * 4
    //           = 0.84375 + 2.53125 + 0.75 + 0.0625 = 4.1875.
    // Agrees with the Hermite form above.

    // The slope just after the first key is its out-slope 3: v(1 + h) = 2 + 3h + O(h^2); the h^2
    // coefficient is v''(0) / (2 dt^2) = (-6 * 2 - 4 * 12 + 6 * 4 - 2 * (-4)) / (2 * 16) = -28 / 32, so the
    // difference quotient is 3 - 0.875h: 8.75e-7 off at h = 1e-6. Rounding of v (about 1e-15) divided by h
    // adds about 1e-9, so 2e-6 absolute passes while a wrong slope (off by 1e-3 or more) fails.
    const double h = 1e-6;
    CHECK((curve.evaluate(1.0 + h) - 2.0) / h == Approx(3.0).margin(2e-6));
}

TEST_CASE("auto slopes are centred differences at interior keys and flat at the ends", "[host]") {
    const AnimCurve curve({key(0.0, 0.0), key(10.0, 10.0), key(20.0, 30.0)});
    // Middle key: (30 - 0) / (20 - 0) = 1.5; the handle limits 3 * 10 / 10 = 3 and 3 * 20 / 10 = 6 do not
    // bite.
    CHECK(curve.inSlope(1) == near(1.5));
    CHECK(curve.outSlope(1) == near(1.5));
    CHECK(curve.inSlope(0) == 0.0);
    CHECK(curve.outSlope(0) == 0.0);
    CHECK(curve.inSlope(2) == 0.0);
    CHECK(curve.outSlope(2) == 0.0);
    // Segment 1, t = 5, s = 0.5, dt = 10: v0 = 0, m0 = 0, v1 = 10, m1 = 1.5;
    //   v = 0.5 * 10 + (-0.125) * 10 * 1.5 = 5 - 1.875 = 3.125.
    CHECK(curve.evaluate(5.0) == near(3.125));
    // Segment 2, t = 15, s = 0.5: v0 = 10, m0 = 1.5, v1 = 30, m1 = 0;
    //   v = 0.5 * 10 + 0.125 * 10 * 1.5 + 0.5 * 30 = 5 + 1.875 + 15 = 21.875.
    CHECK(curve.evaluate(15.0) == near(21.875));
    // Segment 2, t = 12.5, s = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625;
    //   v = 0.84375 * 10 + 0.140625 * 15 + 0.15625 * 30 = 8.4375 + 2.109375 + 4.6875 = 15.234375.
    CHECK(curve.evaluate(12.5) == near(15.234375));
    CHECK(curve.evaluate(10.0) == 10.0);
}

TEST_CASE("auto slopes are flat at a local extremum so the curve does not overshoot it", "[host]") {
    SECTION("symmetric peak") {
        const AnimCurve curve({key(0.0, 0.0), key(10.0, 10.0), key(20.0, 0.0)});
        CHECK(curve.inSlope(1) == 0.0);
        CHECK(curve.outSlope(1) == 0.0);
        CHECK(curve.evaluate(5.0) == near(5.0));   // smoothstep midpoint of 0 .. 10
        CHECK(curve.evaluate(15.0) == near(5.0));  // and of 10 .. 0
        double highest = -1.0;
        for (int i = -500; i <= 2500; ++i)
            highest = std::max(highest, curve.evaluate(i / 100.0));
        CHECK(highest <= 10.0);
        CHECK(highest == 10.0);  // reached at the key, t = 10
    }
    SECTION("asymmetric peak: the centred difference alone would overshoot") {
        // Centred difference (5 - 0) / 20 = 0.25, but 10 >= both neighbours, so the slope is 0.
        // With 0.25, segment 2 at t = 11 (s = 0.1, dt = 10): h00 = 0.972, h10 = 0.081, h01 = 0.028 would
        // give 9.72 + 0.081 * 10 * 0.25 + 0.028 * 5 = 10.0625 > 10.
        const AnimCurve curve({key(0.0, 0.0), key(10.0, 10.0), key(20.0, 5.0)});
        CHECK(curve.outSlope(1) == 0.0);
        CHECK(curve.evaluate(11.0) == near(9.86));  // 0.972 * 10 + 0.028 * 5 = 9.72 + 0.14
        double highest = -1.0;
        for (int i = -500; i <= 2500; ++i)
            highest = std::max(highest, curve.evaluate(i / 100.0));
        CHECK(highest == 10.0);
    }
    SECTION("a plateau key is an extremum") {
        // 10 <= both neighbours (10 and 20): slope 0, so segment 1 is the constant 10.
        const AnimCurve curve({key(0.0, 10.0), key(10.0, 10.0), key(20.0, 20.0)});
        CHECK(curve.outSlope(1) == 0.0);
        CHECK(curve.evaluate(5.0) == near(10.0));
    }
}

TEST_CASE("auto slopes are limited so unevenly spaced keys do not overshoot either", "[host]") {
    // Keys (0, 0), (99, 1), (100, 100). Centred difference at key 1: (100 - 0) / 100 = 1. Unlimited, the
    // segment [0, 99] at s = 0.5 would be h01 * 1 + h11 * 99 * 1 = 0.5 - 12.375 = -11.875, far below both
    // keys. The handle limit 3 * |1 - 0| / 99 = 1/33 (the other, 3 * 99 / 1 = 297, does not bite) gives
    // 0.5 + (-0.125) * 99 / 33 = 0.5 - 0.375 = 0.125.
    const AnimCurve curve({key(0.0, 0.0), key(99.0, 1.0), key(100.0, 100.0)});
    CHECK(curve.outSlope(1) == near(1.0 / 33.0));
    CHECK(curve.evaluate(49.5) == near(0.125));
    // The control values of both segments are non-decreasing (0, 0, 1 - 99/33/3 = 0, 1 and
    // 1, 1 + 1/33/3, 100, 100), so the curve is non-decreasing and stays within each segment's keys.
    double previous = curve.evaluate(-1.0);
    bool monotone = true;
    bool firstSegmentInRange = true;
    for (int i = 0; i <= 101000; ++i) {
        const double t = i / 1000.0;
        const double v = curve.evaluate(t);
        monotone = monotone && v >= previous;
        if (t <= 99.0) firstSegmentInRange = firstSegmentInRange && v >= 0.0 && v <= 1.0;
        previous = v;
    }
    CHECK(monotone);
    CHECK(firstSegmentInRange);
    CHECK(previous == 100.0);
}

TEST_CASE("each segment follows its own key's interpolation", "[host]") {
    // Linear 0 -> 10, then a step holding 10, then a Bezier from (20, 4) with the auto slope of key 2:
    // neighbours 10 and 0 around 4 (not an extremum), (0 - 10) / (30 - 10) = -0.5; handle limits
    // 3 * 6 / 10 = 1.8 and 3 * 4 / 10 = 1.2 do not bite.
    const AnimCurve curve({key(0.0, 0.0, Interpolation::Linear), key(10.0, 10.0, Interpolation::Constant),
                           key(20.0, 4.0, Interpolation::Bezier), key(30.0, 0.0)});
    CHECK(curve.evaluate(5.0) == near(5.0));
    CHECK(curve.evaluate(10.0) == 10.0);
    CHECK(curve.evaluate(15.0) == 10.0);
    CHECK(curve.evaluate(19.99) == 10.0);
    CHECK(curve.evaluate(20.0) == 4.0);
    CHECK(curve.outSlope(2) == near(-0.5));
    // t = 25, s = 0.5, dt = 10: 0.5 * 4 + 0.125 * 10 * (-0.5) + 0.5 * 0 = 2 - 0.625 = 1.375.
    CHECK(curve.evaluate(25.0) == near(1.375));
    CHECK(curve.evaluate(35.0) == 0.0);
}

TEST_CASE("a single key and a constant curve and a curve with no key are constant", "[host]") {
    const AnimCurve single({key(3.0, 7.0)});
    for (double t : {-1e9, 0.0, 3.0, 4.0, 1e9})
        CHECK(single.evaluate(t) == 7.0);
    CHECK(single.size() == 1);
    CHECK(single.isConstant());

    const AnimCurve constant = AnimCurve::constant(2.5);
    CHECK(constant.evaluate(-3.0) == 2.5);
    CHECK(constant.evaluate(100.0) == 2.5);
    CHECK(constant.size() == 1);
    CHECK(constant.keys()[0].value == 2.5);
    CHECK(constant.isConstant());

    const AnimCurve none;
    CHECK(none.evaluate(4.0) == 0.0);
    CHECK(none.size() == 0);
    CHECK(none.keys().empty());
    CHECK(none.isConstant());

    // Equal values with Auto slopes: every key is an extremum, slopes 0, so the curve is flat.
    const AnimCurve flat({key(0.0, 5.0), key(10.0, 5.0), key(20.0, 5.0)});
    CHECK(flat.isConstant());
    CHECK(flat.evaluate(4.0) == 5.0);
    CHECK(flat.evaluate(13.0) == 5.0);

    CHECK_FALSE(AnimCurve({key(0.0, 5.0), key(10.0, 6.0)}).isConstant());

    // Equal values but an explicit slope: the Bezier bends away from 5. At t = 5 (s = 0.5, dt = 10):
    // 0.5 * 5 + 0.125 * 10 * 1 + 0.5 * 5 = 6.25.
    Key bent = key(0.0, 5.0, Interpolation::Bezier, TangentMode::Explicit);
    bent.outSlope = 1.0;
    const AnimCurve bump({bent, key(10.0, 5.0)});
    CHECK(bump.evaluate(5.0) == near(6.25));
    CHECK_FALSE(bump.isConstant());
    // The same key with linear interpolation ignores its slope: constant again.
    bent.interpolation = Interpolation::Linear;
    const AnimCurve line({bent, key(10.0, 5.0)});
    CHECK(line.evaluate(5.0) == 5.0);
    CHECK(line.isConstant());
}

TEST_CASE("bad keys throw InvalidInput naming the curve and the key", "[host]") {
    using Catch::Contains;
    const double nan = std::nan("");
    const double inf = std::numeric_limits<double>::infinity();

    CHECK_THROWS_AS(AnimCurve({key(0.0, 0.0), key(10.0, 1.0), key(5.0, 2.0)}), deformkit::InvalidInput);
    CHECK_THROWS_WITH(AnimCurve({key(0.0, 0.0), key(10.0, 1.0), key(5.0, 2.0)}, "curve 'envelope'"),
                      Contains("curve 'envelope'") && Contains("key 2") && Contains("time 5") &&
                          Contains("strictly increasing"));
    // Equal times are not increasing either.
    CHECK_THROWS_WITH(AnimCurve({key(0.0, 0.0), key(0.0, 1.0)}, "curve 'envelope'"),
                      Contains("curve 'envelope'") && Contains("key 1"));

    CHECK_THROWS_AS(AnimCurve({key(0.0, 0.0), key(1.0, nan)}), deformkit::InvalidInput);
    CHECK_THROWS_WITH(
        AnimCurve({key(0.0, 0.0), key(1.0, nan)}, "curve 'jaw'"),
        Contains("curve 'jaw'") && Contains("key 1") && Contains("value nan") && Contains("finite"));
    CHECK_THROWS_WITH(AnimCurve({key(inf, 0.0)}, "curve 'jaw'"),
                      Contains("curve 'jaw'") && Contains("key 0"));

    Key steep = key(1.0, 0.0, Interpolation::Bezier, TangentMode::Explicit);
    steep.outSlope = inf;
    CHECK_THROWS_WITH(AnimCurve({key(0.0, 0.0), steep}, "curve 'jaw'"),
                      Contains("curve 'jaw'") && Contains("key 1") && Contains("slope"));

    CHECK_THROWS_AS(AnimCurve(std::vector<Key>{}), deformkit::InvalidInput);
    CHECK_THROWS_WITH(AnimCurve(std::vector<Key>{}, "curve 'blink'"),
                      Contains("curve 'blink'") && Contains("no key"));
    CHECK_THROWS_AS(AnimCurve::constant(nan), deformkit::InvalidInput);

    // Finite times whose span overflows a double.
    CHECK_THROWS_WITH(AnimCurve({key(-1e308, 0.0), key(1e308, 1.0)}, "curve 'jaw'"),
                      Contains("curve 'jaw'") && Contains("keys"));
}
