#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include "deformkit/error.h"
#include "deformkit/io/obj.h"
#include "deformkit/uvwarp/inversion.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/tile_warp.h"

using namespace deformkit;

namespace {

// A unit square in the z = 0 plane, n x n quads, its UVs the square scaled into [0.05, 0.95]^2 of tile 1001.
geom::Mesh uvPlane(int n) {
    geom::Mesh::Data d;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float x = float(i) / n, y = float(j) / n;
            d.points.emplace_back(x, y, 0.0f);
            d.uvs.emplace_back(0.05f + 0.9f * x, 0.05f + 0.9f * y);
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i;
            d.faceCounts.push_back(4);
            d.faceIndices.insert(d.faceIndices.end(), {a, a + 1, a + n + 2, a + n + 1});
        }
    d.uvIndices = d.faceIndices;
    return geom::Mesh(std::move(d), "uv plane");
}

// Rigid disks (radius 0.06 in uv) on a 3 x 3 lattice, elastic elsewhere; T x T texels, row 0 at v = 1.
io::Image diskRigidity(int texels) {
    io::Image map(texels, texels, 1);
    for (int y = 0; y < texels; ++y)
        for (int x = 0; x < texels; ++x) {
            const float u = (x + 0.5f) / texels, v = 1.0f - (y + 0.5f) / texels;
            for (float cu : {0.3f, 0.5f, 0.7f})
                for (float cv : {0.3f, 0.5f, 0.7f})
                    if (std::hypot(u - cu, v - cv) < 0.06f) map.at(x, y, 0) = 1.0f;
        }
    return map;
}

// One rigid disk of radius T / 6 texels at the tile's centre, elastic elsewhere; T x T texels.
io::Image centreDisk(int32_t texels) {
    io::Image map(texels, texels, 1);
    for (int32_t y = 0; y < texels; ++y)
        for (int32_t x = 0; x < texels; ++x)
            map.at(x, y, 0) = std::hypot(x + 0.5 - texels / 2.0, y + 0.5 - texels / 2.0) < texels / 6.0;
    return map;
}

// The mesh stretched along x by 1 + 0.5 x: 1x at x = 0 growing to 1.5x at x = 1.
std::vector<glm::vec3> widening(const geom::Mesh& mesh) {
    std::vector<glm::vec3> out(mesh.points().begin(), mesh.points().end());
    for (glm::vec3& p : out)
        p.x *= 1.0f + 0.5f * p.x;
    return out;
}

std::vector<glm::vec3> stretched(const geom::Mesh& mesh, float sx) {
    std::vector<glm::vec3> out(mesh.points().begin(), mesh.points().end());
    for (auto& p : out)
        p.x *= sx;
    return out;
}

// The largest difference between `density` and the density heuristic brute-forced here: the mean of channel
// 0 over the clamped (2r + 1)^2 window of each texel, divided by the largest such mean.
double worstDensityError(const io::Image& rigidity, int r, const io::Image& density) {
    const int w = rigidity.width, h = rigidity.height;
    std::vector<double> mean(static_cast<size_t>(w) * h);
    double largest = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double sum = 0.0;
            int count = 0;
            for (int wy = std::max(0, y - r); wy <= std::min(h - 1, y + r); ++wy)
                for (int wx = std::max(0, x - r); wx <= std::min(w - 1, x + r); ++wx) {
                    sum += rigidity.at(wx, wy, 0);
                    ++count;
                }
            mean[static_cast<size_t>(y) * w + x] = sum / count;
            largest = std::max(largest, sum / count);
        }
    double worst = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            worst = std::max(worst,
                             std::abs(density.at(x, y, 0) - mean[static_cast<size_t>(y) * w + x] / largest));
    return worst;
}

}  // namespace

TEST_CASE("tile warp: a UV-mapped plane stretched 1.5x keeps its rigid disks, folds nothing, inverts",
          "[uvwarp]") {
    const geom::Mesh mesh = uvPlane(32);
    uvwarp::TileWarp tile(mesh, 1001, diskRigidity(128));  // mask derived from the UVs
    tile.solve(stretched(mesh, 1.5f));
    const uvwarp::WarpMetrics m = tile.metrics();
    INFO("rigid stretch error: identity " << m.identityStretchError << ", warp " << m.rigidStretchError);
    CHECK(m.rigidStretchError <= 0.2 * m.identityStretchError);  // at least 80% removed
    CHECK(m.foldOvers == 0);
    CHECK(m.maxMaskedDisplacement == 0.0);
    CHECK(m.maxBorderDisplacement == 0.0);
    CHECK(m.pointsOutside == 0);

    const io::Image redirect = tile.redirect();
    REQUIRE(redirect.width == 128);
    REQUIRE(redirect.channels == 2);
    // W(W^-1(uv)) = uv within half a texel over the tile.
    const uvwarp::InversionError e = uvwarp::inversionError(tile.warp(), redirect);
    INFO("inversion error max " << e.maxTexels << " texels, mean " << e.meanTexels);
    CHECK(e.maxTexels < 0.5);
    // Outside the chart nothing warps: the redirect is the texel's own uv (grid.h texel centres).
    for (int y : {0, 1, 126, 127})
        for (int x : {0, 1, 126, 127}) {
            CHECK(redirect.at(x, y, 0) == Approx((x + 0.5) / 128.0).margin(1e-6));
            CHECK(redirect.at(x, y, 1) == Approx(1.0 - (y + 0.5) / 128.0).margin(1e-6));
        }
}

TEST_CASE("tile warp: the rest pose gives the identity redirect", "[uvwarp]") {
    const geom::Mesh mesh = uvPlane(16);
    uvwarp::TileWarp tile(mesh, 1001, diskRigidity(64));
    tile.solve(mesh.points());
    const io::Image redirect = tile.redirect();
    double worst = 0.0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            worst = std::max(worst, std::abs(redirect.at(x, y, 0) - (x + 0.5) / 64.0));
            worst = std::max(worst, std::abs(redirect.at(x, y, 1) - (1.0 - (y + 0.5) / 64.0)));
        }
    CHECK(worst < 1e-5);
}

