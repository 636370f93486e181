// The UV-warp solver's fold repair (untangle) and the fold count of a warp.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "deformkit/uvwarp/solver.h"
#include "solver_kernels.h"
#include "solver_state.h"

namespace deformkit::uvwarp {

namespace detail {
namespace {

// True when moving level point (i, j) to (x, y) keeps all 12 triangles around it (both splittings of its
// four cells) positively oriented. Only called for movable points, which are never on the border.
bool keepsOrientation(const SolverState& state, const Level& level, int32_t i, int32_t j, float x, float y) {
    const size_t s = static_cast<size_t>(level.stride);
    const size_t row = s * static_cast<size_t>(state.side());
    const size_t k = state.fine(level, i, j);
    const float* u = state.grid.u.data();
    const float* v = state.grid.v.data();
    // Neighbours counter-clockwise from east.
    const size_t n[8] = {k + s, k + s + row, k + row, k - s + row, k - s, k - s - row, k - row, k + s - row};
    for (int q = 0; q < 4; ++q) {  // cell between neighbours 2q (edge), 2q+1 (diagonal), 2q+2 (edge)
        const size_t a = n[2 * q], d = n[2 * q + 1], b = n[(2 * q + 2) % 8];
        if (orient(x, y, u[a], v[a], u[d], v[d]) <= 0.0f) return false;
        if (orient(x, y, u[d], v[d], u[b], v[b]) <= 0.0f) return false;
        if (orient(x, y, u[a], v[a], u[b], v[b]) <= 0.0f) return false;
    }
    return true;
}

bool isFolded(const SolverState& state, const Level& level, int32_t i, int32_t j) {
    const size_t k = state.fine(level, i, j);
    return !keepsOrientation(state, level, i, j, state.grid.u[k], state.grid.v[k]);
}

// Pushes the interior corners of cell (i, j)'s triangles (both splittings) at or below `nearZero` area.
void collectFolded(const SolverState& state, const Level& level, int32_t i, int32_t j, float nearZero,
                   std::vector<int32_t>& out) {
    const int32_t c = level.cells;
    const size_t s = static_cast<size_t>(level.stride);
    const size_t a = state.fine(level, i, j), b = a + s, d = a + s * static_cast<size_t>(state.side()),
                 e = d + s;
    const float* u = state.grid.u.data();
    const float* v = state.grid.v.data();
    // Corners 0..3 = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1); the four triangles of the cell.
    const bool bad[4] = {orient(u[a], v[a], u[b], v[b], u[e], v[e]) <= nearZero,
                         orient(u[a], v[a], u[e], v[e], u[d], v[d]) <= nearZero,
                         orient(u[a], v[a], u[b], v[b], u[d], v[d]) <= nearZero,
                         orient(u[b], v[b], u[e], v[e], u[d], v[d]) <= nearZero};
    constexpr int32_t kCorners[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 1, 3}, {1, 2, 3}};
    constexpr int32_t kDi[4] = {0, 1, 1, 0}, kDj[4] = {0, 0, 1, 1};
    for (int t = 0; t < 4; ++t) {
        if (!bad[t]) continue;
        for (int32_t corner : kCorners[t]) {
            const int32_t ci = i + kDi[corner], cj = j + kDj[corner];
            if (ci > 0 && cj > 0 && ci < c && cj < c) out.push_back(cj * (c + 1) + ci);
        }
    }
}

// Triangles (both splittings) at or below nearZero area in the `cells` cells of a row starting at u, v
// (points `spacing` apart, the next row `rowStep` on); Spacing != 0 fixes the spacing at compile time.
template <int32_t Spacing>
int32_t countNearZero(const float* u, const float* v, size_t rowStep, size_t spacing, int32_t cells,
                      float nearZero) {
    const size_t s = Spacing != 0 ? Spacing : spacing;
    int32_t count = 0;
#pragma omp simd reduction(+ : count)
    for (int32_t i = 0; i < cells; ++i) {
        const size_t a = static_cast<size_t>(i) * s, b = a + s, d = a + rowStep, e = d + s;
        count += (orient(u[a], v[a], u[b], v[b], u[e], v[e]) <= nearZero ? 1 : 0) +
                 (orient(u[a], v[a], u[e], v[e], u[d], v[d]) <= nearZero ? 1 : 0) +
                 (orient(u[a], v[a], u[b], v[b], u[d], v[d]) <= nearZero ? 1 : 0) +
                 (orient(u[b], v[b], u[e], v[e], u[d], v[d]) <= nearZero ? 1 : 0);
    }
    return count;
}

// Triangles at or below nearZero area in the cells of row j of a level that have a corner that may move (the
// level's cellRuns; the other cells never change).
int32_t countInRuns(const SolverState& state, const Level& level, int32_t j, float nearZero) {
    const size_t s = static_cast<size_t>(level.stride);
    const size_t rowStep = s * static_cast<size_t>(state.side());
    const float* u = state.grid.u.data() + static_cast<size_t>(j) * rowStep;
    const float* v = state.grid.v.data() + static_cast<size_t>(j) * rowStep;
    const int32_t* run = level.cellRuns.data() + 2 * static_cast<size_t>(level.cellRunBegin[j]);
    const int32_t runs = level.cellRunBegin[j + 1] - level.cellRunBegin[j];
    int32_t count = 0;
    for (int32_t r = 0; r < runs; ++r) {
        const size_t first = static_cast<size_t>(run[2 * r]) * s;
        const int32_t cells = run[2 * r + 1] - run[2 * r];
        // The finest level's points are contiguous: a constant spacing gives vector loads.
        count += s == 1 ? countNearZero<1>(u + first, v + first, rowStep, 1, cells, nearZero)
                        : countNearZero<0>(u + first, v + first, rowStep, s, cells, nearZero);
    }
    return count;
}

// The first t in (0, 1] at which triangle (a, b, c) of the finest grid, its corners moving in a straight line
// from where they were (before) to where they are (grid), has zero area; 2 when its area stays positive, or
// when it had none to start with (a fold of cells that never change). Double precision: the area is a
// quadratic in t whose coefficients cancel when the step is small.
template <class Before>
double firstZeroArea(const float* u, const float* v, const Before& before, size_t a, size_t b, size_t c) {
    const auto [au, av] = before(a);
    const auto [bu, bv] = before(b);
    const auto [cu, cv] = before(c);
    const double e1u = bu - au, e1v = bv - av, e2u = cu - au, e2v = cv - av;
    const double f1u = (static_cast<double>(u[b]) - bu) - (static_cast<double>(u[a]) - au);
    const double f1v = (static_cast<double>(v[b]) - bv) - (static_cast<double>(v[a]) - av);
    const double f2u = (static_cast<double>(u[c]) - cu) - (static_cast<double>(u[a]) - au);
    const double f2v = (static_cast<double>(v[c]) - cv) - (static_cast<double>(v[a]) - av);
    const double area = e1u * e2v - e1v * e2u;  // A + B t + C t^2
    if (!(area > 0.0)) return 2.0;
    const double linear = e1u * f2v - e1v * f2u + f1u * e2v - f1v * e2u;
    const double square = f1u * f2v - f1v * f2u;
    double first = 2.0;
    if (square == 0.0) {
        if (linear < 0.0) first = -area / linear;
        return first;
    }
    const double disc = linear * linear - 4.0 * area * square;
    if (disc < 0.0) return first;
    // The roots q / C and A / q, q = -(B + sign(B) sqrt(disc)) / 2: no cancellation.
    const double q = -0.5 * (linear + std::copysign(std::sqrt(disc), linear));
    for (const double t : {q / square, q != 0.0 ? area / q : 2.0}) {
        if (t > 0.0 && t < first) first = t;
    }
    return first;
}

// revertFolds puts back at most 1 / kShortenShare of the points an iteration moved (at least kRevertFloor),
// and at most kRevertFloor points that had moved farther than kLargeStep grid cells, before it shortens the
// iteration's step instead (around the folds first, then everywhere); from 1 / kRestartShare of the moved
// points (at least kRevertFloor) the velocities are dropped. Measured on a fully covered 8192^2 tile (a
// spread repair there left no iteration any progress: -4.9% of the rigid stretch removed, 89.7% with these)
// and on the Fox's shot at 1024^2 (smaller limits shortened steps that a local repair serves better: up to 6
// points less).
constexpr size_t kShortenShare = 16;
constexpr size_t kRestartShare = 256;
constexpr size_t kRevertFloor = 256;
constexpr float kLargeStep = 16.0f;
// shortenLocally: fold cells are gathered in blocks of kFoldBlock cells a side, at most kMaxFoldBlocks of
// them (beyond, the step is shortened everywhere); the step scale rises from 0.9 of a block's fold-free step
// to the full step over kRampSteps times the largest step an iteration made.
constexpr int32_t kFoldBlock = 64;
constexpr size_t kMaxFoldBlocks = 1024;
constexpr double kRampSteps = 2.0;

// fn(k) for each point k of row j of the finest level's movable runs that may move (runs may hold points
// that may not, closer than the runs' gap).
template <class Fn>
void forMovableInRow(const Level& level, int32_t j, const Fn& fn) {
    const size_t row = static_cast<size_t>(level.side());
    const int32_t* run = level.movableRuns.data() + 2 * static_cast<size_t>(level.movableBegin[j]);
    const int32_t runs = level.movableBegin[j + 1] - level.movableBegin[j];
    for (int32_t r = 0; r < runs; ++r) {
        for (int32_t i = run[2 * r]; i < run[2 * r + 1]; ++i) {
            const size_t k = static_cast<size_t>(j) * row + static_cast<size_t>(i);
            if (level.movable(k)) fn(k);
        }
    }
}

// fn(k) for each point k of the finest level that may move, rows in parallel; returns the sum of what fn
// returns.
template <class Fn>
int64_t sumOverMovable(const SolverState& state, const Fn& fn) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    int64_t sum = 0;
#pragma omp parallel for schedule(dynamic, kBlockRows) reduction(+ : sum) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j <= c; ++j)
        forMovableInRow(level, j, [&](size_t k) { sum += fn(k); });
    return sum;
}

// fn(i, t) for each cell i of row j of the finest level's cell runs, t the least step at which one of its
// triangles (both splittings) has zero area while its corners move in straight lines from (oldU, oldV) to
// where they are (firstZeroArea; points that may not move keep no old position: they have not moved).
template <class Fn>
void forCellStepsInRow(const SolverState& state, const float* oldU, const float* oldV, int32_t j,
                       const Fn& fn) {
    const Level& level = state.levels[0];
    const size_t row = static_cast<size_t>(level.side());
    const float* u = state.grid.u.data();
    const float* v = state.grid.v.data();
    const auto before = [&](size_t k) {
        return level.movable(k) ? std::pair<double, double>(oldU[k], oldV[k])
                                : std::pair<double, double>(u[k], v[k]);
    };
    const int32_t* run = level.cellRuns.data() + 2 * static_cast<size_t>(level.cellRunBegin[j]);
    const int32_t runs = level.cellRunBegin[j + 1] - level.cellRunBegin[j];
    for (int32_t r = 0; r < runs; ++r) {
        for (int32_t i = run[2 * r]; i < run[2 * r + 1]; ++i) {
            const size_t a = static_cast<size_t>(j) * row + static_cast<size_t>(i), b = a + 1, d = a + row,
                         e = d + 1;
            fn(i, std::min({firstZeroArea(u, v, before, a, b, e), firstZeroArea(u, v, before, a, e, d),
                            firstZeroArea(u, v, before, a, b, d), firstZeroArea(u, v, before, b, e, d)}));
        }
    }
}

// The largest t in (0, 1] such that no triangle of the finest grid (both splittings) has zero area while its
// corners move in straight lines from (oldU, oldV) to t of the way to where they are: the flip-free step of
// Smith and Schaefer's line search (2015). 1 when no triangle in the runs folds on the way.
double foldFreeStep(const SolverState& state, const float* oldU, const float* oldV) {
    const int32_t c = state.levels[0].cells;
    double largest = 1.0;
#pragma omp parallel for schedule(dynamic, kBlockRows) \
    reduction(min                                      \
              : largest) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j < c; ++j)
        forCellStepsInRow(state, oldU, oldV, j, [&](int32_t, double t) { largest = std::min(largest, t); });
    return largest;
}

