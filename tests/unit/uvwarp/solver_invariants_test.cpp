// Invariants of the UV-warp solver on any input, over random cases with a fixed seed:
// every grid triangle keeps its orientation (counted here, not by the solver), no value is NaN, the tile
// border and masked points stay where they are. And the convergence stop (SolverOptions::tolerance) and the
// choice of OpenMP team (SolverOptions::threads).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "deformkit/uvwarp/solver.h"
#include "uvwarp/team_chooser.h"

using namespace deformkit;
using uvwarp::PointField;
using uvwarp::WarpGrid;

namespace {

PointField zeros(int32_t cells, int32_t channels) {
    PointField out;
    out.cells = cells;
    out.channels = channels;
    out.values.assign(static_cast<size_t>(cells + 1) * (cells + 1) * channels, 0.0f);
    return out;
}

// Grid triangles with signed area <= 0, both diagonal splittings of every cell, in double precision.
int foldedTriangles(const WarpGrid& w) {
    const int n = w.cells, side = n + 1;
    const auto orient = [&](size_t a, size_t b, size_t c) {
        return (double(w.u[b]) - w.u[a]) * (double(w.v[c]) - w.v[a]) -
               (double(w.v[b]) - w.v[a]) * (double(w.u[c]) - w.u[a]);
    };
    int folds = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const size_t a = static_cast<size_t>(j) * side + i, b = a + 1, c = a + side + 1, d = a + side;
            folds += (orient(a, b, c) <= 0) + (orient(a, c, d) <= 0) + (orient(a, b, d) <= 0) +
                     (orient(b, c, d) <= 0);
        }
    return folds;
}

// A random case: a rest surface (a plane, or a bumpy sheet), a deformed one made of a random affine map, a
// bend, and noise up to collapsing, folding or tearing f_D; rigidity as random disks, some fractional;
// a mask with random holes, stripes and single pinned points; random solver options.
struct Case {
    PointField rest, deformed, rigidity, mask;
    uvwarp::SolverOptions options;
};

Case randomCase(std::mt19937& rng, int32_t cells) {
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const auto range = [&](float lo, float hi) { return lo + (hi - lo) * unit(rng); };
    Case c;
    c.rest = zeros(cells, 3);
    c.deformed = zeros(cells, 3);
    c.rigidity = zeros(cells, 1);
    c.mask = zeros(cells, 1);
    const float bump = unit(rng) < 0.5f ? 0.0f : range(0.0f, 0.3f);
    const float a = range(0.3f, 2.5f), b = range(-0.8f, 0.8f), d = range(0.3f, 2.5f);
    const float bend = range(-2.0f, 2.0f), noise = unit(rng) < 0.3f ? range(0.0f, 0.05f) : 0.0f;
    const bool collapse = unit(rng) < 0.2f;  // a band of f_D squeezed to a line
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    struct Disk {
        float u, v, r, value;
    };
    std::vector<Disk> disks(static_cast<size_t>(range(1.0f, 12.0f)));
    for (Disk& k : disks)
        k = {unit(rng), unit(rng), range(0.03f, 0.2f), unit(rng) < 0.7f ? 1.0f : range(0.2f, 1.0f)};
    std::vector<Disk> holes(static_cast<size_t>(range(0.0f, 4.0f)));
    for (Disk& k : holes)
        k = {unit(rng), unit(rng), range(0.0f, 0.1f), 0.0f};
    const float stripe = unit(rng) < 0.3f ? range(0.2f, 0.8f) : -1.0f;
    const float pinned = unit(rng) < 0.3f ? 0.02f : 0.0f;
    for (int32_t j = 0; j <= cells; ++j) {
        for (int32_t i = 0; i <= cells; ++i) {
            const size_t k = c.rigidity.index(i, j);
            const float u = static_cast<float>(i) / cells, v = static_cast<float>(j) / cells;
            float* r = &c.rest.values[3 * k];
            r[0] = u;
            r[1] = v;
            r[2] = bump * std::sin(7.0f * u) * std::cos(5.0f * v);
            float* p = &c.deformed.values[3 * k];
            const float x = a * u + b * v, y = d * v;
            p[0] = x * std::cos(bend * v);
            p[1] = y;
            p[2] = r[2] + x * std::sin(bend * v);
            if (collapse && std::abs(u - 0.5f) < 0.1f) p[0] = a * 0.5f;
            for (int q = 0; q < 3; ++q)
                p[q] += noise * gauss(rng);
            float rigid = 0.0f;
            for (const Disk& disk : disks)
                if (std::hypot(u - disk.u, v - disk.v) < disk.r) rigid = std::max(rigid, disk.value);
            c.rigidity.values[k] = rigid;
            bool movable = true;
            for (const Disk& hole : holes)
                movable &= std::hypot(u - hole.u, v - hole.v) >= hole.r;
            movable &= std::abs(u - stripe) > 0.01f;
            movable &= unit(rng) >= pinned;
            c.mask.values[k] = movable ? 1.0f : 0.0f;
        }
    }
    c.options.iterations = static_cast<int32_t>(range(1.0f, 8.0f));
    c.options.damping = range(0.0f, 1.0f);
    c.options.coarseStiffness = range(0.5f, 1.0f);
    c.options.orientationPreservation = range(0.0f, 0.3f);
    c.options.smoothing = range(0.0f, 1.0f);
    c.options.coarseRelaxation = range(1.0f, 2.0f);
    return c;
}

