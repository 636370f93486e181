#pragma once

#include <cstdint>
#include <span>
#include <string>

#include <glm/vec2.hpp>

#include "deformkit/io/image.h"
#include "deformkit/io/sampling.h"

namespace deformkit::warp {

// Resampling a whole image through an inverse map (paper §4.2, §8.3: every destination pixel looks up
// the source position it comes from). Float, any channel count, (H, W, C) layout as io::Image.
//
// Positions are in pixel units with the origin at the top-left corner of the image, clamp-to-edge
// (io/sampling.h).

// The destination image (width x height, the source's channel count): pixel (x, y) = source sampled at
// map[y * width + x]. Throws InvalidInput for an empty source, a non-finite source pixel (a sample blends
// its neighbours: one NaN would spread), a map of the wrong size or a non-finite map entry, naming the
// pixel and `sourceName` (the image's file, when it has one). OpenMP over rows; bit-identical for any
// thread count.
[[nodiscard]] io::Image resampleImage(const io::Image& source, std::span<const glm::vec2> map, int32_t width,
                                      int32_t height, io::SampleFilter filter = io::SampleFilter::Bilinear,
                                      const std::string& sourceName = "image warp");

}  // namespace deformkit::warp