TEST_CASE("tile warp: bad maps name the tile and what was expected", "[uvwarp]") {
    const geom::Mesh mesh = uvPlane(8);
    CHECK_THROWS_WITH(uvwarp::TileWarp(mesh, 1001, io::Image(48, 48, 1)), Catch::Contains("power of two"));
    CHECK_THROWS_WITH(uvwarp::TileWarp(mesh, 1001, io::Image(64, 32, 1)), Catch::Contains("square map"));
    CHECK_THROWS_WITH(uvwarp::TileWarp(mesh, 1001, io::Image(64, 64, 1), io::Image(32, 32, 1)),
                      Catch::Contains("the rigidity map's size"));
    // An orientation map is read texel for texel beside the rigidity, as in setMaps and a shot.
    CHECK_THROWS_WITH(uvwarp::TileWarp(mesh, 1001, io::Image(64, 64, 1), {}, {}, io::Image(128, 128, 1)),
                      Catch::Contains("orientation map, UDIM tile 1001") &&
                          Catch::Contains("128 texels per side") &&
                          Catch::Contains("the rigidity map's size"));
    io::Image bad(64, 64, 1);
    bad.at(3, 4, 0) = 2.0f;
    CHECK_THROWS_AS(uvwarp::TileWarp(mesh, 1001, bad), InvalidInput);
    uvwarp::TileWarp tile(mesh, 1001, io::Image(64, 64, 1));
    const std::vector<glm::vec3> wrongCount(5);
    CHECK_THROWS_AS(tile.solve(wrongCount), InvalidInput);
}

TEST_CASE("tile warp: the density heuristic for orientation preservation", "[uvwarp][options]") {
    // densityOrientationMap against a brute-force window mean written here: a rigid left half, a rigid disk
    // on the right; the map is the mean over the clamped (2r + 1)^2 window divided by its largest value.
    const int t = 32, r = 3;
    io::Image rigidity(t, t, 1);
    for (int y = 0; y < t; ++y)
        for (int x = 0; x < t; ++x)
            rigidity.at(x, y, 0) = x < t / 2 || std::hypot(x - 24.0, y - 16.0) < 4.0 ? 1.0f : 0.0f;
    const io::Image density = uvwarp::densityOrientationMap(rigidity, r);
    CHECK(worstDensityError(rigidity, r, density) < 1e-6);
    CHECK(density.at(2, 2, 0) == 1.0f);   // dense: the rigid half
    CHECK(density.at(30, 2, 0) == 0.0f);  // sparse: nothing rigid near
    CHECK(uvwarp::densityOrientationMap(io::Image(8, 8, 1), 2).pixels == std::vector<float>(64, 0.0f));
    CHECK_THROWS_AS(uvwarp::densityOrientationMap(rigidity, 0), InvalidInput);

    // The option is that map painted as the orientation map, bit for bit.
    const geom::Mesh plane = uvPlane(8);
    const std::vector<glm::vec3> squeezed = stretched(plane, 0.5f);  // severe compression
    uvwarp::TileWarpOptions options;
    options.orientationDensity = r;
    uvwarp::TileWarp heuristic(plane, 1001, rigidity, {}, options);
    uvwarp::TileWarp painted(plane, 1001, rigidity, {}, {}, density);
    uvwarp::TileWarp uniform(plane, 1001, rigidity);
    const std::vector<float> a = heuristic.solve(squeezed).u;
    const std::vector<float> b = painted.solve(squeezed).u;
    const std::vector<float> c = uniform.solve(squeezed).u;
    CHECK(a == b);
    CHECK(a != c);
}

TEST_CASE("tile warp: the density map over several column blocks, any thread count", "[uvwarp][options]") {
    // Random rigidity in [0, 1] on a map wider than the implementation's blocks of 64 columns (the last one
    // partial), against the window mean brute-forced here, and the same bytes on 1, 2 and 3 threads.
    const int w = 150, h = 97, r = 7;
    io::Image rigidity(w, h, 1);
    std::mt19937 random(7);
    std::uniform_real_distribution<float> value(0.0f, 1.0f);
    for (float& p : rigidity.pixels)
        p = value(random) < 0.3f ? value(random) : 0.0f;
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    const io::Image one = uvwarp::densityOrientationMap(rigidity, r);
    omp_set_num_threads(2);
    const io::Image two = uvwarp::densityOrientationMap(rigidity, r);
    omp_set_num_threads(3);  // three blocks of columns, one a thread (where three are granted)
    const io::Image three = uvwarp::densityOrientationMap(rigidity, r);
    omp_set_num_threads(threads);
    CHECK(one.pixels == two.pixels);
    CHECK(one.pixels == three.pixels);
    CHECK(worstDensityError(rigidity, r, two) < 1e-6);
    CHECK(*std::max_element(two.pixels.begin(), two.pixels.end()) == 1.0f);
}

