#include "deformkit/uvwarp/inversion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "memory/large_buffers.h"
#include "uvwarp/raster_points.h"

namespace deformkit::uvwarp {
namespace {

// Output rows per parallel work item: fixed, so which triangle wins an overlapped texel of a folded warp
// does not depend on the thread count.
constexpr int32_t kBandRows = 16;
// Cells per chunk: the unit of work a band looks up.
constexpr int32_t kChunkCells = 64;

void requireRegion(const io::Image& image, int32_t size, const char* what) {
    if (image.width != size || image.height != size || image.channels < 1 ||
        image.pixels.size() != static_cast<size_t>(size) * size * image.channels) {
        throw InvalidInput(formatError("inversion error", what,
                                       "is " + std::to_string(image.width) + " x " +
                                           std::to_string(image.height) + " with " +
                                           std::to_string(image.channels) + " channels",
                                       "the redirect map's size"));
    }
}

using detail::RasterPoint;
using detail::rasterY;
using detail::snap;

// Twice the signed area of (a, b, c) in snapped units, positive when c is left of a -> b with y up.
inline int64_t edgeFunction(const RasterPoint& a, const RasterPoint& b, int64_t cx, int64_t cy) {
    return (b.sx - a.sx) * (cy - a.sy) - (b.sy - a.sy) * (cx - a.sx);
}

// Smallest pixel whose centre (256 i + 128) is >= s, largest whose centre is <= s; int32 in vector loops
// (snapped positions are within 2^28), int64 elsewhere.
template <class Int>
inline Int firstCentreAtOrAbove(Int s) {
    return -((128 - s) >> 8);
}
template <class Int>
inline Int lastCentreAtOrBelow(Int s) {
    return (s - 128) >> 8;
}

using ChunkRow = detail::RasterRow<kChunkCells + 1>;

// Per cell of a chunk (cell m has corners m, m + 1 of the lower and upper point rows), the texel centres in
// its bounding box, within the band's rows [y0, y1) and the map: an empty range for a still cell (drawn
// without edge tests). A loop the compiler vectorises.
struct CandidateBoxes {
    int32_t xFirst[kChunkCells], xLast[kChunkCells], yFirst[kChunkCells], yLast[kChunkCells];

