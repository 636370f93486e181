#include "deformkit/uvwarp/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/uvwarp/inversion.h"
#include "lookup.h"
#include "uvwarp/field_checks.h"

namespace deformkit::uvwarp {
namespace {

inline float distance2(const float* a, const float* b) {
    const float dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    return dx * dx + dy * dy + dz * dz;
}

double orientation(double ax, double ay, double bx, double by, double cx, double cy) {
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

struct RowSums {
    double ours = 0.0, identity = 0.0;
    int64_t edges = 0, skipped = 0, folds = 0, outside = 0;
    double maskedDisplacement = 0.0, borderDisplacement = 0.0;
};

}  // namespace

WarpMetrics measureWarp(const WarpGrid& warp, const PointField& rest, const PointField& deformed,
                        const PointField& rigidity, const PointField& mask, const MetricsOptions& options) {
    validateWarpGrid(warp, "warp metrics: warp grid");
    const int32_t n = warp.cells, side = n + 1;
    // The geometry images: of the grid's cells, or of half of them (Solver: looked up between their points).
    const int32_t imageCells = rest.cells == n / 2 && n >= 2 ? n / 2 : n;
    detail::requireField(rest, imageCells, 3, "warp metrics", "rest geometry image");
    detail::requireField(deformed, imageCells, 3, "warp metrics", "deformed geometry image");
    detail::requireField(rigidity, n, 1, "warp metrics", "rigidity");
    detail::requireField(mask, n, 1, "warp metrics", "mask");
    if (options.texels < 0) {
        throw InvalidInput(formatError("warp metrics", "texels", "is " + std::to_string(options.texels),
                                       "0 (grid cells) or a positive map size"));
    }
    const double unit = options.texels > 0 ? options.texels : n;
    const double inverseCells = 1.0 / n;  // exact: n is a power of two

    // The size of f_O, for the degenerate-edge threshold (the image's points: between them f_O is their
    // blend).
    const int32_t imageSide = imageCells + 1;
    std::vector<float> rowLo(static_cast<size_t>(imageSide) * 3), rowHi(static_cast<size_t>(imageSide) * 3);
#pragma omp parallel for schedule(static)
    for (int32_t j = 0; j < imageSide; ++j) {
        float lo[3], hi[3];
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::numeric_limits<float>::infinity();
            hi[c] = -std::numeric_limits<float>::infinity();
        }
        for (int32_t i = 0; i < imageSide; ++i) {
            const size_t k = static_cast<size_t>(j) * imageSide + i;
            for (int c = 0; c < 3; ++c) {
                lo[c] = std::min(lo[c], rest.values[3 * k + c]);
                hi[c] = std::max(hi[c], rest.values[3 * k + c]);
            }
        }
        for (int c = 0; c < 3; ++c) {
            rowLo[3 * j + c] = lo[c];
            rowHi[3 * j + c] = hi[c];
        }
    }
    double extent2 = 0.0;
    for (int c = 0; c < 3; ++c) {
        float lo = rowLo[c], hi = rowHi[c];
        for (int32_t j = 1; j < imageSide; ++j) {
            lo = std::min(lo, rowLo[3 * j + c]);
            hi = std::max(hi, rowHi[3 * j + c]);
        }
        extent2 += (static_cast<double>(hi) - lo) * (static_cast<double>(hi) - lo);
    }
    const auto degenerate2 = static_cast<float>(1e-12 * extent2);  // (1e-6 x the diagonal)^2