TEST_CASE("tile warp: the shot preset's density window by the map's size", "[uvwarp][options]") {
    // 1/16 of the map's texels, at least 1, none on grids of more than 8192 cells (whatever the map's size);
    // an explicit radius is kept.
    STATIC_REQUIRE(uvwarp::orientationDensityFor(uvwarp::kAutomaticDensity, 1024, 1024) == 64);
    STATIC_REQUIRE(uvwarp::orientationDensityFor(uvwarp::kAutomaticDensity, 8192, 8192) == 512);
    STATIC_REQUIRE(uvwarp::orientationDensityFor(uvwarp::kAutomaticDensity, 16384, 16384) == 0);
    STATIC_REQUIRE(uvwarp::orientationDensityFor(uvwarp::kAutomaticDensity, 8192, 16384) == 0);
    STATIC_REQUIRE(uvwarp::orientationDensityFor(uvwarp::kAutomaticDensity, 16384, 8192) == 1024);
    STATIC_REQUIRE(uvwarp::orientationDensityFor(uvwarp::kAutomaticDensity, 8, 8) == 1);
    STATIC_REQUIRE(uvwarp::orientationDensityFor(5, 1024, 16384) == 5);
    STATIC_REQUIRE(uvwarp::orientationDensityFor(0, 1024, 1024) == 0);
    CHECK(uvwarp::shotOptions().orientationDensity == uvwarp::kAutomaticDensity);
    CHECK(uvwarp::presetOptions(uvwarp::Preset::Shot, 256).orientationDensity == uvwarp::kAutomaticDensity);
    CHECK(uvwarp::presetOptions(uvwarp::Preset::Live, 256).orientationDensity == 0);
    CHECK(uvwarp::TileWarpOptions{}.orientationDensity == 0);

    // The automatic window is that radius, bit for bit, and differs from none on a squeezed plane.
    const int t = 64;
    io::Image rigidity(t, t, 1);
    for (int y = 0; y < t; ++y)
        for (int x = 0; x < t; ++x)
            rigidity.at(x, y, 0) =
                std::hypot(x - 20.0, y - 30.0) < 6.0 || std::hypot(x - 44.0, y - 30.0) < 3.0 ? 1.0f : 0.0f;
    const geom::Mesh plane = uvPlane(8);
    const std::vector<glm::vec3> squeezed = stretched(plane, 0.5f);
    const auto solved = [&](int32_t radius) {
        uvwarp::TileWarpOptions options;
        options.orientationDensity = radius;
        uvwarp::TileWarp tile(plane, 1001, rigidity, {}, options);
        return tile.solve(squeezed).u;
    };
    CHECK(solved(uvwarp::kAutomaticDensity) == solved(t / 16));
    CHECK(solved(uvwarp::kAutomaticDensity) != solved(0));

    // A refined tile (the shot preset's grid of twice the cells): the heuristic gives both grids the map a
    // painter would paint, at bind and after setMaps.
    const io::Image density = uvwarp::densityOrientationMap(rigidity, t / 16);
    uvwarp::TileWarpOptions refined;
    refined.refinementSweeps = 2;
    uvwarp::TileWarpOptions heuristic = refined;
    heuristic.orientationDensity = uvwarp::kAutomaticDensity;
    uvwarp::TileWarp byHeuristic(plane, 1001, rigidity, {}, heuristic);
    uvwarp::TileWarp painted(plane, 1001, rigidity, {}, refined, density);
    uvwarp::TileWarp uniform(plane, 1001, rigidity, {}, refined);
    const std::vector<float> a = byHeuristic.solve(squeezed).u;
    CHECK(a == painted.solve(squeezed).u);
    CHECK(a != uniform.solve(squeezed).u);
    io::Image moved(t, t, 1);  // the disks moved: a new density map
    for (int y = 0; y < t; ++y)
        for (int x = 0; x < t; ++x)
            moved.at(x, y, 0) = std::hypot(x - 30.0, y - 20.0) < 6.0 ? 1.0f : 0.0f;
    byHeuristic.setMaps(moved);
    painted.setMaps(moved, {}, uvwarp::densityOrientationMap(moved, t / 16));
    uniform.setMaps(moved);
    const std::vector<float> b = byHeuristic.solve(squeezed).u;
    CHECK(b == painted.solve(squeezed).u);
    CHECK(b != uniform.solve(squeezed).u);
}

namespace {

// The Fox (tests/data/fox, skinned and animated in Blender) and rigid disks of radius 0.02 of the tile on a
// 0.06 lattice, each painted only where its square lies inside the charts.
io::Image foxDisks(const geom::Mesh& fox, int32_t texels) {
    const io::Image mask = uvwarp::deriveWarpMask(fox, 1001, texels);
    io::Image rigidity(texels, texels, 1);
    const float radius = 0.02f * texels, spacing = 0.06f * texels;
    const auto r = static_cast<int32_t>(std::ceil(radius));
    for (float cy = spacing / 2; cy < texels; cy += spacing) {
        for (float cx = spacing / 2; cx < texels; cx += spacing) {
            const auto x0 = static_cast<int32_t>(cx), y0 = static_cast<int32_t>(cy);
            bool inside = x0 - r >= 0 && y0 - r >= 0 && x0 + r < texels && y0 + r < texels;
            for (int32_t y = y0 - r; inside && y <= y0 + r; ++y)
                for (int32_t x = x0 - r; inside && x <= x0 + r; ++x)
                    inside = mask.at(x, y, 0) >= 0.5f;
            for (int32_t y = y0 - r; inside && y <= y0 + r; ++y)
                for (int32_t x = x0 - r; x <= x0 + r; ++x)
                    if (std::hypot(x + 0.5f - cx, y + 0.5f - cy) < radius) rigidity.at(x, y, 0) = 1.0f;
        }
    }
    return rigidity;
}

}  // namespace

