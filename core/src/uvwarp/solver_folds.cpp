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
// iteration's step instead; from 1 / kRestartShare of the moved points (at least kRevertFloor) the velocities
// are dropped. Measured on a fully covered 8192^2 tile (a spread repair there left no iteration any progress:
// -4.9% of the rigid stretch removed, 89.7% with these) and on the Fox's shot at 1024^2 (smaller limits
// shortened steps that a local repair serves better: up to 6 points less).
constexpr size_t kShortenShare = 16;
constexpr size_t kRestartShare = 256;
constexpr size_t kRevertFloor = 256;
constexpr float kLargeStep = 16.0f;

// Rows of the finest level's movable runs: fn(k) for each point k in them that may move (runs may hold
// points that may not, closer than the runs' gap), rows in parallel; returns the sum of what fn returns.
template <class Fn>
int64_t sumOverMovable(const SolverState& state, const Fn& fn) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    const size_t row = static_cast<size_t>(level.side());
    int64_t sum = 0;
#pragma omp parallel for schedule(dynamic, kBlockRows) reduction(+ : sum) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j <= c; ++j) {
        const int32_t* run = level.movableRuns.data() + 2 * static_cast<size_t>(level.movableBegin[j]);
        const int32_t runs = level.movableBegin[j + 1] - level.movableBegin[j];
        for (int32_t r = 0; r < runs; ++r) {
            for (int32_t i = run[2 * r]; i < run[2 * r + 1]; ++i) {
                const size_t k = static_cast<size_t>(j) * row + static_cast<size_t>(i);
                if (level.movable(k)) sum += fn(k);
            }
        }
    }
    return sum;
}

// The largest t in (0, 1] such that no triangle of the finest grid (both splittings) has zero area while its
// corners move in straight lines from (oldU, oldV) to t of the way to where they are: the flip-free step of
// Smith and Schaefer's line search (2015). 1 when no triangle in the runs folds on the way.
double foldFreeStep(const SolverState& state, const float* oldU, const float* oldV) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    const size_t row = static_cast<size_t>(level.side());
    const float* u = state.grid.u.data();
    const float* v = state.grid.v.data();
    // Points that may not move keep no old position (they have not moved).
    const auto before = [&](size_t k) {
        return level.movable(k) ? std::pair<double, double>(oldU[k], oldV[k])
                                : std::pair<double, double>(u[k], v[k]);
    };
    double largest = 1.0;
#pragma omp parallel for schedule(dynamic, kBlockRows) \
    reduction(min                                      \
              : largest) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j < c; ++j) {
        const int32_t* run = level.cellRuns.data() + 2 * static_cast<size_t>(level.cellRunBegin[j]);
        const int32_t runs = level.cellRunBegin[j + 1] - level.cellRunBegin[j];
        for (int32_t r = 0; r < runs; ++r) {
            for (int32_t i = run[2 * r]; i < run[2 * r + 1]; ++i) {
                const size_t a = static_cast<size_t>(j) * row + static_cast<size_t>(i), b = a + 1,
                             d = a + row, e = d + 1;
                largest = std::min(
                    {largest, firstZeroArea(u, v, before, a, b, e), firstZeroArea(u, v, before, a, e, d),
                     firstZeroArea(u, v, before, a, b, d), firstZeroArea(u, v, before, b, e, d)});
            }
        }
    }
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
// points put back from steps over kLargeStep cells, the points take their positions again and every point
// goes 0.9 of the fold-free part of its step instead (shortenStep). A
// repair past kRestartShare (or a shortened step) asks for the velocities to be dropped (restart): points put
// back have none, their neighbours large ones, and the next prediction would fold between them (an adaptive
// restart of the momentum, as O'Donoghue and Candes's). Serial, in ascending order: deterministic.
FoldRepair revertFolds(SolverState& state, const float* oldU, const float* oldV) {
    const Level& level = state.levels[0];
    const int32_t c = level.cells;
    float* u = state.grid.u.data();
    float* v = state.grid.v.data();
    int32_t* counts = state.rowFolds.data();
    // Cells whose corners may not move are skipped: none of their corners would go back.
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(c))
    for (int32_t j = 0; j < c; ++j)
        counts[j] = countInRuns(state, level, j, 0.0f);
    std::vector<int32_t>& work = state.untangleWork;
    work.clear();
    for (int32_t j = 0; j < c; ++j) {
        if (counts[j] == 0) continue;
        for (int32_t i = 0; i < c; ++i)
            collectFolded(state, level, i, j, 0.0f, work);
    }
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
    while (!work.empty() && !repair.shortened) {
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
                shortenStep(state, oldU, oldV, 0.9f * static_cast<float>(foldFreeStep(state, oldU, oldV)));
                std::fill(counts, counts + c, 1);
                repair = {0, true};
                next.clear();
                break;
            }
            log.push_back({k, u[k], v[k]});
            u[k] = oldU[k];
            v[k] = oldV[k];
            ++repair.reverted;
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
    repair.restart = repair.shortened || static_cast<size_t>(repair.reverted) > restartAt;
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
