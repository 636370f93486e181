#pragma once

#include <cstdint>

namespace deformkit::ptex {

// IEEE 754 binary16 bits to float: exact for every one of the 65536 patterns (NaN payloads kept).
[[nodiscard]] float halfToFloat(uint16_t bits);

// Float to binary16 bits, rounding to nearest, ties to even; overflow gives infinity, NaN stays NaN with
// its top payload bits (so floatToHalf(halfToFloat(h)) == h for every h).
[[nodiscard]] uint16_t floatToHalf(float value);

}  // namespace deformkit::ptex
