#pragma once

#include <cstdint>
#include <span>

#include <glm/vec2.hpp>

#include "deformkit/io/image.h"

namespace deformkit::warp {

// Resampling a whole image through an inverse map (paper §4.2, §8.3: every destination pixel looks up
// the source position it comes from). Float, any channel count, (H, W, C) layout as io::Image.
//
// Conventions: positions are in pixel units with the origin at the top-left corner of the image, so
// the centre of pixel (i, j) is (i + 0.5, j + 0.5) and sampling exactly there returns that pixel.
// Outside the image the edge pixels are repeated (clamp-to-edge): no black borders, no wrap.

enum class Interpolation {
    Bilinear,  // 2x2 taps; reproduces images linear in x and y exactly
    Bicubic,   // 4x4 taps, Keys' cubic convolution with a = -0.5 (Catmull-Rom); reproduces quadratics
               // exactly away from the border; may overshoot the input range near edges (not clamped)
};

// One sample at source position `position`: writes image.channels values to out.
void sampleImage(const io::Image& image, glm::vec2 position, Interpolation interpolation,
                 std::span<float> out);

// The destination image (width x height, the source's channel count): pixel (x, y) = source sampled at
// map[y * width + x]. Throws InvalidInput for an empty source, a map of the wrong size or a non-finite
// map entry (naming the pixel). OpenMP over rows; bit-identical for any thread count.
[[nodiscard]] io::Image resampleImage(const io::Image& source, std::span<const glm::vec2> map, int32_t width,
                                      int32_t height, Interpolation interpolation = Interpolation::Bilinear);

}  // namespace deformkit::warp