    void compute(const ChunkRow& lower, const ChunkRow& upper, const uint8_t* __restrict still, int32_t n,
                 int32_t size, int32_t y0, int32_t y1) {
        const int32_t* __restrict lx = lower.sx;
        const int32_t* __restrict ly = lower.sy;
        const int32_t* __restrict ux = upper.sx;
        const int32_t* __restrict uy = upper.sy;
        int32_t* __restrict xf = xFirst;
        int32_t* __restrict xl = xLast;
        int32_t* __restrict yf = yFirst;
        int32_t* __restrict yl = yLast;
        for (int32_t m = 0; m < n; ++m) {
            const int32_t minX = std::min(std::min(lx[m], lx[m + 1]), std::min(ux[m], ux[m + 1]));
            const int32_t maxX = std::max(std::max(lx[m], lx[m + 1]), std::max(ux[m], ux[m + 1]));
            const int32_t minY = std::min(std::min(ly[m], ly[m + 1]), std::min(uy[m], uy[m + 1]));
            const int32_t maxY = std::max(std::max(ly[m], ly[m + 1]), std::max(uy[m], uy[m + 1]));
            xf[m] = std::max(0, firstCentreAtOrAbove(minX));
            xl[m] = still[m] ? -1 : std::min(size - 1, lastCentreAtOrBelow(maxX));
            yf[m] = std::max(y0, firstCentreAtOrAbove(minY));
            yl[m] = std::min(y1 - 1, lastCentreAtOrBelow(maxY));
        }
    }
};

// The edge function of from -> to at (cx, cy), minus 1 when the edge does not own the centres on it: an
// edge of a positively oriented triangle owns them when it is a top or a left edge (geom::rasterizeTriangle's
// rule), so triangles tiling a region cover each centre exactly once.
inline int64_t ownedEdge(const RasterPoint& from, const RasterPoint& to, int64_t cx, int64_t cy) {
    const int64_t dx = to.sx - from.sx, dy = to.sy - from.sy;
    const int64_t notTopLeft = (dy > 0 || (dy == 0 && dx <= 0)) ? 1 : 0;
    return dx * (cy - from.sy) - dy * (cx - from.sx) - notTopLeft;
}

// Twice the signed area of (a, b, c) from the unsnapped positions.
inline double exactArea(const RasterPoint& a, const RasterPoint& b, const RasterPoint& c) {
    return (static_cast<double>(b.x) - a.x) * (static_cast<double>(c.y) - a.y) -
           (static_cast<double>(b.y) - a.y) * (static_cast<double>(c.x) - a.x);
}

// Does triangle (a, b, c), of snapped twice-signed-area `area`, cover the pixel centre (cx, cy) (snapped
// units)? As geom::rasterizeTriangle, a triangle that is degenerate before or after snapping covers nothing.
inline bool covers(const RasterPoint& a, const RasterPoint& b, const RasterPoint& c, int64_t area, int64_t cx,
                   int64_t cy) {
    if (area == 0) return false;
    const RasterPoint& p1 = area > 0 ? b : c;
    const RasterPoint& p2 = area > 0 ? c : b;
    if ((ownedEdge(p1, p2, cx, cy) | ownedEdge(p2, a, cx, cy) | ownedEdge(a, p1, cx, cy)) < 0) return false;
    return exactArea(a, b, c) != 0.0;
}

// Barycentric coordinates (of b and c) of pixel centre (x + 0.5, y + 0.5) in a triangle (a, b, c) that
// covers it, from the unsnapped positions so they reproduce the centre exactly.
inline void barycentric(const RasterPoint& a, const RasterPoint& b, const RasterPoint& c, int64_t x,
                        int64_t y, double& bb, double& bc) {
    const double ax = a.x, ay = a.y, bx = b.x, by = b.y, cx = c.x, cy = c.y;
    const double px = static_cast<double>(x) + 0.5, py = static_cast<double>(y) + 0.5;
    const double area = exactArea(a, b, c);
    // Both divisions in one vector instruction (each lane is the IEEE quotient, as two scalar divisions).
    using Pair = double __attribute__((vector_size(16)));
    const Pair numerators = {(px - ax) * (cy - ay) - (py - ay) * (cx - ax),
                             (bx - ax) * (py - ay) - (by - ay) * (px - ax)};
    const Pair quotients = numerators / area;
    bb = quotients[0];
    bc = quotients[1];
}

// A cell's two triangles as the inversion draws them: lower (i, j), (i+1, j), (i+1, j+1) and upper (i, j),
// (i+1, j+1), (i, j+1). Where both cover a centre (a fold) the upper one, drawn later, wins.
struct CellRaster {
    enum Hit { kNone, kLower, kUpper };

    CellRaster(const RasterPoint& p00, const RasterPoint& p10, const RasterPoint& p01, const RasterPoint& p11)
        : p00(p00),
          p10(p10),
          p01(p01),
          p11(p11),
          lowerArea(edgeFunction(p00, p10, p11.sx, p11.sy)),
          upperArea(edgeFunction(p00, p11, p01.sx, p01.sy)),
          // Same orientation: the two lie on opposite sides of the diagonal, which decides a centre's
          // triangle with one edge test (the diagonal's top-left owner).
          split((lowerArea > 0 && upperArea > 0) || (lowerArea < 0 && upperArea < 0)),
          diagFrom(upperArea > 0 ? p00 : p11),
          diagTo(upperArea > 0 ? p11 : p00) {}

    [[nodiscard]] Hit hit(int64_t cx, int64_t cy) const {
        if (split) {
            if (ownedEdge(diagFrom, diagTo, cx, cy) >= 0)
                return covers(p00, p11, p01, upperArea, cx, cy) ? kUpper : kNone;
            return covers(p00, p10, p11, lowerArea, cx, cy) ? kLower : kNone;
        }
        if (covers(p00, p11, p01, upperArea, cx, cy)) return kUpper;
        return covers(p00, p10, p11, lowerArea, cx, cy) ? kLower : kNone;
    }

