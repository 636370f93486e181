#include "deformkit/uvwarp/solver.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/uvwarp/inversion.h"
#include "deformkit/uvwarp/options.h"
#include "memory/large_buffers.h"
#include "row_wavefront.h"
#include "simd/cpu.h"
#include "solver_kernels.h"
#include "solver_state.h"
#include "team_chooser.h"
#include "uvwarp/field_checks.h"

namespace deformkit::uvwarp {

using detail::forRowBlocks;
using detail::kBlockRows;
using detail::kFixed;
using detail::kGauss;
using detail::kParallelRows;
using detail::Level;

namespace {

// Level::movableRuns and cellRuns: runs closer than this are merged.
constexpr int32_t kRunGap = 8;

// The cascade of coarse levels (UV-38): levels a run sweeps at least once it has left the coarsest out (the
// finest alone converges slowly: the Fox's shot at 256^2, 3 levels, lost 2-3 points), and the fewest
// iterations a run cascades (the live preset's first frame of the Fox's Run, 2 iterations from the identity,
// kept 62.9% of its rigid stretch removed cascaded, 66.8% sweeping every level).
constexpr size_t kCascadeFloor = 2;
constexpr int32_t kCascadeRun = 4;

// Level::setRuns: runs of segments fewer than this apart are merged: the lanes of a pair (kPair), the unit of
// the projection's blocks (UV-27).
constexpr int32_t kRunGapLanes = 2;

// The kernels of an instruction set: the same bytes from each.
const detail::SolverKernels& kernelsFor(simd::Isa isa) {
#ifdef DEFORMKIT_SIMD_X86
    if (isa == simd::Isa::Avx2) return detail::kAvx2Kernels;
#endif
    (void)isa;
    return detail::kBaselineKernels;
}

// The largest distance, in cells (chessboard: 8-neighbour steps), from a point that may move (mask >= 0.5,
// not on the tile border) to the nearest point that may not: the half-width of the widest chart. The exact
// chessboard distance transform of Meijster, Roerdink and Hesselink (2000), separable: per column the
// distance to the nearest fixed point of the column, then per row the lower envelope of
// max(|x - i|, g(i)); columns (in blocks walked row by row, so that each row's stretch is read whole),
// then rows, in parallel.
int32_t widestChartRadius(const PointField& mask) {
    const int32_t side = mask.side();
    std::vector<int32_t> g;  // per point: the distance to the nearest fixed point of its column
    deformkit::detail::assignLarge(g, static_cast<size_t>(side) * side, 0);
    constexpr int32_t kBlockColumns = 64;
    const int32_t blocks = (side + kBlockColumns - 1) / kBlockColumns;
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(side))
    for (int32_t b = 0; b < blocks; ++b) {
        const int32_t i0 = b * kBlockColumns, i1 = std::min(side, i0 + kBlockColumns);
        const auto row = [&](int32_t j) { return g.data() + static_cast<size_t>(j) * side; };
        for (int32_t j = 1; j < side; ++j) {
            int32_t* here = row(j);
            const int32_t* below = row(j - 1);
            const float* m = &mask.values[mask.index(0, j)];
            for (int32_t i = i0; i < i1; ++i) {
                const bool fixed = i == 0 || i == side - 1 || j == side - 1 || m[i] < 0.5f;
                here[i] = fixed ? 0 : below[i] + 1;
            }
        }
        for (int32_t j = side - 2; j >= 0; --j) {
            int32_t* here = row(j);
            const int32_t* above = row(j + 1);
            for (int32_t i = i0; i < i1; ++i)
                here[i] = std::min(here[i], above[i] + 1);
        }
    }
    int32_t widest = 0;
#pragma omp parallel reduction(max : widest) if (kParallelRows < static_cast <int64_t>(side))
    {
        std::vector<int32_t> s(static_cast<size_t>(side)), t(static_cast<size_t>(side));
#pragma omp for schedule(static)
        for (int32_t j = 0; j < side; ++j) {
            const int32_t* row = g.data() + static_cast<size_t>(j) * side;
            const auto f = [&](int32_t x, int32_t i) { return std::max(std::abs(x - i), row[i]); };
            // The first x from which column u's term is below column i's (i < u).
            const auto sep = [&](int32_t i, int32_t u) {
                return row[i] <= row[u] ? std::max(i + row[u], (i + u) / 2)
                                        : std::min(u - row[i], (i + u) / 2);
            };
            int32_t q = 0;
            s[0] = 0;
            t[0] = 0;
            for (int32_t u = 1; u < side; ++u) {
                while (q >= 0 && f(t[q], s[q]) > f(t[q], u))
                    --q;
                if (q < 0) {
                    q = 0;
                    s[0] = u;
                } else if (const int32_t w = 1 + sep(s[q], u); w < side) {
                    ++q;
                    s[q] = u;
                    t[q] = w;
                }
            }
            for (int32_t u = side - 1; u >= 0; --u) {
                widest = std::max(widest, f(u, s[q]));
                if (u == t[q]) --q;
            }
        }
    }
    return widest;
}

// Runs [start, end), given in ascending order, appended to `out` as [out[2r], out[2r + 1]), those fewer than
// `gap` apart merged (0: none).
struct RunMerger {
    std::vector<int32_t>& out;
    int32_t gap;
    int32_t count = 0, open = -1, end = -1;  // the run [open, end) being built

    void add(int32_t start, int32_t stop) {
        if (open >= 0 && start - end < gap) {
            end = stop;
            return;
        }
        emit();
        open = start;
        end = stop;
    }
    // Appends the last run; returns how many were appended.
    int32_t finish() {
        emit();
        open = -1;
        return count;
    }

