#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "deformkit/uvwarp/grid.h"
#include "deformkit/uvwarp/metrics.h"

namespace deformkit::uvwarp {

// Ranges, defaults and each option's name in the CLI, scenes, Python and Maya: uvwarp/options.h.
struct SolverOptions {
    // Hierarchy depth (paper §4.4): number of levels including the finest. 0 picks it from the warp mask:
    // down to an 8-cell grid, but no level whose points are farther apart than a third of the widest chart's
    // half-width (docs/decisions.md UV-18).
    int32_t levels = 0;
    // With levels = 0, at most this many levels (0: no cap). The live presets of large grids cap the depth:
    // a warm-started frame follows the motion better without the coarsest levels (UV-30).
    int32_t maxLevels = 0;
    // PBD iterations per solve (paper §4.1): the number run when `tolerance` is 0, the most run otherwise.
    // With warm start, frames after the first start from the last warp.
    int32_t iterations = 4;
    // Iterations of a solve that starts from the identity (a solver's first, the first after reset(), every
    // solve without warm start) when > 0; 0: `iterations`. The live presets use 2 or 3, so that a preview's
    // first frame, and the first after a cut, is within 2 points of converged as well (docs/decisions.md
    // UV-30).
    int32_t coldIterations = 0;
    // Convergence stop, in grid cells: > 0 ends a solve after the first iteration in which no point moved
    // farther than this (SolveStats::converged); 0 runs `iterations` iterations whatever they change. A
    // warm-started frame of a smooth animation then pays for the iterations its change needs.
    float tolerance = 0.0f;
    // Constraint-projection sweeps (all 8 parallel sets) per iteration at each level, finest first; levels
    // beyond the list use its last value. Coarse levels are cheap and carry the large-scale motion. Empty
    // (the default): by the grid's size, defaultSweeps(cells); a refined TileWarp's solved grid:
    // defaultSweeps(cells, true).
    std::vector<int32_t> sweepsPerLevel;
    // Orientation preservation in [0, 1] (§4.2): after projection a segment is turned this fraction of the
    // way back towards its canonical direction (0°, 45°, 90°, 135°). Multiplied by the optional map.
    float orientationPreservation = 0.02f;
    // s in Eq. 4: how much as-rigid-as-possible points are smoothed (non-rigid points are smoothed fully).
    float smoothing = 0.1f;
    // Velocity damping in [0, 1]: the fraction of the velocity removed each iteration (§4.1 step 1).
    float damping = 0.5f;
    // Stiffness multiplier per level above the finest: level l applies corrections scaled by
    // coarseStiffness^l (§4.4: coarse segments map to curves, not lines, so coarse corrections are applied
    // more conservatively).
    float coarseStiffness = 0.9f;
    // Over-relaxation of the levels above the finest, in [1, 2]: their corrections are further multiplied by
    // it (successive over-relaxation of their Gauss-Seidel sweeps; the finest level is never scaled). 1, the
    // default, is the paper's. The live presets use 1.4: a warm-started frame of one iteration then follows
    // the motion with fewer coarse sweeps (docs/decisions.md UV-30).
    float coarseRelaxation = 1.0f;
    // OpenMP threads of an iteration: 0 chooses per iteration between all the caller allows
    // (omp_get_max_threads()) and one, from measured times, so that next to other work (a host's threads,
    // another process on a core) all threads are never slower than one; n > 0 uses min(n, allowed). The
    // warp is the same, byte for byte, whatever the choice.
    int32_t threads = 0;
    // Warm start (paper §4.1, temporal coherence): each solve starts from the last warp, unless that start
    // jams (SolveStats::coldRestart: the frame is then solved again from the identity). false: each solve
    // starts from the identity, so a frame's warp depends on that frame's inputs alone, not on the frames
    // solved before it (a farm chunk's maps are then an uninterrupted run's, byte for byte, with no warm-up
    // frames; docs/decisions.md UV-20). The default schedule reaches the same quality either way.
    bool warmStart = true;

