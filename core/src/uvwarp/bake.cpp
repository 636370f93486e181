#include "deformkit/uvwarp/bake.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "io/sample_kernels.h"

namespace deformkit::uvwarp {
namespace {

std::string sizeText(const io::Image& image) {
    return std::to_string(image.width) + " x " + std::to_string(image.height) + " with " +
           std::to_string(image.channels) + " channels";
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
        throw InvalidInput(
            formatError("bake", "redirect map", "is " + sizeText(redirect),
                        "a square map with 2 channels (u', v'), or more: the first two are read"));
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

    // A non-finite texel would spread into every baked texel that filters it (inf - inf is NaN).
    io::requireFinitePixels(texture, "bake: texture", "finite values (a baked texel filters its neighbours)");

    const int32_t width = options.width > 0 ? options.width : texture.width;
    const int32_t height = options.height > 0 ? options.height : texture.height;
    const int32_t channels = texture.channels;
    if (out.width != width || out.height != height || out.channels != channels ||
        out.pixels.size() != static_cast<size_t>(width) * height * channels) {
        out = io::Image(width, height, channels);
    }
    const bool direct = width == size && height == size;
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
                io::detail::sampleBilinear(redirect, u * r, (1.0f - v) * r, 2, uvPrime);
            }
            float* texel = &out.pixels[(static_cast<size_t>(y) * width + x) * channels];
            const float px = uvPrime[0] * tw, py = (1.0f - uvPrime[1]) * th;
            io::detail::sample(texture, px, py, options.filter, channels, texel);
        }
    }
}

io::Image bakeTexture(const io::Image& texture, const io::Image& redirect, const BakeOptions& options) {
    io::Image out;
    bakeTexture(texture, redirect, out, options);
    return out;
}

}  // namespace deformkit::uvwarp
