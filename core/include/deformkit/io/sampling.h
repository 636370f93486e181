#pragma once

#include <span>

#include <glm/vec2.hpp>

#include "deformkit/io/image.h"

namespace deformkit::io {

// Sampling an image between its pixels: the one filter implementation behind image warps, texture bakes,
// weights from texture maps and Ptex look-ups.
//
// Conventions: positions are in pixel units with the origin at the top-left corner of the image, so the
// centre of pixel (i, j) is (i + 0.5, j + 0.5) and sampling exactly there returns that pixel. Outside the
// image the edge pixels are repeated (clamp-to-edge): no black borders, no wrap.
enum class SampleFilter {
    Bilinear,  // 2x2 taps; reproduces images linear in x and y exactly
    Bicubic,   // 4x4 taps, Keys' cubic convolution with a = -0.5 (Catmull-Rom); reproduces quadratics
               // exactly away from the border; may overshoot the input range near edges (not clamped)
};

// One sample at `position`: writes image.channels values to out. Throws InvalidInput for an empty or
// inconsistent image, an output of another size or a non-finite position.
void sampleImage(const Image& image, glm::vec2 position, SampleFilter filter, std::span<float> out);

}  // namespace deformkit::io