// Triangles of the finest grid's runs with non-positive area (both splittings).
int32_t foldsInRuns(const SolverState& state) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    int32_t folds = 0;
#pragma omp parallel for schedule(dynamic, kBlockRows) reduction(+ : folds) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j < c; ++j)
        folds += countInRuns(state, level, j, 0.0f);
    return folds;
}

// Every point of the finest grid that may move goes `step` of the way along its straight path from (oldU,
// oldV) to where it is; while a triangle is still folded (rounding: `step` is below the exact flip-free
// step) it goes half of what is left, and back to (oldU, oldV), a fold-free state, after 24 halvings.
void shortenStep(SolverState& state, const float* oldU, const float* oldV, float step) {
    float* u = state.grid.u.data();
    float* v = state.grid.v.data();
    for (int halvings = 0;; ++halvings) {
        const float scale = halvings < 24 ? step : 0.0f;
        sumOverMovable(state, [&](size_t k) {
            u[k] = oldU[k] + scale * (u[k] - oldU[k]);
            v[k] = oldV[k] + scale * (v[k] - oldV[k]);
            return 0;
        });
        if (scale == 0.0f || foldsInRuns(state) == 0) return;
        step = 0.5f;
    }
}

// The largest distance a point that may move went from (oldU, oldV), in uv units: a max, the same whatever
// the order.
double largestStep(const SolverState& state, const float* oldU, const float* oldV) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    const float* u = state.grid.u.data();
    const float* v = state.grid.v.data();
    float largest = 0.0f;
