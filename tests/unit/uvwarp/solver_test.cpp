#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

#include <omp.h>
#include <catch2/catch.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/uvwarp/solver.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using uvwarp::PointField;
using uvwarp::WarpGrid;

namespace {

// Independent bilinear look-up of a 3-channel field (the test's own, not the solver's).
glm::dvec3 lookup(const PointField& f, double u, double v) {
    const double x = std::clamp(u, 0.0, 1.0) * f.cells, y = std::clamp(v, 0.0, 1.0) * f.cells;
    const int i = std::min(static_cast<int>(x), f.cells - 1), j = std::min(static_cast<int>(y), f.cells - 1);
    const double fx = x - i, fy = y - j;
    auto at = [&](int a, int b) {
        const float* p = &f.values[f.index(a, b)];
        return glm::dvec3(p[0], p[1], p[2]);
    };
    return (1 - fx) * (1 - fy) * at(i, j) + fx * (1 - fy) * at(i + 1, j) + (1 - fx) * fy * at(i, j + 1) +
           fx * fy * at(i + 1, j + 1);
}

// Mean |l_def / l_org - 1| over the 8-connected edges whose rigidity (max of the ends) is >= 0.5.
double rigidStretchError(const WarpGrid& w, const PointField& rest, const PointField& deformed,
                         const PointField& rigidity) {
    const int n = w.cells, side = n + 1;
    double sum = 0.0;
    int count = 0;
    const int offsets[4][4] = {{0, 0, 1, 0}, {0, 0, 0, 1}, {0, 0, 1, 1}, {1, 0, 0, 1}};
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            for (const auto& o : offsets) {
                const int ai = i + o[0], aj = j + o[1], bi = i + o[2], bj = j + o[3];
                if (std::max({ai, bi}) > n || std::max({aj, bj}) > n) continue;
                const size_t a = static_cast<size_t>(aj) * side + ai, b = static_cast<size_t>(bj) * side + bi;
                if (std::max(rigidity.values[a], rigidity.values[b]) < 0.5f) continue;
                const double lOrg = glm::length(lookup(rest, double(bi) / n, double(bj) / n) -
                                                lookup(rest, double(ai) / n, double(aj) / n));
                const double lDef =
                    glm::length(lookup(deformed, w.u[b], w.v[b]) - lookup(deformed, w.u[a], w.v[a]));
                sum += std::abs(lDef / lOrg - 1.0);
                ++count;
            }
    return sum / count;
}

struct Scene {
    PointField rest, deformed, rigidity, mask;
};

Scene stretchedPlane(int32_t cells, float stretch) {
    Scene s;
    s.rest = test::pointField(cells, 3, [](float u, float v, float* p) {
        p[0] = u;
        p[1] = v;
        p[2] = 0.0f;
    });
    s.deformed = test::pointField(cells, 3, [&](float u, float v, float* p) {
        p[0] = stretch * u;
        p[1] = v;
        p[2] = 0.0f;
    });
    s.rigidity =
        test::pointField(cells, 1, [](float u, float v, float* p) { p[0] = test::latticeDisks(u, v); });
    s.mask = test::pointField(cells, 1, [](float, float, float* p) { p[0] = 1.0f; });
    return s;
}

}  // namespace

TEST_CASE("uv warp keeps rigid disks at rest size on a plane stretched 1.5x along u", "[uvwarp]") {
    const Scene s = stretchedPlane(128, 1.5f);
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
    const WarpGrid identity = WarpGrid::identity(128);
    const double before = rigidStretchError(identity, s.rest, s.deformed, s.rigidity);
    const WarpGrid& warp = solver.solve(s.deformed);
    const double after = rigidStretchError(warp, s.rest, s.deformed, s.rigidity);
    INFO("rigid stretch error: identity " << before << ", warp " << after << ", removed "
                                          << 100.0 * (1.0 - after / before) << "%, untangled "
                                          << solver.stats().untangledPoints);
    CHECK(after <= 0.2 * before);  // at least 80% removed
    CHECK(uvwarp::countFolds(warp) == 0);
    CHECK(solver.stats().remainingFolds == 0);
}

TEST_CASE("uv warp under 0.7x compression removes at least half the rigid error", "[uvwarp]") {
    const Scene s = stretchedPlane(128, 0.7f);
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
    const double before = rigidStretchError(WarpGrid::identity(128), s.rest, s.deformed, s.rigidity);
    const WarpGrid& warp = solver.solve(s.deformed);
    const double after = rigidStretchError(warp, s.rest, s.deformed, s.rigidity);
    INFO("compression 0.7: identity " << before << " warp " << after << " untangled "
                                      << solver.stats().untangledPoints);
    CHECK(after <= 0.5 * before);  // at least 50%: a bounded domain cannot grow every feature
    CHECK(uvwarp::countFolds(warp) == 0);
}

