#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/grid.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/metrics.h"
#include "deformkit/uvwarp/redirect_metrics.h"
#include "deformkit/uvwarp/redirect_repair.h"
#include "deformkit/uvwarp/solver.h"

namespace deformkit::uvwarp {

// Every option's range, default and name in each interface (`resolution` for cells, `maskBorderWidth` for
// derivedMask.borderWidth): uvwarp/options.h, which checks them.
struct TileWarpOptions {
    // Grid cells per side (a power of two); 0 = the rigidity map's resolution T.
    int32_t cells = 0;
    SolverOptions solver;
    DerivedMaskOptions derivedMask;  // used when no mask map is given
    int32_t dilationRings = 4;       // geometry-image dilation past chart borders
    // > 0: without a painted orientation map, the paper's heuristic for severe compression
    // (densityOrientationMap of the rigidity map with this window radius, texels); 0: 1 everywhere;
    // kAutomaticDensity: by the map's size (orientationDensityFor), the presets'.
    int32_t orientationDensity = 0;
    // > 0: each solve ends with one more iteration of this many sweeps on a grid of twice the cells, started
    // from the solved warp (Solver::startFrom) with the finest level only; that grid's warp is the one
    // delivered. 0: none. kAutomaticRefinement: by the grid's size (refinementSweepsFor), the shot preset's.
    int32_t refinementSweeps = 0;
    // Cells per side of the geometry images f_O and f_D: the grid's, or half of them (a quarter of their
    // memory; f_O and f_D are affine inside each UV triangle, where the solver's bilinear look-ups between
    // the image's points are then exact). 0: geometryImageCellsFor.
    int32_t geometryImageCells = 0;
    // With a derived mask: content next to a seam (a chart border whose mesh edges have their other UV copy
    // in the tile) slides along it, the same way in both charts, so that rigid detail a seam cuts is undone
    // along the seam as well (docs/decisions.md UV-42). Off: chart borders are fixed. The shot preset's.
    bool seamSlide = false;
};

// The geometry images of grids up to this many cells have the grid's cells; finer grids' have half of them
// (a 16384^2 tile: 18 bytes a cell less, so that it solves in 40 bytes a cell; docs/decisions.md UV-22).
inline constexpr int32_t kFullGeometryImageCells = 8192;
// The geometry images' cells of a grid of `cells` cells for the option's value `imageCells`.
[[nodiscard]] constexpr int32_t geometryImageCellsFor(int32_t imageCells, int32_t cells) {
    if (imageCells != 0) return imageCells;
    return cells <= kFullGeometryImageCells ? cells : cells / 2;
}

// refinementSweeps chosen by the grid's size: kAutomaticRefinementSweeps on grids up to
// kAutomaticRefinementCells cells, none on finer grids (they sample the posed surface as finely already, and
// the refining grid would hold four times their memory).
inline constexpr int32_t kAutomaticRefinement = -1;
inline constexpr int32_t kAutomaticRefinementSweeps = 4;
inline constexpr int32_t kAutomaticRefinementCells = 1024;
// The refinement sweeps a grid of `cells` cells runs for the option's value `sweeps`.
[[nodiscard]] constexpr int32_t refinementSweepsFor(int32_t sweeps, int32_t cells) {
    if (sweeps != kAutomaticRefinement) return sweeps;
    return cells <= kAutomaticRefinementCells ? kAutomaticRefinementSweeps : 0;
}

// orientationDensity chosen by the map's size: a window radius of 1/kAutomaticDensityShare of the map's
// texels (64 at 1024^2), on grids up to kAutomaticDensityCells cells; none on finer grids, whose orientation
// field (4 bytes a cell and its levels) would take a 16384-cell tile past 40 bytes a cell (UV-22, UV-40).
inline constexpr int32_t kAutomaticDensity = -1;
inline constexpr int32_t kAutomaticDensityShare = 16;
inline constexpr int32_t kAutomaticDensityCells = 8192;
// The window radius, texels, a map of `texels` per side on a grid of `cells` gets for the option's value
// `radius` (0: none).
[[nodiscard]] constexpr int32_t orientationDensityFor(int32_t radius, int32_t texels, int32_t cells) {
    if (radius != kAutomaticDensity) return radius;
    if (cells > kAutomaticDensityCells) return 0;
    return texels / kAutomaticDensityShare > 1 ? texels / kAutomaticDensityShare : 1;
}

// The content-aware UV warp of one UDIM tile, from maps and meshes to redirect maps: binds the rest mesh's
// UV triangles of the tile (geometry images), the rigidity map R, the warp mask M (derived from the UVs
// when none is given) and an optional orientation-preservation map, then per frame rasterises the deformed
// positions, runs the solver (warm-started from the previous frame) and inverts the warp.
class TileWarp {
  public:
    // rest: mesh with UVs; tile: UDIM number; rigidity: T x T, channel 0 used, values in [0, 1]; mask: T x T
    // (channel 0, >= 0.5 may warp) or an empty Image to derive one; orientation: T x T in [0, 1] or empty.
    // `source` names the tile's inputs in errors ("rig.1001.exr"). Throws InvalidInput for: a mesh without
    // UVs or a face straddling tiles, a non-square map or one whose size is not a power of two (when
    // cells = 0), maps of different sizes, rigidity outside [0, 1], cells not a power of two. The warp keeps
    // the rigidity map (the delivered figures read it): a 1-channel map passed with std::move is kept
    // without a copy.
    TileWarp(const geom::Mesh& rest, int tile, io::Image rigidity, const io::Image& mask = {},
             const TileWarpOptions& options = {}, const io::Image& orientation = {},
             const std::string& source = "tile");
    ~TileWarp();
    TileWarp(TileWarp&&) noexcept;
    TileWarp& operator=(TileWarp&&) noexcept;