#pragma omp parallel for schedule(dynamic, kBlockRows) \
    reduction(max                                      \
              : largest) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j <= c; ++j) {
        forMovableInRow(level, j, [&](size_t k) {
            const float du = u[k] - oldU[k], dv = v[k] - oldV[k];
            largest = std::max(largest, du * du + dv * dv);
        });
    }
    return std::sqrt(static_cast<double>(largest));
}

// A block of cells with a triangle that would fold on the way, and the least step at which one does.
struct FoldBlock {
    int32_t i0, j0, i1, j1;  // cells [i0, i1] x [j0, j1] of the block holding such triangles
    double step;
};

// Shortens the iteration's step only around the triangles that fold on the way (UV-16): a point at distance
// d (cells) from a block of such triangles goes s(d) = 0.9 t + (1 - 0.9 t) min(1, d / ramp) of its step, t
// the block's fold-free step (foldFreeStep's, over the block), the least over blocks; ramp = kRampSteps times
// the largest step in cells, so that neighbouring points' steps differ by at most about half a cell of
// motion. Points farther than the ramp from every block keep their step (bit for bit). The scale is
// evaluated at the corners of a kFoldBlock grid at their distance to a block less the grid's cell diagonal,
// and blended bilinearly: never above s(d) of the point itself. Returns false, and moves nothing, when no
// triangle folds on the way or more than kMaxFoldBlocks blocks hold one (the caller shortens everywhere).
bool shortenLocally(SolverState& state, const float* oldU, const float* oldV) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    const size_t row = static_cast<size_t>(level.side());
    float* u = state.grid.u.data();
    float* v = state.grid.v.data();
    // Fold-free step per block of cells, found row of blocks by row of blocks (rows in parallel, each block
    // row's cells written by one thread: deterministic).
    const int32_t blocks = (c + kFoldBlock - 1) / kFoldBlock;
    std::vector<FoldBlock> grid(static_cast<size_t>(blocks) * blocks, FoldBlock{c, c, -1, -1, 2.0});