// The flat unit square (f_O = f_D = (u, v, 0)) with rigidity 0 and nothing movable: tests fill in the rest.
Case planeCase(int32_t cells) {
    Case c;
    c.rest = zeros(cells, 3);
    c.rigidity = zeros(cells, 1);
    c.mask = zeros(cells, 1);
    for (int32_t j = 0; j <= cells; ++j)
        for (int32_t i = 0; i <= cells; ++i) {
            const size_t k = c.mask.index(i, j);
            c.rest.values[3 * k] = static_cast<float>(i) / cells;
            c.rest.values[3 * k + 1] = static_cast<float>(j) / cells;
        }
    c.deformed = c.rest;
    return c;
}

// The plane stretched along u (x = stretch u + bend v^2), a rigid disk of `radius` at the centre, every point
// movable.
Case stretchedDiskCase(int32_t cells, float stretch, float bend, float radius) {
    Case c = planeCase(cells);
    for (int32_t j = 0; j <= cells; ++j)
        for (int32_t i = 0; i <= cells; ++i) {
            const size_t k = c.mask.index(i, j);
            const float u = static_cast<float>(i) / cells, v = static_cast<float>(j) / cells;
            c.deformed.values[3 * k] = stretch * u + bend * v * v;
            c.rigidity.values[k] = std::hypot(u - 0.5f, v - 0.5f) < radius ? 1.0f : 0.0f;
            c.mask.values[k] = 1.0f;
        }
    return c;
}

// Random cases [first, last) of the fixed seed's sequence (64 and 128 cells, 3 frames each): each frame's
// grid is finite, keeps its border and masked points where they are and has no folded triangle (counted
// here). Returns {cases whose fold repair ran, iterations whose step was shortened around the folds}.
std::array<int, 2> checkRandomCases(int first, int last) {
    std::mt19937 rng(20261202);
    int casesRepaired = 0, shortenedLocally = 0, shortenedEverywhere = 0;
    for (int n = 0; n < last; ++n) {
        const int32_t cells = n % 3 == 0 ? 128 : 64;
        const Case c = randomCase(rng, cells);
        if (n < first) continue;
        uvwarp::Solver solver(c.rest, c.rigidity, c.mask, c.options);
        const WarpGrid identity = WarpGrid::identity(cells);
        for (int frame = 0; frame < 3; ++frame) {
            const WarpGrid& w = solver.solve(c.deformed);
            INFO("case " << n << ", frame " << frame << ", " << cells << " cells");
            bool finite = true;
            double pinnedMove = 0.0;
            for (int32_t j = 0; j <= cells; ++j)
                for (int32_t i = 0; i <= cells; ++i) {
                    const size_t k = c.mask.index(i, j);
                    finite &= std::isfinite(w.u[k]) && std::isfinite(w.v[k]);
                    const bool border = i == 0 || j == 0 || i == cells || j == cells;
                    if (border || c.mask.values[k] < 0.5f)
                        pinnedMove = std::max<double>(
                            pinnedMove, std::hypot(w.u[k] - identity.u[k], w.v[k] - identity.v[k]));
                }
            REQUIRE(finite);
            CHECK(pinnedMove == 0.0);
            CHECK(foldedTriangles(w) == 0);
            CHECK(solver.stats().remainingFolds == 0);
            shortenedLocally += solver.stats().shortenedSteps - solver.stats().shortenedEverywhere;
            shortenedEverywhere += solver.stats().shortenedEverywhere;
        }
        casesRepaired += solver.stats().revertedPoints > 0 || solver.stats().untangledPoints > 0;
    }
    return {casesRepaired, shortenedLocally};
}

}  // namespace

