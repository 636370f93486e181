#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace deformkit::geom {

// The finiteness check every input of positions gets (no NaN, no infinity in any coordinate).
[[nodiscard]] inline bool isFinite(glm::vec2 p) {
    return std::isfinite(p.x) && std::isfinite(p.y);
}
[[nodiscard]] inline bool isFinite(const glm::vec3& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// The largest coordinate magnitude where lengths are squared in float (the UV warp's solver, Wires,
// Beier-Neely): squares overflow near 1.8e19 (a point that far was left unmoved, a length became inf); 1e15
// keeps a margin of 1e4 below that, far above any scene's units.
inline constexpr float kMaxSquaredCoordinate = 1e15f;
// Finite, and within +-kMaxSquaredCoordinate in every coordinate.
[[nodiscard]] inline bool isWithinSquaredRange(glm::vec2 p) {
    return std::abs(p.x) <= kMaxSquaredCoordinate && std::abs(p.y) <= kMaxSquaredCoordinate;
}
[[nodiscard]] inline bool isWithinSquaredRange(const glm::vec3& p) {
    return isWithinSquaredRange(glm::vec2(p)) && std::abs(p.z) <= kMaxSquaredCoordinate;
}

// Whether every coordinate of `points` is finite: a float whose exponent bits are all ones is infinite or
// NaN, and adding one to such an exponent carries into the sign bit. Integer operations over the coordinates
// as one array, which the compiler vectorises; inline, so that a loop can check a run of outputs it has just
// written (still in cache) instead of testing each point.
[[nodiscard]] inline bool allFinite(std::span<const glm::vec3> points) {
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

// The index of the first point of `points` that is not finite, or points.size() when every one is: one
// branch-free pass over the coordinates (vectorised, on every thread for large spans: the answer is the
// same for any thread count), then a search in order only when one is bad.
[[nodiscard]] size_t firstNonFinite(std::span<const glm::vec3> points);

}  // namespace deformkit::geom
