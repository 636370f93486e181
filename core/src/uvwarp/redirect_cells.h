#pragma once
// The texel-centre grid of a redirect map R: cell (x, y) has the centres of texels (x, y), (x + 1, y),
// (x, y + 1) and (x + 1, y + 1) as corners and is split along both diagonals, four triangles a cell. A
// triangle is inverted when its signed area in r = R(q) has the opposite sign of the identity's (r = q).
// Shared by the delivered metrics, which count inverted triangles, and the fold repair, which removes them.
#include <cmath>
#include <cstdint>

#include <glm/vec2.hpp>

#include "deformkit/io/image.h"

namespace deformkit::uvwarp::detail {

// Twice the signed area of (a, b, c).
inline double redirectArea2(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

inline glm::dvec2 redirectAt(const io::Image& redirect, int32_t x, int32_t y) {
    return {redirect.at(x, y, 0), redirect.at(x, y, 1)};
}

// Inverted triangles (0 to 4) of cell (x, y); 0 <= x, y < T - 1. Texel centres sit at ((x + 0.5) / T,
// 1 - (y + 0.5) / T), v falling with y, so the identity's triangles listed with corners running +x then +y
// in the image have negative signed area in uv: a positive one is inverted.
inline int invertedInCell(const io::Image& redirect, int32_t x, int32_t y) {
    const glm::dvec2 p00 = redirectAt(redirect, x, y), p10 = redirectAt(redirect, x + 1, y),
                     p01 = redirectAt(redirect, x, y + 1), p11 = redirectAt(redirect, x + 1, y + 1);
    return (redirectArea2(p00, p10, p11) > 0.0 ? 1 : 0) + (redirectArea2(p00, p11, p01) > 0.0 ? 1 : 0) +
           (redirectArea2(p00, p10, p01) > 0.0 ? 1 : 0) + (redirectArea2(p10, p11, p01) > 0.0 ? 1 : 0);
}

// Cells of row y (0 <= y < T - 1) that may hold an inverted triangle, found in float arithmetic: a quick
// filter before invertedInCell. Each float edge product (two rounded differences, one rounded product) is
// within 3 2^-24 of the exact one relative to itself, so a triangle whose area m1 - m2 is positive (exactly,
// or as invertedInCell's doubles round it) has a float area above -1.8e-7 (|m1| + |m2|); the margin is
// 1e-6 (|m1| + |m2|), and 1e-30 more covers products that underflow. A cell this does not count holds no
// triangle invertedInCell counts. Vectorisable: no branch in the loop.
template <size_t Channels>
int32_t foldCandidatesIn(const float* a, const float* b, int32_t cells, size_t channels) {
    const size_t c = Channels != 0 ? Channels : channels;
    const auto suspect = [](float ex, float ey, float fx, float fy) {
        const float m1 = ex * fy, m2 = ey * fx;
        return m1 - m2 > -1e-6f * (std::abs(m1) + std::abs(m2)) - 1e-30f ? 1 : 0;
    };
    int32_t count = 0;
#pragma omp simd reduction(+ : count)
    for (int32_t x = 0; x < cells; ++x) {
        const size_t i = static_cast<size_t>(x) * c;
        // p00 = a[x], p10 = a[x + 1], p01 = b[x], p11 = b[x + 1], as invertedInCell lists its triangles.
        const float x00 = a[i], y00 = a[i + 1], x10 = a[i + c], y10 = a[i + c + 1];
        const float x01 = b[i], y01 = b[i + 1], x11 = b[i + c], y11 = b[i + c + 1];
        count += suspect(x10 - x00, y10 - y00, x11 - x00, y11 - y00) |
                 suspect(x11 - x00, y11 - y00, x01 - x00, y01 - y00) |
                 suspect(x10 - x00, y10 - y00, x01 - x00, y01 - y00) |
                 suspect(x11 - x10, y11 - y10, x01 - x10, y01 - y10);
    }
    return count;
}

// The cells of row y (channels 0 and 1 of a map with any number of channels).
inline int32_t foldCandidatesInRow(const io::Image& redirect, int32_t y) {
    const size_t channels = static_cast<size_t>(redirect.channels);
    const float* a = &redirect.pixels[static_cast<size_t>(y) * redirect.width * channels];
    const float* b = a + static_cast<size_t>(redirect.width) * channels;
    // The redirect maps the library makes have 2 channels: a constant stride gives vector loads.
    return channels == 2 ? foldCandidatesIn<2>(a, b, redirect.width - 1, 2)
                         : foldCandidatesIn<0>(a, b, redirect.width - 1, channels);
}

// Inverted triangles of the cells of rows [y0, y1).
inline int64_t invertedInRows(const io::Image& redirect, int32_t y0, int32_t y1) {
    int64_t inverted = 0;
    for (int32_t y = y0; y < y1 && y + 1 < redirect.height; ++y)
        for (int32_t x = 0; x + 1 < redirect.width; ++x)
            inverted += invertedInCell(redirect, x, y);
    return inverted;
}

}  // namespace deformkit::uvwarp::detail