TEST_CASE("uv warp: an empty schedule is the grid's default schedule, byte for byte",
          "[uvwarp][options][slow]") {
    // The rule of defaultSweeps, and a solve with sweepsPerLevel empty equal to one with that list spelled
    // out, below and above the size where the default changes.
    CHECK(uvwarp::defaultSweeps(64) == std::vector<int32_t>{4, 8, 16});
    CHECK(uvwarp::defaultSweeps(1024) == std::vector<int32_t>{4, 8, 16});
    CHECK(uvwarp::defaultSweeps(2048) == std::vector<int32_t>{4, 8, 16, 32, 64});
    CHECK(uvwarp::defaultSweeps(16384) == std::vector<int32_t>{4, 8, 16, 32, 64});
    CHECK(uvwarp::defaultSweeps(512, true) == std::vector<int32_t>{4, 8, 16});
    CHECK(uvwarp::defaultSweeps(uvwarp::kHalvedFinestCells, true) == std::vector<int32_t>{2, 8, 64, 16});
    CHECK(uvwarp::defaultSweeps(2048, true) == std::vector<int32_t>{2, 8, 16, 32, 64});
    CHECK(uvwarp::SolverOptions{}.sweepsPerLevel.empty());
    const geom::Mesh plane = uvPlane(8);
    const std::vector<glm::vec3> stretched = widening(plane);
    for (const int32_t texels : {64, 2048}) {
        CAPTURE(texels);
        const io::Image rigidity = centreDisk(texels);
        uvwarp::TileWarpOptions automatic;
        automatic.solver.iterations = 1;
        uvwarp::TileWarpOptions spelled = automatic;
        spelled.solver.sweepsPerLevel = uvwarp::defaultSweeps(texels);
        uvwarp::TileWarp a(plane, 1001, rigidity, {}, automatic);
        uvwarp::TileWarp b(plane, 1001, rigidity, {}, spelled);
        CHECK(a.solve(stretched).u == b.solve(stretched).u);
        CHECK(a.warp().v == b.warp().v);
    }
}

TEST_CASE(
    "uv warp: a refined grid's empty schedule halves its finest sweeps from 1024 cells and sweeps its third "
    "level 64 times at 1024, byte for byte",
    "[uvwarp][options][slow]") {
    // With refinement sweeps, the solved grid's default schedule is defaultSweeps(cells, true): on a grid of
    // kHalvedFinestCells the same warp as {2, 8, 64, 16} spelled out and not the unrefined default's
    // {4, 8, 16}; on a coarser grid the unrefined default's.
    const geom::Mesh plane = uvPlane(8);
    const std::vector<glm::vec3> stretched = widening(plane);
    for (const int32_t texels : {512, uvwarp::kHalvedFinestCells}) {
        CAPTURE(texels);
        const io::Image rigidity = centreDisk(texels);
        uvwarp::TileWarpOptions automatic;
        automatic.solver.iterations = 1;
        automatic.refinementSweeps = 2;
        uvwarp::TileWarpOptions halved = automatic, full = automatic;
        halved.solver.sweepsPerLevel = {2, 8, 64, 16};
        full.solver.sweepsPerLevel = {4, 8, 16};
        const bool halves = texels >= uvwarp::kHalvedFinestCells;
        uvwarp::TileWarp a(plane, 1001, rigidity, {}, automatic);
        uvwarp::TileWarp b(plane, 1001, rigidity, {}, halves ? halved : full);
        uvwarp::TileWarp c(plane, 1001, rigidity, {}, halves ? full : halved);
        const uvwarp::WarpGrid warp = a.solve(stretched);
        CHECK(warp.cells == 2 * texels);  // the refined grid's warp is the one delivered
        CHECK(warp.u == b.solve(stretched).u);
        CHECK(warp.v == b.warp().v);
        CHECK(warp.u != c.solve(stretched).u);
    }
}

TEST_CASE("uv warp: where skinning folds the grid, it ends fold-free, and so do the maps",
          "[uvwarp][invariants]") {
    // The Fox's frame 8 at 512^2 with the default schedule and orientation preservation 0.05: the prediction
    // and propagation fold the triangles around thousands of points (5,157 untangled; shortened steps are
    // tested on random cases, solver_invariants_test.cpp). The solver's grid ends fold-free (counted here),
    // the delivered map has no inverted triangle and no off-chart texel, and the rigid stretch removed is
    // 79.3%, the floor 2 points under.
    const geom::Mesh fox = io::readObj(DEFORMKIT_TEST_DATA "/fox/rest.obj").mesh;
    const io::ObjContent posed = io::readObj(DEFORMKIT_TEST_DATA "/fox/anim.0008.obj");
    const std::vector<glm::vec3> points(posed.mesh.points().begin(), posed.mesh.points().end());
    uvwarp::TileWarpOptions options;
    options.solver.warmStart = false;
    options.solver.orientationPreservation = 0.05f;
    uvwarp::TileWarp warp(fox, 1001, foxDisks(fox, 512), {}, options);
    const uvwarp::WarpGrid& grid = warp.solve(points);
    CHECK(warp.stats().remainingFolds == 0);
    const int32_t n = grid.cells;
    int64_t folds = 0;
    bool finite = true;
    for (int32_t j = 0; j < n; ++j) {
        for (int32_t i = 0; i < n; ++i) {
            const size_t a = static_cast<size_t>(j) * (n + 1) + i, b = a + 1, d = a + n + 1, e = d + 1;
            const auto area = [&](size_t p, size_t q, size_t r) {
                return (double(grid.u[q]) - grid.u[p]) * (double(grid.v[r]) - grid.v[p]) -
                       (double(grid.v[q]) - grid.v[p]) * (double(grid.u[r]) - grid.u[p]);
            };
            folds +=
                (area(a, b, e) <= 0) + (area(a, e, d) <= 0) + (area(a, b, d) <= 0) + (area(b, e, d) <= 0);
            finite &= std::isfinite(grid.u[a]) && std::isfinite(grid.v[a]);
        }
    }
    CHECK(finite);
    CHECK(folds == 0);
    io::Image map;
    warp.redirect(map);
    const uvwarp::DeliveredMetrics delivered = warp.measure(map);
    CHECK(delivered.invertedTriangles == 0);
    CHECK(delivered.offChartTexels == 0);
    CHECK(delivered.removed > 0.77);
}