  private:
    void emit() {
        if (open < 0) return;
        out.push_back(open);
        out.push_back(end);
        ++count;
    }
};

// Appends to `runs` the runs [runs[2r], runs[2r + 1]) of the bytes p[0, n) that are 1 (all others 0), runs
// fewer than `gap` apart merged (0: none); returns how many. Eight bytes at a time across stretches of zeros
// or ones.
int32_t appendByteRuns(const uint8_t* p, int32_t n, int32_t gap, std::vector<int32_t>& runs) {
    constexpr uint64_t kOnes = 0x0101010101010101ull;
    const auto word = [p](int32_t i) {
        uint64_t w = 0;
        std::memcpy(&w, p + i, sizeof w);
        return w;
    };
    RunMerger merger{runs, gap};
    int32_t i = 0;
    while (i < n) {
        while (i + 8 <= n && word(i) == 0)
            i += 8;
        while (i < n && p[i] == 0)
            ++i;
        if (i == n) break;
        const int32_t start = i;
        while (i + 8 <= n && word(i) == kOnes)
            i += 8;
        while (i < n && p[i] != 0)
            ++i;
        merger.add(start, i);
    }
    return merger.finish();
}

// A thread's scratch while it finds rows' runs: a row's byte map, and runs before they are merged (per edge
// type). Made once per thread and call: thread_local vectors on OpenMP's threads crash LeakSanitizer's exit
// scan.
struct RowScratch {
    std::vector<uint8_t> bytes;
    std::vector<int32_t> typeRuns[4];
};

// Runs per row and part (a row's runs of each of `parts` kinds): appendRow(j, out, count, scratch) appends
// row j's runs to `out`, part after part, and sets count[p] to part p's number of them. Afterwards runs
// [runs[2r], runs[2r + 1]) for r in [begin[j parts + p], begin[j parts + p + 1]) are part p of row j. Rows
// are found in parallel, each into a list of its own, then laid end to end in row order: the same arrays as
// one pass over the rows.
template <class AppendRow>
void collectRuns(int32_t rows, int32_t parts, const AppendRow& appendRow, std::vector<int32_t>& begin,
                 std::vector<int32_t>& runs) {
    std::vector<std::vector<int32_t>> rowRuns(static_cast<size_t>(rows));
    begin.assign(static_cast<size_t>(rows) * parts + 1, 0);
#pragma omp parallel if (kParallelRows < static_cast <int64_t>(rows))
    {
        RowScratch scratch;
#pragma omp for schedule(dynamic, kBlockRows)
        for (int32_t j = 0; j < rows; ++j)
            appendRow(j, rowRuns[j], &begin[static_cast<size_t>(j) * parts + 1], scratch);
    }
    for (size_t k = 1; k < begin.size(); ++k)
        begin[k] += begin[k - 1];
    runs.resize(2 * static_cast<size_t>(begin.back()));
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(rows))
    for (int32_t j = 0; j < rows; ++j)
        std::copy(rowRuns[j].begin(), rowRuns[j].end(),
                  runs.begin() + 2 * static_cast<ptrdiff_t>(begin[static_cast<size_t>(j) * parts]));
}

// Per row j of `rows`, the runs [runs[2r], runs[2r + 1]) of i in [0, columns) whose byte fillRow(j, bytes)
// sets to 1 (the others 0), r in [begin[j], begin[j + 1]); runs closer than kRunGap are merged.
template <class FillRow>
void findRuns(int32_t columns, int32_t rows, const FillRow& fillRow, std::vector<int32_t>& begin,
              std::vector<int32_t>& runs) {
    collectRuns(
        rows, 1,
        [&](int32_t j, std::vector<int32_t>& out, int32_t* count, RowScratch& scratch) {
            scratch.bytes.resize(static_cast<size_t>(columns));
            fillRow(j, scratch.bytes.data());
            count[0] = appendByteRuns(scratch.bytes.data(), columns, kRunGap, out);
        },
        begin, runs);
}

// Image points between neighbouring points of `level` in a geometry image of imageCells cells over a grid of
// fineCells (imageCells = fineCells or fineCells / 2); 0: the finest level over an image of half its cells,
// whose points lie between the image's.
int32_t imagePointsApart(const Level& level, int32_t fineCells, int32_t imageCells) {
    return imageCells < fineCells ? level.stride / 2 : level.stride;
}

// The kernels' view of a level whose points are at u[j * row + i * step], in a grid of fineCells cells whose
// f_O is `rest` (a geometry image of fineCells or fineCells / 2 cells).
detail::KernelLevel kernelLevel(const Level& level, int32_t fineCells, const PointField& rest, float* u,
                                float* v, int32_t step, ptrdiff_t row) {
    const bool compact = !level.rest.empty();
    const int32_t apart = imagePointsApart(level, fineCells, rest.cells);
    const bool between = !compact && apart == 0;
    const int32_t imageStride = between ? 1 : apart;
    return {level.cells,
            compact ? level.rest.data() : rest.values.data(),
            compact ? 3 * static_cast<ptrdiff_t>(level.side())
                    : 3 * static_cast<ptrdiff_t>(imageStride) * (rest.cells + 1),
            compact ? 3 : 3 * imageStride,
            between ? 1 : 0,
            u,
            v,
            step,
            row,
            level.rigidity.data(),
            level.orientation.empty() ? nullptr : level.orientation.data(),
            level.setRunBegin.data(),
            level.setRuns.data(),
            level.movableBegin.data(),
            level.movableRuns.data()};
}

}  // namespace

// The solver's state, and the steps of one iteration over the hierarchy (§4.1, §4.4).
struct Solver::Impl : detail::SolverState {
    const detail::SolverKernels* kernels = &kernelsFor(simd::activeIsa());
    detail::TeamChooser team;  // SolverOptions::threads == 0
    bool fromIdentity = true;  // the next solve starts from the identity (SolverOptions::coldIterations)
    bool started = false;      // the next solve starts from a coarser warp (startFrom): no cold restart
    bool keepState = false;    // keepSolveState(): without warmStart, the solve state stays between solves
    // The wavefront's per-block flags (forRowBlocks), enough for any level's rows.
    std::vector<std::atomic<int32_t>> blockDone;

    [[nodiscard]] detail::KernelGrid kernelGrid() {
        return {cells, deformed, rest.cells, options.orientationPreservation, options.smoothing};
    }

    // Rows of cells j moves points on rows j and j + 1 and reads rows j - 1 .. j + 2 (the clamp and the
    // fold check read 8-neighbours): forRowBlocks' blocks keep parallel rows apart.
    void sweepLevel(const detail::KernelLevel& l, float stiffness, int32_t count) {
        const detail::KernelGrid g = kernelGrid();
        forRowBlocks(0, l.cells, count, blockDone, [&](int32_t j) { kernels->sweepRow(g, l, j, stiffness); });
    }

    // The level's points where they are, in the warp.
    detail::KernelLevel inPlace(const Level& level) {
        return kernelLevel(level, cells, rest, grid.u.data(), grid.v.data(), level.stride,
                           static_cast<ptrdiff_t>(level.stride) * side());
    }

