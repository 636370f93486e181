#pragma once

// Checks the warp framework's entry points and loops share: sizes, with the message every one of them gives,
// and the finiteness of the points a loop writes.

#include <cstddef>
#include <cstdint>
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

// The first point that is not finite, or points.size(): the slow path once a loop's flag says there is one.
inline int64_t firstNonFinite(std::span<const glm::vec3> points) {
    return static_cast<int64_t>(geom::firstNonFinite(points));
}

// The first point of out[begin, begin + count) that is not finite, or n: the check of a run of outputs once
// written, a vectorised pass, then the search only when it fails.
inline int64_t firstNonFiniteOfRun(std::span<const glm::vec3> out, int64_t begin, int64_t count, int64_t n) {
    const std::span<const glm::vec3> written =
        out.subspan(static_cast<size_t>(begin), static_cast<size_t>(count));
    if (geom::allFinite(written)) return n;
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
