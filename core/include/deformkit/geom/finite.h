#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
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
// branch-free pass over the coordinates (vectorised), then a search only when one is bad.
[[nodiscard]] inline size_t firstNonFinite(std::span<const glm::vec3> points) {
    if (points.empty()) return 0;
    const float* f = &points.data()->x;
    bool finite = true;
    for (size_t i = 0; i < 3 * points.size(); ++i)
        finite &= std::abs(f[i]) <= std::numeric_limits<float>::max();
    if (finite) return points.size();
    for (size_t u = 0; u < points.size(); ++u)
        if (!isFinite(points[u])) return u;
    return points.size();
}

}  // namespace deformkit::geom
