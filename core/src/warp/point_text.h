#pragma once

// How the warps' messages print a point: "(x, y, z)" with std::to_string's six decimals.

#include <string>

#include <glm/vec3.hpp>

namespace deformkit::warp::detail {

inline std::string pointText(const glm::vec3& v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

}  // namespace deformkit::warp::detail