// The cases are hard enough to need the fold repair, its step shortened around the folds among it (else the
// tests would prove nothing about them). The first 16 also run under the sanitizers; all 48 (88 shortened
// iterations, none shortened everywhere) on the plain build.
TEST_CASE("uv warp: no grid triangle folds, nothing is NaN, pinned points stay, on random inputs",
          "[uvwarp][invariants]") {
    const std::array<int, 2> seen = checkRandomCases(0, 16);
    CHECK(seen[0] > 0);
    CHECK(seen[1] > 0);
}

TEST_CASE("uv warp: no grid triangle folds, nothing is NaN, pinned points stay, on more random inputs",
          "[uvwarp][invariants][slow]") {
    const std::array<int, 2> seen = checkRandomCases(16, 48);
    CHECK(seen[0] > 0);
    CHECK(seen[1] > 0);
}

TEST_CASE("uv warp: where shortening the step around the folds is not enough, the whole step is shortened",
          "[uvwarp][invariants]") {
    // Case 99 of a longer run of the random cases above (64 and 128 cells; the only one of 300 whose fold
    // repair spread again after the local shortening, at its second frame): the whole step is shortened, and
    // the grid still ends fold-free.
    std::mt19937 rng(20261202);
    Case c;
    for (int n = 0; n <= 99; ++n)
        c = randomCase(rng, n % 3 == 0 ? 128 : 64);
    uvwarp::Solver solver(c.rest, c.rigidity, c.mask, c.options);
    int32_t everywhere = 0;
    for (int frame = 0; frame < 2; ++frame) {
        const WarpGrid& w = solver.solve(c.deformed);
        everywhere += solver.stats().shortenedEverywhere;
        CHECK(foldedTriangles(w) == 0);
        CHECK(solver.stats().remainingFolds == 0);
    }
    CHECK(everywhere > 0);
}

TEST_CASE("uv warp: the tolerance ends a solve once no point moves farther", "[uvwarp][options]") {
    const int32_t cells = 64;
    const Case c = stretchedDiskCase(cells, 1.5f, 0.0f, 0.2f);
    uvwarp::SolverOptions options;
    options.iterations = 400;
    options.tolerance = 0.01f;
    uvwarp::Solver stopping(c.rest, c.rigidity, c.mask, options);
    stopping.solve(c.deformed);
    const uvwarp::SolveStats stats = stopping.stats();
    INFO("converged after " << stats.iterations << " iterations, last move " << stats.lastMove << " cells");
    REQUIRE(stats.converged);
    CHECK(stats.iterations < 400);
    CHECK(stats.lastMove <= 0.01f);

    // The same schedule without the stop, one iteration short and exactly as long: the last iteration's
    // largest move, measured here, is the reported one, and it is the first below the tolerance.
    options.tolerance = 0.0f;
    options.iterations = stats.iterations;
    uvwarp::Solver full(c.rest, c.rigidity, c.mask, options);
    const WarpGrid last = full.solve(c.deformed);
    CHECK_FALSE(full.stats().converged);
    CHECK(full.stats().iterations == stats.iterations);
    CHECK(std::memcmp(last.u.data(), stopping.warp().u.data(), last.u.size() * sizeof(float)) == 0);
    options.iterations = stats.iterations - 1;
    uvwarp::Solver shorter(c.rest, c.rigidity, c.mask, options);
    const WarpGrid before = shorter.solve(c.deformed);
    double move = 0.0;
    for (size_t k = 0; k < last.u.size(); ++k)
        move = std::max(move, std::hypot(double(last.u[k]) - before.u[k], double(last.v[k]) - before.v[k]));
    CHECK(move * cells == Approx(stats.lastMove).epsilon(1e-4));
    CHECK(shorter.stats().lastMove > 0.01f);

    // A warm-started frame of the settled pose converges too: its run sweeps every level first again
    // (UV-38), which moves it off the state the cascade's last iterations settled, so it takes about as many
    // iterations as from the identity (59 against 61 measured) and stops there.
    options.iterations = 400;
    options.tolerance = 0.01f;
    uvwarp::Solver warm(c.rest, c.rigidity, c.mask, options);
    warm.solve(c.deformed);
    warm.solve(c.deformed);
    INFO("warm-started: " << warm.stats().iterations << " iterations");
    CHECK(warm.stats().converged);
    CHECK(warm.stats().lastMove <= 0.01f);
    CHECK(warm.stats().iterations < 400);

    options.tolerance = 1.5f;
    CHECK_THROWS_WITH(uvwarp::Solver(c.rest, c.rigidity, c.mask, options), Catch::Contains("tolerance"));
}

