#pragma once

// Private to core/src/uvwarp: the bilinear look-up of a 3-channel point field, without checks.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/vec3.hpp>

namespace deformkit::uvwarp::detail {

// `values`: (cells + 1)^2 points x 3 channels, row-major by j. (u, v) clamped to [0, 1] (NaN to 0).
inline glm::vec3 bilinear3(const float* values, int32_t cells, float u, float v) {
    const auto n = static_cast<float>(cells);
    const float x = std::clamp(std::isnan(u) ? 0.0f : u, 0.0f, 1.0f) * n;
    const float y = std::clamp(std::isnan(v) ? 0.0f : v, 0.0f, 1.0f) * n;
    const int32_t i = std::min(static_cast<int32_t>(x), cells - 1);
    const int32_t j = std::min(static_cast<int32_t>(y), cells - 1);
    const float tx = x - static_cast<float>(i), ty = y - static_cast<float>(j);
    const size_t side = static_cast<size_t>(cells) + 1;
    const float* p00 = values + (static_cast<size_t>(j) * side + static_cast<size_t>(i)) * 3;
    const float* p10 = p00 + 3;
    const float* p01 = p00 + side * 3;
    const float* p11 = p01 + 3;
    glm::vec3 out;
    for (int c = 0; c < 3; ++c) {
        const float bottom = p00[c] + tx * (p10[c] - p00[c]);
        const float top = p01[c] + tx * (p11[c] - p01[c]);
        out[c] = bottom + ty * (top - bottom);
    }
    return out;
}

}  // namespace deformkit::uvwarp::detail