TEST_CASE("uv warp: texels the painted mask holds stay at their centres through the fold repair",
          "[uvwarp][invariants]") {
    // The Fox running, shot preset, 40 random rigid disks 2 to 12 texels across anywhere on the tile (over
    // joints too), the mask 0 on the tile's left half and on its top eighth, 1 elsewhere (off the charts
    // too). Maps of 128 texels on the preset's grid (refined), and of 100 texels on 64 cells, where a texel
    // spans no power-of-two number of cells. A texel whose mask texels within `reach` are all 0 has every
    // grid point around it fixed (maskAtPoints: the texels within max(1, texels / cells) of a point), so W
    // is the identity about its centre and it must show its own content: exactly where the inversion is
    // exact, within 1e-3 texel otherwise. The repair ends folds next to the masked region; its smoothing
    // once moved such texels (up to 127 a frame at 128^2, 0.75 texel; 0.002 texel at 100 texels).
    const geom::Mesh fox = io::readObj(DEFORMKIT_TEST_DATA "/fox/rest.obj").mesh;
    struct Case {
        int32_t texels, cells, reach;
    };
    for (const Case c : {Case{128, 0, 1}, Case{100, 64, 3}}) {
        const int32_t t = c.texels;
        io::Image mask(t, t, 1);
        for (int32_t y = t / 8; y < t; ++y)
            for (int32_t x = t / 2; x < t; ++x)
                mask.at(x, y, 0) = 1.0f;
        const auto heldReference = [&](int32_t x, int32_t y) {
            for (int32_t dy = -c.reach; dy <= c.reach; ++dy)
                for (int32_t dx = -c.reach; dx <= c.reach; ++dx) {
                    const int32_t nx = std::clamp(x + dx, 0, t - 1), ny = std::clamp(y + dy, 0, t - 1);
                    if (mask.at(nx, ny, 0) >= 0.5f) return false;
                }
            return true;
        };
        io::Image rigidity(t, t, 1);
        std::mt19937 rng(20261207);
        std::uniform_real_distribution<float> at(0.0f, static_cast<float>(t)), radius(2.0f, 12.0f);
        for (int disk = 0; disk < 40; ++disk) {
            const float cx = at(rng), cy = at(rng), r = radius(rng);
            for (int32_t y = 0; y < t; ++y)
                for (int32_t x = 0; x < t; ++x)
                    if (std::hypot(x - cx, y - cy) < r) rigidity.at(x, y, 0) = 1.0f;
        }
        uvwarp::TileWarpOptions options = uvwarp::presetOptions(uvwarp::Preset::Shot, c.cells ? c.cells : t);
        options.cells = c.cells;
        uvwarp::TileWarp warp(fox, 1001, rigidity, mask, options);
        int64_t repairedFrames = 0, heldTexels = 0;
        double farthest = 0.0;
        for (int f = 1; f <= 24; ++f) {
            char name[64];
            std::snprintf(name, sizeof name, "/fox/anim.%04d.obj", f);
            const io::ObjContent posed = io::readObj(std::string(DEFORMKIT_TEST_DATA) + name);
            warp.solve(std::vector<glm::vec3>(posed.mesh.points().begin(), posed.mesh.points().end()));
            io::Image map;
            const uvwarp::FoldRepair repair = warp.redirect(map);
            repairedFrames += repair.texelsMoved > 0 ? 1 : 0;
            INFO(t << " texels, frame " << f);
            for (int32_t y = 0; y < t; ++y) {
                for (int32_t x = 0; x < t; ++x) {
                    if (!heldReference(x, y)) continue;
                    ++heldTexels;
                    const glm::dvec2 q((x + 0.5) / t, 1.0 - (y + 0.5) / t);
                    const double off =
                        std::max(std::abs(map.at(x, y, 0) - q.x), std::abs(map.at(x, y, 1) - q.y)) * t;
                    farthest = std::max(farthest, off);
                    if (c.cells == 0) {  // 128 texels on a grid of 128 or 256 cells: the inversion is exact
                        CHECK(map.at(x, y, 0) == static_cast<float>(q.x));
                        CHECK(map.at(x, y, 1) == static_cast<float>(q.y));
                    }
                }
            }
            const uvwarp::DeliveredMetrics delivered = warp.measure(map);
            CHECK(delivered.invertedTriangles == 0);
            CHECK(delivered.offChartTexels == 0);
        }
        INFO(t << " texels: the farthest a held texel shows from its centre, " << farthest << " texel");
        CHECK(farthest <= 1e-3);
        CHECK(repairedFrames > 12);  // the repair does work next to the held texels
        CHECK(heldTexels > 24 * t * t / 4);
    }
}