// The team chooser (core/src/uvwarp/team_chooser.h) on made-up times and CPU shares: it must follow whichever
// team is faster, try the other one now and then, and try less often while the choice holds; while all
// threads get their cores (a share of 0.96 or more, a quiet machine) it never tries one thread.
TEST_CASE("uv warp: the solver's team follows the faster of all threads and one", "[uvwarp][threads]") {
    uvwarp::detail::TeamChooser chooser;
    std::vector<int32_t> teams;
    // allTime, oneTime: seconds a run takes on all threads, on one; share: all threads' CPU share of it.
    const auto run = [&](int32_t allowed, double allTime, double oneTime, double share) {
        const int32_t team = chooser.next(allowed);
        chooser.record(team, team == 1 ? oneTime : allTime, share);
        teams.push_back(team);
        return team;
    };
    // A core taken: all threads 1.3x slower than one, running half the time. All for 8 runs, then one, then
    // one but for rare tries of all.
    for (int k = 0; k < 200; ++k)
        run(2, 1.3, 1.0, 0.5);
    CHECK(std::count(teams.begin(), teams.begin() + 8, 2) == 8);
    CHECK(teams[8] == 1);
    CHECK(teams[9] == 1);
    const auto allRuns = std::count(teams.begin() + 9, teams.end(), 2);
    CHECK(allRuns >= 2);  // it keeps trying
    CHECK(allRuns <= 6);  // tries after 8, 16, 32, 64, 128 runs
    CHECK(chooser.chosen() == 1);
    // The core given back: all threads twice as fast, on their cores. Within the next two tries (128 runs
    // apart at most; the running mean of all threads' times, 1.3 before, needs two runs at 0.5 to fall below
    // 0.8 of one's) it goes back to all threads, and stays there without a try of one.
    teams.clear();
    std::vector<int32_t> choices;
    for (int k = 0; k < 400; ++k) {
        run(2, 0.5, 1.0, 1.0);
        choices.push_back(chooser.chosen());
    }
    CHECK(chooser.chosen() == 2);
    const auto switchedAt = std::find(choices.begin(), choices.end(), 2) - choices.begin();
    CHECK(switchedAt <= 2 * 129);
    CHECK(std::count(teams.begin() + switchedAt + 1, teams.end(), 1) == 0);
    // A core taken again: the share falls, and one thread is tried at once (the tries were due).
    teams.clear();
    for (int k = 0; k < 4; ++k)
        run(2, 1.3, 1.0, 0.5);
    CHECK(std::count(teams.begin(), teams.end(), 1) >= 1);
    // Next to other work, all threads are often about as fast as one and now and then much slower: a
    // near-tie (all threads 0.9 to 1.1 times one, a run in 10 three times one) stays on one thread.
    teams.clear();
    for (int k = 0; k < 300; ++k)
        run(2, k % 10 == 0 ? 3.0 : (k % 2 == 0 ? 0.9 : 1.1), 1.0, 0.6);
    CHECK(chooser.chosen() == 1);
    CHECK(std::count(teams.begin(), teams.end(), 2) <= 12);
    // All threads clearly faster (0.7 of one) on a machine with more cores and one taken: all threads.
    teams.clear();
    for (int k = 0; k < 300; ++k)
        run(2, 0.7, 1.0, 0.8);
    CHECK(chooser.chosen() == 2);
    // A quiet machine: one thread is never timed, however long the job.
    uvwarp::detail::TeamChooser quiet;
    for (int k = 0; k < 300; ++k) {
        const int32_t team = quiet.next(2);
        CHECK(team == 2);
        quiet.record(team, 0.5, 0.97);
    }
    // Next to other work: a short job (a cold frame's few iterations) runs on all threads, then one thread is
    // timed once.
    uvwarp::detail::TeamChooser fresh;
    for (int k = 0; k < 8; ++k) {
        const int32_t team = fresh.next(2);
        CHECK(team == 2);
        fresh.record(team, 0.5, 0.6);
    }
    CHECK(fresh.next(2) == 1);
    // The caller allows one thread: nothing to choose.
    CHECK(chooser.next(1) == 1);
    CHECK(chooser.chosen() == 1);
}

