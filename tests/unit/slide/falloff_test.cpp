#include <catch2/catch.hpp>

#include "deformkit/error.h"
#include "deformkit/slide/falloff.h"

using deformkit::slide::Falloff;

TEST_CASE("smooth falloff is the smoothstep ramp 1 - 3x^2 + 2x^3", "[slide]") {
    const Falloff f = Falloff::smooth();
    for (double x : {0.0, 0.1, 0.25, 0.5, 0.8, 0.999})
        CHECK(f(x) == Approx(1.0 - 3.0 * x * x + 2.0 * x * x * x).margin(1e-15));
    CHECK(f(1.0) == 0.0);
    CHECK(f(3.0) == 0.0);
    CHECK(f(std::nan("")) == 0.0);
}

TEST_CASE("a falloff ramp interpolates its samples linearly over distance / radius", "[slide]") {
    const std::vector<float> samples = {1.0f, 0.25f, 0.75f, 0.0f};  // at x = 0, 1/3, 2/3, 1
    const Falloff f = Falloff::ramp(samples);
    CHECK(f(0.0) == Approx(1.0));
    CHECK(f(1.0 / 6.0) == Approx(0.625));
    CHECK(f(0.5) == Approx(0.5));
    CHECK(f(2.0 / 3.0) == Approx(0.75));
    CHECK(f(5.0 / 6.0) == Approx(0.375));
    CHECK(f(1.0) == 0.0);
    CHECK(Falloff::linear()(0.3) == Approx(0.7));
}

TEST_CASE("a bad falloff ramp names the sample", "[slide]") {
    const std::vector<float> one = {1.0f};
    CHECK_THROWS_WITH(Falloff::ramp(one), Catch::Contains("at least 2 values"));
    const std::vector<float> big = {1.0f, 1.5f};
    CHECK_THROWS_WITH(Falloff::ramp(big),
                      Catch::Contains("sample 1: is 1.5 (expected a finite value in [0, 1])"));
    const std::vector<float> nan = {std::nanf(""), 0.0f};
    CHECK_THROWS_AS(Falloff::ramp(nan), deformkit::InvalidInput);
}
