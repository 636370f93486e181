#include "deformkit/ptex/half.h"

#include <bit>

namespace deformkit::ptex {

float halfToFloat(uint16_t bits) {
    const uint32_t sign = static_cast<uint32_t>(bits & 0x8000u) << 16;
    const uint32_t exponent = (bits >> 10) & 0x1fu;
    uint32_t mantissa = bits & 0x3ffu;
    if (exponent == 0x1f) return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));
    if (exponent != 0) return std::bit_cast<float>(sign | ((exponent + 112) << 23) | (mantissa << 13));
    if (mantissa == 0) return std::bit_cast<float>(sign);
    // Subnormal half: normalise into a float exponent.
    int32_t e = 113;
    while ((mantissa & 0x400u) == 0) {
        mantissa <<= 1;
        --e;
    }
    return std::bit_cast<float>(sign | (static_cast<uint32_t>(e) << 23) | ((mantissa & 0x3ffu) << 13));
}

uint16_t floatToHalf(float value) {
    const uint32_t f = std::bit_cast<uint32_t>(value);
    const auto sign = static_cast<uint16_t>((f >> 16) & 0x8000u);
    const uint32_t exponent = (f >> 23) & 0xffu;
    const uint32_t mantissa = f & 0x7fffffu;
    if (exponent == 0xff) {
        if (mantissa == 0) return sign | 0x7c00u;
        const uint32_t payload = mantissa >> 13;
        return static_cast<uint16_t>(sign | 0x7c00u | (payload != 0 ? payload : 0x200u));
    }
    const int32_t e = static_cast<int32_t>(exponent) - 127 + 15;
    if (e >= 0x1f) return sign | 0x7c00u;  // overflow to infinity
    if (e <= 0) {
        // Subnormal half (or zero): shift the full significand, rounding to nearest even.
        if (e < -10) return sign;
        const uint32_t significand = mantissa | 0x800000u;
        const uint32_t shift = static_cast<uint32_t>(14 - e);
        uint32_t half = significand >> shift;
        const uint32_t rest = significand & ((1u << shift) - 1);
        const uint32_t halfway = 1u << (shift - 1);
        if (rest > halfway || (rest == halfway && (half & 1u))) ++half;
        return static_cast<uint16_t>(sign | half);
    }
    uint32_t half = (static_cast<uint32_t>(e) << 10) | (mantissa >> 13);
    const uint32_t rest = mantissa & 0x1fffu;
    if (rest > 0x1000u || (rest == 0x1000u && (half & 1u))) ++half;  // may carry into infinity: correct
    return static_cast<uint16_t>(sign | half);
}

}  // namespace deformkit::ptex