    std::vector<RowSums> rows(side);
    const float* fo = rest.values.data();
    const float* fd = deformed.values.data();
    const float* r = rigidity.values.data();
    const bool between = imageCells < n;
#pragma omp parallel
    {
        // f_D(W(p)) of point rows j and j + 1; the upper row is kept for the next j of this thread.
        std::vector<float> lowerRow(static_cast<size_t>(side) * 3), upperRow(static_cast<size_t>(side) * 3);
        auto lookUpRow = [&](int32_t j, std::vector<float>& out) {
            for (int32_t i = 0; i < side; ++i) {
                const size_t k = static_cast<size_t>(j) * side + i;
                const glm::vec3 p = detail::bilinear3(fd, imageCells, warp.u[k], warp.v[k]);
                out[3 * i] = p.x;
                out[3 * i + 1] = p.y;
                out[3 * i + 2] = p.z;
            }
        };
        // f_O and f_D at the grid points of rows j and j + 1: the images' own rows, or their look-ups
        // between the points of an image of half the cells.
        std::vector<float> gridRows[2][2];  // [f_O, f_D][lower, upper]
        const auto gridRow = [&](const float* image, int32_t jj, std::vector<float>& out) -> const float* {
            if (!between) return image + 3 * static_cast<size_t>(jj) * side;
            out.resize(static_cast<size_t>(side) * 3);
            for (int32_t i = 0; i < side; ++i) {
                const glm::vec3 p = detail::bilinear3(image, imageCells, static_cast<float>(i * inverseCells),
                                                      static_cast<float>(jj * inverseCells));
                out[3 * i] = p.x;
                out[3 * i + 1] = p.y;
                out[3 * i + 2] = p.z;
            }
            return out.data();
        };
        int32_t cached = -1, cachedGrid = -1;
#pragma omp for schedule(static)
        for (int32_t j = 0; j < side; ++j) {
            if (cached == j) {
                lowerRow.swap(upperRow);
            } else {
                lookUpRow(j, lowerRow);
            }
            if (j < n) {
                lookUpRow(j + 1, upperRow);
                cached = j + 1;
            }
            const float* wLower = lowerRow.data();
            const float* wUpper = upperRow.data();
            // Between an image's points, row j's look-ups are the last j's upper row when this thread made
            // it.
            const int32_t jUp = std::min(j + 1, n);
            const bool reuse = between && cachedGrid == j;
            if (reuse) {
                gridRows[0][0].swap(gridRows[0][1]);
                gridRows[1][0].swap(gridRows[1][1]);
            }
            const float* foRow[2] = {reuse ? gridRows[0][0].data() : gridRow(fo, j, gridRows[0][0]),
                                     gridRow(fo, jUp, gridRows[0][1])};
            const float* fdRow[2] = {reuse ? gridRows[1][0].data() : gridRow(fd, j, gridRows[1][0]),
                                     gridRow(fd, jUp, gridRows[1][1])};
            cachedGrid = jUp;
            RowSums sums;
            // Ratios in float (relative error ~1e-7), sums in double. Ends a and b: grid points (ia, row a)
            // and (ib, row b) of rows j (0) and j + 1 (1).
            auto edge = [&](int32_t ia, int32_t rowA, int32_t ib, int32_t rowB, const float* wa,
                            const float* wb) {
                const size_t a = static_cast<size_t>(j + rowA) * side + ia,
                             b = static_cast<size_t>(j + rowB) * side + ib;
                if (std::max(r[a], r[b]) < options.rigidThreshold) return;
                const float original2 = distance2(foRow[rowA] + 3 * ia, foRow[rowB] + 3 * ib);
                if (!(original2 > degenerate2)) {
                    ++sums.skipped;
                    return;
                }
                const float inverse = 1.0f / std::sqrt(original2);
                sums.ours += std::abs(std::sqrt(distance2(wa, wb)) * inverse - 1.0f);
                sums.identity += std::abs(
                    std::sqrt(distance2(fdRow[rowA] + 3 * ia, fdRow[rowB] + 3 * ib)) * inverse - 1.0f);
                ++sums.edges;
            };
            for (int32_t i = 0; i < side; ++i) {
                const size_t k = static_cast<size_t>(j) * side + i;
                const float* w = wLower + 3 * i;
                const float* wUp = wUpper + 3 * i;
                if (i < n) edge(i, 0, i + 1, 0, w, w + 3);             // horizontal
                if (j < n) edge(i, 0, i, 1, w, wUp);                   // vertical
                if (i < n && j < n) edge(i, 0, i + 1, 1, w, wUp + 3);  // diagonal (i, j)-(i+1, j+1)
                if (i < n && j < n) edge(i + 1, 0, i, 1, w + 3, wUp);  // diagonal (i+1, j)-(i, j+1)

                const bool masked = mask.values[k] < 0.5f, border = i == 0 || j == 0 || i == n || j == n;
                if (masked || border) {
                    const double du = static_cast<double>(warp.u[k]) - i * inverseCells;
                    const double dv = static_cast<double>(warp.v[k]) - j * inverseCells;
                    const double moved = std::sqrt(du * du + dv * dv) * unit;
                    if (masked) sums.maskedDisplacement = std::max(sums.maskedDisplacement, moved);
                    if (border) sums.borderDisplacement = std::max(sums.borderDisplacement, moved);
                }
                if (warp.u[k] < 0.0f || warp.u[k] > 1.0f || warp.v[k] < 0.0f || warp.v[k] > 1.0f)
                    ++sums.outside;

                if (i < n && j < n) {
                    const size_t k10 = k + 1, k01 = k + side, k11 = k01 + 1;
                    const double x00 = warp.u[k], y00 = warp.v[k], x10 = warp.u[k10], y10 = warp.v[k10];
                    const double x01 = warp.u[k01], y01 = warp.v[k01], x11 = warp.u[k11], y11 = warp.v[k11];
                    // Split along (i, j)-(i+1, j+1), then along (i+1, j)-(i, j+1).
                    sums.folds += orientation(x00, y00, x10, y10, x11, y11) <= 0.0;
                    sums.folds += orientation(x00, y00, x11, y11, x01, y01) <= 0.0;
                    sums.folds += orientation(x00, y00, x10, y10, x01, y01) <= 0.0;
                    sums.folds += orientation(x10, y10, x11, y11, x01, y01) <= 0.0;
                }
            }
            rows[j] = sums;
        }
    }

