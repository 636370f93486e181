#include "deformkit/io/sampling.h"

#include <cmath>
#include <string>

#include "deformkit/error.h"
#include "io/sample_kernels.h"

namespace deformkit::io {

void sampleImage(const Image& image, glm::vec2 position, SampleFilter filter, std::span<float> out) {
    if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
        image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
        throw InvalidInput(formatError("sampleImage", "image",
                                       "is " + std::to_string(image.width) + " x " +
                                           std::to_string(image.height) + " with " +
                                           std::to_string(image.channels) + " channels and " +
                                           std::to_string(image.pixels.size()) + " values",
                                       "at least 1 x 1 pixels, 1 channel, width * height * channels values"));
    }
    if (out.size() != static_cast<size_t>(image.channels)) {
        throw InvalidInput(formatError("sampleImage", "output",
                                       "has " + std::to_string(out.size()) + " values",
                                       std::to_string(image.channels) + " (one per channel)"));
    }
    if (!std::isfinite(position.x) || !std::isfinite(position.y)) {
        throw InvalidInput(
            formatError("sampleImage", "position", "is not finite", "finite pixel coordinates"));
    }
    detail::sample(image, position.x, position.y, filter, image.channels, out.data());
}

}  // namespace deformkit::io