#pragma omp parallel for schedule(dynamic, 1) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t bj = 0; bj < blocks; ++bj) {
        for (int32_t j = bj * kFoldBlock; j < std::min(c, (bj + 1) * kFoldBlock); ++j) {
            forCellStepsInRow(state, oldU, oldV, j, [&](int32_t i, double t) {
                if (t >= 1.0) return;
                FoldBlock& f = grid[static_cast<size_t>(bj) * blocks + i / kFoldBlock];
                f = {std::min(f.i0, i), std::min(f.j0, j), std::max(f.i1, i), std::max(f.j1, j),
                     std::min(f.step, t)};
            });
        }
    }
    std::vector<FoldBlock> folds;
    for (const FoldBlock& f : grid) {
        if (f.step < 1.0) folds.push_back(f);
    }
    if (folds.empty() || folds.size() > kMaxFoldBlocks) return false;
    const double ramp = std::max(1.0, kRampSteps * largestStep(state, oldU, oldV) * c);
    // The scale at the corners of the block grid (corner (I, J) at cell (I B, J B)).
    const int32_t corners = blocks + 1;
    const double diagonal = kFoldBlock * std::sqrt(2.0);
    std::vector<float> scale(static_cast<size_t>(corners) * corners, 1.0f);
    for (int32_t cj = 0; cj < corners; ++cj) {
        for (int32_t ci = 0; ci < corners; ++ci) {
            const double x = static_cast<double>(ci) * kFoldBlock, y = static_cast<double>(cj) * kFoldBlock;
            double least = 1.0;
            for (const FoldBlock& f : folds) {
                // Distance to the block's cells [i0, i1 + 1] x [j0, j1 + 1], less the blend's reach.
                const double dx = std::max({0.0, f.i0 - x, x - (f.i1 + 1.0)});
                const double dy = std::max({0.0, f.j0 - y, y - (f.j1 + 1.0)});
                const double d = std::max(0.0, std::sqrt(dx * dx + dy * dy) - diagonal);
                const double near = 0.9 * f.step;
                least = std::min(least, near + (1.0 - near) * std::min(1.0, d / ramp));
            }
            scale[static_cast<size_t>(cj) * corners + ci] = static_cast<float>(least);
        }
    }
    const int64_t moved = sumOverMovable(state, [&](size_t k) {
        const int32_t i = static_cast<int32_t>(k % row), j = static_cast<int32_t>(k / row);
        const int32_t bi = std::min(i / kFoldBlock, blocks - 1), bj = std::min(j / kFoldBlock, blocks - 1);
        const float* s0 = scale.data() + static_cast<size_t>(bj) * corners + bi;
        const float* s1 = s0 + corners;
        if (s0[0] == 1.0f && s0[1] == 1.0f && s1[0] == 1.0f && s1[1] == 1.0f) return 0;
        const float fx = static_cast<float>(i - bi * kFoldBlock) / kFoldBlock,
                    fy = static_cast<float>(j - bj * kFoldBlock) / kFoldBlock;
        const float s =
            (1.0f - fy) * ((1.0f - fx) * s0[0] + fx * s0[1]) + fy * ((1.0f - fx) * s1[0] + fx * s1[1]);
        u[k] = oldU[k] + s * (u[k] - oldU[k]);
        v[k] = oldV[k] + s * (v[k] - oldV[k]);
        return 1;
    });
    return moved > 0;
}

}  // namespace

