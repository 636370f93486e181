#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "deformkit/ptex/half.h"

using deformkit::ptex::floatToHalf;
using deformkit::ptex::halfToFloat;

namespace {

// binary16 by its definition: (-1)^s × 2^(e-15) × (1 + m/1024), subnormals 2^-14 × m/1024.
double halfByDefinition(uint16_t h) {
    const double sign = (h & 0x8000) ? -1.0 : 1.0;
    const int e = (h >> 10) & 0x1f;
    const int m = h & 0x3ff;
    if (e == 0) return sign * std::ldexp(m, -24);
    if (e == 31) return m == 0 ? sign * std::numeric_limits<double>::infinity() : std::nan("");
    return sign * std::ldexp(1024 + m, e - 25);
}

}  // namespace

TEST_CASE("every half converts to its defined value and back to the same bits", "[ptex][half]") {
    // Exact: every binary16 value is a float, and the round trip keeps NaN payloads, so no tolerance.
    int mismatches = 0;
    for (uint32_t h = 0; h <= 0xffff; ++h) {
        const float f = halfToFloat(static_cast<uint16_t>(h));
        const double expected = halfByDefinition(static_cast<uint16_t>(h));
        if (std::isnan(expected) ? !std::isnan(f) : static_cast<double>(f) != expected) ++mismatches;
        if (std::isnan(expected) == false && std::signbit(f) != ((h & 0x8000) != 0)) ++mismatches;
        if (floatToHalf(f) != h) ++mismatches;
    }
    CHECK(mismatches == 0);
}

TEST_CASE("float to half rounds to nearest with ties to even, overflowing to infinity", "[ptex][half]") {
    // Between each pair of neighbouring positive finite halves: the midpoint goes to the even one, a float
    // just below it to the lower, just above to the upper. Midpoints of halves are exact floats.
    int mismatches = 0;
    for (uint16_t h = 0; h < 0x7bff; ++h) {
        const double lo = halfByDefinition(h);
        const double hi = halfByDefinition(static_cast<uint16_t>(h + 1));
        const float mid = static_cast<float>((lo + hi) / 2);
        const uint16_t even = (h & 1) ? static_cast<uint16_t>(h + 1) : h;
        if (floatToHalf(mid) != even) ++mismatches;
        if (floatToHalf(std::nextafter(mid, 0.0f)) != h) ++mismatches;
        if (floatToHalf(std::nextafter(mid, 1e9f)) != h + 1) ++mismatches;
        if (floatToHalf(-mid) != (even | 0x8000)) ++mismatches;
    }
    CHECK(mismatches == 0);
    CHECK(floatToHalf(65504.0f) == 0x7bff);
    CHECK(floatToHalf(65519.99f) == 0x7bff);  // below the midpoint to 65536
    CHECK(floatToHalf(65520.0f) == 0x7c00);   // the midpoint, ties to even: infinity
    CHECK(floatToHalf(1e30f) == 0x7c00);
    CHECK(floatToHalf(-std::numeric_limits<float>::infinity()) == 0xfc00);
    CHECK(floatToHalf(std::ldexp(1.0f, -25)) == 0x0000);  // half the smallest subnormal: tie to 0
    CHECK(floatToHalf(std::nextafter(std::ldexp(1.0f, -25), 1.0f)) ==
          0x0001);  // just above: smallest subnormal
    CHECK(floatToHalf(1e-30f) == 0);
    CHECK(std::isnan(halfToFloat(floatToHalf(std::numeric_limits<float>::quiet_NaN()))));
    // A float NaN whose payload sits only in the low bits must stay NaN, not become infinity.
    CHECK(std::isnan(halfToFloat(floatToHalf(std::bit_cast<float>(0x7f800001u)))));
}
