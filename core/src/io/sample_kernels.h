#pragma once

// The filters of io::sampleImage without its checks, inline for the loops that sample every pixel of an
// image (image warps, texture bakes). Positions in pixel units from the top-left corner, clamp-to-edge.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "deformkit/io/image.h"
#include "deformkit/io/sampling.h"

namespace deformkit::io::detail {

// Continuous index of a position along one axis (pixel centres at integers), limited to a range where
// clamp-to-edge already decides the result, so the integer part cannot overflow.
inline float continuousIndex(float position, int32_t size, float margin) {
    return std::clamp(position - 0.5f, -margin, static_cast<float>(size) - 1.0f + margin);
}

// Channels [0, channels) of the bilinear sample at (px, py) into out.
inline void sampleBilinear(const Image& image, float px, float py, int32_t channels, float* out) {
    const float fx = continuousIndex(px, image.width, 2.0f);
    const float fy = continuousIndex(py, image.height, 2.0f);
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float tx = fx - x0f, ty = fy - y0f;
    const auto x0 = static_cast<int32_t>(x0f), y0 = static_cast<int32_t>(y0f);
    const int32_t xa = std::clamp(x0, 0, image.width - 1), xb = std::clamp(x0 + 1, 0, image.width - 1);
    const int32_t ya = std::clamp(y0, 0, image.height - 1), yb = std::clamp(y0 + 1, 0, image.height - 1);
    const auto stride = static_cast<size_t>(image.channels);
    const size_t width = static_cast<size_t>(image.width);
    const float* aa = &image.pixels[(static_cast<size_t>(ya) * width + static_cast<size_t>(xa)) * stride];
    const float* ab = &image.pixels[(static_cast<size_t>(ya) * width + static_cast<size_t>(xb)) * stride];
    const float* ba = &image.pixels[(static_cast<size_t>(yb) * width + static_cast<size_t>(xa)) * stride];
    const float* bb = &image.pixels[(static_cast<size_t>(yb) * width + static_cast<size_t>(xb)) * stride];
    for (int32_t k = 0; k < channels; ++k) {
        const float top = aa[k] + tx * (ab[k] - aa[k]);
        const float bottom = ba[k] + tx * (bb[k] - ba[k]);
        out[k] = top + ty * (bottom - top);
    }
}

// Keys (1981) cubic convolution weights with a = -0.5 for taps at -1, 0, 1, 2 and fraction t in [0, 1).
inline void keysWeights(float t, float w[4]) {
    const float t2 = t * t, t3 = t2 * t;
    w[0] = 0.5f * (-t3 + 2.0f * t2 - t);
    w[1] = 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f);
    w[2] = 0.5f * (-3.0f * t3 + 4.0f * t2 + t);
    w[3] = 0.5f * (t3 - t2);
}

// Channels [0, channels) of the bicubic sample at (px, py) into out: rows of 4 taps, then 4 rows.
inline void sampleBicubic(const Image& image, float px, float py, int32_t channels, float* out) {
    const float fx = continuousIndex(px, image.width, 3.0f);
    const float fy = continuousIndex(py, image.height, 3.0f);
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    float wx[4], wy[4];
    keysWeights(fx - x0f, wx);
    keysWeights(fy - y0f, wy);
    const auto stride = static_cast<size_t>(image.channels);
    const float* rows[4];
    size_t xs[4];
    for (int32_t i = 0; i < 4; ++i) {
        xs[i] =
            static_cast<size_t>(std::clamp(static_cast<int32_t>(x0f) - 1 + i, 0, image.width - 1)) * stride;
        const auto y =
            static_cast<size_t>(std::clamp(static_cast<int32_t>(y0f) - 1 + i, 0, image.height - 1));
        rows[i] = &image.pixels[y * static_cast<size_t>(image.width) * stride];
    }
    for (int32_t k = 0; k < channels; ++k) {
        float value = 0.0f;
        for (int32_t j = 0; j < 4; ++j) {
            float row = 0.0f;
            for (int32_t i = 0; i < 4; ++i)
                row += wx[i] * rows[j][xs[i] + static_cast<size_t>(k)];
            value += wy[j] * row;
        }
        out[k] = value;
    }
}

inline void sample(const Image& image, float px, float py, SampleFilter filter, int32_t channels,
                   float* out) {
    if (filter == SampleFilter::Bicubic) {
        sampleBicubic(image, px, py, channels, out);
    } else {
        sampleBilinear(image, px, py, channels, out);
    }
}

}  // namespace deformkit::io::detail
