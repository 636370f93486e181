#pragma once

#include <cmath>
#include <cstddef>
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

// The index of the first point of `points` that is not finite, or points.size() when every one is: one
// branch-free pass over the coordinates (vectorised, on every thread for large spans: the answer is the
// same for any thread count), then a search in order only when one is bad.
[[nodiscard]] size_t firstNonFinite(std::span<const glm::vec3> points);

}  // namespace deformkit::geom
