#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "deformkit/uvwarp/grid.h"

namespace deformkit::uvwarp {

// Quality figures of a warp, measured on the solver's grid: diagnostics of the solve. What a renderer is
// handed is measured on the redirect map (redirect_metrics.h).
struct MetricsOptions {
    // Unit of the displacements: texels of a T x T map; 0 measures in grid cells (texels when n = T).
    int32_t texels = 0;
    // An edge is rigid when the larger rigidity of its two points (Eq. 1) is >= this.
    float rigidThreshold = 0.5f;
};

struct WarpMetrics {
    // Rigid stretch error: mean |l_def / l_org - 1| over the rigid edges of the 8-connected grid (Eq. 1),
    // l_org = |f_O(p_j) - f_O(p_i)| at the rest points, l_def = |f_D(W(p_j)) - f_D(W(p_i))| with f_D looked
    // up bilinearly (bilinearLookup) at the warped points. `identityStretchError` is the same with the
    // identity warp (no correction), so "identity vs ours" shows what the warp removed.
    double rigidStretchError = 0.0;
    double identityStretchError = 0.0;
    int64_t rigidEdges = 0;  // edges averaged over
    // Rigid edges left out because l_org <= 1e-6 x the diagonal of f_O's bounding box (a degenerate
    // triangle, or geometry-image values copied flat beyond the dilation rings): the ratio is undefined.
    int64_t skippedEdges = 0;
    // Grid triangles with signed area <= 0, counting both diagonal splittings of every cell (4 per cell).
    int64_t foldOvers = 0;
    // Largest |W(p) - p| of points with mask < 0.5, and of points on the tile border, in MetricsOptions
    // units.
    double maxMaskedDisplacement = 0.0;
    double maxBorderDisplacement = 0.0;
    int64_t pointsOutside = 0;  // warped points outside the closed unit square
};

// Measures `warp` given the geometry images `rest` (f_O) and `deformed` (f_D), 3 channels, on the warp's
// grid or of half its cells (looked up bilinearly between their points), and the `rigidity` and
// `mask` point fields, 1 channel, on the warp's grid. OpenMP over rows, sums per row
// in a fixed order: bit-identical for any thread count. Throws InvalidInput for an invalid warp
// (validateWarpGrid) or a field of another grid or channel count, naming the field.
[[nodiscard]] WarpMetrics measureWarp(const WarpGrid& warp, const PointField& rest,
                                      const PointField& deformed, const PointField& rigidity,
                                      const PointField& mask, const MetricsOptions& options = {});

// One figure of a solve as every host reports it, by one name: the shot job's JSON log and report, Python's
// metrics(). The redirect map's figures (redirect_metrics.h) come first; the grid's are named grid_*.
struct ReportedFigure {
    enum class Kind { Number, Count, Flag };
    std::string_view name;  // snake_case
    Kind kind = Kind::Number;
    double value = 0.0;
};

// The grid figures of `m` (grid_rigid_stretch_error, ... grid_fold_overs, ...), in the order hosts report
// them.
[[nodiscard]] std::vector<ReportedFigure> reportedFigures(const WarpMetrics& m);

}  // namespace deformkit::uvwarp
