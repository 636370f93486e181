#include "deformkit/uvwarp/geometry_image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"
#include "geom/rasterize_triangle.h"
#include "lookup.h"
#include "memory/large_buffers.h"
#include "row_runs.h"
#include "tile_uvs.h"

namespace deformkit::uvwarp {
namespace {

constexpr int32_t kMaxRings = 64;
constexpr uint8_t kUnassigned = 255;
// Points this close (in cells) to a chart border count as covered by the border's triangle.
constexpr double kBorderTolerance = 1e-3;

constexpr std::array<std::array<int32_t, 2>, 4> kAxisDirections{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
constexpr std::array<std::array<int32_t, 2>, 4> kDiagonalDirections{{{1, 1}, {-1, 1}, {1, -1}, {-1, -1}}};

double distanceToSegment(double px, double py, double ax, double ay, double bx, double by) {
    const double dx = bx - ax, dy = by - ay;
    const double length2 = dx * dx + dy * dy;
    double t = length2 > 0.0 ? ((px - ax) * dx + (py - ay) * dy) / length2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double ex = ax + t * dx - px, ey = ay + t * dy - py;
    return std::sqrt(ex * ex + ey * ey);
}

// Nearest covered point of every point by an exact Euclidean distance transform (Felzenszwalb and
// Huttenlocher): per column the nearest covered row, then per row the lower envelope of parabolas.
// Ties go to the lower column, then (within a column) to the lower row.
std::vector<int32_t> nearestCovered(const std::vector<int32_t>& triangle, int32_t side) {
    const size_t count = static_cast<size_t>(side) * side;
    std::vector<int32_t> nearRow;
    deformkit::detail::assignLarge(nearRow, count, -1);
#pragma omp parallel for schedule(static)
    for (int32_t i = 0; i < side; ++i) {
        int32_t last = -1;
        for (int32_t j = 0; j < side; ++j) {
            const size_t k = static_cast<size_t>(j) * side + i;
            if (triangle[k] >= 0) last = j;
            nearRow[k] = last;
        }
        int32_t next = -1;
        for (int32_t j = side - 1; j >= 0; --j) {
            const size_t k = static_cast<size_t>(j) * side + i;
            if (triangle[k] >= 0) next = j;
            if (next >= 0 && (nearRow[k] < 0 || next - j < j - nearRow[k])) nearRow[k] = next;
        }
    }
    std::vector<int32_t> nearest;
    deformkit::detail::assignLarge(nearest, count, -1);
#pragma omp parallel
    {
        std::vector<int32_t> sites(static_cast<size_t>(side));
        std::vector<double> bounds(static_cast<size_t>(side) + 1);
#pragma omp for schedule(static)
        for (int32_t j = 0; j < side; ++j) {
            const size_t row = static_cast<size_t>(j) * side;
            auto height = [&](int32_t i) {
                const double d = static_cast<double>(j - nearRow[row + i]);
                return d * d + static_cast<double>(i) * i;
            };
            int32_t top = -1;
            for (int32_t q = 0; q < side; ++q) {
                if (nearRow[row + q] < 0) continue;
                if (top < 0) {
                    top = 0;
                    sites[0] = q;
                    bounds[0] = -std::numeric_limits<double>::infinity();
                    bounds[1] = std::numeric_limits<double>::infinity();
                    continue;
                }
                // Where the new parabola drops below the envelope; bounds[0] = -inf ends the loop.
                double s = (height(q) - height(sites[top])) / (2.0 * (q - sites[top]));
                while (s <= bounds[top]) {
                    --top;
                    s = (height(q) - height(sites[top])) / (2.0 * (q - sites[top]));
                }
                ++top;
                sites[top] = q;
                bounds[top] = s;
                bounds[top + 1] = std::numeric_limits<double>::infinity();
            }
            if (top < 0) continue;  // no column has a covered point: cannot happen once one point is covered
            int32_t k = 0;
            for (int32_t i = 0; i < side; ++i) {
                while (k < top && bounds[k + 1] < i)
                    ++k;
                const int32_t site = sites[k];
                nearest[row + i] = nearRow[row + site] * side + site;
            }
        }
    }
    return nearest;
}

}  // namespace

GeometryImager::GeometryImager(const geom::Mesh& rest, int tile, int32_t cells,
                               const GeometryImageOptions& options)
    : GeometryImager(rest, tile, cells, options, nullptr) {}

GeometryImager::GeometryImager(const geom::Mesh& rest, const detail::TileUVs& uvs, int32_t cells,
                               const GeometryImageOptions& options)
    : GeometryImager(rest, uvs.tile, cells, options, &uvs) {}

GeometryImager::GeometryImager(const geom::Mesh& rest, int tile, int32_t cells,
                               const GeometryImageOptions& options, const detail::TileUVs* collected)
    : tile_(tile), cells_(cells), numVertices_(rest.numVertices()), label_(options.label) {
    if (!isPowerOfTwo(cells) || cells > kMaxGridCells) {
        throw InvalidInput(formatError(label_, "geometry image cells", "is " + std::to_string(cells),
                                       "a power of two from 1 to " + std::to_string(kMaxGridCells)));
    }
    if (options.dilationRings < 0 || options.dilationRings > kMaxRings) {
        throw InvalidInput(formatError(label_, "dilation rings",
                                       "is " + std::to_string(options.dilationRings),
                                       "0 to " + std::to_string(kMaxRings)));
    }
    std::optional<detail::TileUVs> own;
    if (collected == nullptr) own = detail::collectTileUVs(rest, tile, label_);
    const detail::TileUVs& uvs = collected != nullptr ? *collected : *own;
    if (uvs.face.empty()) {
        throw InvalidInput(formatError(detail::tileSource(label_, tile), "", "holds no UV face",
                                       "a tile with at least one face whose UV centroid lies in it"));
    }

    const auto numTriangles = static_cast<int32_t>(uvs.face.size());
    cornerA_.resize(numTriangles);
    cornerB_.resize(numTriangles);
    cornerC_.resize(numTriangles);
    for (int32_t t = 0; t < numTriangles; ++t) {
        cornerA_[t] = uvs.vertices[t][0];
        cornerB_[t] = uvs.vertices[t][1];
        cornerC_[t] = uvs.vertices[t][2];
    }

    const int32_t side = cells + 1;
    const size_t count = static_cast<size_t>(side) * side;
    const auto n = static_cast<float>(cells);
    // Per point during the bind: its covering triangle, -1 if none.
    std::vector<int32_t> pointTriangle;
    deformkit::detail::assignLarge(pointTriangle, count, -1);

    // Point (i, j) is the centre of raster pixel (i, j): raster coordinates uv * n + 0.5.
    const geom::RasterGrid grid{side, side};
    rasterCorners_.resize(static_cast<size_t>(numTriangles) * 3);
    for (int32_t t = 0; t < numTriangles; ++t)
        for (int k = 0; k < 3; ++k)
            rasterCorners_[static_cast<size_t>(t) * 3 + k] = uvs.uvs[t][k] * n + 0.5f;
    geom::rasterizeTrianglesInBands(
        grid, numTriangles,
        [&](int32_t t, glm::vec2& a, glm::vec2& b, glm::vec2& c) {
            const glm::vec2* corners = &rasterCorners_[static_cast<size_t>(t) * 3];
            a = corners[0];
            b = corners[1];
            c = corners[2];
        },
        [&](int32_t t, int32_t x, int32_t y, const glm::vec3&) {
            pointTriangle[static_cast<size_t>(y) * side + x] = t;
        });

    // Points on a chart's outline that the top-left rule left out: walk each border edge row by row.
    for (size_t e = 0; e < uvs.borderEdges.size(); ++e) {
        const int32_t t = uvs.borderTriangle[e];
        const double ax = static_cast<double>(uvs.borderEdges[e][0].x) * cells;
        const double ay = static_cast<double>(uvs.borderEdges[e][0].y) * cells;
        const double bx = static_cast<double>(uvs.borderEdges[e][1].x) * cells;
        const double by = static_cast<double>(uvs.borderEdges[e][1].y) * cells;
        const auto jLo = static_cast<int32_t>(std::max(0.0, std::ceil(std::min(ay, by) - kBorderTolerance)));
        const auto jHi = static_cast<int32_t>(
            std::min(static_cast<double>(cells), std::floor(std::max(ay, by) + kBorderTolerance)));
        for (int32_t j = jLo; j <= jHi; ++j) {
            double xLo = std::min(ax, bx), xHi = std::max(ax, bx);
            if (std::abs(by - ay) > 1e-12) {
                const double t0 = std::clamp((j - kBorderTolerance - ay) / (by - ay), 0.0, 1.0);
                const double t1 = std::clamp((j + kBorderTolerance - ay) / (by - ay), 0.0, 1.0);
                xLo = std::min(ax + t0 * (bx - ax), ax + t1 * (bx - ax));
                xHi = std::max(ax + t0 * (bx - ax), ax + t1 * (bx - ax));
            }
            const auto iLo = static_cast<int32_t>(std::max(0.0, std::ceil(xLo - kBorderTolerance)));
            const auto iHi = static_cast<int32_t>(
                std::min(static_cast<double>(cells), std::floor(xHi + kBorderTolerance)));
            for (int32_t i = iLo; i <= iHi; ++i) {
                const size_t k = static_cast<size_t>(j) * side + i;
                if (pointTriangle[k] >= 0) continue;
                if (distanceToSegment(i, j, ax, ay, bx, by) > kBorderTolerance) continue;
                // Barycentrics of the point in the border's triangle, clamped onto the triangle.
                const auto& c = uvs.uvs[t];
                const double x0 = static_cast<double>(c[0].x) * cells,
                             y0 = static_cast<double>(c[0].y) * cells;
                const double x1 = static_cast<double>(c[1].x) * cells,
                             y1 = static_cast<double>(c[1].y) * cells;
                const double x2 = static_cast<double>(c[2].x) * cells,
                             y2 = static_cast<double>(c[2].y) * cells;
                const double area = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0);
                if (area == 0.0) continue;
                double b1 = ((i - x0) * (y2 - y0) - (j - y0) * (x2 - x0)) / area;
                double b2 = ((x1 - x0) * (j - y0) - (y1 - y0) * (i - x0)) / area;
                double b0 = 1.0 - b1 - b2;
                b0 = std::max(b0, 0.0);
                b1 = std::max(b1, 0.0);
                b2 = std::max(b2, 0.0);
                const double sum = b0 + b1 + b2;
                pointTriangle[k] = t;
                outlinePoint_.push_back(static_cast<int32_t>(k));
                outlineTriangle_.push_back(t);
                outlineB_.push_back(static_cast<float>(b1 / sum));
                outlineC_.push_back(static_cast<float>(b2 / sum));
            }
        }
    }