    // A coarse level's sweeps run on a compact copy of its points (workU, workV): the kernels then read
    // their neighbourhoods as contiguous stretches, as on the finest level, not one scattered point per lane.
    // The same arithmetic on the same values: the same bytes as in place.
    detail::KernelLevel gather(const Level& level) {
        const int32_t n = level.side();
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(n))
        for (int32_t j = 0; j < n; ++j) {
            for (int32_t i = 0; i < n; ++i) {
                const size_t k = fine(level, i, j);
                workU[level.index(i, j)] = grid.u[k];
                workV[level.index(i, j)] = grid.v[k];
            }
        }
        return kernelLevel(level, cells, rest, workU.data(), workV.data(), 1, n);
    }

    // The copy's points back into the warp: those that may move (the sweeps move no other).
    void scatter(const Level& level) {
        maxOverMovable(level, [&](int32_t i, int32_t j) {
            const size_t k = fine(level, i, j);
            grid.u[k] = workU[level.index(i, j)];
            grid.v[k] = workV[level.index(i, j)];
            return 0.0f;
        });
    }

    // A row of points moves only itself and reads one row either side.
    void regulariseAll(const Level& level, bool onlyNew) {
        const detail::KernelGrid g = kernelGrid();
        const detail::KernelLevel l = inPlace(level);
        forRowBlocks(1, level.cells, 1, blockDone,
                     [&](int32_t j) { kernels->regulariseRow(g, l, j, onlyNew); });
    }

    // §4.4: coarse-level displacements interpolated to the in-between points of the next finer level:
    // the mean of the displacements of the 2 or 4 coarse points around each (bilinear at the midpoints).
    // The coarse points are read from `from`: the warp, or the compact copy the level was swept in.
    void propagate(const Level& coarse, const Level& finer, const detail::KernelLevel& from) {
        const int32_t c = coarse.cells;
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(finer.cells))
        for (int32_t jj = 0; jj <= finer.cells; ++jj) {
            const int32_t j0 = jj >> 1, j1 = std::min(j0 + (jj & 1), c);
            // Coarse rows j0 and j1: positions (in `from`), and their snapshots.
            const float* u0 = from.u + j0 * from.row;
            const float* v0 = from.v + j0 * from.row;
            const float* u1 = from.u + j1 * from.row;
            const float* v1 = from.v + j1 * from.row;
            const float* su0 = coarse.snapshotU.data() + coarse.index(0, j0);
            const float* sv0 = coarse.snapshotV.data() + coarse.index(0, j0);
            const float* su1 = coarse.snapshotU.data() + coarse.index(0, j1);
            const float* sv1 = coarse.snapshotV.data() + coarse.index(0, j1);
            const int32_t cs = from.step;
            const ptrdiff_t finerRow = static_cast<ptrdiff_t>(finer.stride) * side();
            float* u = grid.u.data() + jj * finerRow;
            float* v = grid.v.data() + jj * finerRow;
            const float* rigidity = finer.rigidity.data() + finer.index(0, jj);
            const int32_t fs = finer.stride;
            // Point ii of the finer row lies between coarse points i0 = ii / 2 and i1 = (ii + 1) / 2 (the
            // same point for even ii). The loops run over m with ii = 2m or 2m + 1, so every index is affine
            // in m (vector loads at a fixed stride, not one address computed per lane).
            const auto move = [&](int32_t ii, int32_t i0, int32_t i1) {
                float du = 0.0f, dv = 0.0f;
                du += 0.25f * (u0[i0 * cs] - su0[i0]);
                dv += 0.25f * (v0[i0 * cs] - sv0[i0]);
                du += 0.25f * (u0[i1 * cs] - su0[i1]);
                dv += 0.25f * (v0[i1 * cs] - sv0[i1]);
                du += 0.25f * (u1[i0 * cs] - su1[i0]);
                dv += 0.25f * (v1[i0 * cs] - sv1[i0]);
                du += 0.25f * (u1[i1 * cs] - su1[i1]);
                dv += 0.25f * (v1[i1 * cs] - sv1[i1]);
                const float m = rigidity[ii] >= 0.0f ? 1.0f : 0.0f;  // fixed points: kFixed < 0
                const int32_t k = ii * fs;
                u[k] += m * du;
                v[k] += m * dv;
            };
            // Coarse points (both indices even) are moved by their own level: on an even row only the odd
            // points are new. Only the row's runs of points that may move are visited (the others would move
            // by 0).
            const int32_t* run = finer.movableRuns.data() + 2 * static_cast<size_t>(finer.movableBegin[jj]);
            const int32_t runs = finer.movableBegin[jj + 1] - finer.movableBegin[jj];
            for (int32_t r = 0; r < runs; ++r) {
                const int32_t a = run[2 * r], b = run[2 * r + 1];  // points ii in [a, b)
                if (jj & 1) {
                    const int32_t last = std::min((b + 1) >> 1, c + 1);
#pragma omp simd
                    for (int32_t m = (a + 1) >> 1; m < last; ++m)
                        move(2 * m, m, m);
                }
                const int32_t last = std::min(b >> 1, c);
#pragma omp simd
                for (int32_t m = a >> 1; m < last; ++m)
                    move(2 * m + 1, m, m + 1);
            }
        }
    }

    void snapshot(Level& level) {
        const int32_t n = level.side();
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(n))
        for (int32_t j = 0; j < n; ++j) {
            for (int32_t i = 0; i < n; ++i) {
                const size_t k = fine(level, i, j);
                level.snapshotU[level.index(i, j)] = grid.u[k];
                level.snapshotV[level.index(i, j)] = grid.v[k];
            }
        }
    }

    // Runs fn(i, j) for the points (i, j) of `level` in its runs of points that may move, rows in parallel,
    // and returns the largest value fn returns (0 without points): a max, the same whatever the order, so
    // the same bytes for any thread count. On the finest level these are the only points that ever move
    // (a point a coarser level moves may move on the finest, Eq. 8).
    template <class Fn>
    float maxOverMovable(const Level& level, const Fn& fn) {
        const int32_t n = level.side();
        float largest = 0.0f;
#pragma omp parallel for schedule(dynamic, kBlockRows) \
    reduction(max                                      \
              : largest) if (kParallelRows < static_cast <int64_t>(n))
        for (int32_t j = 0; j < n; ++j) {
            const int32_t* run = level.movableRuns.data() + 2 * static_cast<size_t>(level.movableBegin[j]);
            const int32_t runs = level.movableBegin[j + 1] - level.movableBegin[j];
            for (int32_t r = 0; r < runs; ++r)
                for (int32_t i = run[2 * r]; i < run[2 * r + 1]; ++i)
                    largest = std::max(largest, fn(i, j));
        }
        return largest;
    }

    int32_t sweepsAt(size_t level) const {
        return sweeps[std::min(level, sweeps.size() - 1)];
    }

    // Points placed off their rest positions (placePoints), and placing them: the fixed ones (by the current
    // mask), and with movableToo the others (a solve from the identity starts there).
    std::vector<int64_t> placedIndex;
    std::vector<float> placedU, placedV;
    void placeListed(bool movableToo) {
        for (size_t k = 0; k < placedIndex.size(); ++k) {
            if (!movableToo && levels[0].movable(static_cast<size_t>(placedIndex[k]))) continue;
            grid.u[placedIndex[k]] = placedU[k];
            grid.v[placedIndex[k]] = placedV[k];
        }
    }

    // Whether the last iteration's fold repair spread (FoldRepair::restart).
    bool lastRepairSpread = false;

    // Up to `planned` iterations (fewer once converged), counted into stats.
    void run(int32_t planned) {
        const int32_t allowed = omp_get_max_threads();
        stats.converged = false;
        for (int32_t n = 0; n < planned && !stats.converged; ++n) {
            const int32_t team =
                options.threads > 0 ? std::min(options.threads, allowed) : this->team.next(allowed);
            omp_set_num_threads(team);
            const bool chosen = options.threads == 0;
            const double cpuBefore = chosen && team > 1 ? detail::teamCpuSeconds() : 0.0;
            const auto start = std::chrono::steady_clock::now();
            stats.lastMove = iterate(n, planned) * static_cast<float>(cells);
            if (chosen) {
                const double seconds =
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                const double share = team > 1 && seconds > 0.0
                                         ? (detail::teamCpuSeconds() - cpuBefore) / (seconds * team)
                                         : 1.0;
                this->team.record(team, seconds, share);
            }
            stats.threads = team;
            ++stats.iterations;
            stats.converged = options.tolerance > 0.0f && stats.lastMove <= options.tolerance;
        }
        omp_set_num_threads(allowed);
    }

    // Levels that iteration n of a run of `planned` iterations sweeps: all of them first, then one coarsest
    // level fewer each iteration, down to kCascadeFloor levels (UV-38). The coarse levels carry the
    // large-scale motion early; swept every iteration, their own fixed point (segments spanning many cells,
    // measured as chords of the surface) pulls the fine solution away from its optimum, more with each
    // iteration. A run of fewer than kCascadeRun iterations (the live presets' frames, whose schedules lean
    // on the coarse sweeps) sweeps every level throughout.
    [[nodiscard]] size_t levelsSwept(int32_t n, int32_t planned) const {
        const size_t all = levels.size();
        if (planned < kCascadeRun) return all;
        return std::max(std::min(all, kCascadeFloor), all - std::min(all, static_cast<size_t>(n)));
    }

    // Iteration n of a run of `planned`; returns the largest distance a point moved, in fine-grid uv units.
    float iterate(int32_t n, int32_t planned) {
        const float keep = 1.0f - options.damping;
        // §4.1 steps 1-2: damping and prediction (explicit Euler, unit time step, no external force). Points
        // that may not move are left out here and in the integration: their velocity stays 0, and velU, velV
        // hold no position of theirs (revertFolds never moves them).
        const Level& finest = levels[0];
        maxOverMovable(finest, [&](int32_t i, int32_t j) {
            const size_t k = finest.index(i, j);
            const float du = keep * velU[k], dv = keep * velV[k];
            velU[k] = grid.u[k];  // the position before prediction, until integration
            velV[k] = grid.v[k];
            grid.u[k] += du;
            grid.v[k] += dv;
            return 0.0f;
        });
        stats.untangledPoints += detail::untangle(*this, levels[0]);
        // Step 3, hierarchical (§4.4): coarsest level first; then propagate, smooth, and go finer.
        // Every level's points are recorded before any level moves, so the displacement a level hands down
        // includes what it received from the levels above it.
        const size_t swept = levelsSwept(n, planned);
        for (size_t l = 1; l < swept; ++l)
            snapshot(levels[l]);
        for (size_t l = swept; l-- > 0;) {
            Level& level = levels[l];
            const float stiffness =
                l == 0 ? 1.0f
                       : std::pow(options.coarseStiffness, static_cast<float>(l)) * options.coarseRelaxation;
            const int32_t sweeps = sweepsAt(l);
            detail::KernelLevel points = inPlace(level);
            if (l > 0 && sweeps > 0) points = gather(level);
            sweepLevel(points, stiffness, sweeps);
            if (points.u != grid.u.data()) scatter(level);
            if (l > 0) {
                Level& finer = levels[l - 1];
                propagate(level, finer, points);
                regulariseAll(finer, true);
                stats.untangledPoints += detail::untangle(*this, finer);
            }
        }
        // Step 4: regularisation (Eq. 4-5) on the finest grid.
        regulariseAll(levels[0], false);
        // Prediction and propagation move points without the fold check of the projection and the
        // regularisation, and the neighbours' mean (untangle) does not always repair what they fold: points
        // of triangles still folded go back to where the iteration found them (velU, velV), so every
        // iteration ends fold-free and a point the steps fight over stops moving (UV-16).
        const detail::FoldRepair repair = detail::revertFolds(*this, velU.data(), velV.data());
        stats.revertedPoints += repair.reverted;
        stats.shortenedSteps += repair.shortened ? 1 : 0;
        stats.shortenedEverywhere += repair.everywhere ? 1 : 0;
        lastRepairSpread = repair.restart;
        // Step 5: integration, without velocities after a repair that spread (revertFolds). The largest move
        // is a max, the same whatever the order: bit-identical for any thread count.
        const float keepVelocity = repair.restart ? 0.0f : 1.0f;
        const float largest = maxOverMovable(finest, [&](int32_t i, int32_t j) {
            const size_t k = finest.index(i, j);
            const float du = grid.u[k] - velU[k], dv = grid.v[k] - velV[k];
            velU[k] = keepVelocity * du;
            velV[k] = keepVelocity * dv;
            return du * du + dv * dv;
        });
        return std::sqrt(largest);
    }

    // What an iteration works in besides the warp: the velocities (zero), the coarse levels' snapshots and
    // the compact copy a coarse level is swept in. A warm-started solver keeps them between solves (the
    // velocities carry over); one that solves every frame from the identity holds them only during a solve,
    // so that the redirect map and the delivered figures made after it (and the next tile of a shot) reuse
    // their memory, or keeps them (keepSolveState): reset() and startFrom() zero the velocities, and the
    // snapshots and working copies are written before they are read.
    void allocateSolveState() {
        const size_t n = grid.numPoints();
        if (velU.size() == n) return;
        deformkit::detail::assignLarge(velU, n, 0.0f);
        deformkit::detail::assignLarge(velV, n, 0.0f);
        for (size_t l = 1; l < levels.size(); ++l) {
            Level& level = levels[l];
            const size_t count = static_cast<size_t>(level.side()) * level.side();
            deformkit::detail::assignLarge(level.snapshotU, count, 0.0f);
            deformkit::detail::assignLarge(level.snapshotV, count, 0.0f);
            if (l == 1) {  // the largest coarse level: its points fit every coarser level's
                deformkit::detail::assignLarge(workU, count, 0.0f);
                deformkit::detail::assignLarge(workV, count, 0.0f);
            }
        }
    }
    void releaseSolveState() {
        const auto release = [](std::vector<float>& values) { std::vector<float>().swap(values); };
        release(velU);
        release(velV);
        release(workU);
        release(workV);
        for (Level& level : levels) {
            release(level.snapshotU);
            release(level.snapshotV);
        }
    }

    // `rigidity` becomes the finest level's map (pass it with std::move to keep one copy).
    void buildMaps(PointField rigidity, const PointField& mask, PointField orientation);
    static void findLevelRuns(Level& level, int32_t fineCells);
};