TEST_CASE("uv warp: a warm start that jams is solved again from the identity, as after a cut",
          "[uvwarp][invariants][slow]") {
    // The live preset (one warm-started iteration a frame) on the Fox running at 512^2: where the last
    // frame's warp folds under the new pose, the iteration's fold repair spreads, and the frame is solved
    // again from the identity (SolveStats::coldRestart). Such a frame's warp is, byte for byte, what a solver
    // that never saw the frames before it gives; the others keep their warm start. The worst frame's rigid
    // stretch removed, on the delivered map, stays above 74% (75.7% measured, the shot preset's worst frame
    // 79.0%; with orientation preservation 0.05, UV-37, 67.9% and 68.8%, and 52.7% when jammed frames kept
    // their warm start).
    const geom::Mesh fox = io::readObj(DEFORMKIT_TEST_DATA "/fox/rest.obj").mesh;
    const io::Image rigidity = foxDisks(fox, 512);
    const uvwarp::TileWarpOptions live = uvwarp::presetOptions(uvwarp::Preset::Live, 512);
    uvwarp::TileWarp warp(fox, 1001, rigidity, {}, live);
    int restarts = 0;
    double worst = 1.0;
    io::Image map;
    for (int f = 1; f <= 24; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "/fox/anim.%04d.obj", f);
        const io::ObjContent posed = io::readObj(std::string(DEFORMKIT_TEST_DATA) + name);
        const std::vector<glm::vec3> points(posed.mesh.points().begin(), posed.mesh.points().end());
        warp.solve(points);
        CHECK(warp.stats().remainingFolds == 0);
        warp.redirect(map);
        worst = std::min(worst, warp.measure(map).removed);
        if (f == 1 || !warp.stats().coldRestart) continue;
        ++restarts;
        INFO("frame " << f);
        CHECK(warp.stats().iterations == live.solver.iterations + live.solver.coldIterations);
        uvwarp::TileWarp fresh(fox, 1001, rigidity, {}, live);
        fresh.solve(points);
        const bool same = warp.warp().u == fresh.warp().u && warp.warp().v == fresh.warp().v;
        CHECK(same);
    }
    CHECK(restarts > 0);
    CHECK(worst > 0.74);

    // A smooth stretch keeps its warm start on every frame.
    const geom::Mesh plane = uvPlane(16);
    uvwarp::TileWarp smooth(plane, 1001, diskRigidity(128), {},
                            uvwarp::presetOptions(uvwarp::Preset::Live, 128));
    for (int f = 0; f < 24; ++f) {
        smooth.solve(stretched(plane, 1.0f + 0.5f * static_cast<float>(f) / 23.0f));
        CHECK_FALSE(smooth.stats().coldRestart);
    }
}

TEST_CASE(
    "tile warp: solved from the identity every frame, it keeps nothing between frames and gives the same "
    "bytes",
    "[uvwarp]") {
    // The shot preset frees f_D, the velocities and the coarse levels' copies after each solve, its refining
    // grid's too; a warp that keeps them (warm start) and is reset before each frame is the reference. The
    // rigidity map handed over with 3 channels (channel 0 read) against 1.
    const geom::Mesh mesh = uvPlane(32);
    const io::Image disks = diskRigidity(128);
    io::Image rgb(128, 128, 3);
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            rgb.at(x, y, 0) = disks.at(x, y, 0);
            rgb.at(x, y, 1) = 0.25f;
            rgb.at(x, y, 2) = 1.0f - disks.at(x, y, 0);
        }
    uvwarp::TileWarp cold(mesh, 1001, std::move(rgb), {}, uvwarp::presetOptions(uvwarp::Preset::Shot, 128));
    uvwarp::TileWarpOptions warmOptions = uvwarp::presetOptions(uvwarp::Preset::Shot, 128);
    warmOptions.solver.warmStart = true;
    uvwarp::TileWarp warm(mesh, 1001, disks, {}, warmOptions);
    for (const float sx : {1.2f, 1.6f, 1.3f}) {
        const std::vector<glm::vec3> pose = stretched(mesh, sx);
        cold.solve(pose);
        warm.reset();
        warm.solve(pose);
        INFO("stretch " << sx);
        REQUIRE(cold.stats().iterations > 0);
        REQUIRE(cold.warp().cells == 256);  // refined (the shot preset at 128 cells)
        CHECK(cold.warp().u == warm.warp().u);
        CHECK(cold.warp().v == warm.warp().v);
        const io::Image coldMap = cold.redirect(), warmMap = warm.redirect();
        CHECK(coldMap.pixels == warmMap.pixels);
        const uvwarp::DeliveredMetrics coldFigures = cold.measure(coldMap),
                                       warmFigures = warm.measure(warmMap);
        CHECK(coldFigures.rigidStretchError == warmFigures.rigidStretchError);
        CHECK(coldFigures.rigidEdges == warmFigures.rigidEdges);
        CHECK(coldFigures.removed > 0.5);
        // The grid figures read f_D again from the deformed mesh where it was not kept.
        const uvwarp::WarpMetrics coldGrid = cold.metrics(), warmGrid = warm.metrics();
        CHECK(coldGrid.rigidStretchError == warmGrid.rigidStretchError);
        CHECK(coldGrid.identityStretchError == warmGrid.identityStretchError);
        CHECK(coldGrid.foldOvers == 0);
    }
    // A mask given to setMaps, then none: the bound (derived) mask again.
    const uvwarp::PointField bound = cold.maskAtGridPoints();
    io::Image everywhere(128, 128, 1);
    std::fill(everywhere.pixels.begin(), everywhere.pixels.end(), 1.0f);
    cold.setMaps(disks, everywhere);
    CHECK(cold.maskAtGridPoints().values != bound.values);
    cold.setMaps(disks);
    CHECK(cold.maskAtGridPoints().values == bound.values);
}

