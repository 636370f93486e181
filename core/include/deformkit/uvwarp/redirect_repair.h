#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec2.hpp>

#include "deformkit/io/image.h"
#include "deformkit/uvwarp/metrics.h"

namespace deformkit::uvwarp {

// Whether texel (x, y) of a redirect map may show the rest content at tile-local r (RedirectMetrics::mayShow:
// a chart texel only content on a chart).
using ContentCheck = std::function<bool(int32_t x, int32_t y, glm::dvec2 r)>;
// The same question for a whole row of a map, answered at once (RedirectMetrics::refusedInRow): appends
// to `refused` the columns x of row y whose content mayShow would refuse, ascending.
using ContentRowCheck =
    std::function<void(const io::Image& redirect, int32_t y, std::vector<int32_t>& refused)>;
// Whether texel (x, y) of a redirect map is held where the warp mask keeps it (TileWarp: every point of the
// delivered grid around its centre fixed by the mask). A held texel the inversion left at its own centre
// (within 1e-3 texel: its rounding where a texel spans no power-of-two number of cells) is never smoothed.
using TexelCheck = std::function<bool(int32_t x, int32_t y)>;

// What repairFolds did to a map.
struct FoldRepair {
    int64_t invertedFound = 0;         // inverted triangles of the map it was given
    int64_t offChartFound = 0;         // texels of it showing content mayShow refuses
    int64_t texelsMoved = 0;           // smoothing moves made
    int32_t passes = 0;                // smoothing passes run
    int32_t regionsScaledLocally = 0;  // clusters of folds unfolded by scaling back around them (step 2)
    int32_t regionsScaled = 0;         // regions whose displacement was scaled back (the guarantee, step 3)
    double smallestScale = 1.0;        // the smallest scale applied (1 when none)
};

// Makes a redirect map (T x T x >= 2, channels 0 and 1 tile-local r, invertWarp's layout) fold-free: on
// return no triangle of its texel-centre grid is inverted (DeliveredMetrics::invertedTriangles = 0), and no
// texel shows content `mayShow` refuses, whatever the map it was given.
//
// The PL inverse of a fold-free warp is fold-free, but sampled at texel centres it can fold where the warp is
// strongly anisotropic (a cell stretched ten times one way, or crushed to a sliver): the interpolant's
// triangles straddle the kinks of W^-1. And a grid coarser than the map cannot follow a chart border texel by
// texel: texels next to a border can show content from off the chart. Three steps:
//  0. Content: every displaced texel whose content `mayShow` refuses moves towards its own centre (which a
//     texel may always show), to the farthest allowed point a bisection of the segment finds.
//  1. Smoothing: the corners of inverted cells move to the mean of their 8 neighbours (exact for an affine
//     map, so where R is locally affine it barely moves), in ascending order, pass after pass over the cells
//     still inverted; after every 16 passes the moved set grows by a ring. A mean `mayShow` refuses (past a
//     chart border) gives way to the point halfway to the texel's own centre, then to the centre, then no
//     move. A texel `held` names that sits at its own centre (within 1e-3 texel) never moves. This ends
//     almost every fold within a few texels of it.
//  2. Local scale-back: if folds remain after 256 passes, each cluster of them (folds fewer than 2 cells
//     apart) has the displacement around it scaled back: in a window 4, 8, ... 256 texels past the
//     cluster's box, by 1/2, 1/4, 1/8 or 0 within half the window's reach of the box, rising linearly to 1
//     at its edge; the first window and scale that leave none of its cells inverted and no texel showing
//     refused content is kept. The warp away from the fold is kept whole.
//  3. The guarantee: if folds still remain, each 8-connected region of texels displaced from their own
//     centre that holds one has its displacement scaled by 1/2, 1/4, ... down to 0 until neither a fold
//     nor refused content is left in the cells it touches. At 0 the region is the identity, fold-free and on
//     chart, so this always ends.
// Smoothing never moves texels on the tile's border. Serial over the texels concerned after parallel scans:
// bit-identical for any thread count. Throws InvalidInput for a map that is not square with >= 2 channels.
// `refusedInRow`, when given, must agree with mayShow; it makes step 0's scan of every texel cheaper. Steps
// 0, 2 and 3 move displaced texels only, towards their centres, so a held texel keeps its centre through
// every step: masked content stays where it is painted.
FoldRepair repairFolds(io::Image& redirect, const ContentCheck& mayShow,
                       const ContentRowCheck& refusedInRow = {}, const TexelCheck& held = {});

// The figures of `r` as hosts report them (metrics.h): repair_inverted_found, repair_off_chart_found,
// repair_texels_moved, repair_passes, repair_regions_scaled, repair_folds_scaled_locally,
// repair_smallest_scale.
[[nodiscard]] std::vector<ReportedFigure> reportedFigures(const FoldRepair& r);

}  // namespace deformkit::uvwarp
