#include "deformkit/warp/image_warp.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "deformkit/error.h"
#include "io/sample_kernels.h"

namespace deformkit::warp {
namespace {

void checkSource(const io::Image& image, const std::string& name) {
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
    io::requireFinitePixels(image, name, "finite values (a warped pixel blends its neighbours)");
}

}  // namespace

io::Image resampleImage(const io::Image& source, std::span<const glm::vec2> map, int32_t width,
                        int32_t height, io::SampleFilter filter, const std::string& sourceName) {
    checkSource(source, sourceName);
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
            io::detail::sample(source, map[i].x, map[i].y, filter, source.channels,
                               &out.pixels[i * source.channels]);
        }
    }
    return out;
}

}  // namespace deformkit::warp
