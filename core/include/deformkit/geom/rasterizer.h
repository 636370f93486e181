#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>

namespace deformkit::geom {

// A regular grid of width x height pixels in raster coordinates: pixel (x, y) covers [x, x+1) x [y, y+1)
// and is sampled at its centre (x + 0.5, y + 0.5). How raster coordinates relate to an image's rows or
// to UV space is the caller's mapping.
struct RasterGrid {
    int32_t width = 0;
    int32_t height = 0;
};

// Per-pixel result of rasterizeAttributes.
struct AttributeRaster {
    int32_t width = 0;
    int32_t height = 0;
    int32_t channels = 0;
    std::vector<float> values;      // width * height * channels, row y = 0 first; 0 where uncovered
    std::vector<int32_t> triangle;  // width * height: covering triangle index, -1 where uncovered
};

// Rasterises triangles (vertex index triples into `positions`, raster coordinates) and interpolates
// `attributes` (#positions x channels, vertex-major) barycentrically at every covered pixel centre.
// Where triangles overlap, the one with the highest index wins (deterministic).
void rasterizeAttributes(const RasterGrid& grid, std::span<const glm::vec2> positions,
                         std::span<const std::array<int32_t, 3>> triangles, std::span<const float> attributes,
                         int32_t channels, AttributeRaster& out);

}  // namespace deformkit::geom