// One scan over the level's cells (4 orientation tests per cell, vectorisable) finds the triangles at or
// near zero area; their corners are the candidates, each checked exactly before it moves. After that only
// the neighbourhoods of moved points are looked at again, in ascending order (deterministic, serial: the
// list is short in normal use).
int32_t untangle(SolverState& state, const Level& level) {
    const int32_t c = level.cells;
    const size_t s = static_cast<size_t>(level.stride);
    const size_t rowStep = s * static_cast<size_t>(state.side());
    // Below a thousandth of a cell's area a triangle is a candidate: far above the rounding of orient() on
    // unit-square coordinates, far below any triangle of a sound grid.
    const float cellSize = static_cast<float>(level.stride) / static_cast<float>(state.cells);
    const float nearZero = 1e-3f * cellSize * cellSize;
    WarpGrid& grid = state.grid;
    int32_t* counts = state.rowFolds.data();
    // Cells whose corners may not move are skipped: none of their corners would be moved.
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j < c; ++j)
        counts[j] = countInRuns(state, level, j, nearZero);
    std::vector<int32_t>& work = state.untangleWork;
    work.clear();
    for (int32_t j = 0; j < c; ++j) {
        if (counts[j] == 0) continue;
        for (int32_t i = 0; i < c; ++i)
            collectFolded(state, level, i, j, nearZero, work);
    }
    std::sort(work.begin(), work.end());
    work.erase(std::unique(work.begin(), work.end()), work.end());
    int32_t moved = 0;
    const size_t row = rowStep;
    std::vector<int32_t>& next = state.untangleNext;
    for (int pass = 0; pass < 64 && !work.empty(); ++pass) {
        next.clear();
        for (int32_t id : work) {
            const int32_t i = id % (c + 1), j = id / (c + 1);
            if (!level.movable(level.index(i, j)) || !isFolded(state, level, i, j)) continue;
            const size_t k = state.fine(level, i, j);
            const size_t n[8] = {k + s, k + s + row, k + row, k - s + row,
                                 k - s, k - s - row, k - row, k + s - row};
            float mu = 0.0f, mv = 0.0f;
            for (size_t q : n) {
                mu += grid.u[q] / 8.0f;
                mv += grid.v[q] / 8.0f;
            }
            grid.u[k] = mu;  // the neighbours' mean repairs most folds at once
            grid.v[k] = mv;
            ++moved;
            for (int32_t dj = -1; dj <= 1; ++dj) {
                for (int32_t di = -1; di <= 1; ++di) {
                    const int32_t ni = i + di, nj = j + dj;
                    if (ni > 0 && nj > 0 && ni < c && nj < c) next.push_back(nj * (c + 1) + ni);
                }
            }
        }
        std::sort(next.begin(), next.end());
        next.erase(std::unique(next.begin(), next.end()), next.end());
        work.clear();
        for (int32_t id : next) {
            if (isFolded(state, level, id % (c + 1), id / (c + 1))) work.push_back(id);
        }
    }
    return moved;
}