TEST_CASE("tile warp: refinement sweeps end each solve on a grid of twice the cells", "[uvwarp][options]") {
    // The Fox's frame 18 at 256^2 (skinning squashes its hip), each solve from the identity: with 2
    // refinement sweeps the delivered warp is a 512-cell grid, fold-free, its map has no inverted triangle
    // and no off-chart texel and keeps more of the rigid stretch removed; the same bytes on 1 and 2 threads.
    const geom::Mesh fox = io::readObj(DEFORMKIT_TEST_DATA "/fox/rest.obj").mesh;
    const io::ObjContent posed = io::readObj(DEFORMKIT_TEST_DATA "/fox/anim.0018.obj");
    const std::vector<glm::vec3> points(posed.mesh.points().begin(), posed.mesh.points().end());
    uvwarp::TileWarpOptions options;
    options.solver.warmStart = false;
    uvwarp::TileWarp plain(fox, 1001, foxDisks(fox, 256), {}, options);
    plain.solve(points);
    const uvwarp::DeliveredMetrics before = plain.deliveredMetrics();

    options.refinementSweeps = 2;
    uvwarp::TileWarp refined(fox, 1001, foxDisks(fox, 256), {}, options);
    const uvwarp::WarpGrid& grid = refined.solve(points);
    CHECK(refined.cells() == 256);
    CHECK(grid.cells == 512);
    CHECK(refined.stats().iterations == plain.stats().iterations + 1);
    CHECK(refined.stats().remainingFolds == 0);
    CHECK(uvwarp::countFolds(grid) == 0);
    const uvwarp::DeliveredMetrics after = refined.deliveredMetrics();
    CHECK(after.invertedTriangles == 0);
    CHECK(after.offChartTexels == 0);
    INFO("removed " << before.removed << " -> " << after.removed);
    CHECK(after.removed > before.removed);
    const uvwarp::WarpMetrics figures = refined.metrics();
    CHECK(figures.foldOvers == 0);
    // The refinement fixes only points whose start is the identity: no fixed point has moved.
    CHECK(figures.maxMaskedDisplacement == 0.0);
    CHECK(figures.maxBorderDisplacement == 0.0);

    uvwarp::TileWarpOptions one = options;
    one.solver.threads = 1;
    uvwarp::TileWarp single(fox, 1001, foxDisks(fox, 256), {}, one);
    const uvwarp::WarpGrid& alone = single.solve(points);
    CHECK(alone.u == grid.u);
    CHECK(alone.v == grid.v);

    // New maps reach both grids: without rigid texels nothing warps.
    refined.setMaps(io::Image(256, 256, 1));
    const uvwarp::WarpGrid& still = refined.solve(points);
    double moved = 0.0;
    for (int32_t j = 0; j <= 512; ++j)
        for (int32_t i = 0; i <= 512; ++i) {
            const size_t k = static_cast<size_t>(j) * 513 + i;
            moved = std::max({moved, std::abs(still.u[k] - i / 512.0), std::abs(still.v[k] - j / 512.0)});
        }
    CHECK(moved < 1e-6);

    // The refinement's grid has twice the cells: at most kMaxGridCells, checked before anything is bound.
    uvwarp::TileWarpOptions largest = options;
    largest.cells = uvwarp::kMaxGridCells;
    CHECK_THROWS_WITH(uvwarp::TileWarp(fox, 1001, foxDisks(fox, 256), {}, largest),
                      Catch::Contains("at most 16384"));
}

TEST_CASE("tile warp: the shot preset refines grids up to 1024 cells with 4 sweeps, finer grids not",
          "[uvwarp][options]") {
    // refinementSweeps -1 (the shot preset's, by the grid's size), as the option's reference states it.
    for (const int32_t cells : {2, 64, 256, 1024})
        CHECK(uvwarp::refinementSweepsFor(uvwarp::kAutomaticRefinement, cells) == 4);
    for (const int32_t cells : {2048, 4096, 16384})
        CHECK(uvwarp::refinementSweepsFor(uvwarp::kAutomaticRefinement, cells) == 0);
    CHECK(uvwarp::refinementSweepsFor(0, 64) == 0);
    CHECK(uvwarp::refinementSweepsFor(7, 4096) == 7);  // a value given is kept, whatever the grid
    CHECK(uvwarp::shotOptions().refinementSweeps == uvwarp::kAutomaticRefinement);
    CHECK(uvwarp::presetOptions(uvwarp::Preset::Live, 1024).refinementSweeps == 0);
    CHECK(uvwarp::TileWarpOptions{}.refinementSweeps == 0);  // the library's warm-started solvers: none

    // A shot on the plane's 128-cell grid delivers the 256-cell grid of 4 explicit sweeps, bit for bit.
    const geom::Mesh mesh = uvPlane(32);
    const std::vector<glm::vec3> pose = stretched(mesh, 1.5f);
    uvwarp::TileWarp shot(mesh, 1001, diskRigidity(128), {}, uvwarp::shotOptions());
    uvwarp::TileWarpOptions explicitSweeps = uvwarp::shotOptions();
    explicitSweeps.refinementSweeps = 4;
    uvwarp::TileWarp four(mesh, 1001, diskRigidity(128), {}, explicitSweeps);
    const uvwarp::WarpGrid& delivered = shot.solve(pose);
    const uvwarp::WarpGrid& reference = four.solve(pose);
    CHECK(delivered.cells == 256);
    CHECK(delivered.u == reference.u);
    CHECK(delivered.v == reference.v);

    // A 2048-cell grid keeps its own: the refinement would hold four times its memory.
    uvwarp::TileWarpOptions fine = uvwarp::shotOptions();
    fine.cells = 2048;
    const uvwarp::TileWarp large(mesh, 1001, diskRigidity(128), {}, fine);
    CHECK(large.warp().cells == 2048);
}

TEST_CASE("uv warp: a warm-started solver's first solve is the cold solver's, byte for byte", "[uvwarp]") {
    // A solver that keeps its state between solves reads f_O on its coarse levels from compact copies of
    // their points; one that starts every solve from the identity reads the fine image. From the identity,
    // with the same schedule, the first solves are the same arithmetic on the same values.
    const geom::Mesh plane = uvPlane(16);
    for (const int32_t texels : {128, 256}) {
        CAPTURE(texels);
        uvwarp::TileWarpOptions cold;
        cold.solver.warmStart = false;
        cold.refinementSweeps = 0;
        uvwarp::TileWarpOptions warm = cold;
        warm.solver.warmStart = true;
        uvwarp::TileWarp a(plane, 1001, diskRigidity(texels), {}, cold);
        uvwarp::TileWarp b(plane, 1001, diskRigidity(texels), {}, warm);
        const std::vector<glm::vec3> pose = stretched(plane, 1.4f);
        const uvwarp::WarpGrid& coldWarp = a.solve(pose);
        const uvwarp::WarpGrid& warmWarp = b.solve(pose);
        REQUIRE(a.stats().levels >= 3);  // a level 4 fine points apart or more
        CHECK(coldWarp.u == warmWarp.u);
        CHECK(coldWarp.v == warmWarp.v);
    }
}