namespace {

double maxMove(const WarpGrid& a, const WarpGrid& b) {
    double worst = 0.0;
    for (size_t k = 0; k < a.u.size(); ++k)
        worst = std::max(worst, std::hypot(double(a.u[k]) - b.u[k], double(a.v[k]) - b.v[k]));
    return worst;
}

}  // namespace

TEST_CASE("uv warp: extreme compression keeps every grid triangle positive", "[uvwarp]") {
    for (float squeeze : {0.4f, 0.25f}) {
        const Scene s = stretchedPlane(64, squeeze);
        uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
        for (int frame = 0; frame < 3; ++frame)
            solver.solve(s.deformed);
        INFO("squeeze " << squeeze);
        CHECK(uvwarp::countFolds(solver.warp()) == 0);
    }
}

TEST_CASE("uv warp: masked points and the tile border do not move", "[uvwarp]") {
    Scene s = stretchedPlane(64, 1.5f);
    // A masked vertical stripe through the middle disk's column.
    s.mask = test::pointField(
        64, 1, [](float u, float, float* p) { p[0] = std::abs(u - 0.5f) < 0.05f ? 0.0f : 1.0f; });
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
    const WarpGrid& warp = solver.solve(s.deformed);
    const WarpGrid identity = WarpGrid::identity(64);
    double worstMasked = 0.0, worstBorder = 0.0, moved = 0.0;
    for (int j = 0; j <= 64; ++j)
        for (int i = 0; i <= 64; ++i) {
            const size_t k = static_cast<size_t>(j) * 65 + i;
            const double d = std::hypot(double(warp.u[k]) - identity.u[k], double(warp.v[k]) - identity.v[k]);
            if (s.mask.values[k] < 0.5f) worstMasked = std::max(worstMasked, d);
            if (i == 0 || j == 0 || i == 64 || j == 64) worstBorder = std::max(worstBorder, d);
            moved = std::max(moved, d);
        }
    CHECK(worstMasked == 0.0);
    CHECK(worstBorder == 0.0);
    CHECK(moved > 0.01);  // the rest of the tile did warp
}

TEST_CASE("uv warp: an undeformed pose keeps the identity warp", "[uvwarp]") {
    const Scene s = stretchedPlane(64, 1.0f);  // f_D = f_O
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
    const WarpGrid& warp = solver.solve(s.deformed);
    CHECK(maxMove(warp, WarpGrid::identity(64)) < 1e-6);  // float rounding of the Gaussian blend only
}

TEST_CASE("uv warp: a static pose converges to a static warp with warm start", "[uvwarp]") {
    const Scene s = stretchedPlane(64, 1.5f);
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
    WarpGrid previous = solver.solve(s.deformed);
    double firstChange = 0.0, lastChange = 0.0;
    for (int frame = 1; frame < 12; ++frame) {
        const WarpGrid& current = solver.solve(s.deformed);
        const double change = maxMove(current, previous);
        if (frame == 1) firstChange = change;
        lastChange = change;
        previous = current;
    }
    INFO("warp change per frame: first " << firstChange << ", last " << lastChange << " (texels: x64)");
    CHECK(lastChange < 0.05 / 64.0);  // under a twentieth of a texel per frame once settled
    CHECK(lastChange < 0.25 * firstChange);
}

