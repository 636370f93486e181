#pragma once

// Checks the warp framework's entry points and loops share: sizes, with the message every one of them gives,
// and the finiteness of the points a loop writes.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"

namespace deformkit::warp::detail {

// 1 when the point's coordinates are finite, 0 otherwise, without a branch (a loop's flag, kept with & or
// a min): x * 0 is 0 for a finite x and NaN for an infinite or NaN one.
inline int finiteBits(const glm::vec3& p) {
    return static_cast<int>(p.x * 0.0f + p.y * 0.0f + p.z * 0.0f == 0.0f);
}

// Whether every coordinate of `points` is finite: a float whose exponent bits are all ones is infinite or
// NaN, and adding one to such an exponent carries into the sign bit. Integer operations over the coordinates
// as one array, which the compiler vectorises: the check a loop makes on a run of outputs it has just written
// (still in cache) instead of a per-point test.
inline bool allFinite(std::span<const glm::vec3> points) {
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 holds three packed floats");
    const auto* f = reinterpret_cast<const float*>(points.data());
    const size_t n = 3 * points.size();
    uint32_t any = 0;
    for (size_t i = 0; i < n; ++i) {
        uint32_t bits;
        std::memcpy(&bits, f + i, sizeof(bits));
        any |= (bits & 0x7f800000u) + 0x00800000u;
    }
    return (any & 0x80000000u) == 0;
}

// The first point that is not finite, or points.size(): the slow path once a loop's flag says there is one.
inline int64_t firstNonFinite(std::span<const glm::vec3> points) {
    return static_cast<int64_t>(geom::firstNonFinite(points));
}

// The first point of out[begin, begin + count) that is not finite, or n: the check of a run of outputs once
// written, a vectorised pass, then the search only when it fails.
inline int64_t firstNonFiniteOfRun(std::span<const glm::vec3> out, int64_t begin, int64_t count, int64_t n) {
    const std::span<const glm::vec3> written =
        out.subspan(static_cast<size_t>(begin), static_cast<size_t>(count));
    if (allFinite(written)) return n;
    const int64_t i = firstNonFinite(written);
    return i < count ? begin + i : n;
}

// "<source>: <what>: has <got> entries (expected <expected> entries)".
inline void requireCount(const char* source, const char* what, size_t got, size_t expected) {
    if (got != expected) {
        throw InvalidInput(formatError(source, what, "has " + std::to_string(got) + " entries",
                                       std::to_string(expected) + " entries"));
    }
}

}  // namespace deformkit::warp::detail