void Solver::Impl::buildMaps(PointField rigidity, const PointField& mask, PointField orientation) {
    detail::requireField(rigidity, cells, 1, source, "rigidity");
    detail::requireField(mask, cells, 1, source, "mask");
    if (!orientation.values.empty()) detail::requireField(orientation, cells, 1, source, "orientation map");
    // The first value outside [0, 1], found in parallel (the least index over the threads').
    const auto values = static_cast<int64_t>(rigidity.values.size());
    int64_t firstBad = values;
#pragma omp parallel for schedule(static) reduction(min \
                                                    : firstBad) if (kParallelRows * kParallelRows < values)
    for (int64_t k = 0; k < values; ++k) {
        const float r = rigidity.values[k];
        if (!(r >= 0.0f && r <= 1.0f)) firstBad = std::min(firstBad, k);
    }
    if (firstBad < values) {
        throw InvalidInput(formatError(source, "rigidity at grid point " + std::to_string(firstBad),
                                       std::to_string(rigidity.values[firstBad]), "a value in [0, 1]"));
    }
    const bool oriented = !orientation.values.empty();
    for (Level& level : levels) {
        const size_t count = static_cast<size_t>(level.side()) * level.side();
        if (&level == &levels.front())
            level.rigidity = std::move(rigidity.values);  // R of the finest level: the map itself
        else
            deformkit::detail::assignLarge(level.rigidity, count, 0.0f);
        if (!oriented) {
            level.orientation.clear();
            level.orientation.shrink_to_fit();
        } else if (&level == &levels.front()) {
            level.orientation = std::move(orientation.values);  // the map itself, clamped below
        } else {
            deformkit::detail::assignLarge(level.orientation, count, 1.0f);
        }
    }
    // Per point of the level being built from: may it move (mask, Eq. 8, and not on the tile border)?
    // Written into Level::rigidity as kFixed - R once the next level's blur (Eq. 7) has read the level's R.
    std::vector<uint8_t> movable, coarser;
    deformkit::detail::assignLarge(movable, static_cast<size_t>(side()) * side(), uint8_t{0});
    const auto markFixed = [](Level& level, const std::vector<uint8_t>& canMove) {
        const auto count = static_cast<int64_t>(canMove.size());
#pragma omp parallel for schedule(static) if (kParallelRows * kParallelRows < count)
        for (int64_t k = 0; k < count; ++k)
            if (canMove[k] == 0) level.rigidity[k] = detail::fixedRigidity(level.rigidity[k]);
    };
    Level& finest = levels[0];
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(cells))
    for (int32_t j = 0; j <= cells; ++j) {
        for (int32_t i = 0; i <= cells; ++i) {
            const size_t k = finest.index(i, j);
            const bool border = i == 0 || j == 0 || i == cells || j == cells;
            movable[k] = (!border && mask.values[k] >= 0.5f) ? 1 : 0;
            if (!finest.orientation.empty())
                finest.orientation[k] = std::clamp(finest.orientation[k], 0.0f, 1.0f);
        }
    }
    // Eq. 7 (rigidity and orientation blurred by K_G) and Eq. 8 (mask min over 3x3), then subsampled.
    for (size_t l = 1; l < levels.size(); ++l) {
        const Level& from = levels[l - 1];
        Level& to = levels[l];
        const int32_t fc = from.cells;
        const bool mapped = !from.orientation.empty();
        coarser.assign(static_cast<size_t>(to.side()) * to.side(), 0);
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(to.cells))
        for (int32_t j = 0; j <= to.cells; ++j) {
            for (int32_t i = 0; i <= to.cells; ++i) {
                float r = 0.0f, o = 0.0f;
                uint8_t m = 1;
                for (int dj = -1; dj <= 1; ++dj) {
                    for (int di = -1; di <= 1; ++di) {
                        const int32_t si = std::clamp(2 * i + di, 0, fc), sj = std::clamp(2 * j + dj, 0, fc);
                        const size_t q = from.index(si, sj);
                        const float w = kGauss[di + 1] * kGauss[dj + 1];
                        r += w * from.rigidity[q];
                        if (mapped) o += w * from.orientation[q];
                        m = std::min(m, movable[q]);
                    }
                }
                const size_t k = to.index(i, j);
                const bool border = i == 0 || j == 0 || i == to.cells || j == to.cells;
                to.rigidity[k] = r;
                if (mapped) to.orientation[k] = o;
                coarser[k] = border ? 0 : m;
            }
        }
        markFixed(levels[l - 1], movable);
        movable.swap(coarser);
    }
    markFixed(levels.back(), movable);
    for (Level& level : levels)
        findLevelRuns(level, cells);
}