TEST_CASE("uv warp: without warm start a solve depends on its own frame alone", "[uvwarp]") {
    const Scene a = stretchedPlane(64, 1.5f), b = stretchedPlane(64, 1.3f);
    uvwarp::SolverOptions options;
    options.warmStart = false;
    uvwarp::Solver history(a.rest, a.rigidity, a.mask, options);
    for (int frame = 0; frame < 3; ++frame)
        history.solve(a.deformed);
    const WarpGrid& afterHistory = history.solve(b.deformed);
    uvwarp::Solver fresh(b.rest, b.rigidity, b.mask, options);
    const WarpGrid& alone = fresh.solve(b.deformed);
    CHECK(std::memcmp(afterHistory.u.data(), alone.u.data(), alone.u.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(afterHistory.v.data(), alone.v.data(), alone.v.size() * sizeof(float)) == 0);
    // Warm-started, the same frames give another warp (the frames before it count).
    options.warmStart = true;
    uvwarp::Solver warm(a.rest, a.rigidity, a.mask, options);
    for (int frame = 0; frame < 3; ++frame)
        warm.solve(a.deformed);
    CHECK(maxMove(warm.solve(b.deformed), alone) > 0.01 / 64.0);
}

TEST_CASE("uv warp: a solver that keeps its solve state's memory gives the same bytes", "[uvwarp]") {
    // Without warm start, keepSolveState only keeps the memory: each solve starts from zero velocities (reset
    // or startFrom), as with fresh buffers. Frames a, a, b against a solver that has seen b alone,
    // and a refining solver (one level, started from a coarser warp each frame) against one that frees its
    // state: bit for bit.
    const Scene a = stretchedPlane(64, 1.5f), b = stretchedPlane(64, 1.3f);
    uvwarp::SolverOptions options;
    options.warmStart = false;
    uvwarp::Solver keeping(a.rest, a.rigidity, a.mask, options);
    keeping.keepSolveState(true);
    keeping.solve(a.deformed);
    keeping.solve(a.deformed);
    const WarpGrid afterHistory = keeping.solve(b.deformed);
    uvwarp::Solver fresh(b.rest, b.rigidity, b.mask, options);
    const WarpGrid& alone = fresh.solve(b.deformed);
    CHECK(std::memcmp(afterHistory.u.data(), alone.u.data(), alone.u.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(afterHistory.v.data(), alone.v.data(), alone.v.size() * sizeof(float)) == 0);

    const Scene coarseA = stretchedPlane(32, 1.5f), coarseB = stretchedPlane(32, 1.3f);
    uvwarp::Solver coarse(coarseA.rest, coarseA.rigidity, coarseA.mask, options);
    uvwarp::SolverOptions refine = options;
    refine.iterations = 1;
    refine.levels = 1;
    refine.sweepsPerLevel = {4};
    uvwarp::Solver kept(a.rest, a.rigidity, a.mask, refine), freed(a.rest, a.rigidity, a.mask, refine);
    kept.keepSolveState(true);
    for (const auto& [coarseScene, scene] : {std::pair{&coarseA, &a}, {&coarseA, &a}, {&coarseB, &b}}) {
        const WarpGrid& from = coarse.solve(coarseScene->deformed);
        kept.startFrom(from);
        freed.startFrom(from);
        const WarpGrid& x = kept.solve(scene->deformed);
        const WarpGrid& y = freed.solve(scene->deformed);
        CHECK(std::memcmp(x.u.data(), y.u.data(), y.u.size() * sizeof(float)) == 0);
        CHECK(std::memcmp(x.v.data(), y.v.data(), y.v.size() * sizeof(float)) == 0);
    }
    kept.keepSolveState(false);  // frees it again; the next solve allocates afresh
    kept.startFrom(coarse.solve(coarseB.deformed));
    freed.startFrom(coarse.warp());
    const WarpGrid& x = kept.solve(b.deformed);
    const WarpGrid& y = freed.solve(b.deformed);
    CHECK(std::memcmp(x.u.data(), y.u.data(), y.u.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(x.v.data(), y.v.data(), y.v.size() * sizeof(float)) == 0);
}

TEST_CASE("uv warp: a slow animation changes the warp in proportion", "[uvwarp]") {
    // Stretch ramps 1.30, 1.31, ... : the per-frame warp change stays bounded by a small multiple of the
    // change a 1-frame step causes at a settled state, and never jumps.
    const int n = 64;
    Scene s = stretchedPlane(n, 1.3f);
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
    for (int f = 0; f < 6; ++f)
        solver.solve(s.deformed);  // settle on the first pose
    WarpGrid previous = solver.warp();
    std::vector<double> changes;
    for (int f = 1; f <= 8; ++f) {
        const float stretch = 1.3f + 0.01f * f;
        s.deformed = test::pointField(n, 3, [&](float u, float v, float* p) {
            p[0] = stretch * u;
            p[1] = v;
            p[2] = 0.0f;
        });
        const WarpGrid& current = solver.solve(s.deformed);
        changes.push_back(maxMove(current, previous));
        previous = current;
    }
    const double largest = *std::max_element(changes.begin(), changes.end());
    const double smallest = *std::min_element(changes.begin(), changes.end());
    INFO("per-frame change from " << smallest << " to " << largest);
    CHECK(largest < 4.0 * smallest);
    CHECK(largest < 2.0 / n);  // under two texels for a 0.01 stretch step
}

TEST_CASE("uv warp: the same bytes for 1 and 2 threads", "[uvwarp]") {
    // 64 cells: the sweeps and regularisations of levels over 32 rows run on both threads in 2-row blocks
    // (wavefrontBlockRows, the narrowest blocks), every other loop on one thread (kParallelRows); 256 cells,
    // with the mask fixing stripes and a corner (the solver then visits runs of movable points and cells
    // only), runs the finer levels' other loops on both threads too.
    for (const int32_t cells : {64, 256}) {
        Scene s = stretchedPlane(cells, 0.6f);
        if (cells == 256)
            s.mask = test::pointField(cells, 1, [](float u, float v, float* p) {
                p[0] = (u < 0.3f && v < 0.3f) || std::fmod(u * 7.0f, 1.0f) < 0.15f ? 0.0f : 1.0f;
            });
        const int saved = omp_get_max_threads();
        omp_set_num_threads(1);
        uvwarp::Solver one(s.rest, s.rigidity, s.mask);
        const WarpGrid a = one.solve(s.deformed);
        omp_set_num_threads(2);
        uvwarp::SolverOptions twoThreads;
        twoThreads.threads = 2;  // not chosen per iteration: every iteration on two
        uvwarp::Solver two(s.rest, s.rigidity, s.mask, twoThreads);
        const WarpGrid b = two.solve(s.deformed);
        omp_set_num_threads(saved);
        INFO(cells << " cells");
        CHECK(std::memcmp(a.u.data(), b.u.data(), a.u.size() * sizeof(float)) == 0);
        CHECK(std::memcmp(a.v.data(), b.v.data(), a.v.size() * sizeof(float)) == 0);
        CHECK(one.stats().remainingFolds == 0);
        CHECK(uvwarp::countFolds(a) == 0);
        // The mask fixes what it fixes: those points stay at the identity.
        const WarpGrid identity = WarpGrid::identity(cells);
        size_t fixedMoved = 0;
        for (size_t k = 0; k < a.u.size(); ++k)
            fixedMoved += s.mask.values[k] < 0.5f && (a.u[k] != identity.u[k] || a.v[k] != identity.v[k]);
        CHECK(fixedMoved == 0);
    }
}

TEST_CASE("uv warp: bad solver input names what is wrong", "[uvwarp]") {
    const Scene s = stretchedPlane(64, 1.5f);
    Scene bad = stretchedPlane(48, 1.5f);
    CHECK_THROWS_WITH(uvwarp::Solver(bad.rest, bad.rigidity, bad.mask), Catch::Contains("power of two"));
    PointField wrong = s.rigidity;
    wrong.values.pop_back();
    CHECK_THROWS_WITH(uvwarp::Solver(s.rest, wrong, s.mask), Catch::Contains("rigidity"));
    PointField outOfRange = s.rigidity;
    outOfRange.values[100] = 1.5f;
    CHECK_THROWS_WITH(uvwarp::Solver(s.rest, outOfRange, s.mask), Catch::Contains("grid point 100"));
    // Two bad values, one in each half of the 4,225 points (each of two threads finds one): the first is
    // named.
    outOfRange = s.rigidity;
    outOfRange.values[3000] = -0.5f;
    outOfRange.values[1500] = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(uvwarp::Solver(s.rest, outOfRange, s.mask),
                      Catch::Contains("rigidity at grid point 1500") && Catch::Contains("nan"));
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask);
    CHECK_THROWS_WITH(solver.solve(bad.deformed), Catch::Contains("deformed geometry image"));
    uvwarp::SolverOptions options;
    options.damping = 2.0f;
    CHECK_THROWS_AS(uvwarp::Solver(s.rest, s.rigidity, s.mask, options), InvalidInput);
}

// Each solver option must change the result the way its definition says; a value the solver ignored would
// give equal figures and fail the strict inequalities. The 1.5x stretched plane of the tests above, 64
// cells; the figures in the comments were measured on it.
namespace {

// The schedule the figures of these tests were measured with: 12 iterations of sweeps {1, 2, 4}, one sweep
// per level doubling towards the coarsest as the paper's solve does. An option's effect is the test's
// subject, not the schedule's.
uvwarp::SolverOptions paperSchedule() {
    uvwarp::SolverOptions options;
    options.iterations = 12;
    options.sweepsPerLevel = {1, 2, 4};
    return options;
}

WarpGrid solveWith(const Scene& s, const uvwarp::SolverOptions& options, int frames = 1) {
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask, options);
    for (int f = 0; f < frames; ++f)
        solver.solve(s.deformed);
    return solver.warp();
}

}  // namespace

TEST_CASE("uv warp: non-binary rigidity warps in proportion to it", "[uvwarp][options]") {
    // Disks of rigidity 0, 0.25, 0.5, 1: the error left (measured against the rigid disks) falls strictly
    // with rigidity (1, 0.43, 0.26, 0.14 of the identity's), and rigidity 0 leaves the identity exactly.
    const Scene base = stretchedPlane(64, 1.5f);
    const double before = rigidStretchError(WarpGrid::identity(64), base.rest, base.deformed, base.rigidity);
    std::vector<double> left;
    for (const float r : {0.0f, 0.25f, 0.5f, 1.0f}) {
        Scene s = base;
        for (float& x : s.rigidity.values)
            x *= r;
        const WarpGrid w = solveWith(s, {});
        if (r == 0.0f) CHECK(maxMove(w, WarpGrid::identity(64)) == 0.0);
        left.push_back(rigidStretchError(w, base.rest, base.deformed, base.rigidity) / before);
    }
    INFO("error left: " << left[0] << ", " << left[1] << ", " << left[2] << ", " << left[3]);
    CHECK(left[0] == Approx(1.0));
    CHECK(left[1] < 0.9 * left[0]);
    CHECK(left[2] < 0.9 * left[1]);
    CHECK(left[3] < 0.9 * left[2]);
}

TEST_CASE("uv warp: smoothing evens the warp at rigid points, not elsewhere", "[uvwarp][options]") {
    // Eq. 4's s smooths as-rigid-as-possible points; other points are smoothed fully whatever s is. The
    // mean |discrete Laplacian| of the warp (texels) over rigid points falls with s (0.034, 0.031, 0.022,
    // 0.012 for s = 0, 0.1, 0.5, 1); over the others it stays (0.0627 within 0.1%).
    const int n = 64;
    const Scene base = stretchedPlane(n, 1.5f);
    std::vector<double> rigid, elastic;
    for (const float smoothing : {0.0f, 0.1f, 0.5f, 1.0f}) {
        uvwarp::SolverOptions options = paperSchedule();
        options.smoothing = smoothing;
        const WarpGrid w = solveWith(base, options);
        double sumRigid = 0.0, sumElastic = 0.0;
        int countRigid = 0, countElastic = 0;
        for (int j = 1; j < n; ++j)
            for (int i = 1; i < n; ++i) {
                const size_t k = static_cast<size_t>(j) * (n + 1) + i;
                const double lu =
                    double(w.u[k - 1]) + w.u[k + 1] + w.u[k - n - 1] + w.u[k + n + 1] - 4.0 * w.u[k];
                const double lv =
                    double(w.v[k - 1]) + w.v[k + 1] + w.v[k - n - 1] + w.v[k + n + 1] - 4.0 * w.v[k];
                const double laplacian = std::hypot(lu, lv) * n;
                if (base.rigidity.values[k] >= 0.5f) {
                    sumRigid += laplacian;
                    ++countRigid;
                } else {
                    sumElastic += laplacian;
                    ++countElastic;
                }
            }
        rigid.push_back(sumRigid / countRigid);
        elastic.push_back(sumElastic / countElastic);
    }
    INFO("rigid points: " << rigid[0] << ", " << rigid[1] << ", " << rigid[2] << ", " << rigid[3]);
    for (size_t k = 1; k < rigid.size(); ++k) {
        CHECK(rigid[k] < rigid[k - 1]);
        CHECK(elastic[k] == Approx(elastic[0]).epsilon(0.01));
    }
    CHECK(rigid[3] < 0.5 * rigid[0]);
}

TEST_CASE("uv warp: damping, coarse stiffness and the hierarchy set how far 4 iterations get",
          "[uvwarp][options]") {
    // After 4 iterations from the identity (error left, measured): damping 0, 0.5, 0.9 leaves 0.26, 0.038,
    // 0.056 (velocity removed each iteration slows it; none removed overshoots); coarse stiffness 0.3, 0.9, 1
    // leaves 0.16, 0.038, 0.034 (weaker coarse corrections carry less of the large-scale motion); one level
    // leaves 0.36, two 0.076, the default depth (8-cell coarsest grid, 4 levels, the cascade of UV-38) 0.038.
    const Scene base = stretchedPlane(64, 1.5f);
    const double before = rigidStretchError(WarpGrid::identity(64), base.rest, base.deformed, base.rigidity);
    auto left = [&](const std::function<void(uvwarp::SolverOptions&)>& set) {
        uvwarp::SolverOptions options;
        options.iterations = 4;
        set(options);
        return rigidStretchError(solveWith(base, options), base.rest, base.deformed, base.rigidity) / before;
    };
    const double damping0 = left([](auto& o) { o.damping = 0.0f; });
    const double damping5 = left([](auto& o) { o.damping = 0.5f; });
    const double damping9 = left([](auto& o) { o.damping = 0.9f; });
    INFO("damping: " << damping0 << ", " << damping5 << ", " << damping9);
    CHECK(damping5 < damping0);
    CHECK(damping5 < damping9);
    const double stiff3 = left([](auto& o) { o.coarseStiffness = 0.3f; });
    const double stiff9 = left([](auto& o) { o.coarseStiffness = 0.9f; });
    const double stiff10 = left([](auto& o) { o.coarseStiffness = 1.0f; });
    INFO("coarse stiffness: " << stiff3 << ", " << stiff9 << ", " << stiff10);
    CHECK(stiff3 > 2.0 * stiff9);
    CHECK(stiff10 < stiff9);
    const double one = left([](auto& o) { o.levels = 1; });
    const double two = left([](auto& o) { o.levels = 2; });
    const double deep = left([](auto& o) { o.levels = 0; });
    INFO("levels: 1 " << one << ", 2 " << two << ", default " << deep);
    CHECK(two < 0.5 * one);
    CHECK(deep < 0.75 * two);
}

TEST_CASE("uv warp: coarse relaxation scales the coarse levels' corrections, not the finest's",
          "[uvwarp][options]") {
    const Scene base = stretchedPlane(64, 1.5f);
    const auto same = [](const WarpGrid& a, const WarpGrid& b) { return a.u == b.u && a.v == b.v; };
    const auto with = [&](int32_t levels, float stiffness, float relaxation) {
        uvwarp::SolverOptions options = paperSchedule();
        options.iterations = 2;
        options.levels = levels;
        options.coarseStiffness = stiffness;
        options.coarseRelaxation = relaxation;
        return solveWith(base, options);
    };
    // One level: nothing to relax, the same bytes.
    CHECK(same(with(1, 0.9f, 1.9f), with(1, 0.9f, 1.0f)));
    // Two levels: level 1's factor is stiffness x relaxation, 0.5 x 1.6 = 0.8 (exact in floats): the same
    // bytes as stiffness 0.8 alone, and not those of stiffness 0.5 alone.
    CHECK(same(with(2, 0.5f, 1.6f), with(2, 0.8f, 1.0f)));
    CHECK_FALSE(same(with(2, 0.5f, 1.6f), with(2, 0.5f, 1.0f)));
    // What it is for: a warm-started solve of one iteration a frame, few coarse sweeps (the live presets),
    // gets further per frame. Error left after each of 3 frames of the static pose, measured: without
    // relaxation 0.40, 0.25, 0.19; with 1.4 0.31, 0.19, 0.14.
    const double before = rigidStretchError(WarpGrid::identity(64), base.rest, base.deformed, base.rigidity);
    const auto leftAfterFrames = [&](float relaxation) {
        uvwarp::SolverOptions options;
        options.iterations = 1;
        options.sweepsPerLevel = {1, 1, 4};
        options.coarseRelaxation = relaxation;
        uvwarp::Solver solver(base.rest, base.rigidity, base.mask, options);
        std::vector<double> left;
        for (int f = 0; f < 3; ++f) {
            solver.solve(base.deformed);
            left.push_back(rigidStretchError(solver.warp(), base.rest, base.deformed, base.rigidity) /
                           before);
            CHECK(solver.stats().remainingFolds == 0);
        }
        return left;
    };
    const std::vector<double> plain = leftAfterFrames(1.0f), relaxed = leftAfterFrames(1.4f);
    for (size_t f = 0; f < plain.size(); ++f) {
        INFO("frame " << f + 1 << ": " << plain[f] << " left without relaxation, " << relaxed[f]
                      << " with 1.4");
        CHECK(relaxed[f] < plain[f]);
    }
    // Out of range: below 1 (use coarseStiffness) or above 2.
    for (const float bad : {0.9f, 2.1f}) {
        uvwarp::SolverOptions options;
        options.coarseRelaxation = bad;
        CHECK_THROWS_WITH(
            uvwarp::Solver(base.rest, base.rigidity, base.mask, options),
            Catch::Contains("option coarseRelaxation: is " + std::string(bad < 1 ? "0.9" : "2.1")) &&
                Catch::Contains("(expected a number from 1 to 2)"));
    }
}

TEST_CASE("uv warp: coldIterations runs a solve from the identity longer", "[uvwarp][options]") {
    const Scene base = stretchedPlane(64, 1.5f);
    uvwarp::SolverOptions options;
    options.iterations = 1;
    options.coldIterations = 3;
    uvwarp::Solver warm(base.rest, base.rigidity, base.mask, options);
    const auto iterationsRun = [&] {
        warm.solve(base.deformed);
        return warm.stats().iterations;
    };
    std::vector<int32_t> ran;
    for (int f = 0; f < 3; ++f)
        ran.push_back(iterationsRun());
    warm.reset();  // a cut: the next solve starts from the identity again
    ran.push_back(iterationsRun());
    CHECK(ran == std::vector<int32_t>{3, 1, 1, 3});
    // Without warm start every solve starts from the identity.
    options.warmStart = false;
    uvwarp::Solver cold(base.rest, base.rigidity, base.mask, options);
    for (int f = 0; f < 2; ++f) {
        cold.solve(base.deformed);
        CHECK(cold.stats().iterations == 3);
    }
    // 0 (the default): `iterations` throughout; the same bytes as 3 iterations asked for directly.
    uvwarp::SolverOptions three;
    three.iterations = 3;
    uvwarp::Solver direct(base.rest, base.rigidity, base.mask, three);
    direct.solve(base.deformed);
    CHECK(direct.warp().u == cold.warp().u);
    CHECK(direct.warp().v == cold.warp().v);
    uvwarp::SolverOptions bad;
    bad.coldIterations = -1;
    CHECK_THROWS_WITH(uvwarp::Solver(base.rest, base.rigidity, base.mask, bad),
                      Catch::Contains("option coldIterations: is -1"));
    CHECK(uvwarp::liveOptions(512).coldIterations == 3);
    CHECK(uvwarp::liveOptions(1024).coldIterations == 2);
}

TEST_CASE("uv warp: maxLevels caps the automatic depth, not an explicit one", "[uvwarp][options]") {
    // The plane's one chart fills the tile: the automatic depth goes down to an 8-cell grid, 4 levels at 64
    // cells.
    const Scene base = stretchedPlane(64, 1.5f);
    const auto depth = [&](int32_t levels, int32_t maxLevels) {
        uvwarp::SolverOptions options;
        options.levels = levels;
        options.maxLevels = maxLevels;
        return uvwarp::Solver(base.rest, base.rigidity, base.mask, options).levels();
    };
    CHECK(depth(0, 0) == 4);
    CHECK(depth(0, 2) == 2);
    CHECK(depth(0, 9) == 4);
    CHECK(depth(5, 2) == 5);
    uvwarp::SolverOptions bad;
    bad.maxLevels = -1;
    CHECK_THROWS_WITH(uvwarp::Solver(base.rest, base.rigidity, base.mask, bad),
                      Catch::Contains("option maxLevels: is -1"));
    // The live presets cap it from 1024 cells on, at a 128-cell coarsest grid.
    CHECK(uvwarp::liveOptions(512).maxLevels == 0);
    CHECK(uvwarp::liveOptions(1024).maxLevels == 4);
    CHECK(uvwarp::liveOptions(2048).maxLevels == 5);
    CHECK(uvwarp::liveOptions(4096).maxLevels == 6);
}

TEST_CASE("uv warp: orientation preservation turns rigid segments back to their directions",
          "[uvwarp][options]") {
    // Under a shear (u + 0.5 v, v) a rigid disk keeps its lengths under any turn; §4.2's orientation
    // preservation picks the one nearest its canonical directions. The mean |angle| of the warped rigid
    // u-edges falls with it (0.190, 0.189, 0.159, 0.122 rad for 0, 0.05, 0.5, 1), paid for in stretch. Full
    // preservation keeps 0.64 of the turn, its last iterations sweeping 2 of the 4 levels (UV-38).
    const int n = 64;
    Scene sheared = stretchedPlane(n, 1.0f);
    sheared.deformed = test::pointField(n, 3, [](float u, float v, float* p) {
        p[0] = u + 0.5f * v;
        p[1] = v;
        p[2] = 0.0f;
    });
    std::vector<double> angle;
    for (const float preservation : {0.0f, 0.05f, 0.5f, 1.0f}) {
        uvwarp::SolverOptions options = paperSchedule();
        options.orientationPreservation = preservation;
        const WarpGrid w = solveWith(sheared, options, 3);
        double sum = 0.0;
        int count = 0;
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i < n; ++i) {
                const size_t a = static_cast<size_t>(j) * (n + 1) + i, b = a + 1;
                if (std::max(sheared.rigidity.values[a], sheared.rigidity.values[b]) < 0.5f) continue;
                sum += std::abs(std::atan2(double(w.v[b]) - w.v[a], double(w.u[b]) - w.u[a]));
                ++count;
            }
        angle.push_back(sum / count);
    }
    INFO("mean |angle|: " << angle[0] << ", " << angle[1] << ", " << angle[2] << ", " << angle[3]);
    for (size_t k = 1; k < angle.size(); ++k)
        CHECK(angle[k] < angle[k - 1]);
    CHECK(angle[3] < 0.7 * angle[0]);
}

