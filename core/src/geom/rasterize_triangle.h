#pragma once

// The triangle rasteriser under rasterizeAttributes, the UV-warp geometry images, masks and inversion,
// and previews: a template over the per-pixel visitor, so it stays private to the library.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"

namespace deformkit::geom {

namespace rasterizer_detail {

// Subpixel precision: coordinates are multiples of 1/256 pixel.
inline constexpr int64_t kSubpixels = 256;
// Largest |coordinate| in pixels a triangle touching the grid may have: keeps fixed-point coordinates
// below 2^29, so every edge function (a difference of two products of differences) fits in int64.
inline constexpr double kMaxCoordinate = 2097152.0;  // 2^21

struct FixedPoint {
    int64_t x, y;
};

inline FixedPoint snap(const glm::vec2& p) {
    return {static_cast<int64_t>(std::llround(static_cast<double>(p.x) * kSubpixels)),
            static_cast<int64_t>(std::llround(static_cast<double>(p.y) * kSubpixels))};
}

// Twice the signed area of (a, b, c), in subpixel units squared: positive when c lies to the left of a->b
// with y up.
inline int64_t edgeFunction(const FixedPoint& a, const FixedPoint& b, const FixedPoint& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Top-left rule for a triangle with positive edge functions inside: a sample exactly on edge a->b counts
// iff the edge is a "top" or "left" one. This equals moving every sample by the same infinitesimal
// (+e, +e k) with 0 < k << 1, so triangles that tile a region claim each sample exactly once.
inline bool isTopLeft(const FixedPoint& a, const FixedPoint& b) {
    const int64_t dy = b.y - a.y;
    return dy < 0 || (dy == 0 && b.x - a.x > 0);
}

// Smallest pixel index whose centre (256 i + 128 in subpixels) is >= v, and largest one whose centre is <= v.
inline int64_t firstCentreAtOrAbove(int64_t v) {
    return -((kSubpixels / 2 - v) >> 8);
}
inline int64_t lastCentreAtOrBelow(int64_t v) {
    return (v - kSubpixels / 2) >> 8;
}

[[noreturn]] inline void throwBadVertex(int corner, const glm::vec2& p) {
    throw InvalidInput(formatError("rasterizeTriangle", "vertex " + std::to_string(corner),
                                   "coordinates (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                                       ") are not finite or lie too far from the grid",
                                   "finite raster coordinates within +-2^21 pixels"));
}

// The checks of a triangle before it is rasterised: throws for a corner that is not finite, and for one too
// far from the grid (kMaxCoordinate) when the triangle's box reaches the grid; false when it does not (or the
// grid is empty), so the triangle covers no pixel.
inline bool touchesGrid(const RasterGrid& grid, const glm::vec2& p0, const glm::vec2& p1,
                        const glm::vec2& p2) {
    const glm::vec2* corners[3] = {&p0, &p1, &p2};
    for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(corners[k]->x) || !std::isfinite(corners[k]->y)) throwBadVertex(k, *corners[k]);
    }
    if (grid.width <= 0 || grid.height <= 0) return false;
    // Pixel centres lie in [0.5, size - 0.5]; snapping moves a vertex by at most 1/512 pixel.
    const float minX = std::min({p0.x, p1.x, p2.x}), maxX = std::max({p0.x, p1.x, p2.x});
    const float minY = std::min({p0.y, p1.y, p2.y}), maxY = std::max({p0.y, p1.y, p2.y});
    if (maxX < 0.0f || maxY < 0.0f || minX > static_cast<float>(grid.width) ||
        minY > static_cast<float>(grid.height)) {
        return false;
    }
    for (int k = 0; k < 3; ++k) {
        if (std::abs(corners[k]->x) > kMaxCoordinate || std::abs(corners[k]->y) > kMaxCoordinate)
            throwBadVertex(k, *corners[k]);
    }
    return true;
}

}  // namespace rasterizer_detail