void detail::findSetRuns(Level& level, int32_t fineCells) {
    const int32_t c = level.cells;
    const float least = detail::leastRigidity(c, fineCells);
    const size_t side = static_cast<size_t>(level.side());
    // Per row and set, the runs of segments it projects. A gap shorter than a pair of lanes costs a sweep
    // nothing (the pair is computed whole), so runs are merged across it. Whether the segment of each edge
    // type at each cell of the row is projected is found first, for the whole row in loops that vectorise,
    // then the runs of cells of each type; a set takes the cells i = first + g step of its type's runs (every
    // second or fourth cell), merged by RunMerger as every kind of run is: the same runs as testing each of
    // its segments on its own.
    collectRuns(
        c, detail::kSets,
        [&](int32_t j, std::vector<int32_t>& out, int32_t* count, RowScratch& scratch) {
            std::vector<uint8_t>& projected = scratch.bytes;
            std::vector<int32_t>(&typeRuns)[4] = scratch.typeRuns;
            projected.resize(static_cast<size_t>(c));
            for (int32_t type = 0; type < 4; ++type) {
                const detail::EdgeType e = detail::kEdgeTypes[type];  // ends on rows j, j + 1 <= c
                const float* __restrict a = level.rigidity.data() + (j + e.aj) * side + e.ai;
                const float* __restrict b = level.rigidity.data() + (j + e.bj) * side + e.bi;
                uint8_t* __restrict p = projected.data();
                const int32_t n = c;  // locals: the byte stores could alias the captured ones
                const float floor = least;
                for (int32_t i = 0; i < n; ++i)
                    p[i] = detail::segmentProjected(a[i], b[i], floor) ? 1 : 0;
                typeRuns[type].clear();
                appendByteRuns(p, n, 0, typeRuns[type]);
            }
            for (int32_t set = 0; set < detail::kSets; ++set) {
                const int32_t type = detail::kSetType[set], first = detail::kSetFirst[set];
                const int32_t step = detail::setStep(type);
                int32_t gMin = 0, gMax = 0;
                detail::setLanes(type, first, j, c, gMin, gMax);
                // The first g with first + g step >= i.
                const auto firstAtOrAfter = [&](int32_t i) {
                    return i <= first ? 0 : (i - first + step - 1) / step;
                };
                RunMerger merger{out, kRunGapLanes};
                const std::vector<int32_t>& cellRuns = typeRuns[type];
                for (size_t r = 0; r < cellRuns.size(); r += 2) {
                    const int32_t ga = std::max(gMin, firstAtOrAfter(cellRuns[r]));
                    const int32_t gb = std::min(gMax, firstAtOrAfter(cellRuns[r + 1]));
                    if (ga < gb) merger.add(ga, gb);
                }
                count[set] = merger.finish();
            }
        },
        level.setRunBegin, level.setRuns);
}