TEST_CASE("uv warp: the same bytes whichever team each iteration runs on", "[uvwarp][threads]") {
    std::mt19937 rng(7);
    const Case c = randomCase(rng, 64);
    uvwarp::SolverOptions options = c.options;
    options.iterations = 6;
    std::vector<WarpGrid> warps;
    for (int32_t threads : {1, 2, 0}) {  // one thread, two, and chosen per iteration
        options.threads = threads;
        uvwarp::Solver solver(c.rest, c.rigidity, c.mask, options);
        solver.solve(c.deformed);
        warps.push_back(solver.solve(c.deformed));
    }
    for (size_t k = 1; k < warps.size(); ++k) {
        CHECK(std::memcmp(warps[0].u.data(), warps[k].u.data(), warps[0].u.size() * sizeof(float)) == 0);
        CHECK(std::memcmp(warps[0].v.data(), warps[k].v.data(), warps[0].v.size() * sizeof(float)) == 0);
    }
}

// The automatic depth (SolverOptions::levels = 0, UV-18): down to an 8-cell grid, but no level whose point
// spacing exceeds a third of the widest chart's half-width, the largest chessboard distance from a movable
// point to a fixed one (mask < 0.5 or the tile border), computed here by brute force.
TEST_CASE("uv warp: the automatic depth follows the widest chart", "[uvwarp][options]") {
    const int32_t cells = 64;
    // Fixed vertical lines every `gap` cells (0: none); then (gap < 0) random fixed rectangles, fixed seed.
    std::mt19937 random(64);
    for (int32_t gap : {0, 40, 24, 12, 6, -1, -2, -3, -4, -5, -6, -7, -8}) {
        Case c = planeCase(cells);
        std::vector<std::array<int32_t, 4>> boxes;  // i0, j0, i1, j1
        for (int32_t b = 0; gap < 0 && b < -gap; ++b) {
            const auto i0 = static_cast<int32_t>(random() % cells),
                       j0 = static_cast<int32_t>(random() % cells);
            boxes.push_back(
                {i0, j0, i0 + static_cast<int32_t>(random() % 6), j0 + static_cast<int32_t>(random() % 20)});
        }
        for (int32_t j = 0; j <= cells; ++j)
            for (int32_t i = 0; i <= cells; ++i) {
                const size_t k = c.mask.index(i, j);
                bool fixedHere = gap > 0 && i % gap == 0;
                for (const auto& box : boxes)
                    fixedHere = fixedHere || (i >= box[0] && i <= box[2] && j >= box[1] && j <= box[3]);
                c.mask.values[k] = fixedHere ? 0.0f : 1.0f;
            }
        const auto fixed = [&](int32_t i, int32_t j) {
            return i == 0 || j == 0 || i == cells || j == cells || c.mask.values[c.mask.index(i, j)] < 0.5f;
        };
        int32_t widest = 0;
        for (int32_t j = 0; j <= cells; ++j)
            for (int32_t i = 0; i <= cells; ++i) {
                if (fixed(i, j)) continue;
                int32_t nearest = 4 * cells;
                for (int32_t b = 0; b <= cells; ++b)
                    for (int32_t a = 0; a <= cells; ++a)
                        if (fixed(a, b))
                            nearest = std::min(nearest, std::max(std::abs(a - i), std::abs(b - j)));
                widest = std::max(widest, nearest);
            }
        int32_t expected = 1;
        while ((cells >> expected) >= 8 && (1 << expected) <= std::max(widest / 3, 1))
            ++expected;
        const uvwarp::Solver solver(c.rest, c.rigidity, c.mask);
        INFO("fixed lines every " << gap << " cells, widest half-width " << widest);
        CHECK(solver.levels() == expected);
        if (gap == 0) CHECK(solver.levels() == 4);  // one chart: down to the 8-cell grid, as before
        if (gap == 6) CHECK(solver.levels() == 1);
    }
}