// The barycentrics rasterizeTriangle hands its visitor, as a function of the pixel: from the unsnapped
// corners (raster coordinates), so they reproduce the pixel centre exactly. A caller that keeps only which
// triangle covers a pixel gets the visitor's barycentrics back, bit for bit, from at().
class BarycentricFrame {
  public:
    BarycentricFrame(const glm::vec2& p0, const glm::vec2& p1, const glm::vec2& p2)
        : q0x_(p0.x), q0y_(p0.y), q1x_(p1.x), q1y_(p1.y), q2x_(p2.x), q2y_(p2.y) {
        const double exactArea = (q1x_ - q0x_) * (q2y_ - q0y_) - (q1y_ - q0y_) * (q2x_ - q0x_);
        inverseArea_ = exactArea == 0.0 ? 0.0 : 1.0 / exactArea;
    }
    // False for a triangle of zero area, which covers no pixel.
    [[nodiscard]] bool valid() const { return inverseArea_ != 0.0; }
    // (b0, b1, b2) at the centre of pixel (x, y).
    [[nodiscard]] glm::vec3 at(int64_t x, int64_t y) const {
        const double cx = static_cast<double>(x) + 0.5, cy = static_cast<double>(y) + 0.5;
        const double b1 = ((cx - q0x_) * (q2y_ - q0y_) - (cy - q0y_) * (q2x_ - q0x_)) * inverseArea_;
        const double b2 = ((q1x_ - q0x_) * (cy - q0y_) - (q1y_ - q0y_) * (cx - q0x_)) * inverseArea_;
        const double b0 = ((q1x_ - cx) * (q2y_ - cy) - (q1y_ - cy) * (q2x_ - cx)) * inverseArea_;
        return {static_cast<float>(b0), static_cast<float>(b1), static_cast<float>(b2)};
    }

  private:
    double q0x_, q0y_, q1x_, q1y_, q2x_, q2y_;
    double inverseArea_ = 0.0;
};

// Calls visit(x, y, barycentric) for every pixel whose centre lies inside triangle (p0, p1, p2), given in
// raster coordinates, either winding; barycentric (b0, b1, b2) sums to 1 and reproduces the centre.
// Pixel centres on an edge follow the top-left rule, so a pixel is visited exactly once by a set of
// triangles that tile a region without overlap (shared edges are never drawn twice or skipped).
// Degenerate (zero-area) triangles and pixels outside the grid are skipped. Vertex coordinates are snapped
// to 1/256 pixel, as GPUs do, which makes the rule exact.
// Rows [rowBegin, rowEnd) of the grid only: the same pixels, with the same barycentrics, as the whole grid's
// rasterisation visits in those rows.
template <class Visit>
void rasterizeTriangleRows(const RasterGrid& grid, int32_t rowBegin, int32_t rowEnd, const glm::vec2& p0,
                           const glm::vec2& p1, const glm::vec2& p2, Visit&& visit) {
    namespace rd = rasterizer_detail;
    if (!rd::touchesGrid(grid, p0, p1, p2)) return;

    rd::FixedPoint v0 = rd::snap(p0), v1 = rd::snap(p1), v2 = rd::snap(p2);
    const int64_t area = rd::edgeFunction(v0, v1, v2);
    if (area == 0) return;
    if (area < 0) std::swap(v1, v2);

    // Barycentrics come from the unsnapped vertices so they reproduce the pixel centre exactly; only
    // coverage uses the snapped ones.
    const BarycentricFrame barycentrics(p0, p1, p2);
    if (!barycentrics.valid()) return;

    const int64_t x0 = std::max<int64_t>(0, rd::firstCentreAtOrAbove(std::min({v0.x, v1.x, v2.x})));
    const int64_t x1 =
        std::min<int64_t>(grid.width - 1, rd::lastCentreAtOrBelow(std::max({v0.x, v1.x, v2.x})));
    const int64_t y0 =
        std::max<int64_t>(std::max(rowBegin, 0), rd::firstCentreAtOrAbove(std::min({v0.y, v1.y, v2.y})));
    const int64_t y1 = std::min<int64_t>(std::min(rowEnd, grid.height) - 1,
                                         rd::lastCentreAtOrBelow(std::max({v0.y, v1.y, v2.y})));
    if (x0 > x1 || y0 > y1) return;

    // Edge k is opposite vertex k. A bias of -1 turns "> 0" into ">= 0" for edges that do not own their
    // samples.
    const rd::FixedPoint start{x0 * rd::kSubpixels + rd::kSubpixels / 2,
                               y0 * rd::kSubpixels + rd::kSubpixels / 2};
    const rd::FixedPoint* from[3] = {&v1, &v2, &v0};
    const rd::FixedPoint* to[3] = {&v2, &v0, &v1};
    int64_t rowValue[3], stepX[3], stepY[3];
    for (int k = 0; k < 3; ++k) {
        rowValue[k] = rd::edgeFunction(*from[k], *to[k], start) - (rd::isTopLeft(*from[k], *to[k]) ? 0 : 1);
        stepX[k] = -(to[k]->y - from[k]->y) * rd::kSubpixels;
        stepY[k] = (to[k]->x - from[k]->x) * rd::kSubpixels;
    }

    for (int64_t y = y0; y <= y1; ++y) {
        int64_t w0 = rowValue[0], w1 = rowValue[1], w2 = rowValue[2];
        for (int64_t x = x0; x <= x1; ++x) {
            if ((w0 | w1 | w2) >= 0)
                visit(static_cast<int32_t>(x), static_cast<int32_t>(y), barycentrics.at(x, y));
            w0 += stepX[0];
            w1 += stepX[1];
            w2 += stepX[2];
        }
        for (int k = 0; k < 3; ++k)
            rowValue[k] += stepY[k];
    }
}

