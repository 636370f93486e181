#pragma once

// How the warps' messages print a point: "(x, y, z)", each the shortest text that reads back as the float
// ("0.5", "2e+19"; std::to_string printed 20-digit integers and rounded small values to 0.000000).

#include <string>

#include <glm/vec3.hpp>

#include "deformkit/error.h"

namespace deformkit::warp::detail {

// Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on a chain of "literal" + std::string.
inline std::string pointText(const glm::vec3& v) {
    std::string text = "(";
    text += numberText(v.x);
    text += ", ";
    text += numberText(v.y);
    text += ", ";
    text += numberText(v.z);
    text += ")";
    return text;
}

}  // namespace deformkit::warp::detail