TEST_CASE("uv warp: points a new mask fixes stay put, and the fold count stays the grid's",
          "[uvwarp][maps]") {
    // A warm-started solve moves points; a new mask then fixes the left half where they moved (away from
    // the identity). The solver skips cells whose corners may not move in its fold scans and counts their
    // folds once after a map change: its count must still be the whole grid's, and the fixed points must
    // not move again.
    const int32_t cells = 64;
    const Case c = stretchedDiskCase(cells, 1.4f, 0.2f, 0.25f);
    uvwarp::SolverOptions options;
    options.iterations = 3;
    uvwarp::Solver solver(c.rest, c.rigidity, c.mask, options);
    solver.solve(c.deformed);
    const WarpGrid before = solver.warp();
    PointField half = c.mask;
    size_t movedThenFixed = 0;
    for (int32_t j = 0; j <= cells; ++j)
        for (int32_t i = 0; i <= cells / 2; ++i) {
            const size_t k = half.index(i, j);
            half.values[k] = 0.0f;
            movedThenFixed += before.u[k] != static_cast<float>(i) / cells;
        }
    REQUIRE(movedThenFixed > 100);
    solver.setMaps(c.rigidity, half, {});
    for (int frame = 0; frame < 2; ++frame) {
        const WarpGrid& w = solver.solve(c.deformed);
        CHECK(solver.stats().remainingFolds == foldedTriangles(w));
        CHECK(solver.stats().remainingFolds == uvwarp::countFolds(w));
        for (int32_t j = 0; j <= cells; ++j)
            for (int32_t i = 0; i <= cells / 2; ++i) {
                const size_t k = half.index(i, j);
                CHECK((w.u[k] == before.u[k] && w.v[k] == before.v[k]));
            }
    }
}

TEST_CASE("uv warp: maps set after construction solve as maps given at construction", "[uvwarp][maps]") {
    // Everything the solver derives from its maps (the levels' rigidity, the runs of points that may move
    // and of the segments each row projects) is rebuilt by setMaps: a solver built with other maps, or none
    // rigid, and given these before its first solve gives the bytes of one built with them. A run of
    // projected segments left from the old maps would leave the new rigid disk's segments unprojected.
    const int32_t cells = 64;
    const Case c = stretchedDiskCase(cells, 1.4f, 0.2f, 0.25f);
    uvwarp::SolverOptions options;
    options.iterations = 3;
    PointField free = c.rigidity, shifted = c.rigidity;
    std::fill(free.values.begin(), free.values.end(), 0.0f);
    for (int32_t j = 0; j <= cells; ++j)  // the disks moved a quarter of the tile
        for (int32_t i = 0; i <= cells; ++i)
            shifted.values[shifted.index(i, j)] =
                c.rigidity.values[c.rigidity.index((i + cells / 4) % (cells + 1), j)];
    uvwarp::Solver reference(c.rest, c.rigidity, c.mask, options);
    for (const PointField* before : {&free, &shifted}) {
        uvwarp::Solver changed(c.rest, *before, c.mask, options);
        changed.setMaps(c.rigidity, c.mask, {});
        for (int frame = 0; frame < 2; ++frame) {
            const WarpGrid& expected = reference.solve(c.deformed);
            const WarpGrid& got = changed.solve(c.deformed);
            CHECK(std::memcmp(got.u.data(), expected.u.data(), 4 * got.u.size()) == 0);
            CHECK(std::memcmp(got.v.data(), expected.v.data(), 4 * got.v.size()) == 0);
        }
        reference.reset();
    }
    // The test can fail: the maps do make a difference.
    uvwarp::Solver other(c.rest, shifted, c.mask, options);
    reference.reset();
    CHECK(std::memcmp(other.solve(c.deformed).u.data(), reference.solve(c.deformed).u.data(),
                      4 * static_cast<size_t>(cells + 1) * (cells + 1)) != 0);
}