    std::vector<uint8_t> ring;
    deformkit::detail::assignLarge(ring, count, kUnassigned);
    int64_t covered = 0;
#pragma omp parallel for schedule(static) reduction(+ : covered)
    for (int32_t j = 0; j < side; ++j) {
        for (int32_t i = 0; i < side; ++i) {
            const size_t k = static_cast<size_t>(j) * side + i;
            if (pointTriangle[k] < 0) continue;
            ring[k] = 0;
            ++covered;
        }
    }
    numCovered_ = covered;
    // The dilation starts from the covered points next to an uncovered one (the others have no uncovered
    // 8-neighbour to reach), in ascending order: rows found in parallel, then laid end to end.
    std::vector<std::vector<int32_t>> frontierRows(static_cast<size_t>(side));
#pragma omp parallel for schedule(dynamic, 16)
    for (int32_t j = 0; j < side; ++j) {
        for (int32_t i = 0; i < side; ++i) {
            const size_t k = static_cast<size_t>(j) * side + i;
            if (ring[k] != 0) continue;
            bool edge = false;
            for (int32_t dj = -1; dj <= 1 && !edge; ++dj)
                for (int32_t di = -1; di <= 1 && !edge; ++di)
                    edge = i + di >= 0 && j + dj >= 0 && i + di < side && j + dj < side &&
                           ring[static_cast<size_t>(j + dj) * side + i + di] != 0;
            if (edge) frontierRows[j].push_back(static_cast<int32_t>(k));
        }
    }
    std::vector<int32_t> frontier;
    for (const std::vector<int32_t>& row : frontierRows)
        frontier.insert(frontier.end(), row.begin(), row.end());
    frontierRows = {};