    // Every option equal: a solver built with one set behaves as one built with the other.
    bool operator==(const SolverOptions&) const = default;
};

// The default schedule (SolverOptions::sweepsPerLevel empty) of a grid of `cells` cells per side: {4, 8, 16}
// up to 1024 cells; from 2048, where rigid detail spans more cells and the hierarchy is deeper, the sweeps
// double with each coarser level up to 64, {4, 8, 16, 32, 64}, so that the rigid stretch removed on a fully
// covered tile stays within 2 points from 2048^2 to 8192^2 (docs/decisions.md UV-19). `refined`: a grid of
// at least kHalvedFinestCells cells whose solve a refinement follows (TileWarpOptions::refinementSweeps)
// sweeps its finest level half as often, 2 instead of 4: the refining grid's sweeps take the finest detail
// over from there (UV-41). Coarser grids keep 4: their finest level carries more of the detail. A refined
// grid of 1024 cells sweeps its third level (points 4 cells apart) kRefinedThirdLevelSweeps times: what
// rigid detail 5-25 texels inside a chart border keeps is the mid-scale's convergence (UV-43).
inline constexpr int32_t kHalvedFinestCells = 1024;
inline constexpr int32_t kRefinedThirdLevelSweeps = 64;
[[nodiscard]] std::vector<int32_t> defaultSweeps(int32_t cells, bool refined = false);

// The live-preview preset for a grid of `cells` cells per side: one warm-started iteration a frame, the
// coarse levels over-relaxed by 1.4, sweeps per level by the grid's size ({8, 16, 32} up to 128 cells,
// {3, 8, 12} at 256, {2, 2, 10} at 512, {1, 1, 10} at 1024, {1, 1, 2, 8} from 2048) and, from 1024 cells, no
// level coarser than 128 cells (maxLevels): the cheapest settings measured within 2 points of a converged
// default solve on every probed frame of a smooth animation, on two real models, on the solver's grid; a
// solve from the identity (the first frame, or after a cut) runs 2 iterations (3 at 512 cells) to be within
// 2 points as well (docs/decisions.md UV-28, UV-30). On the delivered maps, against the shot preset, the
// gap is larger (docs/uvwarp.md, Performance and limits). The other options are the defaults.
[[nodiscard]] SolverOptions liveOptions(int32_t cells);

// Figures from the last solve.
struct SolveStats {
    int32_t iterations = 0;  // iterations run by the last solve (those before a cold restart included)
    // Largest distance a point moved in the last iteration, in grid cells, and whether it was within
    // SolverOptions::tolerance (false when the tolerance is 0).
    float lastMove = 0.0f;
    bool converged = false;
    int32_t levels = 0;
    int32_t untangledPoints = 0;  // points moved by the fold repair (should be 0 in normal use)
    // Points put back to where their iteration found them because a triangle around them stayed folded
    // (every iteration ends fold-free).
    int32_t revertedPoints = 0;
    // Iterations whose step was shortened towards the fold-free part of it instead (putting points back
    // would have undone more of the iteration's motion: large smooth steps of a large grid): around the
    // triangles that fold on the way, and of those, shortenedEverywhere: the whole step (the local
    // shortening left folds whose repair spread again).
    int32_t shortenedSteps = 0;
    int32_t shortenedEverywhere = 0;
    // Whether a warm-started solve jammed and was solved again from the identity: its last iteration's fold
    // repair spread (more than 1/256 of the moved points put back, or the step shortened), which a warm start
    // that folds under the frame's motion does frame after frame (docs/decisions.md UV-34).
    bool coldRestart = false;
    int32_t remainingFolds = 0;  // grid triangles left with non-positive area (both cell splittings)
    int32_t threads = 0;         // OpenMP threads of the last iteration
};

// The content-aware warp solver of Koniaris et al. on one UV tile's grid: hierarchical position-based
// dynamics over the 8-connected grid's edge constraints (Eq. 1-3), with regularisation (Eq. 4-5).
// State (positions, velocities) persists between solves: each solve warm-starts from the last warp, so a
// static pose converges to a static warp and an animation changes smoothly.
//
// Inputs are fields on the (n + 1)^2 grid points (grid.h): rigidity R in [0, 1], mask M (0 or 1;
// tile-border points never move whatever the mask says), and optionally an orientation-preservation map in
// [0, 1] (empty: 1 everywhere); restGeometry f_O (3 channels) on the grid's points, or a geometry image of
// n / 2 cells (f_O at a grid point between the image's points is the mean of the 2 or 4 around it, their
// bilinear look-up: exact where f_O is affine, as inside a UV triangle; TileWarpOptions::geometryImageCells).
// The solver keeps f_O (rest lengths are measured through it) and R (its finest level's map): pass them
// with std::move to keep one copy.
//
// Memory per fine grid point: 8 bytes for positions, 12 for f_O (3 on an image of half the cells), 4 for
// rigidity and movability, 1.3 for the coarser levels' (+ 4 and 1.3 with an orientation map); during a
// solve 8 more for velocities and 4.7 for the coarser levels' working copies. With SolverOptions::warmStart
// (the velocities carry over) those stay between solves and a solve allocates nothing once the fold-repair
// scratch has grown to the largest fold count seen; without it they are allocated at the start of each solve
// and freed at its end, unless keepSolveState() says to keep their memory.
class Solver {
  public:
    // The rigidity and orientation fields become the finest level's own (passed as rvalues, no copy).
    Solver(PointField restGeometry, PointField rigidity, const PointField& mask,
           const SolverOptions& options = {}, PointField orientation = {},
           const std::string& source = "tile");
    ~Solver();
    Solver(Solver&&) noexcept;
    Solver& operator=(Solver&&) noexcept;