TEST_CASE("uv warp: the hierarchy's rigidity and masks follow Eq. 7 and 8", "[uvwarp][options]") {
    // Recomputed here from the level below, level by level: R_l = K_G * R_{l-1} at the even points (indices
    // clamped at the tile edge); a point may move when every point of the 3x3 below it may and it is not on
    // the tile border (Eq. 8). The finest level is the maps themselves: R as given, the mask >= 0.5 off the
    // border. A masked stripe and the disks make every rule matter.
    const int n = 64;
    Scene s = stretchedPlane(n, 1.5f);
    s.mask = test::pointField(
        n, 1, [](float u, float, float* p) { p[0] = std::abs(u - 0.55f) < 0.04f ? 0.0f : 1.0f; });
    uvwarp::SolverOptions fourLevels;
    fourLevels.levels = 4;  // the automatic depth stops at 3 for this mask's charts
    uvwarp::Solver solver(s.rest, s.rigidity, s.mask, fourLevels);
    REQUIRE(solver.levels() == 4);
    const PointField r0 = solver.levelRigidity(0), m0 = solver.levelMovable(0);
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const size_t k = static_cast<size_t>(j) * (n + 1) + i;
            const bool border = i == 0 || j == 0 || i == n || j == n;
            CHECK(r0.values[k] == s.rigidity.values[k]);
            CHECK(m0.values[k] == (!border && s.mask.values[k] >= 0.5f ? 1.0f : 0.0f));
        }
    const float gauss[3] = {0.25f, 0.5f, 0.25f};
    int fixedByEq8 = 0;
    for (int l = 1; l < solver.levels(); ++l) {
        const PointField fr = solver.levelRigidity(l - 1), fm = solver.levelMovable(l - 1);
        const PointField cr = solver.levelRigidity(l), cm = solver.levelMovable(l);
        const int fc = fr.cells, c = cr.cells;
        REQUIRE(c * 2 == fc);
        double worst = 0.0;
        for (int j = 0; j <= c; ++j)
            for (int i = 0; i <= c; ++i) {
                double r = 0.0;
                bool movable = true;
                for (int dj = -1; dj <= 1; ++dj)
                    for (int di = -1; di <= 1; ++di) {
                        const int si = std::clamp(2 * i + di, 0, fc), sj = std::clamp(2 * j + dj, 0, fc);
                        const size_t q = static_cast<size_t>(sj) * (fc + 1) + si;
                        r += gauss[di + 1] * gauss[dj + 1] * fr.values[q];
                        movable = movable && fm.values[q] == 1.0f;
                    }
                const bool border = i == 0 || j == 0 || i == c || j == c;
                const size_t k = static_cast<size_t>(j) * (c + 1) + i;
                worst = std::max(worst, std::abs(r - cr.values[k]));
                const bool expected = movable && !border;
                CHECK(cm.values[k] == (expected ? 1.0f : 0.0f));
                const size_t centre = static_cast<size_t>(2 * j) * (fc + 1) + 2 * i;
                fixedByEq8 += !expected && !border && fm.values[centre] == 1.0f ? 1 : 0;
            }
        INFO("level " << l);
        CHECK(worst < 1e-6);
    }
    CHECK(fixedByEq8 > 0);  // points whose own finer point may move but a neighbour may not
    CHECK_THROWS_AS(solver.levelMovable(solver.levels()), InvalidInput);
}