    // Dilation rings (breadth-first over 8-neighbours from the covered points).
    auto inside = [&](int32_t i, int32_t j) { return i >= 0 && j >= 0 && i < side && j < side; };
    ringBegin_.push_back(0);
    entryBegin_.push_back(0);
    std::vector<int32_t> next;
    for (int32_t r = 1; r <= options.dilationRings && !frontier.empty(); ++r) {
        next.clear();
        for (int32_t p : frontier) {
            const int32_t pi = p % side, pj = p / side;
            for (int32_t dj = -1; dj <= 1; ++dj) {
                for (int32_t di = -1; di <= 1; ++di) {
                    if (!inside(pi + di, pj + dj)) continue;
                    const int32_t q = (pj + dj) * side + pi + di;
                    if (ring[q] != kUnassigned) continue;
                    ring[q] = static_cast<uint8_t>(r);
                    next.push_back(q);
                }
            }
        }
        std::sort(next.begin(), next.end());
        for (int32_t p : next) {
            const int32_t pi = p % side, pj = p / side;
            // Candidate directions, in order of preference: linear continuation along the axes, along
            // the diagonals, then plain copies.
            auto gather = [&](const std::array<std::array<int32_t, 2>, 4>& directions, bool extrapolate) {
                int32_t found = 0;
                std::array<int32_t, 4> inner{}, outer{};
                for (const auto& d : directions) {
                    const int32_t qi = pi + d[0], qj = pj + d[1];
                    if (!inside(qi, qj) || ring[qj * side + qi] >= r) continue;
                    const int32_t q = qj * side + qi;
                    if (extrapolate) {
                        const int32_t q2i = pi + 2 * d[0], q2j = pj + 2 * d[1];
                        if (!inside(q2i, q2j) || ring[q2j * side + q2i] >= r) continue;
                        outer[found] = q2j * side + q2i;
                    }
                    inner[found++] = q;
                }
                if (found == 0) return false;
                const float share = 1.0f / static_cast<float>(found);
                for (int32_t m = 0; m < found; ++m) {
                    source_.push_back(inner[m]);
                    weight_.push_back(extrapolate ? 2.0f * share : share);
                    if (extrapolate) {
                        source_.push_back(outer[m]);
                        weight_.push_back(-share);
                    }
                }
                return true;
            };
            if (!gather(kAxisDirections, true) && !gather(kDiagonalDirections, true) &&
                !gather(kAxisDirections, false)) {
                gather(kDiagonalDirections, false);
            }
            dilatedPoint_.push_back(p);
            entryBegin_.push_back(static_cast<int64_t>(source_.size()));
        }
        ringBegin_.push_back(static_cast<int64_t>(dilatedPoint_.size()));
        frontier.swap(next);
    }