void Solver::Impl::findLevelRuns(Level& level, int32_t fineCells) {
    detail::findSetRuns(level, fineCells);
    detail::findMovableRuns(level);
}

void detail::findMovableRuns(Level& level) {
    const int32_t c = level.cells;
    const size_t side = static_cast<size_t>(level.side());
    const float* rigidity = level.rigidity.data();  // movable: >= 0 (Level::movable)
    findRuns(
        c + 1, c + 1,
        [&](int32_t j, uint8_t* __restrict out) {
            const float* __restrict r = rigidity + j * side;
            const int32_t n = c + 1;
            for (int32_t i = 0; i < n; ++i)
                out[i] = r[i] >= 0.0f ? 1 : 0;
        },
        level.movableBegin, level.movableRuns);
    findRuns(
        c, c,
        [&](int32_t j, uint8_t* __restrict out) {
            const float* __restrict r0 = rigidity + j * side;
            const float* __restrict r1 = r0 + side;
            const int32_t n = c;
            for (int32_t i = 0; i < n; ++i)
                out[i] =
                    (r0[i] >= 0.0f) | (r0[i + 1] >= 0.0f) | (r1[i] >= 0.0f) | (r1[i + 1] >= 0.0f) ? 1 : 0;
        },
        level.cellRunBegin, level.cellRuns);
}

Solver::Solver(PointField restGeometry, PointField rigidity, const PointField& mask,
               const SolverOptions& options, PointField orientation, const std::string& source)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.source = source;
    m.options = options;
    // The grid is the maps' (rigidity, mask); f_O is a geometry image of the grid's cells or half of them.
    const bool halfImage = rigidity.cells == 2 * restGeometry.cells && restGeometry.cells >= 2;
    m.cells = halfImage ? rigidity.cells : restGeometry.cells;
    m.sweeps = options.sweepsPerLevel.empty() ? defaultSweeps(m.cells) : options.sweepsPerLevel;
    if (!isPowerOfTwo(m.cells) || m.cells < 2) {
        throw InvalidInput(formatError(source, "grid", std::to_string(m.cells) + " cells per side",
                                       "a power of two, at least 2"));
    }
    if (m.cells > kMaxGridCells) {
        throw InvalidInput(formatError(source, "grid", std::to_string(m.cells) + " cells per side",
                                       "at most " + std::to_string(kMaxGridCells)));
    }
    detail::requireField(restGeometry, halfImage ? m.cells / 2 : m.cells, 3, source, "rest geometry image");
    m.blockDone =
        std::vector<std::atomic<int32_t>>(static_cast<size_t>(detail::mostWavefrontBlocks(m.cells)));
    checkOptions(options, source);
    int32_t levelCount = options.levels;
    if (levelCount == 0) {
        // Down to an 8-cell grid, but no level whose cells are wider than a third of the widest chart's
        // half-width: coarser cells straddle charts and pinned borders, and on real layouts they cost
        // quality (UV-18).
        detail::requireField(mask, m.cells, 1, source, "mask");
        const int32_t widestStride = std::max(widestChartRadius(mask) / 3, 1);
        levelCount = 1;
        while ((m.cells >> levelCount) >= 8 && (1 << levelCount) <= widestStride &&
               (options.maxLevels == 0 || levelCount < options.maxLevels))
            ++levelCount;
    }
    levelCount = std::min(levelCount, static_cast<int32_t>(std::log2(m.cells)));
    levelCount = std::max(levelCount, 1);
    m.levels.resize(levelCount);
    for (int32_t l = 0; l < levelCount; ++l) {
        Level& level = m.levels[l];
        level.cells = m.cells >> l;
        level.stride = 1 << l;
    }
    m.rest = std::move(restGeometry);
    for (Level& level : m.levels) {
        if (!m.options.warmStart || level.stride < detail::kCompactRestStride) continue;
        const int32_t n = level.side();
        const auto imageStride = static_cast<size_t>(imagePointsApart(level, m.cells, m.rest.cells));
        const size_t imageSide = static_cast<size_t>(m.rest.cells) + 1;
        level.rest.resize(3 * static_cast<size_t>(n) * n);
        for (int32_t j = 0; j < n; ++j) {
            for (int32_t i = 0; i < n; ++i) {
                const float* from = &m.rest.values[3 * imageStride * (j * imageSide + i)];
                std::copy(from, from + 3, &level.rest[3 * level.index(i, j)]);
            }
        }
    }
    m.untangleWork.reserve(8 * static_cast<size_t>(m.cells + 1));
    m.untangleNext.reserve(8 * static_cast<size_t>(m.cells + 1));
    m.rowFolds.assign(static_cast<size_t>(m.cells) + 1, 0);
    m.buildMaps(std::move(rigidity), mask, std::move(orientation));
    m.grid = WarpGrid::identity(m.cells);
    if (m.options.warmStart) m.allocateSolveState();
    m.stats.levels = levelCount;
}

Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

