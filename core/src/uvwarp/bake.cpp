#include "deformkit/uvwarp/bake.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "deformkit/error.h"

namespace deformkit::uvwarp {
namespace {

std::string sizeText(const io::Image& image) {
    return std::to_string(image.width) + " x " + std::to_string(image.height) + " with " +
           std::to_string(image.channels) + " channels";
}

// The filters of warp::sampleImage (same formulas, same order of operations, so the same bits), without
// its per-call checks and channel limit: positions in pixel units from the top-left corner, clamp-to-edge.
// Writes the first `c` channels.
inline void bilinear(const io::Image& image, float px, float py, int32_t c, float* out) {
    const float fx = std::clamp(px - 0.5f, -2.0f, static_cast<float>(image.width) + 1.0f);
    const float fy = std::clamp(py - 0.5f, -2.0f, static_cast<float>(image.height) + 1.0f);
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float tx = fx - x0f, ty = fy - y0f;
    const auto x0 = static_cast<int32_t>(x0f), y0 = static_cast<int32_t>(y0f);
    const int32_t xa = std::clamp(x0, 0, image.width - 1), xb = std::clamp(x0 + 1, 0, image.width - 1);
    const int32_t ya = std::clamp(y0, 0, image.height - 1), yb = std::clamp(y0 + 1, 0, image.height - 1);
    const size_t stride = static_cast<size_t>(image.channels);
    const float* aa = &image.pixels[(static_cast<size_t>(ya) * image.width + xa) * stride];
    const float* ab = &image.pixels[(static_cast<size_t>(ya) * image.width + xb) * stride];
    const float* ba = &image.pixels[(static_cast<size_t>(yb) * image.width + xa) * stride];
    const float* bb = &image.pixels[(static_cast<size_t>(yb) * image.width + xb) * stride];
    for (int32_t k = 0; k < c; ++k) {
        const float top = aa[k] + tx * (ab[k] - aa[k]);
        const float bottom = ba[k] + tx * (bb[k] - ba[k]);
        out[k] = top + ty * (bottom - top);
    }
}

// Keys (1981) cubic convolution weights with a = -0.5 (Catmull-Rom) for taps -1, 0, 1, 2 at fraction t.
inline void keysWeights(float t, float w[4]) {
    const float t2 = t * t, t3 = t2 * t;
    w[0] = 0.5f * (-t3 + 2.0f * t2 - t);
    w[1] = 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f);
    w[2] = 0.5f * (-3.0f * t3 + 4.0f * t2 + t);
    w[3] = 0.5f * (t3 - t2);
}

inline void bicubic(const io::Image& image, float px, float py, float* out) {
    const float fx = std::clamp(px - 0.5f, -3.0f, static_cast<float>(image.width) + 2.0f);
    const float fy = std::clamp(py - 0.5f, -3.0f, static_cast<float>(image.height) + 2.0f);
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    float wx[4], wy[4];
    keysWeights(fx - x0f, wx);
    keysWeights(fy - y0f, wy);
    const float* rows[4];
    int32_t xs[4];
    for (int32_t i = 0; i < 4; ++i) {
        xs[i] = std::clamp(static_cast<int32_t>(x0f) - 1 + i, 0, image.width - 1) * image.channels;
        rows[i] = &image.pixels[static_cast<size_t>(
                                    std::clamp(static_cast<int32_t>(y0f) - 1 + i, 0, image.height - 1)) *
                                image.width * image.channels];
    }
    for (int32_t k = 0; k < image.channels; ++k) {
        float value = 0.0f;
        for (int32_t j = 0; j < 4; ++j) {
            float row = 0.0f;
            for (int32_t i = 0; i < 4; ++i)
                row += wx[i] * rows[j][xs[i] + k];
            value += wy[j] * row;
        }
        out[k] = value;
    }
}

}  // namespace

void bakeTexture(const io::Image& texture, const io::Image& redirect, io::Image& out,
                 const BakeOptions& options) {
    if (texture.width < 1 || texture.height < 1 || texture.channels < 1 ||
        texture.pixels.size() != static_cast<size_t>(texture.width) * texture.height * texture.channels) {
        throw InvalidInput(formatError("bake", "texture", "is " + sizeText(texture), "a non-empty image"));
    }
    if (redirect.width < 1 || redirect.height != redirect.width || redirect.channels < 2 ||
        redirect.pixels.size() != static_cast<size_t>(redirect.width) * redirect.height * redirect.channels) {
        throw InvalidInput(formatError("bake", "redirect map", "is " + sizeText(redirect),
                                       "a square map with 2 channels (u', v')"));
    }
    if (options.width < 0 || options.height < 0) {
        throw InvalidInput(
            formatError("bake", "output size",
                        "is " + std::to_string(options.width) + " x " + std::to_string(options.height),
                        "0 (the texture's size) or positive"));
    }
    const int32_t size = redirect.width;
    std::vector<int32_t> badColumn(size, -1);
#pragma omp parallel for schedule(static)
    for (int32_t y = 0; y < size; ++y) {
        for (int32_t x = 0; x < size; ++x) {
            if (!std::isfinite(redirect.at(x, y, 0)) || !std::isfinite(redirect.at(x, y, 1))) {
                badColumn[y] = x;
                break;
            }
        }
    }
    for (int32_t y = 0; y < size; ++y) {
        if (badColumn[y] >= 0) {
            throw InvalidInput(formatError(
                "bake", "redirect texel (" + std::to_string(badColumn[y]) + ", " + std::to_string(y) + ")",
                "is not finite", "finite tile-local UVs"));
        }
    }

    const int32_t width = options.width > 0 ? options.width : texture.width;
    const int32_t height = options.height > 0 ? options.height : texture.height;
    const int32_t channels = texture.channels;
    if (out.width != width || out.height != height || out.channels != channels ||
        out.pixels.size() != static_cast<size_t>(width) * height * channels) {
        out = io::Image(width, height, channels);
    }
    const bool direct = width == size && height == size;
    const bool cubic = options.filter == warp::Interpolation::Bicubic;
    const auto tw = static_cast<float>(texture.width), th = static_cast<float>(texture.height);
    const auto r = static_cast<float>(size);
#pragma omp parallel for schedule(static)
    for (int32_t y = 0; y < height; ++y) {
        const float v = 1.0f - (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
        float uvPrime[2];
        for (int32_t x = 0; x < width; ++x) {
            if (direct) {
                uvPrime[0] = redirect.at(x, y, 0);
                uvPrime[1] = redirect.at(x, y, 1);
            } else {
                const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(width);
                bilinear(redirect, u * r, (1.0f - v) * r, 2, uvPrime);
            }
            float* texel = &out.pixels[(static_cast<size_t>(y) * width + x) * channels];
            const float px = uvPrime[0] * tw, py = (1.0f - uvPrime[1]) * th;
            if (cubic) {
                bicubic(texture, px, py, texel);
            } else {
                bilinear(texture, px, py, channels, texel);
            }
        }
    }
}

io::Image bakeTexture(const io::Image& texture, const io::Image& redirect, const BakeOptions& options) {
    io::Image out;
    bakeTexture(texture, redirect, out, options);
    return out;
}

}  // namespace deformkit::uvwarp