    if (numCovered_ + numDilated() < static_cast<int64_t>(count)) {
        const std::vector<int32_t> nearest = nearestCovered(pointTriangle, side);
        const auto far = static_cast<size_t>(static_cast<int64_t>(count) - numCovered_ - numDilated());
        deformkit::detail::reserveLarge(farPoint_, far);
        deformkit::detail::reserveLarge(farSource_, far);
        for (size_t k = 0; k < count; ++k) {
            if (ring[k] != kUnassigned) continue;
            farPoint_.push_back(static_cast<int32_t>(k));
            farSource_.push_back(nearest[k]);
        }
    }

    // The rasteriser's triangles as runs per row (the outline points keep their own entries).
    for (const int32_t k : outlinePoint_)
        pointTriangle[static_cast<size_t>(k)] = -1;
    detail::encodeRowRuns(pointTriangle, side, side, rowRunBegin_, runStart_, runTriangle_);
}

size_t firstUnusablePoint(std::span<const glm::vec3> points) {
    for (size_t v = 0; v < points.size(); ++v) {
        const glm::vec3& p = points[v];
        if (!(std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate &&
              std::abs(p.z) <= kMaxCoordinate))
            return v;
    }
    return points.size();
}

void GeometryImager::sample(std::span<const glm::vec3> positions, PointField& out) const {
    if (positions.size() != static_cast<size_t>(numVertices_)) {
        throw InvalidInput(formatError(label_, "positions",
                                       "has " + std::to_string(positions.size()) + " vertices",
                                       std::to_string(numVertices_) + " (the rest mesh's vertex count)"));
    }
    if (const size_t v = firstUnusablePoint(positions); v < positions.size()) {
        const glm::vec3& p = positions[v];
        throw InvalidInput(formatError(
            label_, "vertex " + std::to_string(v),
            "position is (" + numberText(p.x) + ", " + numberText(p.y) + ", " + numberText(p.z) + ")",
            "finite coordinates within +-1e15"));
    }
    const int32_t side = cells_ + 1;
    out.cells = cells_;
    out.channels = 3;
    if (out.values.size() != static_cast<size_t>(side) * side * 3)
        deformkit::detail::assignLarge(out.values, static_cast<size_t>(side) * side * 3, 0.0f);
    float* values = out.values.data();
    const glm::vec3* p = positions.data();

    const auto blend = [&](size_t k, int32_t t, float b, float c) {
        const float a = 1.0f - b - c;
        const glm::vec3 value = a * p[cornerA_[t]] + b * p[cornerB_[t]] + c * p[cornerC_[t]];
        values[3 * k] = value.x;
        values[3 * k + 1] = value.y;
        values[3 * k + 2] = value.z;
    };
#pragma omp parallel for schedule(static)
    for (int32_t j = 0; j < side; ++j) {
        const size_t row = static_cast<size_t>(j) * side;
        for (int64_t r = rowRunBegin_[j]; r < rowRunBegin_[j + 1]; ++r) {
            const int32_t t = runTriangle_[r];
            if (t < 0) continue;
            const int32_t end = r + 1 < rowRunBegin_[j + 1] ? runStart_[r + 1] : side;
            const glm::vec2* corners = &rasterCorners_[static_cast<size_t>(t) * 3];
            const geom::BarycentricFrame frame(corners[0], corners[1], corners[2]);
            for (int32_t i = runStart_[r]; i < end; ++i) {
                const glm::vec3 b = frame.at(i, j);
                blend(row + i, t, b[1], b[2]);
            }
        }
    }
    const auto outline = static_cast<int64_t>(outlinePoint_.size());
#pragma omp parallel for schedule(static)
    for (int64_t o = 0; o < outline; ++o)
        blend(static_cast<size_t>(outlinePoint_[o]), outlineTriangle_[o], outlineB_[o], outlineC_[o]);
    for (size_t r = 1; r < ringBegin_.size(); ++r) {
#pragma omp parallel for schedule(static)
        for (int64_t d = ringBegin_[r - 1]; d < ringBegin_[r]; ++d) {
            float x = 0.0f, y = 0.0f, z = 0.0f;
            for (int64_t e = entryBegin_[d]; e < entryBegin_[d + 1]; ++e) {
                const float* s = values + 3 * static_cast<size_t>(source_[e]);
                x += weight_[e] * s[0];
                y += weight_[e] * s[1];
                z += weight_[e] * s[2];
            }
            float* o = values + 3 * static_cast<size_t>(dilatedPoint_[d]);
            o[0] = x;
            o[1] = y;
            o[2] = z;
        }
    }
    const auto numFar = static_cast<int64_t>(farPoint_.size());
#pragma omp parallel for schedule(static)
    for (int64_t f = 0; f < numFar; ++f) {
        const float* s = values + 3 * static_cast<size_t>(farSource_[f]);
        float* o = values + 3 * static_cast<size_t>(farPoint_[f]);
        o[0] = s[0];
        o[1] = s[1];
        o[2] = s[2];
    }
}

std::vector<uint8_t> GeometryImager::coverage() const {
    const int32_t side = cells_ + 1;
    std::vector<uint8_t> covered(static_cast<size_t>(side) * side, 0);
    for (int32_t j = 0; j < side; ++j) {
        for (int64_t r = rowRunBegin_[j]; r < rowRunBegin_[j + 1]; ++r) {
            const int32_t end = r + 1 < rowRunBegin_[j + 1] ? runStart_[r + 1] : side;
            if (runTriangle_[r] >= 0)
                std::fill(covered.begin() + static_cast<ptrdiff_t>(j) * side + runStart_[r],
                          covered.begin() + static_cast<ptrdiff_t>(j) * side + end, uint8_t{1});
        }
    }
    for (const int32_t k : outlinePoint_)
        covered[static_cast<size_t>(k)] = 1;
    return covered;
}

PointField GeometryImager::sample(std::span<const glm::vec3> positions) const {
    PointField out;
    sample(positions, out);
    return out;
}

glm::vec3 bilinearLookup(const PointField& field, float u, float v) {
    const size_t expected = static_cast<size_t>(field.cells + 1) * static_cast<size_t>(field.cells + 1) * 3;
    if (field.channels != 3 || field.cells < 1 || field.values.size() != expected) {
        throw InvalidInput(formatError("bilinear look-up", "point field",
                                       "has " + std::to_string(field.channels) + " channels, " +
                                           std::to_string(field.cells) + " cells and " +
                                           std::to_string(field.values.size()) + " values",
                                       "3 channels and (cells + 1)^2 * 3 values"));
    }
    return detail::bilinear3(field.values.data(), field.cells, u, v);
}

}  // namespace deformkit::uvwarp
