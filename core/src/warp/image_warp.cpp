#include "deformkit/warp/image_warp.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "deformkit/error.h"

namespace deformkit::warp {
namespace {

constexpr int kMaxChannels = 64;

// Continuous index of a position along one axis (pixel centres at integers), limited to a range where
// clamp-to-edge already decides the result, so the integer part cannot overflow.
inline float continuousIndex(float position, int32_t size, float margin) {
    return std::clamp(position - 0.5f, -margin, static_cast<float>(size) - 1.0f + margin);
}

inline int32_t clampIndex(int32_t i, int32_t size) {
    return std::clamp(i, 0, size - 1);
}

// Keys (1981) cubic convolution weights with a = -0.5 for taps at -1, 0, 1, 2 and fraction t in [0, 1).
inline void keysWeights(float t, float w[4]) {
    const float t2 = t * t, t3 = t2 * t;
    w[0] = 0.5f * (-t3 + 2.0f * t2 - t);
    w[1] = 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f);
    w[2] = 0.5f * (-3.0f * t3 + 4.0f * t2 + t);
    w[3] = 0.5f * (t3 - t2);
}

inline void sample(const io::Image& image, glm::vec2 position, Interpolation interpolation, float* out) {
    const int32_t c = image.channels;
    if (interpolation == Interpolation::Bilinear) {
        const float fx = continuousIndex(position.x, image.width, 2.0f);
        const float fy = continuousIndex(position.y, image.height, 2.0f);
        const float x0f = std::floor(fx), y0f = std::floor(fy);
        const float tx = fx - x0f, ty = fy - y0f;
        const int32_t x0 = static_cast<int32_t>(x0f), y0 = static_cast<int32_t>(y0f);
        const int32_t xa = clampIndex(x0, image.width), xb = clampIndex(x0 + 1, image.width);
        const int32_t ya = clampIndex(y0, image.height), yb = clampIndex(y0 + 1, image.height);
        for (int32_t k = 0; k < c; ++k) {
            const float top = image.at(xa, ya, k) + tx * (image.at(xb, ya, k) - image.at(xa, ya, k));
            const float bottom = image.at(xa, yb, k) + tx * (image.at(xb, yb, k) - image.at(xa, yb, k));
            out[k] = top + ty * (bottom - top);
        }
        return;
    }
    const float fx = continuousIndex(position.x, image.width, 3.0f);
    const float fy = continuousIndex(position.y, image.height, 3.0f);
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    float wx[4], wy[4];
    keysWeights(fx - x0f, wx);
    keysWeights(fy - y0f, wy);
    int32_t xs[4], ys[4];
    for (int32_t i = 0; i < 4; ++i) {
        xs[i] = clampIndex(static_cast<int32_t>(x0f) - 1 + i, image.width);
        ys[i] = clampIndex(static_cast<int32_t>(y0f) - 1 + i, image.height);
    }
    for (int32_t k = 0; k < c; ++k) {
        float value = 0.0f;
        for (int32_t j = 0; j < 4; ++j) {
            float row = 0.0f;
            for (int32_t i = 0; i < 4; ++i)
                row += wx[i] * image.at(xs[i], ys[j], k);
            value += wy[j] * row;
        }
        out[k] = value;
    }
}

void checkSource(const io::Image& image) {
    if (image.width <= 0 || image.height <= 0 || image.channels <= 0) {
        throw InvalidInput(formatError("image warp", "source image",
                                       "is " + std::to_string(image.width) + " x " +
                                           std::to_string(image.height) + " with " +
                                           std::to_string(image.channels) + " channels",
                                       "at least 1 x 1 pixels and 1 channel"));
    }
    const size_t expected = static_cast<size_t>(image.width) * image.height * image.channels;
    if (image.pixels.size() != expected) {
        throw InvalidInput(formatError("image warp", "source image",
                                       "has " + std::to_string(image.pixels.size()) + " values",
                                       std::to_string(expected) + " (width * height * channels)"));
    }
    if (image.channels > kMaxChannels) {
        throw InvalidInput(formatError("image warp", "source image",
                                       "has " + std::to_string(image.channels) + " channels",
                                       "at most " + std::to_string(kMaxChannels)));
    }
}

}  // namespace

void sampleImage(const io::Image& image, glm::vec2 position, Interpolation interpolation,
                 std::span<float> out) {
    checkSource(image);
    if (out.size() != static_cast<size_t>(image.channels)) {
        throw InvalidInput(formatError("image warp", "sample output",
                                       "has " + std::to_string(out.size()) + " values",
                                       std::to_string(image.channels) + " (one per channel)"));
    }
    if (!std::isfinite(position.x) || !std::isfinite(position.y)) {
        throw InvalidInput(
            formatError("image warp", "sample position", "is not finite", "finite pixel coordinates"));
    }
    sample(image, position, interpolation, out.data());
}

io::Image resampleImage(const io::Image& source, std::span<const glm::vec2> map, int32_t width,
                        int32_t height, Interpolation interpolation) {
    checkSource(source);
    if (width <= 0 || height <= 0) {
        throw InvalidInput(formatError("image warp", "destination size",
                                       "is " + std::to_string(width) + " x " + std::to_string(height),
                                       "at least 1 x 1 pixels"));
    }
    const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
    if (map.size() != count) {
        throw InvalidInput(formatError("image warp", "map", "has " + std::to_string(map.size()) + " entries",
                                       std::to_string(count) + " (width * height)"));
    }
    for (size_t i = 0; i < count; ++i) {
        if (!std::isfinite(map[i].x) || !std::isfinite(map[i].y)) {
            throw InvalidInput(formatError(
                "image warp",
                "map entry for pixel (" + std::to_string(i % width) + ", " + std::to_string(i / width) + ")",
                "is not finite", "finite source positions"));
        }
    }
    io::Image out(width, height, source.channels);
#pragma omp parallel for schedule(static)
    for (int32_t y = 0; y < height; ++y) {
        for (int32_t x = 0; x < width; ++x) {
            const size_t i = static_cast<size_t>(y) * width + x;
            sample(source, map[i], interpolation, &out.pixels[i * source.channels]);
        }
    }
    return out;
}

}  // namespace deformkit::warp