namespace {

// The piecewise-linear map of a warp grid at (u, v): the test's own barycentric look-up in the cell's
// triangle ((i, j), (i + 1, j), (i + 1, j + 1) below its diagonal, (i, j), (i + 1, j + 1), (i, j + 1) above).
glm::dvec2 mapAt(const WarpGrid& w, double u, double v) {
    const int n = w.cells;
    const double x = u * n, y = v * n;
    const int i = std::min(static_cast<int>(x), n - 1), j = std::min(static_cast<int>(y), n - 1);
    const double fx = x - i, fy = y - j;
    const auto p = [&](int a, int b) {
        const size_t k = static_cast<size_t>(b) * (n + 1) + a;
        return glm::dvec2(w.u[k], w.v[k]);
    };
    if (fx >= fy) return p(i, j) + fx * (p(i + 1, j) - p(i, j)) + fy * (p(i + 1, j + 1) - p(i + 1, j));
    return p(i, j) + fy * (p(i, j + 1) - p(i, j)) + fx * (p(i + 1, j + 1) - p(i, j + 1));
}

}  // namespace

TEST_CASE("uv warp: a solve started from a coarser warp starts from its map, fold-free", "[uvwarp]") {
    // A 32-cell warp solved under 0.5x compression (far from the identity), then a 64-cell solver of one
    // warm iteration on its finest level started from it: each point where the coarser map takes it (the
    // test's own look-up), no fold; its solve runs that iteration without a restart, fold-free, and takes the
    // rigid disks nearer their rest lengths.
    const Scene coarse = stretchedPlane(32, 0.5f);
    uvwarp::Solver coarseSolver(coarse.rest, coarse.rigidity, coarse.mask);
    const WarpGrid& from = coarseSolver.solve(coarse.deformed);
    REQUIRE(uvwarp::countFolds(from) == 0);

    const Scene fine = stretchedPlane(64, 0.5f);
    uvwarp::SolverOptions refine;
    refine.iterations = 1;
    refine.levels = 1;
    refine.sweepsPerLevel = {4};
    refine.warmStart = true;
    uvwarp::Solver solver(fine.rest, fine.rigidity, fine.mask, refine);
    solver.startFrom(from);
    const WarpGrid started = solver.warp();
    double worst = 0.0;
    for (int j = 0; j <= 64; ++j)
        for (int i = 0; i <= 64; ++i) {
            const glm::dvec2 expected = mapAt(from, i / 64.0, j / 64.0);
            const size_t k = static_cast<size_t>(j) * 65 + i;
            worst = std::max(worst, glm::length(glm::dvec2(started.u[k], started.v[k]) - expected));
        }
    CHECK(worst < 1e-6);
    CHECK(uvwarp::countFolds(started) == 0);

    const WarpGrid& refined = solver.solve(fine.deformed);
    CHECK(solver.stats().iterations == 1);
    CHECK_FALSE(solver.stats().coldRestart);
    CHECK(uvwarp::countFolds(refined) == 0);
    CHECK(rigidStretchError(refined, fine.rest, fine.deformed, fine.rigidity) <
          rigidStretchError(started, fine.rest, fine.deformed, fine.rigidity));

    // A warp of the wrong size, or not finite, is refused with what was expected.
    CHECK_THROWS_WITH(solver.startFrom(WarpGrid::identity(16)),
                      Catch::Contains("32, half the solver's grid"));
    WarpGrid broken = WarpGrid::identity(32);
    broken.u[40] = std::nanf("");
    CHECK_THROWS_AS(solver.startFrom(broken), InvalidInput);
}