    // One frame: deformed positions of the rest mesh's vertices (same count). Returns the warp W.
    const WarpGrid& solve(std::span<const glm::vec3> deformedPoints);
    // W^-1 of the last solve as a T x T x 2 image of tile-local uv (the identity before any solve), made
    // fold-free with no texel showing content off the charts (repairFolds, redirect_repair.h). Returns what
    // the repair did.
    FoldRepair redirect(io::Image& out) const;
    [[nodiscard]] io::Image redirect() const;
    // What the redirect map of the last solve delivers (redirect_metrics.h): the rigid stretch a renderer
    // shows through it against the identity's, its inverted triangles and off-chart texels. measure() takes
    // the map already made by redirect(); deliveredMetrics() makes it.
    [[nodiscard]] DeliveredMetrics measure(const io::Image& redirect) const;
    // `repair`, when given, receives what the repair did to the map measured.
    [[nodiscard]] DeliveredMetrics deliveredMetrics(FoldRepair* repair = nullptr) const;
    // The solver's own figures on the delivered warp's grid (diagnostics: identity vs. ours on grid edges,
    // grid folds, masked and border motion).
    [[nodiscard]] WarpMetrics metrics() const;
    // Back to the identity warp (a cut in the shot).
    void reset();
    // New maps for the next frames (animated maps, a painter's edit): the same size as the bound rigidity
    // map; an empty mask keeps the mask derived from the UVs (or the bound one), an empty orientation means
    // the density heuristic's map where orientationDensity turns it on, else 1 everywhere. Rebuilds the
    // solver's hierarchy (Eq. 7-8) and keeps the warp, so the next solve warm- starts from it. Throws
    // InvalidInput as the constructor does for a map of the wrong size or values.
    void setMaps(const io::Image& rigidity, const io::Image& mask = {}, const io::Image& orientation = {});

    [[nodiscard]] int tile() const;
    [[nodiscard]] int32_t texels() const;
    [[nodiscard]] int32_t cells() const;  // the solver's grid (TileWarpOptions::cells)
    // The warp delivered: with refinementSweeps, the refining grid's (2 cells() cells), else the solver's.
    [[nodiscard]] const WarpGrid& warp() const;
    // The last solve's figures; with refinementSweeps, its iteration and repairs added, its folds left.
    [[nodiscard]] const SolveStats& stats() const;
    // The rigidity map at the solver's grid points (rigidityAtPoints), made on each call.
    [[nodiscard]] PointField rigidityAtGridPoints() const;
    // The warp mask at the solver's grid points (0 or 1), made on each call.
    [[nodiscard]] PointField maskAtGridPoints() const;

  private:
    struct Bind {};  // the constructor's work, before the memory it freed is given back
    TileWarp(Bind, const geom::Mesh& rest, int tile, io::Image rigidity, const io::Image& mask,
             const TileWarpOptions& options, const io::Image& orientation, const std::string& source);

    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace deformkit::uvwarp