void Solver::setMaps(PointField rigidity, const PointField& mask, PointField orientation) {
    Impl& m = *impl_;
    m.buildMaps(std::move(rigidity), mask, std::move(orientation));
    // A point the new maps fix stays where it is: without its velocity, prediction would carry it on.
    const detail::Level& finest = m.levels[0];
    for (size_t k = 0; k < m.velU.size(); ++k) {
        if (!finest.movable(k)) {
            m.velU[k] = 0.0f;
            m.velV[k] = 0.0f;
        }
    }
    m.placeListed(false);  // placed points the new mask fixes sit where they are placed from now on
    m.fixedFolds = -1;     // other cells may change now: their folds are counted again
}

std::vector<ReportedFigure> reportedFigures(const SolveStats& s) {
    using Kind = ReportedFigure::Kind;
    return {{"iterations", Kind::Count, static_cast<double>(s.iterations)},
            {"levels", Kind::Count, static_cast<double>(s.levels)},
            {"untangled_points", Kind::Count, static_cast<double>(s.untangledPoints)},
            {"reverted_points", Kind::Count, static_cast<double>(s.revertedPoints)},
            {"shortened_steps", Kind::Count, static_cast<double>(s.shortenedSteps)},
            {"shortened_everywhere", Kind::Count, static_cast<double>(s.shortenedEverywhere)},
            {"cold_restart", Kind::Flag, s.coldRestart ? 1.0 : 0.0},
            {"remaining_folds", Kind::Count, static_cast<double>(s.remainingFolds)},
            {"last_move", Kind::Number, static_cast<double>(s.lastMove)},
            {"converged", Kind::Flag, s.converged ? 1.0 : 0.0}};
}

std::vector<int32_t> defaultSweeps(int32_t cells, bool refined) {
    const bool halved = refined && cells >= kHalvedFinestCells;
    if (cells <= 1024)
        return halved ? std::vector<int32_t>{2, 8, kRefinedThirdLevelSweeps, 16}
                      : std::vector<int32_t>{4, 8, 16};
    return {halved ? 2 : 4, 8, 16, 32, 64};
}

SolverOptions liveOptions(int32_t cells) {
    SolverOptions options;
    options.iterations = 1;
    options.coldIterations = cells > 256 && cells <= 512 ? 3 : 2;
    options.warmStart = true;
    options.coarseRelaxation = 1.4f;
    if (cells <= 128) {
        options.sweepsPerLevel = {8, 16, 32};
    } else if (cells <= 256) {
        options.sweepsPerLevel = {3, 8, 12};
    } else if (cells <= 512) {
        options.sweepsPerLevel = {2, 2, 10};
    } else if (cells <= 1024) {
        options.sweepsPerLevel = {1, 1, 10};
    } else {
        options.sweepsPerLevel = {1, 1, 2, 8};
    }
    // From 1024 cells on, the coarsest level has 128 cells (or more, where the charts allow fewer levels).
    for (int32_t coarsest = cells; cells >= 1024 && coarsest >= 128; coarsest /= 2)
        ++options.maxLevels;
    return options;
}

const WarpGrid& Solver::solve(const PointField& deformedGeometry) {
    Impl& m = *impl_;
    detail::requireField(deformedGeometry, m.rest.cells, 3, m.source, "deformed geometry image");
    if (!m.options.warmStart && !m.started) reset();  // startFrom says where this solve starts
    m.allocateSolveState();
    m.deformed = deformedGeometry.values.data();
    m.stats.untangledPoints = 0;
    m.stats.revertedPoints = 0;
    m.stats.shortenedSteps = 0;
    m.stats.shortenedEverywhere = 0;
    m.stats.coldRestart = false;
    m.stats.iterations = 0;
    m.stats.lastMove = 0.0f;
    m.stats.converged = false;
    const int32_t cold = m.options.coldIterations > 0 ? m.options.coldIterations : m.options.iterations;
    const bool warm = !m.fromIdentity;
    m.run(warm ? m.options.iterations : cold);
    // A jam (UV-34): the warm start's last iteration ended with a fold repair that spread. The last frame's
    // warp folds under this frame's motion, and frames after it would stay jammed; the frame is solved
    // again from the identity, as after a cut.
    if (warm && !m.started && m.stats.iterations > 0 && m.lastRepairSpread) {
        reset();
        m.stats.coldRestart = true;
        m.run(cold);
    }
    if (m.stats.iterations > 0) m.fromIdentity = false;
    m.started = false;
    // After an iteration the fold revert has counted them; otherwise the grid is scanned.
    m.stats.remainingFolds = m.stats.iterations > 0 ? m.foldsLeft : countFolds(m.grid);
    m.deformed = nullptr;
    if (!m.options.warmStart && !m.keepState) m.releaseSolveState();
    return m.grid;
}

void Solver::keepSolveState(bool keep) {
    Impl& m = *impl_;
    m.keepState = keep;
    if (!keep && !m.options.warmStart) m.releaseSolveState();
}