TEST_CASE(
    "tile warp: geometry images of half the grid's cells give the grid's warp where the surface is affine",
    "[uvwarp][options]") {
    // f_O and f_D are affine inside each UV triangle, and the solver looks the images up bilinearly between
    // their points: on a plane stretched by an affine map (a shear and a stretch), an image of half the
    // grid's cells holds the same surface, and the warp is the full image's up to float rounding. From the
    // identity, and warm-started (whose coarse levels read f_O from compact copies of the image's points).
    const geom::Mesh plane = uvPlane(8);
    std::vector<glm::vec3> sheared(plane.points().begin(), plane.points().end());
    for (glm::vec3& p : sheared)
        p = {1.6f * p.x + 0.3f * p.y, 0.9f * p.y, 0.2f * p.x};
    uvwarp::TileWarpOptions full;
    uvwarp::TileWarpOptions half = full;
    half.geometryImageCells = 64;
    for (const bool warm : {false, true}) {
        full.solver.warmStart = half.solver.warmStart = warm;
        uvwarp::TileWarp a(plane, 1001, diskRigidity(128), {}, full);
        uvwarp::TileWarp b(plane, 1001, diskRigidity(128), {}, half);
        for (int frame = 0; frame < (warm ? 2 : 1); ++frame) {
            const uvwarp::WarpGrid& wa = a.solve(sheared);
            const uvwarp::WarpGrid& wb = b.solve(sheared);
            double gap = 0.0, moved = 0.0;
            for (size_t k = 0; k < wa.u.size(); ++k) {
                gap = std::max<double>(gap, std::hypot(wa.u[k] - wb.u[k], wa.v[k] - wb.v[k]));
                moved = std::max<double>(moved, std::abs(wa.u[k] - (k % 129) / 128.0));
            }
            INFO("warm start " << warm << ", frame " << frame << ": largest gap " << gap * 128
                               << " cells; largest move " << moved * 128 << " cells");
            CHECK(moved * 128 > 1.0);
            CHECK(gap * 128 < 1e-3);
        }
        CHECK(a.stats().levels >= 3);  // level 2's points are 4 fine points apart
        // The solver-grid figures look the images up between their points too.
        const uvwarp::WarpMetrics ma = a.metrics(), mb = b.metrics();
        CHECK(mb.rigidEdges == ma.rigidEdges);
        CHECK(mb.identityStretchError == Approx(ma.identityStretchError).epsilon(1e-5));
        CHECK(mb.rigidStretchError == Approx(ma.rigidStretchError).epsilon(1e-3));
    }

    // By default the grid's cells up to kFullGeometryImageCells, half of them on finer grids; any other size
    // is refused.
    CHECK(uvwarp::geometryImageCellsFor(0, 128) == 128);
    CHECK(uvwarp::geometryImageCellsFor(0, 8192) == 8192);
    CHECK(uvwarp::geometryImageCellsFor(0, 16384) == 8192);
    CHECK(uvwarp::geometryImageCellsFor(0, 32768) == 16384);
    CHECK(uvwarp::geometryImageCellsFor(64, 128) == 64);
    for (const int32_t wrong : {32, 256}) {
        half.geometryImageCells = wrong;
        CHECK_THROWS_WITH(
            uvwarp::TileWarp(plane, 1001, diskRigidity(128), {}, half),
            Catch::Contains("UDIM tile 1001: option geometryImageCells: is " + std::to_string(wrong)) &&
                Catch::Contains("0 (automatic), 128 (the grid's cells) or 64 (half of them)"));
    }
}

TEST_CASE("tile warp: geometry images of half the grid's cells cost the Fox less as the grid grows",
          "[uvwarp][options][slow]") {
    // Where a cell straddles a UV triangle's edge, f is not affine and an image of half the grid's cells
    // blurs it over two cells, a share of the cells that halves as the grid doubles. The Fox running, frame
    // 18, the shot preset without refinement (as grids from 2048 cells run), at 512^2 and 1024^2: the rigid
    // stretch the half images cost halves (4.95 points, then 2.44), and the delivered maps stay fold-free and
    // on the charts.
    const geom::Mesh fox = io::readObj(DEFORMKIT_TEST_DATA "/fox/rest.obj").mesh;
    const io::ObjContent posed = io::readObj(DEFORMKIT_TEST_DATA "/fox/anim.0018.obj");
    const std::vector<glm::vec3> points(posed.mesh.points().begin(), posed.mesh.points().end());
    double cost[2] = {};
    for (int size = 0; size < 2; ++size) {
        const int32_t texels = 512 << size;
        double removed[2] = {};
        for (int half = 0; half < 2; ++half) {
            uvwarp::TileWarpOptions options = uvwarp::presetOptions(uvwarp::Preset::Shot, texels);
            options.refinementSweeps = 0;
            options.geometryImageCells = texels >> half;
            uvwarp::TileWarp warp(fox, 1001, foxDisks(fox, texels), {}, options);
            warp.solve(points);
            io::Image map;
            warp.redirect(map);
            const uvwarp::DeliveredMetrics delivered = warp.measure(map);
            INFO(texels << "^2, images of " << options.geometryImageCells << " cells");
            CHECK(delivered.invertedTriangles == 0);
            CHECK(delivered.offChartTexels == 0);
            removed[half] = delivered.removed;
        }
        cost[size] = removed[0] - removed[1];
    }
    INFO("rigid stretch removed, lost: " << 100 * cost[0] << " points at 512^2, " << 100 * cost[1]
                                         << " at 1024^2");
    CHECK(cost[0] > 0.0);
    CHECK(cost[1] < 0.6 * cost[0]);
    CHECK(cost[1] < 0.03);
}
