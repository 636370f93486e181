#pragma once

// How the warps' messages print a point: "(x, y, z)" with std::to_string's six decimals.

#include <string>

#include <glm/vec3.hpp>

namespace deformkit::warp::detail {

// Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on a chain of "literal" + std::string.
inline std::string pointText(const glm::vec3& v) {
    std::string text = "(";
    text += std::to_string(v.x);
    text += ", ";
    text += std::to_string(v.y);
    text += ", ";
    text += std::to_string(v.z);
    text += ")";
    return text;
}

}  // namespace deformkit::warp::detail
