#pragma once

#include <cmath>

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

}  // namespace deformkit::geom