    WarpMetrics out;
    double ours = 0.0, identity = 0.0;
    for (const RowSums& sums : rows) {
        ours += sums.ours;
        identity += sums.identity;
        out.rigidEdges += sums.edges;
        out.skippedEdges += sums.skipped;
        out.foldOvers += sums.folds;
        out.pointsOutside += sums.outside;
        out.maxMaskedDisplacement = std::max(out.maxMaskedDisplacement, sums.maskedDisplacement);
        out.maxBorderDisplacement = std::max(out.maxBorderDisplacement, sums.borderDisplacement);
    }
    if (out.rigidEdges > 0) {
        out.rigidStretchError = ours / static_cast<double>(out.rigidEdges);
        out.identityStretchError = identity / static_cast<double>(out.rigidEdges);
    }
    return out;
}

std::vector<ReportedFigure> reportedFigures(const WarpMetrics& m) {
    using Kind = ReportedFigure::Kind;
    return {{"grid_rigid_stretch_error", Kind::Number, m.rigidStretchError},
            {"grid_identity_stretch_error", Kind::Number, m.identityStretchError},
            {"grid_rigid_edges", Kind::Count, static_cast<double>(m.rigidEdges)},
            {"grid_skipped_edges", Kind::Count, static_cast<double>(m.skippedEdges)},
            {"grid_fold_overs", Kind::Count, static_cast<double>(m.foldOvers)},
            {"grid_max_masked_displacement", Kind::Number, m.maxMaskedDisplacement},
            {"grid_max_border_displacement", Kind::Number, m.maxBorderDisplacement},
            {"grid_points_outside", Kind::Count, static_cast<double>(m.pointsOutside)}};
}

}  // namespace deformkit::uvwarp