    const RasterPoint &p00, &p10, &p01, &p11;
    const int64_t lowerArea, upperArea;
    const bool split;
    const RasterPoint &diagFrom, &diagTo;
};

// When a cell is 1/q texel wide (q = cells / texels, a power of two from 2 to 256), texel centres lie on grid
// points only: (i, j) with i = j = q/2 (mod q). A cell the warp leaves where it is (a still cell) is then an
// axis-aligned square with no centre inside or on an open edge, and the top-left rule gives each of its
// corners to the same cell around it whatever the square's place (its snapped corners are exact multiples of
// 256 / q): every still cell covers the centre on one corner, its `corner`, and no other. Found by drawing a
// still cell with a centre on each corner in turn. Null when the rule would give none or several (never, for
// a rule under which cells tiling a region cover each centre once).
std::optional<std::pair<int32_t, int32_t>> stillCellCorner(int32_t q) {
    const float side = 1.0f / static_cast<float>(q);
    std::optional<std::pair<int32_t, int32_t>> found;
    int32_t hits = 0;
    for (int32_t b = 0; b <= 1; ++b) {
        for (int32_t a = 0; a <= 1; ++a) {
            // Corner (a, b) on the centre of texel (0, 0), (0.5, 0.5); raster y runs down as v rises.
            const float x0 = 0.5f - static_cast<float>(a) * side, y0 = 0.5f + static_cast<float>(b) * side;
            auto point = [](float x, float y) { return RasterPoint{x, y, snap(x), snap(y)}; };
            const RasterPoint p00 = point(x0, y0), p10 = point(x0 + side, y0);
            const RasterPoint p01 = point(x0, y0 - side), p11 = point(x0 + side, y0 - side);
            if (CellRaster(p00, p10, p01, p11).hit(128, 128) != CellRaster::kNone) {
                found = std::make_pair(a, b);
                ++hits;
            }
        }
    }
    return hits == 1 ? found : std::nullopt;
}

InversionError measure(const WarpGrid& warp, const io::Image& redirect, const io::Image* region) {
    validateWarpGrid(warp, "inversion error: warp grid");
    const int32_t size = redirect.width;
    if (size < 1 || redirect.height != size || redirect.channels < 2 ||
        redirect.pixels.size() != static_cast<size_t>(size) * size * redirect.channels) {
        throw InvalidInput(formatError("inversion error", "redirect map",
                                       "is " + std::to_string(redirect.width) + " x " +
                                           std::to_string(redirect.height) + " with " +
                                           std::to_string(redirect.channels) + " channels",
                                       "a square T x T map with 2 channels (u', v')"));
    }
    if (region) requireRegion(*region, size, "region");

    std::vector<double> rowMax(size, 0.0), rowSum(size, 0.0);
    std::vector<int64_t> rowCount(size, 0);
    std::vector<int32_t> rowBad(size, -1);
    const auto t = static_cast<float>(size);
#pragma omp parallel for schedule(static)
    for (int32_t y = 0; y < size; ++y) {
        const float v = 1.0f - (static_cast<float>(y) + 0.5f) / t;
        double largest = 0.0, sum = 0.0;
        int64_t count = 0;
        for (int32_t x = 0; x < size; ++x) {
            const float ru = redirect.at(x, y, 0), rv = redirect.at(x, y, 1);
            if (!std::isfinite(ru) || !std::isfinite(rv)) {
                rowBad[y] = x;
                break;
            }
            if (region && !(region->at(x, y, 0) >= 0.5f)) continue;
            const float u = (static_cast<float>(x) + 0.5f) / t;
            const glm::vec2 w = evaluateWarp(warp, ru, rv);
            const double du = (static_cast<double>(w.x) - u) * size,
                         dv = (static_cast<double>(w.y) - v) * size;
            const double e = std::sqrt(du * du + dv * dv);
            largest = std::max(largest, e);
            sum += e;
            ++count;
        }
        rowMax[y] = largest;
        rowSum[y] = sum;
        rowCount[y] = count;
    }
    InversionError out;
    double sum = 0.0;
    for (int32_t y = 0; y < size; ++y) {
        if (rowBad[y] >= 0) {
            throw InvalidInput(
                formatError("inversion error",
                            "redirect texel (" + std::to_string(rowBad[y]) + ", " + std::to_string(y) + ")",
                            "is not finite", "finite tile-local UVs"));
        }
        out.maxTexels = std::max(out.maxTexels, rowMax[y]);
        sum += rowSum[y];
        out.texels += rowCount[y];
    }
    out.meanTexels = out.texels > 0 ? sum / static_cast<double>(out.texels) : 0.0;
    return out;
}

}  // namespace

namespace {

// validateWarpGrid's checks of the grid's size and of its arrays' lengths.
void validateWarpShape(const WarpGrid& warp, std::string_view source) {
    if (!isPowerOfTwo(warp.cells) || warp.cells > kMaxGridCells) {
        throw InvalidInput(formatError(source, "cells", "is " + std::to_string(warp.cells),
                                       "a power of two from 1 to " + std::to_string(kMaxGridCells)));
    }
    const size_t count = static_cast<size_t>(warp.cells + 1) * static_cast<size_t>(warp.cells + 1);
    if (warp.u.size() != count || warp.v.size() != count) {
        throw InvalidInput(formatError(
            source, "points",
            "has " + std::to_string(warp.u.size()) + " u and " + std::to_string(warp.v.size()) + " v values",
            std::to_string(count) + " of each ((cells + 1)^2)"));
    }
}

}  // namespace

void validateWarpGrid(const WarpGrid& warp, std::string_view source) {
    validateWarpShape(warp, source);
    const size_t count = warp.u.size();
    for (size_t k = 0; k < count; ++k) {
        if (!std::isfinite(warp.u[k]) || !std::isfinite(warp.v[k])) {
            const size_t side = static_cast<size_t>(warp.cells) + 1;
            throw InvalidInput(formatError(
                source, "point (" + std::to_string(k % side) + ", " + std::to_string(k / side) + ")",
                "is not finite", "finite tile-local UVs"));
        }
    }
}

void invertWarp(const WarpGrid& warp, int32_t texels, io::Image& redirect) {
    // The points' finiteness is checked by the first pass below, which reads every point anyway.
    validateWarpShape(warp, "invert warp: warp grid");
    if (texels < 1) {
        throw InvalidInput(
            formatError("invert warp", "texels", "is " + std::to_string(texels), "at least 1"));
    }
    const int32_t cells = warp.cells, side = cells + 1, size = texels;
    const auto t = static_cast<float>(size);
    const float* wu = warp.u.data();
    const float* wv = warp.v.data();

    // Work is split into bands of output rows; each band draws the chunks of cells (runs of kChunkCells
    // in one cell row) whose raster y range reaches it, in (j, i) order.
    const int32_t numBands = (size + kBandRows - 1) / kBandRows;
    const int32_t chunksPerRow = (cells + kChunkCells - 1) / kChunkCells;
    const int64_t numChunks = static_cast<int64_t>(cells) * chunksPerRow;
    std::vector<int32_t> chunkFirstBand(numChunks), chunkLastBand(numChunks);
    // Per point row and chunk, the range of v and whether every u and v is finite. Raster y falls as v
    // rises (rasterY is monotonic: a subtraction, a product and a clamp, each rounded monotonically), so a
    // chunk's raster y range is rasterY of its largest v down to rasterY of its smallest, exactly what
    // rasterY of every point would give.
    const size_t rowChunks = static_cast<size_t>(side) * chunksPerRow;
    std::vector<float> rowLowV(rowChunks), rowHighV(rowChunks);
    std::vector<uint8_t> rowFinite(rowChunks);
#pragma omp parallel for schedule(static)
    for (int32_t j = 0; j < side; ++j) {
        for (int32_t c = 0; c < chunksPerRow; ++c) {
            const int32_t i0 = c * kChunkCells, i1 = std::min(cells, i0 + kChunkCells);
            const float* ru = wu + static_cast<size_t>(j) * side;
            const float* rv = wv + static_cast<size_t>(j) * side;
            // The chunk's last point (its first in the next chunk) on its own: the vector loop then runs
            // whole vectors only (64 points), with no scalar remainder.
            constexpr float kLargest = std::numeric_limits<float>::max();
            float low = rv[i1], high = rv[i1];
            int32_t bad =
                !(std::abs(ru[i1]) <= kLargest) | !(std::abs(rv[i1]) <= kLargest);  // NaN or infinite
#pragma omp simd reduction(min : low) reduction(max : high) reduction(| : bad)
            for (int32_t i = i0; i < i1; ++i) {
                bad |= !(std::abs(ru[i]) <= kLargest) | !(std::abs(rv[i]) <= kLargest);
                low = std::min(low, rv[i]);
                high = std::max(high, rv[i]);
            }
            const size_t q = static_cast<size_t>(j) * chunksPerRow + c;
            rowLowV[q] = low;
            rowHighV[q] = high;
            rowFinite[q] = bad == 0 ? 1 : 0;
        }
    }
    bool finite = true;
    for (int32_t j = 0; j < cells; ++j) {
        for (int32_t c = 0; c < chunksPerRow; ++c) {
            const size_t lower = static_cast<size_t>(j) * chunksPerRow + c, upper = lower + chunksPerRow;
            const int64_t chunk = static_cast<int64_t>(j) * chunksPerRow + c;
            chunkFirstBand[chunk] = 1;  // no band, unless set below
            chunkLastBand[chunk] = 0;
            if (!rowFinite[lower] || !rowFinite[upper]) {  // reported below, before anything is drawn
                finite = false;
                continue;
            }
            const float lo = rasterY(std::max(rowHighV[lower], rowHighV[upper]), t);
            const float hi = rasterY(std::min(rowLowV[lower], rowLowV[upper]), t);
            // Texel rows whose centre lies within the snapped y range (snapping can move a vertex onto a
            // centre).
            const int64_t first = firstCentreAtOrAbove(snap(lo));
            const int64_t last = lastCentreAtOrBelow(snap(hi));
            if (last < 0 || first >= size || first > last) continue;
            chunkFirstBand[chunk] = static_cast<int32_t>(std::max<int64_t>(first, 0) / kBandRows);
            chunkLastBand[chunk] = static_cast<int32_t>(std::min<int64_t>(last, size - 1) / kBandRows);
        }
    }
    if (!finite) validateWarpGrid(warp, "invert warp: warp grid");  // throws, naming the first bad point
    if (redirect.width != size || redirect.height != size || redirect.channels != 2 ||
        redirect.pixels.size() != static_cast<size_t>(size) * size * 2) {
        redirect = io::Image();
        redirect.width = redirect.height = size;
        redirect.channels = 2;
        deformkit::detail::assignLarge(redirect.pixels, static_cast<size_t>(size) * size * 2, 0.0f);
    }
    float* out = redirect.pixels.data();
    std::vector<int64_t> bandBegin(static_cast<size_t>(numBands) + 1, 0);
    for (int64_t chunk = 0; chunk < numChunks; ++chunk) {
        for (int32_t band = chunkFirstBand[chunk]; band <= chunkLastBand[chunk]; ++band)
            ++bandBegin[band + 1];
    }
    for (int32_t band = 0; band < numBands; ++band)
        bandBegin[band + 1] += bandBegin[band];
    std::vector<int64_t> bandChunks(static_cast<size_t>(bandBegin[numBands]));
    {
        std::vector<int64_t> fill(bandBegin.begin(), bandBegin.end() - 1);
        for (int64_t chunk = 0; chunk < numChunks; ++chunk) {
            for (int32_t band = chunkFirstBand[chunk]; band <= chunkLastBand[chunk]; ++band)
                bandChunks[fill[band]++] = chunk;
        }
    }

    const double inverseCells = 1.0 / cells;  // exact: cells is a power of two
    // Cells the warp leaves where they are (every point fixed by the warp mask, most of a real tile) are
    // drawn as a rectangle of texels, without edge tests, when each cell is a whole number of texels, a power
    // of two (texels = r cells): no texel centre then lies on a cell's edge, so the cell's texels are exactly
    // those of its square, and the rasteriser's barycentric blend, exact for such corners, gives each the
    // value the identity fill below writes. The same bytes as rasterising the cell, folds elsewhere included
    // (it is drawn in its turn, over what earlier cells drew).
    const int32_t ratio = size / cells;
    const bool identityRects = size >= cells && size % cells == 0 && isPowerOfTwo(ratio);
    // A grid finer than the map (a refined solve's): a still cell draws the centre on its owned corner, if
    // that corner is a texel centre (stillCellCorner), with the identity's value, in its turn.
    const int32_t fineness = cells / size;
    const std::optional<std::pair<int32_t, int32_t>> corner =
        size < cells && cells % size == 0 && isPowerOfTwo(fineness) && fineness <= 256
            ? stillCellCorner(fineness)
            : std::nullopt;
    const bool stillCells = identityRects || corner.has_value();
    std::vector<float> identityAt(static_cast<size_t>(side));
    for (int32_t i = 0; i <= cells; ++i)
        identityAt[i] = static_cast<float>(i) / static_cast<float>(cells);  // WarpGrid::identity's values
    // The identity redirect: texel (x, y) -> its own centre.
    std::vector<float> centreU(static_cast<size_t>(size)), centreV(static_cast<size_t>(size));
    for (int32_t x = 0; x < size; ++x) {
        centreU[x] = (static_cast<float>(x) + 0.5f) / t;
        centreV[x] = 1.0f - (static_cast<float>(x) + 0.5f) / t;
    }
#pragma omp parallel
    {
        // Which cells of a chunk are still, the raster points of its two point rows and its cells' candidate
        // texel centres (when any cell moved).
        std::vector<uint8_t> identity(kChunkCells), pointStill(kChunkCells + 1);
        ChunkRow lowerRow, upperRow;
        CandidateBoxes boxes;
#pragma omp for schedule(dynamic, 1)
        for (int32_t band = 0; band < numBands; ++band) {
            const int32_t y0 = band * kBandRows, y1 = std::min(size, y0 + kBandRows);
            for (int32_t y = y0; y < y1; ++y) {
                const float v = centreV[y];
                float* row = out + static_cast<size_t>(y) * size * 2;
                for (int32_t x = 0; x < size; ++x) {
                    row[2 * x] = centreU[x];
                    row[2 * x + 1] = v;
                }
            }
            for (int64_t e = bandBegin[band]; e < bandBegin[band + 1]; ++e) {
                const int64_t chunk = bandChunks[e];
                const auto j = static_cast<int32_t>(chunk / chunksPerRow);
                const auto i0 = static_cast<int32_t>(chunk % chunksPerRow) * kChunkCells;
                const int32_t i1 = std::min(cells, i0 + kChunkCells);
                const size_t k0 = static_cast<size_t>(j) * side + i0;
                bool anyMoved = true;
                if (stillCells) {
                    // Per point of the chunk's two rows whether it is where the identity has it, then per
                    // cell.
                    const float* __restrict lu = wu + k0;
                    const float* __restrict lv = wv + k0;
                    const float* __restrict at = identityAt.data() + i0;
                    const float lowerV = identityAt[j], upperV = identityAt[j + 1];
                    uint8_t* __restrict still = pointStill.data();
                    for (int32_t m = 0; m <= i1 - i0; ++m)
                        still[m] = ((lu[m] == at[m]) & (lv[m] == lowerV) & (lu[m + side] == at[m]) &
                                    (lv[m + side] == upperV))
                                       ? 1
                                       : 0;
                    uint8_t all = 1;
                    for (int32_t m = 0; m < i1 - i0; ++m) {
                        identity[m] = still[m] & still[m + 1];
                        all &= identity[m];
                    }
                    anyMoved = all == 0;
                } else {
                    std::fill(identity.begin(), identity.end(), uint8_t{0});
                }
                if (anyMoved) {  // every point of both rows: cheaper in vector loops than only the moved ones
                    lowerRow.compute(wu + k0, wv + k0, i1 - i0 + 1, t);
                    upperRow.compute(wu + k0 + side, wv + k0 + side, i1 - i0 + 1, t);
                    boxes.compute(lowerRow, upperRow, identity.data(), i1 - i0, size, y0, y1);
                }
                for (int32_t i = i0; i < i1; ++i) {
                    if (identity[i - i0] && corner) {
                        // A still cell finer than a texel: the centre on its owned corner, if there is one.
                        const int32_t ci = i + corner->first, cj = j + corner->second, half = fineness / 2;
                        if (ci % fineness != half || cj % fineness != half) continue;
                        const int32_t x = ci / fineness, y = size - 1 - cj / fineness;
                        if (y < y0 || y >= y1) continue;
                        float* texel = out + (static_cast<size_t>(y) * size + static_cast<size_t>(x)) * 2;
                        texel[0] = centreU[x];
                        texel[1] = centreV[y];
                        continue;
                    }
                    if (identity[i - i0]) {
                        // A run of still cells i .. end - 1, drawn in its turn: texel rows size - (j + 1) r
                        // .. size - j r - 1 (raster y runs down) within the band, columns i r .. end r - 1.
                        int32_t end = i + 1;
                        while (end < i1 && identity[end - i0])
                            ++end;
                        const int32_t yFirst = std::max(y0, size - (j + 1) * ratio);
                        const int32_t yLast = std::min(y1, size - j * ratio);
                        for (int32_t y = yFirst; y < yLast; ++y) {
                            float* __restrict texel = out + static_cast<size_t>(y) * size * 2;
                            const float v = centreV[y];
                            for (int32_t x = i * ratio; x < end * ratio; ++x) {
                                texel[2 * x] = centreU[x];
                                texel[2 * x + 1] = v;
                            }
                        }
                        i = end - 1;
                        continue;
                    }
                    const int32_t m = i - i0;
                    const int64_t xFirst = boxes.xFirst[m], xLast = boxes.xLast[m];
                    const int64_t yFirst = boxes.yFirst[m], yLast = boxes.yLast[m];
                    if (xFirst > xLast || yFirst > yLast) continue;
                    const RasterPoint p00 = lowerRow.point(m), p10 = lowerRow.point(m + 1);
                    const RasterPoint p01 = upperRow.point(m), p11 = upperRow.point(m + 1);
                    const CellRaster cell(p00, p10, p01, p11);
                    for (int64_t y = yFirst; y <= yLast; ++y) {
                        for (int64_t x = xFirst; x <= xLast; ++x) {
                            const CellRaster::Hit hit = cell.hit(256 * x + 128, 256 * y + 128);
                            double bb = 0.0, bc = 0.0, u = 0.0, v = 0.0;
                            if (hit == CellRaster::kUpper) {
                                barycentric(p00, p11, p01, x, y, bb, bc);
                                u = i + bb;
                                v = j + bb + bc;
                            } else if (hit == CellRaster::kLower) {
                                barycentric(p00, p10, p11, x, y, bb, bc);
                                u = i + bb + bc;
                                v = j + bc;
                            } else {
                                continue;
                            }
                            float* texel = out + (static_cast<size_t>(y) * size + static_cast<size_t>(x)) * 2;
                            texel[0] = static_cast<float>(u * inverseCells);
                            texel[1] = static_cast<float>(v * inverseCells);
                        }
                    }
                }
            }
        }
    }
}

io::Image invertWarp(const WarpGrid& warp, int32_t texels) {
    io::Image redirect;
    invertWarp(warp, texels, redirect);
    return redirect;
}

glm::vec2 evaluateWarp(const WarpGrid& warp, float u, float v) {
    const int32_t n = warp.cells;
    const size_t side = static_cast<size_t>(n) + 1;
    const float x = std::clamp(std::isnan(u) ? 0.0f : u, 0.0f, 1.0f) * static_cast<float>(n);
    const float y = std::clamp(std::isnan(v) ? 0.0f : v, 0.0f, 1.0f) * static_cast<float>(n);
    const int32_t i = std::min(static_cast<int32_t>(x), n - 1);
    const int32_t j = std::min(static_cast<int32_t>(y), n - 1);
    const float fx = x - static_cast<float>(i), fy = y - static_cast<float>(j);
    const size_t k00 = static_cast<size_t>(j) * side + i, k10 = k00 + 1, k01 = k00 + side, k11 = k01 + 1;
    const glm::vec2 p00(warp.u[k00], warp.v[k00]), p10(warp.u[k10], warp.v[k10]);
    const glm::vec2 p01(warp.u[k01], warp.v[k01]), p11(warp.u[k11], warp.v[k11]);
    if (fx >= fy) return p00 + fx * (p10 - p00) + fy * (p11 - p10);  // lower triangle
    return p00 + fx * (p11 - p01) + fy * (p01 - p00);                // upper triangle
}

InversionError inversionError(const WarpGrid& warp, const io::Image& redirect) {
    return measure(warp, redirect, nullptr);
}

InversionError inversionError(const WarpGrid& warp, const io::Image& redirect, const io::Image& region) {
    return measure(warp, redirect, &region);
}

}  // namespace deformkit::uvwarp