    // New rigidity / mask / orientation maps (a painter's edit): rebuilds the per-level hierarchies (Eq.
    // 7-8). The warp is kept; a point the new mask fixes stays where it is (its velocity is dropped).
    void setMaps(PointField rigidity, const PointField& mask, PointField orientation = {});
    // One frame: deformedGeometry f_D (3 channels, a geometry image of restGeometry's cells). Returns the
    // warp W.
    const WarpGrid& solve(const PointField& deformedGeometry);
    // Back to the identity warp with zero velocity (a cut in the shot).
    void reset();
    // The next solve starts from `coarser`'s warp, a fold-free grid of half the cells: each point where that
    // piecewise-linear map takes it, so the grid is the same map (every triangle lies inside one of
    // `coarser`'s, so none folds), with zero velocity. That solve runs `iterations` warm iterations, with or
    // without warmStart (which then only says whether the solve's state is kept after it), and never
    // restarts from the identity (a fold repair that spreads keeps the grid fold-free). Points the mask
    // fixes keep the map `coarser` gives them. Throws InvalidInput when `coarser` has not half the cells or
    // is not finite.
    void startFrom(const WarpGrid& coarser);
    // Points placed off their rest positions (TileWarpOptions::seamSlide: content slid along seams): point
    // index[k] (j * (n + 1) + i, ascending) at (u[k], v[k]). A listed point the mask fixes sits there from
    // now on, and after every reset() and startFrom(); a listed point that may move starts there when a solve
    // starts from the identity (the next one, if it does, and every one after a reset()). Points on the tile
    // border are left out. The points listed before go back to rest where they are fixed, and all of them
    // when the next solve starts from the identity (an empty list: none placed). Throws InvalidInput for
    // lists of different lengths, an index out of the grid or not ascending, or a position not finite.
    void placePoints(std::span<const int64_t> index, std::span<const float> u, std::span<const float> v);
    // Without warmStart: whether the solve's state (velocities, the coarser levels' working copies) keeps its
    // memory between solves instead of being allocated and freed by each solve. The same bytes either way:
    // each solve starts from zero velocities (reset or startFrom), and the copies are written before use.
    // Keeping it holds that memory between frames and spares each frame the first touches of fresh pages:
    // glibc hands buffers above its mmap threshold (32 MiB at most) back to the system when they are freed.
    // Off by default; TileWarp keeps its refining solver's on the shot preset's grids (UV-22).
    void keepSolveState(bool keep);

    [[nodiscard]] const WarpGrid& warp() const;
    [[nodiscard]] const PointField& restGeometry() const;
    [[nodiscard]] const SolveStats& stats() const;
    [[nodiscard]] int32_t cells() const;
    [[nodiscard]] int32_t levels() const;
    // The hierarchy as built from the maps (§4.4), for tests and tools: level `level` (0 the finest, each
    // next one every other point of the one before), its rigidity (Eq. 7: the finer level's blurred by K_G,
    // then subsampled) and whether each point may move (Eq. 8: every point of the finer level's 3x3 around it
    // may, and it is not on the tile border). 1-channel fields of the level's cells. Throws InvalidInput for
    // a level out of range.
    [[nodiscard]] PointField levelRigidity(int32_t level) const;
    [[nodiscard]] PointField levelMovable(int32_t level) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The figures of the last solve as hosts report them after the warp's (metrics.h): iterations, levels,
// untangled_points, reverted_points, shortened_steps, shortened_everywhere, cold_restart, remaining_folds,
// last_move, converged.
[[nodiscard]] std::vector<ReportedFigure> reportedFigures(const SolveStats& s);

// Number of grid triangles with signed area <= 0, counting both diagonal splittings of every cell.
[[nodiscard]] int32_t countFolds(const WarpGrid& warp);

}  // namespace deformkit::uvwarp
