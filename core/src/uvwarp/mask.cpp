#include "deformkit/uvwarp/mask.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"
#include "geom/rasterize_triangle.h"
#include "memory/large_buffers.h"
#include "tile_uvs.h"

namespace deformkit::uvwarp {
namespace {

std::string sourceOf(const MapLabel& label) {
    return label.tile == 0 ? label.name : detail::tileSource(label.name, label.tile);
}

std::string texelName(int32_t x, int32_t y) {
    return "texel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

void requireSquareMap(const io::Image& image, const MapLabel& label) {
    if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
        image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
        throw InvalidInput(formatError(sourceOf(label), "image",
                                       "is " + std::to_string(image.width) + " x " +
                                           std::to_string(image.height) + " with " +
                                           std::to_string(image.channels) + " channels and " +
                                           std::to_string(image.pixels.size()) + " values",
                                       "a non-empty image with width * height * channels values"));
    }
    if (image.width != image.height) {
        throw InvalidInput(
            formatError(sourceOf(label), "image",
                        "is " + std::to_string(image.width) + " x " + std::to_string(image.height),
                        "a square T x T map"));
    }
}

void requireCells(int32_t cells, const MapLabel& label) {
    if (!isPowerOfTwo(cells) || cells > kMaxGridCells) {
        throw InvalidInput(formatError(sourceOf(label), "grid cells", "is " + std::to_string(cells),
                                       "a power of two from 1 to " + std::to_string(kMaxGridCells)));
    }
}

// The range of texel indices whose centre lies within `reach` texels of continuous texel coordinate c
// (texel k centred at k), clamped to [0, size - 1].
void texelsWithin(double c, double reach, int32_t size, int32_t& lo, int32_t& hi) {
    lo = std::clamp(static_cast<int32_t>(std::ceil(c - reach)), 0, size - 1);
    hi = std::clamp(static_cast<int32_t>(std::floor(c + reach)), 0, size - 1);
}

void checkMaskOptions(int32_t texels, const DerivedMaskOptions& options) {
    if (texels < 1) {
        throw InvalidInput(
            formatError(options.label, "mask texels", "is " + std::to_string(texels), "at least 1"));
    }
    if (options.borderWidth < 1) {
        throw InvalidInput(formatError(options.label, "mask border width",
                                       "is " + std::to_string(options.borderWidth), "at least 1 texel"));
    }
}

io::Image maskOf(const detail::TileUVs& uvs, int32_t texels, const DerivedMaskOptions& options) {
    const int32_t size = texels;
    const auto t = static_cast<float>(texels);

    // Raster row r holds v from r / T to (r + 1) / T, i.e. image row T - 1 - r.
    io::Image mask;
    mask.width = mask.height = size;
    mask.channels = 1;
    deformkit::detail::assignLarge(mask.pixels, static_cast<size_t>(size) * size, 0.0f);
    const geom::RasterGrid grid{size, size};
    geom::rasterizeTrianglesInBands(
        grid, static_cast<int32_t>(uvs.uvs.size()),
        [&](int32_t k, glm::vec2& a, glm::vec2& b, glm::vec2& c) {
            a = uvs.uvs[k][0] * t;
            b = uvs.uvs[k][1] * t;
            c = uvs.uvs[k][2] * t;
        },
        [&](int32_t, int32_t x, int32_t r, const glm::vec3&) { mask.at(x, size - 1 - r, 0) = 1.0f; });

    // Border band: texel (x, r) is fixed when the edge meets [x - g, x + 1 + g] x [r - g, r + 1 + g].
    const double g = 0.5 * (options.borderWidth - 1);
    for (const auto& edge : uvs.borderEdges) {
        const double ax = static_cast<double>(edge[0].x) * texels,
                     ay = static_cast<double>(edge[0].y) * texels;
        const double bx = static_cast<double>(edge[1].x) * texels,
                     by = static_cast<double>(edge[1].y) * texels;
        const double yMin = std::min(ay, by), yMax = std::max(ay, by);
        const double rFirst = std::max(0.0, std::ceil(yMin - 1.0 - g));
        const double rLast = std::min(static_cast<double>(size - 1), std::floor(yMax + g));
        for (double rr = rFirst; rr <= rLast; rr += 1.0) {
            // The edge clipped to the slab of this row's grown squares.
            double xLo = std::min(ax, bx), xHi = std::max(ax, bx);
            if (by != ay) {
                const double t0 = std::clamp((rr - g - ay) / (by - ay), 0.0, 1.0);
                const double t1 = std::clamp((rr + 1.0 + g - ay) / (by - ay), 0.0, 1.0);
                xLo = std::min(ax + t0 * (bx - ax), ax + t1 * (bx - ax));
                xHi = std::max(ax + t0 * (bx - ax), ax + t1 * (bx - ax));
            }
            const double xFirst = std::max(0.0, std::ceil(xLo - 1.0 - g));
            const double xLast = std::min(static_cast<double>(size - 1), std::floor(xHi + g));
            const int32_t row = size - 1 - static_cast<int32_t>(rr);
            for (double xx = xFirst; xx <= xLast; xx += 1.0)
                mask.at(static_cast<int32_t>(xx), row, 0) = 0.0f;
        }
    }
    return mask;
}

}  // namespace

io::Image deriveWarpMask(const geom::Mesh& rest, int tile, int32_t texels,
                         const DerivedMaskOptions& options) {
    checkMaskOptions(texels, options);
    return maskOf(detail::collectTileUVs(rest, tile, options.label), texels, options);
}

io::Image deriveWarpMask(const detail::TileUVs& uvs, int32_t texels, const DerivedMaskOptions& options) {
    checkMaskOptions(texels, options);
    return maskOf(uvs, texels, options);
}

namespace {

// A mask's channel 0 is thresholded at 0.5; NaN is neither side of it.
void requireMaskNumbers(const io::Image& mask, const MapLabel& label) {
    for (int32_t y = 0; y < mask.height; ++y) {
        for (int32_t x = 0; x < mask.width; ++x) {
            if (std::isnan(mask.at(x, y, 0))) {
                throw InvalidInput(formatError(sourceOf(label), texelName(x, y), "warp mask value is NaN",
                                               "a number (thresholded at 0.5)"));
            }
        }
    }
}

}  // namespace

void validateWarpMask(const io::Image& mask, const MapLabel& label) {
    requireSquareMap(mask, label);
    requireMaskNumbers(mask, label);
}

io::Image binariseWarpMask(const io::Image& mask, const MapLabel& label) {
    validateWarpMask(mask, label);
    io::Image out(mask.width, mask.height, 1);
    for (int32_t y = 0; y < mask.height; ++y) {
        for (int32_t x = 0; x < mask.width; ++x) {
            const float value = mask.at(x, y, 0);
            out.at(x, y, 0) = value >= 0.5f ? 1.0f : 0.0f;
        }
    }
    return out;
}

io::Image readWarpMask(const std::filesystem::path& path, int tile) {
    io::ImageReadOptions read;
    read.role = "warp mask";
    return binariseWarpMask(io::readImage(path, read), MapLabel{path.string(), tile});
}

void validateRigidityMap(const io::Image& rigidity, const MapLabel& label) {
    requireSquareMap(rigidity, label);
    for (int32_t y = 0; y < rigidity.height; ++y) {
        for (int32_t x = 0; x < rigidity.width; ++x) {
            const float value = rigidity.at(x, y, 0);
            if (!(value >= 0.0f && value <= 1.0f)) {
                throw InvalidInput(formatError(sourceOf(label), texelName(x, y), "is " + numberText(value),
                                               "a finite value in [0, 1]"));
            }
        }
    }
}

io::Image readRigidityMap(const std::filesystem::path& path, int tile, const std::string& role) {
    io::ImageReadOptions read;
    read.role = role;
    const io::Image image = io::readImage(path, read);
    validateRigidityMap(image, MapLabel{path.string(), tile});
    io::Image out(image.width, image.height, 1);
    for (size_t k = 0; k < out.pixels.size(); ++k)
        out.pixels[k] = image.pixels[k * image.channels];
    return out;
}

PointField rigidityAtPoints(const io::Image& rigidity, int32_t cells, const MapLabel& label) {
    requireCells(cells, label);
    validateRigidityMap(rigidity, label);
    const int32_t size = rigidity.width;
    PointField out;
    out.cells = cells;
    out.channels = 1;
    const int32_t side = cells + 1;
    deformkit::detail::assignLarge(out.values, static_cast<size_t>(side) * side, 0.0f);
    // Continuous texel coordinates (texel centres at integers) of u = i / n and of v = j / n (image rows
    // run down), clamped to the edge texels: taps and weights per column and per row.
    const double scale = static_cast<double>(size) / cells;
    std::vector<int32_t> x0(side), x1(side), y0(side), y1(side);
    std::vector<float> tx(side), ty(side);
    for (int32_t k = 0; k < side; ++k) {
        const double fx = std::clamp(k * scale - 0.5, 0.0, static_cast<double>(size - 1));
        x0[k] = std::min(static_cast<int32_t>(fx), size - 1);
        x1[k] = std::min(x0[k] + 1, size - 1);
        tx[k] = static_cast<float>(fx - x0[k]);
        const double fy = std::clamp((cells - k) * scale - 0.5, 0.0, static_cast<double>(size - 1));
        y0[k] = std::min(static_cast<int32_t>(fy), size - 1);
        y1[k] = std::min(y0[k] + 1, size - 1);
        ty[k] = static_cast<float>(fy - y0[k]);
    }
    const int32_t channels = rigidity.channels;
#pragma omp parallel for schedule(static)
    for (int32_t j = 0; j < side; ++j) {
        const float* upperRow = &rigidity.pixels[static_cast<size_t>(y0[j]) * size * channels];
        const float* lowerRow = &rigidity.pixels[static_cast<size_t>(y1[j]) * size * channels];
        float* row = &out.values[out.index(0, j)];
        for (int32_t i = 0; i < side; ++i) {
            const size_t a = static_cast<size_t>(x0[i]) * channels, b = static_cast<size_t>(x1[i]) * channels;
            const float upper = upperRow[a] + tx[i] * (upperRow[b] - upperRow[a]);
            const float lower = lowerRow[a] + tx[i] * (lowerRow[b] - lowerRow[a]);
            row[i] = upper + ty[j] * (lower - upper);
        }
    }
    return out;
}

PointField maskAtPoints(const io::Image& mask, int32_t cells, const MapLabel& label) {
    requireCells(cells, label);
    requireSquareMap(mask, label);
    requireMaskNumbers(mask, label);
    const int32_t size = mask.width;
    const int32_t side = cells + 1;
    const double scale = static_cast<double>(size) / cells;
    // One texel, or one cell on a map finer than the grid: the texels of the cells around the point.
    const double reach = std::max(1.0, scale);
    std::vector<int32_t> columnLo(side), columnHi(side), rowLo(side), rowHi(side);
    for (int32_t k = 0; k < side; ++k) {
        texelsWithin(k * scale - 0.5, reach, size, columnLo[k], columnHi[k]);
        texelsWithin((cells - k) * scale - 0.5, reach, size, rowLo[k], rowHi[k]);
    }
    // Separable minimum: over each point column's texel columns per image row, then over texel rows.
    std::vector<uint8_t> rowMin;
    deformkit::detail::assignLarge(rowMin, static_cast<size_t>(size) * side, uint8_t{0});
#pragma omp parallel for schedule(static)
    for (int32_t y = 0; y < size; ++y) {
        for (int32_t i = 0; i < side; ++i) {
            uint8_t value = 1;
            for (int32_t x = columnLo[i]; x <= columnHi[i]; ++x)
                value = mask.at(x, y, 0) >= 0.5f ? value : 0;
            rowMin[static_cast<size_t>(y) * side + i] = value;
        }
    }
    PointField out;
    out.cells = cells;
    out.channels = 1;
    deformkit::detail::assignLarge(out.values, static_cast<size_t>(side) * side, 0.0f);
#pragma omp parallel for schedule(static)
    for (int32_t j = 0; j < side; ++j) {
        for (int32_t i = 0; i < side; ++i) {
            uint8_t value = 1;
            for (int32_t y = rowLo[j]; y <= rowHi[j]; ++y)
                value = std::min(value, rowMin[static_cast<size_t>(y) * side + i]);
            out.values[out.index(i, j)] = value;
        }
    }
    return out;
}

io::Image densityOrientationMap(const io::Image& rigidity, int32_t radius) {
    if (rigidity.width <= 0 || rigidity.height <= 0 || rigidity.channels < 1) {
        throw InvalidInput(formatError("density orientation", "rigidity map", "is empty", "an image"));
    }
    if (radius < 1) {
        throw InvalidInput(
            formatError("density orientation", "radius", "is " + std::to_string(radius), "at least 1 texel"));
    }
    const int32_t w = rigidity.width, h = rigidity.height;
    // Two separable passes through the output itself (4 bytes a texel, a 8192^2 map's bind holds nothing
    // larger): the window sums along each row, then their window sums along each column, each from prefix
    // sums in double over one row or one block of columns (a thread's own), so every texel's arithmetic is
    // the same whatever the thread count.
    io::Image out(w, h, 1);
#pragma omp parallel
    {
        std::vector<double> prefix(static_cast<size_t>(w) + 1, 0.0);
#pragma omp for schedule(static)
        for (int32_t y = 0; y < h; ++y) {
            for (int32_t x = 0; x < w; ++x)
                prefix[x + 1] = prefix[x] + static_cast<double>(rigidity.at(x, y, 0));
            for (int32_t x = 0; x < w; ++x) {
                const int32_t x0 = std::max(x - radius, 0), x1 = std::min(x + radius, w - 1) + 1;
                out.at(x, y, 0) = static_cast<float>(prefix[x1] - prefix[x0]);
            }
        }
    }
    constexpr int32_t kColumns = 64;
    const int32_t blocks = (w + kColumns - 1) / kColumns;
    double largest = 0.0;
    // A team no larger than the blocks: each thread's prefix sums are (h + 1) x 64 doubles.
#pragma omp parallel reduction(max : largest) num_threads(std::min(blocks, omp_get_max_threads()))
    {
        std::vector<double> prefix((static_cast<size_t>(h) + 1) * kColumns, 0.0);
#pragma omp for schedule(static)
        for (int32_t block = 0; block < blocks; ++block) {
            const int32_t first = block * kColumns, count = std::min(kColumns, w - first);
            for (int32_t y = 0; y < h; ++y) {
                const double* below = &prefix[static_cast<size_t>(y) * kColumns];
                double* above = &prefix[static_cast<size_t>(y + 1) * kColumns];
                for (int32_t c = 0; c < count; ++c)
                    above[c] = below[c] + static_cast<double>(out.at(first + c, y, 0));
            }
            for (int32_t y = 0; y < h; ++y) {
                const int32_t y0 = std::max(y - radius, 0), y1 = std::min(y + radius, h - 1) + 1;
                for (int32_t c = 0; c < count; ++c) {
                    const int32_t x = first + c;
                    const int32_t x0 = std::max(x - radius, 0), x1 = std::min(x + radius, w - 1) + 1;
                    const double sum = prefix[static_cast<size_t>(y1) * kColumns + c] -
                                       prefix[static_cast<size_t>(y0) * kColumns + c];
                    const auto mean = static_cast<float>(sum / (static_cast<double>(x1 - x0) * (y1 - y0)));
                    out.at(x, y, 0) = mean;
                    largest = std::max(largest, static_cast<double>(mean));
                }
            }
        }
    }
    if (largest <= 0.0) {  // no rigidity: 0 everywhere
        std::fill(out.pixels.begin(), out.pixels.end(), 0.0f);
        return out;
    }
    const auto count = static_cast<int64_t>(w) * h;
#pragma omp parallel for schedule(static)
    for (int64_t k = 0; k < count; ++k)
        out.pixels[k] =
            static_cast<float>(std::clamp(static_cast<double>(out.pixels[k]) / largest, 0.0, 1.0));
    return out;
}

}  // namespace deformkit::uvwarp