void Solver::placePoints(std::span<const int64_t> index, std::span<const float> u, std::span<const float> v) {
    Impl& m = *impl_;
    if (u.size() != index.size() || v.size() != index.size()) {
        throw InvalidInput(formatError(m.source, "placed points",
                                       std::to_string(index.size()) + " indices, " +
                                           std::to_string(u.size()) + " u and " + std::to_string(v.size()) +
                                           " v",
                                       "as many positions as indices"));
    }
    const auto points = static_cast<int64_t>(m.grid.numPoints());
    for (size_t k = 0; k < index.size(); ++k) {
        if (index[k] < 0 || index[k] >= points || (k > 0 && index[k] <= index[k - 1]) ||
            !std::isfinite(u[k]) || !std::isfinite(v[k])) {
            throw InvalidInput(formatError(m.source, "placed point " + std::to_string(k),
                                           "is point " + std::to_string(index[k]) + " at (" +
                                               std::to_string(u[k]) + ", " + std::to_string(v[k]) + ")",
                                           "a grid point below " + std::to_string(points) +
                                               ", after the one before, at a finite position"));
        }
    }
    // The points listed before go back to rest where they are fixed, or all of them while the next solve
    // starts from the identity; then the new ones are placed.
    const int32_t side = m.grid.side();
    const auto n = static_cast<float>(m.cells);
    const Level& finest = m.levels[0];
    for (size_t k = 0; k < m.placedIndex.size(); ++k) {
        if (!m.fromIdentity && finest.movable(static_cast<size_t>(m.placedIndex[k]))) continue;
        const int64_t p = m.placedIndex[k];
        m.grid.u[p] = static_cast<float>(p % side) / n;
        m.grid.v[p] = static_cast<float>(p / side) / n;
    }
    m.placedIndex.clear();
    m.placedU.clear();
    m.placedV.clear();
    for (size_t k = 0; k < index.size(); ++k) {
        const auto i = static_cast<int32_t>(index[k] % side), j = static_cast<int32_t>(index[k] / side);
        if (i == 0 || j == 0 || i == m.cells || j == m.cells) continue;
        m.placedIndex.push_back(index[k]);
        m.placedU.push_back(u[k]);
        m.placedV.push_back(v[k]);
    }
    m.placeListed(m.fromIdentity);
    m.fixedFolds = -1;  // fixed points moved: their cells' folds are counted again
}

void Solver::reset() {
    Impl& m = *impl_;
    m.grid.setIdentity(m.cells);
    m.fromIdentity = true;
    m.placeListed(true);
    m.fixedFolds = m.placedIndex.empty() ? 0 : -1;  // the identity has none; placed points are counted
    std::fill(m.velU.begin(), m.velU.end(), 0.0f);
    std::fill(m.velV.begin(), m.velV.end(), 0.0f);
}

void Solver::startFrom(const WarpGrid& coarser) {
    Impl& m = *impl_;
    if (coarser.cells * 2 != m.cells || coarser.u.size() != coarser.numPoints() ||
        coarser.v.size() != coarser.numPoints() ||
        coarser.numPoints() != static_cast<size_t>(coarser.side()) * coarser.side()) {
        throw InvalidInput(formatError(m.source, "warp to start from",
                                       "has " + std::to_string(coarser.cells) + " cells per side",
                                       std::to_string(m.cells / 2) + ", half the solver's grid"));
    }
    validateWarpGrid(coarser, m.source + ": warp to start from");
    // Point (i, j) of this grid sits at (i / 2, j / 2) of the coarser one: a coarse point, the middle of a
    // coarse edge, or the middle of a coarse cell, which lies on the cell's (i, j)-(i + 1, j + 1) diagonal
    // where the cell is split (grid.h): the mean of the two ends either way.
    const int32_t side = m.grid.side(), coarseSide = coarser.side();
    const auto at = [&](const std::vector<float>& values, int32_t i, int32_t j) {
        return values[static_cast<size_t>(j) * coarseSide + i];
    };
#pragma omp parallel for schedule(static) if (side > detail::kParallelRows)
    for (int32_t j = 0; j < side; ++j) {
        const int32_t j0 = j / 2, j1 = (j + 1) / 2;
        for (int32_t i = 0; i < side; ++i) {
            const int32_t i0 = i / 2, i1 = (i + 1) / 2;
            const size_t k = static_cast<size_t>(j) * side + i;
            m.grid.u[k] = 0.5f * (at(coarser.u, i0, j0) + at(coarser.u, i1, j1));
            m.grid.v[k] = 0.5f * (at(coarser.v, i0, j0) + at(coarser.v, i1, j1));
        }
    }
    std::fill(m.velU.begin(), m.velU.end(), 0.0f);
    std::fill(m.velV.begin(), m.velV.end(), 0.0f);
    m.placeListed(false);
    m.fromIdentity = false;
    m.started = true;
    m.fixedFolds = -1;  // the fixed cells moved with the map: counted again
}

const WarpGrid& Solver::warp() const {
    return impl_->grid;
}
const PointField& Solver::restGeometry() const {
    return impl_->rest;
}
const SolveStats& Solver::stats() const {
    return impl_->stats;
}
int32_t Solver::cells() const {
    return impl_->cells;
}
int32_t Solver::levels() const {
    return static_cast<int32_t>(impl_->levels.size());
}

namespace {

// A 1-channel field of level `level`'s points, value(level, k) at point k.
template <class Value>
PointField levelField(const std::vector<detail::Level>& levels, int32_t level, const std::string& source,
                      Value value) {
    if (level < 0 || level >= static_cast<int32_t>(levels.size())) {
        throw InvalidInput(formatError(source, "level " + std::to_string(level), "is out of range",
                                       "0 to " + std::to_string(levels.size() - 1)));
    }
    const detail::Level& l = levels[static_cast<size_t>(level)];
    PointField out;
    out.cells = l.cells;
    out.channels = 1;
    out.values.resize(l.rigidity.size());
    for (size_t k = 0; k < l.rigidity.size(); ++k)
        out.values[k] = value(l, k);
    return out;
}

}  // namespace

PointField Solver::levelRigidity(int32_t level) const {
    // Fixed points keep their R as kFixed - R.
    return levelField(impl_->levels, level, impl_->source, [](const detail::Level& l, size_t k) {
        return l.movable(k) ? l.rigidity[k] : kFixed - l.rigidity[k];
    });
}

PointField Solver::levelMovable(int32_t level) const {
    return levelField(impl_->levels, level, impl_->source,
                      [](const detail::Level& l, size_t k) { return l.movable(k) ? 1.0f : 0.0f; });
}

}  // namespace deformkit::uvwarp