// The finest level's triangles are scanned once (vectorised, as untangle's). With a fold, a folded triangle's
// corners that moved since (oldU, oldV) go back there, and the cells around each are looked at again. A point
// goes back at most once and a triangle whose corners are all back is the old one, so this ends, at worst in
// the old state. Where the steps are large and smooth (a coarse level's motion on a large grid), a point put
// back folds its neighbours and the repair spreads: past kShortenShare of the moved points, or kRevertFloor
// points put back from steps over kLargeStep cells, the points take their positions again, the step is
// shortened around the triangles that fold on the way (shortenLocally) and the repair starts again; if it
// spreads again, every point goes 0.9 of the fold-free part of its step instead (shortenStep). A
// repair past kRestartShare (or a shortened step) asks for the velocities to be dropped (restart): points put
// back have none, their neighbours large ones, and the next prediction would fold between them (an adaptive
// restart of the momentum, as O'Donoghue and Candes's). Serial, in ascending order: deterministic.
FoldRepair revertFolds(SolverState& state, const float* oldU, const float* oldV) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    float* u = state.grid.u.data();
    float* v = state.grid.v.data();
    int32_t* counts = state.rowFolds.data();
    // The corners of every folded triangle into `out`, the rows' fold counts into counts. Cells whose corners
    // may not move are skipped: none of their corners would go back.
    const auto scan = [&](std::vector<int32_t>& out) {
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(c))
        for (int32_t j = 0; j < c; ++j)
            counts[j] = countInRuns(state, level, j, 0.0f);
        out.clear();
        for (int32_t j = 0; j < c; ++j) {
            if (counts[j] == 0) continue;
            for (int32_t i = 0; i < c; ++i)
                collectFolded(state, level, i, j, 0.0f, out);
        }
    };
    std::vector<int32_t>& work = state.untangleWork;
    scan(work);
    FoldRepair repair;
    size_t budget = 0;     // points put back before the step is shortened instead
    size_t restartAt = 0;  // points put back from which the velocities are dropped
    size_t large = 0;      // points put back that had moved farther than kLargeStep
    if (!work.empty()) {
        const int64_t moved =
            sumOverMovable(state, [&](size_t k) { return u[k] != oldU[k] || v[k] != oldV[k] ? 1 : 0; });
        budget = std::max<size_t>(kRevertFloor, static_cast<size_t>(moved) / kShortenShare);
        restartAt = std::max<size_t>(kRevertFloor, static_cast<size_t>(moved) / kRestartShare);
    }
    std::vector<int32_t>& next = state.untangleNext;
    std::vector<RevertedPoint>& log = state.revertLog;
    log.clear();
    // counts[j] != 0 from here on: cell row j may hold a folded triangle (the scan found one there, or a
    // point of the row's cells went back).
    bool local = false;  // the step was shortened around the folds
    while (!work.empty() && !repair.everywhere) {
        std::sort(work.begin(), work.end());
        work.erase(std::unique(work.begin(), work.end()), work.end());
        next.clear();
        for (int32_t id : work) {
            const size_t k = static_cast<size_t>(id);
            // A point that may not move has not (and the iteration keeps no old position of it).
            if (!level.movable(k) || (u[k] == oldU[k] && v[k] == oldV[k])) continue;
            const float su = (u[k] - oldU[k]) * static_cast<float>(c),
                        sv = (v[k] - oldV[k]) * static_cast<float>(c);
            large += su * su + sv * sv > kLargeStep * kLargeStep ? 1 : 0;
            if (log.size() >= budget || large > kRevertFloor) {
                for (const RevertedPoint& p : log) {
                    u[p.index] = p.u;
                    v[p.index] = p.v;
                }
                log.clear();
                repair = {0, true};
                // First only around the triangles that fold on the way; if putting points back then spreads
                // again, everywhere.
                if (!local && shortenLocally(state, oldU, oldV)) {
                    local = true;
                    large = 0;
                    scan(next);
                    break;
                }
                std::fill(counts, counts + c, 1);
                next.clear();
                shortenStep(state, oldU, oldV, 0.9f * static_cast<float>(foldFreeStep(state, oldU, oldV)));
                repair.everywhere = true;
                break;
            }
            log.push_back({k, u[k], v[k]});
            u[k] = oldU[k];
            v[k] = oldV[k];
            ++repair.reverted;  // (0 after a shortening: counts the points put back since)
            const int32_t i = id % (c + 1), j = id / (c + 1);
            for (int32_t cj = std::max(j - 1, 0); cj <= std::min(j, c - 1); ++cj) {
                counts[cj] = 1;
                for (int32_t ci = std::max(i - 1, 0); ci <= std::min(i, c - 1); ++ci)
                    collectFolded(state, level, ci, cj, 0.0f, next);
            }
        }
        work.swap(next);
    }
    // The folds left (countFolds of the grid): those of the cells that never change, and of the marked rows'
    // other cells (a triangle changes only when a corner goes back).
    if (state.fixedFolds < 0) state.fixedFolds = countFolds(state.grid) - foldsInRuns(state);
    int32_t left = state.fixedFolds;
    for (int32_t j = 0; j < c; ++j) {
        if (counts[j] != 0) left += countInRuns(state, level, j, 0.0f);
    }
    state.foldsLeft = left;
    repair.restart = repair.everywhere || static_cast<size_t>(repair.reverted) > restartAt;
    return repair;
}

}  // namespace detail

int32_t countFolds(const WarpGrid& warp) {
    using detail::kParallelRows;
    const int32_t n = warp.cells;
    const auto row = static_cast<size_t>(n) + 1;
    int32_t folds = 0;
#pragma omp parallel for schedule(static) reduction(+ : folds) if (kParallelRows < static_cast <int64_t>(n))
    for (int32_t j = 0; j < n; ++j)
        folds += detail::countNearZero<1>(warp.u.data() + static_cast<size_t>(j) * row,
                                          warp.v.data() + static_cast<size_t>(j) * row, row, 1, n, 0.0f);
    return folds;
}

}  // namespace deformkit::uvwarp
