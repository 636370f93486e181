#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <limits>

namespace deformkit::geom {

// Axis-aligned bounding box in scene units. A default box is empty (min > max).
struct Box3 {
    glm::vec3 min{std::numeric_limits<float>::max()};
    glm::vec3 max{-std::numeric_limits<float>::max()};

    [[nodiscard]] bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void extend(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void extend(const Box3& b) {
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }
    [[nodiscard]] glm::vec3 center() const { return 0.5f * (min + max); }
    [[nodiscard]] glm::vec3 extent() const { return max - min; }
};

}  // namespace deformkit::geom
