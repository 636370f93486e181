#include "deformkit/geom/rasterizer.h"
#include "geom/rasterize_triangle.h"

#include <algorithm>
#include <string>

#include "deformkit/error.h"
#include "memory/large_buffers.h"

namespace deformkit::geom {

void rasterizeAttributes(const RasterGrid& grid, std::span<const glm::vec2> positions,
                         std::span<const std::array<int32_t, 3>> triangles, std::span<const float> attributes,
                         int32_t channels, AttributeRaster& out) {
    if (grid.width < 0 || grid.height < 0) {
        throw InvalidInput(
            formatError("rasterizeAttributes", "grid",
                        "size is " + std::to_string(grid.width) + " x " + std::to_string(grid.height),
                        "a non-negative width and height"));
    }
    if (channels < 0) {
        throw InvalidInput(
            formatError("rasterizeAttributes", "channels", "is " + std::to_string(channels), "a count >= 0"));
    }
    if (attributes.size() != positions.size() * static_cast<size_t>(channels)) {
        throw InvalidInput(formatError(
            "rasterizeAttributes", "attributes", "hold " + std::to_string(attributes.size()) + " values",
            std::to_string(positions.size()) + " positions x " + std::to_string(channels) +
                " channels = " + std::to_string(positions.size() * channels)));
    }
    const auto numPositions = static_cast<int64_t>(positions.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            const int32_t v = triangles[t][k];
            if (v < 0 || v >= numPositions) {
                throw InvalidInput(formatError(
                    "rasterizeAttributes", "triangle " + std::to_string(t) + " corner " + std::to_string(k),
                    "position index " + std::to_string(v) + " is out of range",
                    "an index in [0, " + std::to_string(numPositions) + ")"));
            }
        }
    }

    const size_t numPixels = static_cast<size_t>(grid.width) * static_cast<size_t>(grid.height);
    out.width = grid.width;
    out.height = grid.height;
    out.channels = channels;
    deformkit::detail::assignLarge(out.values, numPixels * channels, 0.0f);
    deformkit::detail::assignLarge(out.triangle, numPixels, -1);

    rasterizeTrianglesInBands(
        grid, static_cast<int32_t>(triangles.size()),
        [&](int32_t t, glm::vec2& a, glm::vec2& b, glm::vec2& c) {
            const auto& tri = triangles[static_cast<size_t>(t)];
            a = positions[tri[0]];
            b = positions[tri[1]];
            c = positions[tri[2]];
        },
        [&](int32_t t, int32_t x, int32_t y, const glm::vec3& b) {
            const auto& tri = triangles[static_cast<size_t>(t)];
            const float* a0 = attributes.data() + static_cast<size_t>(tri[0]) * channels;
            const float* a1 = attributes.data() + static_cast<size_t>(tri[1]) * channels;
            const float* a2 = attributes.data() + static_cast<size_t>(tri[2]) * channels;
            const size_t pixel = static_cast<size_t>(y) * grid.width + x;
            out.triangle[pixel] = t;
            float* value = out.values.data() + pixel * channels;
            for (int32_t c = 0; c < channels; ++c)
                value[c] = b[0] * a0[c] + b[1] * a1[c] + b[2] * a2[c];
        });
}

}  // namespace deformkit::geom