template <class Visit>
void rasterizeTriangle(const RasterGrid& grid, const glm::vec2& p0, const glm::vec2& p1, const glm::vec2& p2,
                       Visit&& visit) {
    rasterizeTriangleRows(grid, 0, grid.height, p0, p1, p2, std::forward<Visit>(visit));
}

// Rasterises triangles 0 .. count - 1 in order, corners(t, p0, p1, p2) giving triangle t's raster corners,
// and calls visit(t, x, y, barycentric) for each pixel as rasterizeTriangle does: the pixels of every
// triangle, in triangle order per pixel, so a visitor that keeps the last triangle gets the serial result.
// Rows are split into bands rasterised in parallel (OpenMP), each band's triangles in ascending order; visit
// must be safe to call for pixels of different rows at once. The errors of rasterizeTriangle are thrown
// before any pixel is visited, by the first triangle that raises one.
template <class Corners, class Visit>
void rasterizeTrianglesInBands(const RasterGrid& grid, int32_t count, Corners&& corners, Visit&& visit) {
    namespace rd = rasterizer_detail;
    if (grid.width <= 0 || grid.height <= 0 || count <= 0) return;
    constexpr int32_t kBandRows = 64;
    const int32_t bands = (grid.height + kBandRows - 1) / kBandRows;
    // Each triangle's bands (from its corners' rows, one row of margin for snapping), ascending; and the
    // checks rasterizeTriangle would make, in its order.
    std::vector<std::vector<int32_t>> inBand(static_cast<size_t>(bands));
    glm::vec2 p[3];
    for (int32_t t = 0; t < count; ++t) {
        corners(t, p[0], p[1], p[2]);
        if (!rd::touchesGrid(grid, p[0], p[1], p[2])) continue;
        const float minY = std::min({p[0].y, p[1].y, p[2].y}), maxY = std::max({p[0].y, p[1].y, p[2].y});
        const auto lastRow = static_cast<float>(grid.height - 1);
        const auto first = static_cast<int32_t>(std::clamp(std::floor(minY) - 1.0f, 0.0f, lastRow));
        const auto last = static_cast<int32_t>(std::clamp(std::ceil(maxY) + 1.0f, 0.0f, lastRow));
        for (int32_t b = first / kBandRows; b <= last / kBandRows; ++b)
            inBand[static_cast<size_t>(b)].push_back(t);
    }
#pragma omp parallel for schedule(dynamic, 1)
    for (int32_t b = 0; b < bands; ++b) {
        glm::vec2 q[3];
        const int32_t rowBegin = b * kBandRows, rowEnd = std::min(grid.height, rowBegin + kBandRows);
        for (const int32_t t : inBand[static_cast<size_t>(b)]) {
            corners(t, q[0], q[1], q[2]);
            rasterizeTriangleRows(grid, rowBegin, rowEnd, q[0], q[1], q[2],
                                  [&](int32_t x, int32_t y, const glm::vec3& bary) { visit(t, x, y, bary); });
        }
    }
}

}  // namespace deformkit::geom
