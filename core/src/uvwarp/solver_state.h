#pragma once

// Private to the UV-warp solver: its state, shared by the API and hierarchy (solver.cpp) and the fold
// repair (solver_folds.cpp). The kernels see it through solver_kernels.h's plain views.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "solver_kernels.h"

#include "deformkit/uvwarp/grid.h"
#include "deformkit/uvwarp/solver.h"

namespace deformkit::uvwarp::detail {

// Loops over fewer rows than this run on one thread: coarse levels are tiny, and a fork and barrier per
// tiny loop costs more than the loop (badly so when the machine is oversubscribed).
constexpr int64_t kParallelRows = 64;

// Rows per chunk of the parallel loops over a level's rows that do not depend on each other.
constexpr int32_t kBlockRows = 16;

// Rows per block of the row-wavefront schedule (sweep, regularise) of a level of `rows` rows: a 64th of
// them, from 2 to 16. A block's rows are processed in order; blocks of one parity never touch a point another
// block of that parity reads or moves (a row reads at most one row beyond its block on each side, so blocks
// of 2 rows suffice), so they run in parallel. Blocks depend on the grid size alone, so the result does not
// depend on the thread count, nor on which thread runs a block: blocks (and the rows of the other parallel
// loops) are handed out dynamically, so a thread the machine delays or a row block with more rigid detail
// does not hold the other threads at the next barrier. About 64 blocks per level keep both threads busy on
// the coarse levels (16-row blocks left level 3 of a 1024^2 grid 4 blocks per parity); the shorter blocks'
// order also converges a little faster there (UV-26).
[[nodiscard]] constexpr int32_t wavefrontBlockRows(int32_t rows) {
    return std::clamp(rows / 64, 2, kBlockRows);
}

// Wavefronts over more rows than this run in parallel: with 2-row blocks a 64-row level gives each of two
// threads 8 blocks per parity, while a 32-row level is swept faster on one thread than the two threads' forks
// and barriers cost (timed on a 1024^2 grid's level 5).
constexpr int64_t kParallelWavefrontRows = 32;

// A warm-started solver's levels this many fine points apart or more read f_O from compact copies
// (Level::rest): about 1 byte a fine cell, their sweeps 10-14% faster at 1024^2.
constexpr int32_t kCompactRestStride = 4;

// Level::rigidity of a point that may not move is kFixed - R (kFixed: solver_kernels.h).
[[nodiscard]] inline float fixedRigidity(float r) {
    return kFixed - r;
}

struct Level {
    int32_t cells = 0;   // cells per side at this level
    int32_t stride = 1;  // fine-grid points between neighbouring points of this level
    // R (Eq. 7 on coarser levels) where the point may move; kFixed - R where it may not (masked, Eq. 8, or on
    // the tile border). One float map rather than a float and a byte map: the SIMD kernels then hold only
    // 32-bit values, so their vector loops run 8 lanes per AVX2 iteration, not 32 (a byte map made GCC
    // choose 32 lanes, which left every run shorter than 32 segments to the scalar remainder loop).
    std::vector<float> rigidity;
    std::vector<float> orientation;  // empty without an orientation map (1 everywhere)
    // f_O at this level's points, 3 floats each, in a warm-started solver (SolverOptions::warmStart), on
    // levels kCompactRestStride or more fine points apart; empty otherwise
    // (the level reads the fine image, every point of it a cache line of its own).
    std::vector<float> rest;
    std::vector<float> snapshotU, snapshotV;  // positions before this level's sweeps (for propagation)
    // Per row of cells j and parallel set s (kSets, solver_kernels.h), runs [setRuns[2r], setRuns[2r + 1])
    // of the set's segment numbers g, r in [setRunBegin[j kSets + s], setRunBegin[j kSets + s + 1]), holding
    // every segment the row projects (segmentProjected): the sweeps visit only these. Found from the maps
    // (buildMaps), since whether a segment is projected depends on its ends' rigidity alone.
    std::vector<int32_t> setRunBegin, setRuns;
    // Per row of points j, runs [movableRuns[2r], movableRuns[2r + 1]) of points, r in [movableBegin[j],
    // movableBegin[j + 1]), outside which no point may move: the regularisation, which moves nothing else,
    // visits only these (on a real tile about half of the points are fixed by the warp mask). Runs closer
    // than kRunGap points are merged.
    std::vector<int32_t> movableBegin, movableRuns;
    // The same per row of cells j ([cellRunBegin[j], cellRunBegin[j + 1])): runs of cells with a corner
    // that may move. A cell outside them never changes, so the fold scans visit only these.
    std::vector<int32_t> cellRunBegin, cellRuns;

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t index(int32_t i, int32_t j) const { return static_cast<size_t>(j) * side() + i; }
    [[nodiscard]] bool movable(size_t k) const { return rigidity[k] >= 0.0f; }
};

// A point revertFolds put back, and where it was.
struct RevertedPoint {
    size_t index;
    float u, v;
};

struct SolverState {
    std::string source;
    SolverOptions options;
    int32_t cells = 0;
    std::vector<int32_t> sweeps;  // options.sweepsPerLevel, or the grid's default schedule when that is empty
    std::vector<Level> levels;
    WarpGrid grid;
    // Velocities; between prediction and integration they hold the positions before the prediction (of the
    // points that may move: the others never do, and keep velocity 0).
    std::vector<float> velU, velV;
    // A compact copy of the points of the coarse level being swept (level 1's size: the largest).
    std::vector<float> workU, workV;
    PointField rest;                    // f_O: rest lengths (Eq. 1) are measured through it when needed
    const float* deformed = nullptr;    // f_D of the current solve, 3 floats per point of its image (rest's)
    std::vector<int32_t> untangleWork;  // scratch of untangle(), sized at construction, kept between calls
    std::vector<int32_t> untangleNext;
    std::vector<RevertedPoint> revertLog;  // scratch of revertFolds()
    std::vector<int32_t> rowFolds;         // per cell row of the scan: triangles at or near zero area
    int32_t foldsLeft = 0;                 // folded triangles of the finest grid after the last revertFolds
    // Folded triangles of the finest grid's cells outside its cellRuns (constant: their corners may not
    // move); < 0: to be counted (after setMaps changes which points may move).
    int32_t fixedFolds = 0;
    SolveStats stats;

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t fine(const Level& level, int32_t i, int32_t j) const {
        return static_cast<size_t>(j) * level.stride * side() + static_cast<size_t>(i) * level.stride;
    }
};

// Level::setRunBegin and setRuns from the level's rigidity map, for a grid of fineCells cells (solver.cpp).
void findSetRuns(Level& level, int32_t fineCells);
// Level::movableBegin, movableRuns, cellRunBegin and cellRuns from the level's rigidity map (solver.cpp).
void findMovableRuns(Level& level);

// Repairs folds a propagation or prediction step may have made on `level` (solver_folds.cpp): a movable
// point with a non-positive triangle around it moves to the mean of its 8 neighbours. Returns the number of
// moves.
int32_t untangle(SolverState& state, const Level& level);

// What revertFolds did: points put back, the step shortened (around the folds, and perhaps everywhere);
// restart: the repair spread, and the velocities are to be dropped.
struct FoldRepair {
    int32_t reverted = 0;
    bool shortened = false;
    bool everywhere = false;
    bool restart = false;
};

// Makes the finest grid fold-free whatever the steps of an iteration did (solver_folds.cpp), from (oldU,
// oldV), a fold-free state: the corners of every triangle with non-positive area that moved go back there,
// spreading to the neighbours until no triangle is folded, or, when that spreads over a share of the moved
// points, the points around the triangles that fold on the way go 0.9 of the way to where they fold, the
// share rising to the whole step farther off, and the corners still folded go back; when that spreads
// again, every point goes 0.9 of the way to where the first triangle would fold. Sets foldsLeft
// to the grid's folded triangles (countFolds) without another scan of the whole grid.
FoldRepair revertFolds(SolverState& state, const float* oldU, const float* oldV);

}  // namespace deformkit::uvwarp::detail
