#pragma once

// Private to solver_kernels_<isa>.cpp: the UV-warp solver's kernels, one source for every instruction set.
// Each kernel file includes this header once and instantiates sweepRow and regulariseRow with its own Ops, a
// class of the few steps written per instruction set:
//   static void loadWindows(const float* lo, const float* hi, float* out);
//   template <int32_t Step> static void loadPairWindows(const float* row, const int32_t* cell, float* out);
//   static void blendCells(const float* image, int32_t cells, const uint32_t* p00, const float* fx,
//                          const float* fy, float* x0, float* x1, float* x2);
//   static void storeInterleaved(float* p, const float* even, const float* odd);
//   static void loadPoints(const float* image, const uint32_t* at, float* x0, float* x1, float* x2);
//
// Everything here has internal linkage (an anonymous namespace), and it calls no inline function of the
// standard library (min, max and sqrt are written below): an AVX2 file then emits no function with vague
// linkage, which the linker could pick for the baseline file's calls and run on a CPU without AVX2
// (docs/decisions.md, "SIMD kernels").

#include <cstddef>
#include <cstdint>

#include "solver_kernels.h"

namespace deformkit::uvwarp::detail {
namespace {

template <class T>
[[gnu::always_inline]] inline T minOf(T a, T b) {
    return b < a ? b : a;  // std::min
}
template <class T>
[[gnu::always_inline]] inline T maxOf(T a, T b) {
    return a < b ? b : a;  // std::max
}
[[gnu::always_inline]] inline float sqrtOf(float x) {
    return __builtin_sqrtf(x);  // std::sqrt(float)
}

// Lanes per vector iteration of the kernels: 8 floats per AVX2 register (two SSE ones in the baseline
// build). The projection fills its blocks with kPairs pairs of kPair lanes.
constexpr int32_t kLaneBlock = 8;

// Offset of level point (i, j) in the level's maps.
[[gnu::always_inline]] inline size_t levelIndex(const KernelLevel& level, int32_t i, int32_t j) {
    return static_cast<size_t>(j) * (level.cells + 1) + i;
}

// Rows j - 1, j, j + 1 of a level in the fine warp arrays (south, centre, north).
struct Rows3 {
    const float *uS, *uC, *uN, *vS, *vC, *vN;
};

[[gnu::always_inline]] inline Rows3 rowsAround(const float* u, const float* v, ptrdiff_t centre,
                                               ptrdiff_t row) {
    return {u + centre - row, u + centre, u + centre + row, v + centre - row, v + centre, v + centre + row};
}

// The 8 neighbours of a point, counter-clockwise from east: E, NE, N, NW, W, SW, S, SE.
struct Ring {
    float u[8], v[8];
};
constexpr int32_t kRingDi[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int32_t kRingDj[8] = {0, 1, 1, 1, 0, -1, -1, -1};

// The ring slot of the neighbour at offset (di, dj).
constexpr int32_t ringSlot(int32_t di, int32_t dj) {
    for (int32_t q = 0; q < 8; ++q)
        if (kRingDi[q] == di && kRingDj[q] == dj) return q;
    return -1;
}

// The ring of the point at offset k of the centre row (point spacing s in fine points).
[[gnu::always_inline]] inline Ring ringAround(const Rows3& r, int32_t k, int32_t s) {
    return {{r.uC[k + s], r.uN[k + s], r.uN[k], r.uN[k - s], r.uC[k - s], r.uS[k - s], r.uS[k], r.uS[k + s]},
            {r.vC[k + s], r.vN[k + s], r.vN[k], r.vN[k - s], r.vC[k - s], r.vS[k - s], r.vS[k], r.vS[k + s]}};
}

// The clamp of §4.2 and the fold check of every move, for a point whose 8 neighbours (inside the grid) are
// n: (x, y) is clamped to the bounding box of the neighbours; returns whether it keeps the 12 triangles
// around the point (both diagonal splittings of its 4 cells) positively oriented. Branch-free, so loops
// over independent points vectorise 8 lanes wide.
[[gnu::always_inline]] inline bool clampKeepsOrientation(const Ring& n, float& x, float& y) {
    const float eu = n.u[0], ev = n.v[0], neu = n.u[1], nev = n.v[1];
    const float nu = n.u[2], nv = n.v[2], nwu = n.u[3], nwv = n.v[3];
    const float wu = n.u[4], wv = n.v[4], swu = n.u[5], swv = n.v[5];
    const float su = n.u[6], sv = n.v[6], seu = n.u[7], sev = n.v[7];
    const float minU = minOf(minOf(minOf(eu, neu), minOf(nu, nwu)), minOf(minOf(wu, swu), minOf(su, seu)));
    const float maxU = maxOf(maxOf(maxOf(eu, neu), maxOf(nu, nwu)), maxOf(maxOf(wu, swu), maxOf(su, seu)));
    const float minV = minOf(minOf(minOf(ev, nev), minOf(nv, nwv)), minOf(minOf(wv, swv), minOf(sv, sev)));
    const float maxV = maxOf(maxOf(maxOf(ev, nev), maxOf(nv, nwv)), maxOf(maxOf(wv, swv), maxOf(sv, sev)));
    x = minOf(maxOf(x, minU), maxU);
    y = minOf(maxOf(y, minV), maxV);
    // Per cell (edge neighbour a, diagonal d, edge neighbour b): the three triangles with the point.
    return (orient(x, y, eu, ev, neu, nev) > 0.0f) & (orient(x, y, neu, nev, nu, nv) > 0.0f) &
           (orient(x, y, eu, ev, nu, nv) > 0.0f) & (orient(x, y, nu, nv, nwu, nwv) > 0.0f) &
           (orient(x, y, nwu, nwv, wu, wv) > 0.0f) & (orient(x, y, nu, nv, wu, wv) > 0.0f) &
           (orient(x, y, wu, wv, swu, swv) > 0.0f) & (orient(x, y, swu, swv, su, sv) > 0.0f) &
           (orient(x, y, wu, wv, su, sv) > 0.0f) & (orient(x, y, su, sv, seu, sev) > 0.0f) &
           (orient(x, y, seu, sev, eu, ev) > 0.0f) & (orient(x, y, su, sv, eu, ev) > 0.0f);
}

// Eq. 4-5 for one point at (pu, pv) of rigidity r (kFixed: does not move) with 8 neighbours n: the blend
// with K_G by b = M((1 - R) + R s), the clamp to the neighbours' box and the fold check. (x, y) = where the
// point ends up.
[[gnu::always_inline]] inline void regularisePoint(const Ring& n, float pu, float pv, float r,
                                                   float smoothing, float& x, float& y) {
    const float blend = (1.0f - r) + r * smoothing;
    // K_G's rows south (SW S SE), centre (W . E), north (NW N NE); ring slots E NE N NW W SW S SE.
    const float gu = kGauss[0] * (kGauss[0] * n.u[5] + kGauss[1] * n.u[6] + kGauss[2] * n.u[7]) +
                     kGauss[1] * (kGauss[0] * n.u[4] + kGauss[1] * pu + kGauss[2] * n.u[0]) +
                     kGauss[2] * (kGauss[0] * n.u[3] + kGauss[1] * n.u[2] + kGauss[2] * n.u[1]);
    const float gv = kGauss[0] * (kGauss[0] * n.v[5] + kGauss[1] * n.v[6] + kGauss[2] * n.v[7]) +
                     kGauss[1] * (kGauss[0] * n.v[4] + kGauss[1] * pv + kGauss[2] * n.v[0]) +
                     kGauss[2] * (kGauss[0] * n.v[3] + kGauss[1] * n.v[2] + kGauss[2] * n.v[1]);
    float nx = (1.0f - blend) * pu + blend * gu;
    float ny = (1.0f - blend) * pv + blend * gv;
    const bool ok = (r >= 0.0f) & (blend > 0.0f) & clampKeepsOrientation(n, nx, ny);
    x = ok ? nx : pu;
    y = ok ? ny : pv;
}

// f_D(u, v), a bilinear look-up in a geometry image of `cells` cells (3 floats per point) clamped to the
// tile, in two steps: the cell (offset of its lower-left corner's first float, and the fractions), then the
// blend of its four corners. Branch-free.
[[gnu::always_inline]] inline void imageCell(int32_t cells, float u, float v, uint32_t& p00, float& fx,
                                             float& fy) {
    const float n = static_cast<float>(cells);
    float x = u * n, y = v * n;  // clamped to [0, n]: the same as clamping (u, v) to [0, 1] first
    x = x < 0.0f ? 0.0f : x;
    x = x > n ? n : x;
    y = y < 0.0f ? 0.0f : y;
    y = y > n ? n : y;
    const int32_t i = minOf(static_cast<int32_t>(x), cells - 1);
    const int32_t j = minOf(static_cast<int32_t>(y), cells - 1);
    fx = x - static_cast<float>(i);
    fy = y - static_cast<float>(j);
    // 32-bit offsets (3 (n + 1)^2 < 2^32 up to n = 32768, the largest grid).
    p00 = 3u * (static_cast<uint32_t>(j) * static_cast<uint32_t>(cells + 1) + static_cast<uint32_t>(i));
}

[[gnu::always_inline]] inline void blendCell(const float* image, int32_t cells, uint32_t p00, float fx,
                                             float fy, float& x0, float& x1, float& x2) {
    const uint32_t p10 = p00 + 3u, p01 = p00 + 3u * static_cast<uint32_t>(cells + 1), p11 = p01 + 3u;
    const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
    x0 = w00 * image[p00] + w10 * image[p10] + w01 * image[p01] + w11 * image[p11];
    x1 = w00 * image[p00 + 1] + w10 * image[p10 + 1] + w01 * image[p01 + 1] + w11 * image[p11 + 1];
    x2 = w00 * image[p00 + 2] + w10 * image[p10 + 2] + w01 * image[p01 + 2] + w11 * image[p11 + 2];
}

// Lanes per quad, half a block: the regularisation reads its blocks as two quads of points.
constexpr int32_t kQuad = kLaneBlock / 2;
// Lanes per pair: the projection gathers a row's segments into blocks of kPairs pairs.
constexpr int32_t kPair = 2;
constexpr int32_t kPairs = kLaneBlock / kPair;

// Eq. 1-3 for the segments of type Type anchored at cells i = first (mod step) on row j of a level (step
// 4, or 2 for vertical segments, whose ends share a column), in the runs [runs[2r], runs[2r + 1]) of their
// numbers g (cell first + g step) that hold every segment of the set the row projects (Level::setRuns),
// then orientation preservation, then the clamped, fold-safe moves of both ends. Written branch-free over
// independent segments so the loop vectorises; the same bytes as one segment after another. The point spacing
// stays a run-time value: with a constant 1 the compiler trades gathers for shuffles, which measured slower.
// Out of line, one function per set type, as in the builds UV-14 measured.
//
// Lanes. The segments of the set on the row inside the grid are g in [gMin, gMax). The runs' segments are
// taken kPair consecutive ones at a time (a pair) and kPairs pairs make a block of kLaneBlock lanes, so the
// vector loop runs no scalar remainder and a run's last, partial pair shares its block with the next runs'
// pairs: on a real tile the runs of a row are a few segments long (on the coarse levels often 2 to 5), and
// whole blocks per run left a third of the lanes idle, quads of 4 a quarter (UV-27). The lanes of a pair
// outside every run are not live: they never move, and store back the values they read. A block holds no
// segment twice (the last block of a row is filled with pairs that overlap none in it), so every segment is
// moved once. Segments of one set never share a point nor read a point another one moves, so the lanes are
// independent whatever block holds them: the same bytes as one run after another. A last segment alone at the
// grid's right edge goes in a last block of fewer lanes.
template <class Ops, int32_t Type, bool Mapped>
[[gnu::noinline]] void projectRow(const KernelGrid& grid, const KernelLevel& level, int32_t j, int32_t first,
                                  const int32_t* runs, int32_t runCount, float stiffness) {
    constexpr int32_t step = setStep(Type);
    // Static, so the block lambda below reads it without a capture (a captured copy became a masked load of
    // e.canonicalV, which kept GCC from vectorising the lambda's loop).
    static constexpr EdgeType e = kEdgeTypes[Type];
    const int32_t c = level.cells;
    const int32_t ja = j + e.aj, jb = j + e.bj;  // rows of the two ends
    int32_t gMin = 0, gMax = 0;
    setLanes(Type, first, j, c, gMin, gMax);
    if (gMin >= gMax) return;
    const int32_t s = level.step;
    const ptrdiff_t row = level.row;
    float* __restrict u = level.u;
    float* __restrict v = level.v;
    const ptrdiff_t centreA = ja * row, centreB = jb * row;
    float* uA = u + centreA;
    float* vA = v + centreA;
    float* uB = u + centreB;
    float* vB = v + centreB;
    // f_O at the level's points.
    const int32_t restStep = level.restStep;
    const float* restA = level.restBetween ? level.rest : level.rest + ja * level.restRow;
    const float* restB = level.restBetween ? level.rest : level.rest + jb * level.restRow;
    const float* deformedImage = grid.deformed;
    const int32_t imageCells = grid.imageCells;
    const float* rigidityA = level.rigidity + levelIndex(level, 0, ja);
    const float* rigidityB = level.rigidity + levelIndex(level, 0, jb);
    const float* orientationA = Mapped ? level.orientation + levelIndex(level, 0, ja) : nullptr;
    const float* orientationB = Mapped ? level.orientation + levelIndex(level, 0, jb) : nullptr;
    const float preservation = grid.orientationPreservation;
    const int32_t fineCells = grid.cells;
    const float least = leastRigidity(c, fineCells);  // segmentProjected's, exceeded by a projected segment
    // Each lane reads a window of the warp: point rows j - 1 .. j - 1 + kRows - 1 and columns i - 1 ..
    // i - 1 + kCols - 1 around its segment's cell (i, j), which holds both ends and their 8 neighbours.
    // Windows of different segments of the set do not overlap, and a lane moves only its two ends.
    constexpr int32_t kRows = e.aj == e.bj ? 3 : 4, kCols = e.ai == e.bi ? 3 : 4;
    const float* rowU[kRows];
    const float* rowV[kRows];
    for (int32_t r = 0; r < kRows; ++r) {
        rowU[r] = u + (j - 1 + r) * row;
        rowV[r] = v + (j - 1 + r) * row;
    }
    // Window slots of the ends, and of neighbour q of an end at window slot (ca, ra).
    constexpr int32_t colA = 1 + e.ai, rowA = 1 + e.aj, colB = 1 + e.bi, rowB = 1 + e.bj;
    constexpr auto ringCol = [](int32_t col, int32_t q) { return col + kRingDi[q]; };
    constexpr auto ringRow = [](int32_t r, int32_t q) { return r + kRingDj[q]; };
    constexpr int32_t slotA = ringSlot(e.ai - e.bi, e.aj - e.bj);  // A among B's neighbours
    static_assert(slotA >= 0, "the ends of a segment are neighbours");

    // One block of `lanes` lanes: lane l is the segment at cell cell[l], moved if bit l of liveMask is set.
    // pairs: the block is kPairs pairs of consecutive segments (lanes 2q, 2q + 1), whose windows are read as
    // contiguous stretches when points are one apart.
    const auto project = [&](const int32_t* cell, int32_t lanes, bool pairs, uint32_t liveMask) {
        alignas(32) float wu[kRows][kCols][kLaneBlock], wv[kRows][kCols][kLaneBlock];
        if (s == 1 && pairs) {
            for (int32_t r = 0; r < kRows; ++r) {
                Ops::template loadPairWindows<step>(rowU[r], cell, &wu[r][0][0]);
                Ops::template loadPairWindows<step>(rowV[r], cell, &wv[r][0][0]);
            }
        } else {
#pragma omp simd
            for (int32_t l = 0; l < lanes; ++l) {
                const int32_t i = cell[l];
#pragma GCC unroll 4
                for (int32_t r = 0; r < kRows; ++r) {
#pragma GCC unroll 4
                    for (int32_t col = 0; col < kCols; ++col) {
                        wu[r][col][l] = rowU[r][(i - 1 + col) * s];
                        wv[r][col][l] = rowV[r][(i - 1 + col) * s];
                    }
                }
            }
        }
        // The f_D look-ups at both ends of the block's segments: cells first, then the blends.
        alignas(32) uint32_t cellA[kLaneBlock] = {}, cellB[kLaneBlock] = {};  // 0: lanes past `lanes`
        alignas(32) float fxA[kLaneBlock] = {}, fyA[kLaneBlock] = {}, fxB[kLaneBlock] = {},
                          fyB[kLaneBlock] = {};
#pragma omp simd
        for (int32_t l = 0; l < lanes; ++l) {
            imageCell(imageCells, wu[rowA][colA][l], wv[rowA][colA][l], cellA[l], fxA[l], fyA[l]);
            imageCell(imageCells, wu[rowB][colB][l], wv[rowB][colB][l], cellB[l], fxB[l], fyB[l]);
        }
        alignas(32) float xa0[kLaneBlock], xa1[kLaneBlock], xa2[kLaneBlock];
        alignas(32) float xb0[kLaneBlock], xb1[kLaneBlock], xb2[kLaneBlock];
        Ops::blendCells(deformedImage, imageCells, cellA, fxA, fyA, xa0, xa1, xa2);
        Ops::blendCells(deformedImage, imageCells, cellB, fxB, fyB, xb0, xb1, xb2);
        // f_O at both ends (l_org, Eq. 1, through f_O at the rest grid points, Eq. 6).
        alignas(32) uint32_t restAt[2][kLaneBlock] = {};  // 0: lanes past `lanes`
        alignas(32) float ra0[kLaneBlock], ra1[kLaneBlock], ra2[kLaneBlock];
        alignas(32) float rb0[kLaneBlock], rb1[kLaneBlock], rb2[kLaneBlock];
        if (level.restBetween) {
            // Ends at image point (i / 2, j / 2) and fractions 0 or 1/2: the image's cell inside the grid,
            // since segment ends are (i, j < n).
            alignas(32) float fxRest[2][kLaneBlock] = {};
            alignas(32) float fyRest[2][kLaneBlock];
            const uint32_t imageRow = 3u * static_cast<uint32_t>(imageCells + 1);
            for (int32_t l = 0; l < lanes; ++l) {
                const int32_t ia = cell[l] + e.ai, ib = cell[l] + e.bi;
                restAt[0][l] =
                    static_cast<uint32_t>(ja >> 1) * imageRow + 3u * static_cast<uint32_t>(ia >> 1);
                restAt[1][l] =
                    static_cast<uint32_t>(jb >> 1) * imageRow + 3u * static_cast<uint32_t>(ib >> 1);
                fxRest[0][l] = 0.5f * static_cast<float>(ia & 1);
                fxRest[1][l] = 0.5f * static_cast<float>(ib & 1);
            }
            for (int32_t l = 0; l < kLaneBlock; ++l) {
                fyRest[0][l] = 0.5f * static_cast<float>(ja & 1);
                fyRest[1][l] = 0.5f * static_cast<float>(jb & 1);
            }
            Ops::blendCells(level.rest, imageCells, restAt[0], fxRest[0], fyRest[0], ra0, ra1, ra2);
            Ops::blendCells(level.rest, imageCells, restAt[1], fxRest[1], fyRest[1], rb0, rb1, rb2);
        } else {
            for (int32_t l = 0; l < lanes; ++l) {
                restAt[0][l] = static_cast<uint32_t>((cell[l] + e.ai) * restStep);
                restAt[1][l] = static_cast<uint32_t>((cell[l] + e.bi) * restStep);
            }
            Ops::loadPoints(restA, restAt[0], ra0, ra1, ra2);
            Ops::loadPoints(restB, restAt[1], rb0, rb1, rb2);
        }
        // The per-level maps at both ends, copied into lane arrays, so that the main loop reads lane arrays
        // only.
        alignas(32) float rigA[kLaneBlock], rigB[kLaneBlock], oriA[kLaneBlock] = {}, oriB[kLaneBlock] = {};
        alignas(32) int32_t liveLane[kLaneBlock];  // a lane array: GCC does not vectorise the mask's bits
        for (int32_t l = 0; l < lanes; ++l) {
            liveLane[l] = static_cast<int32_t>((liveMask >> l) & 1u);
            rigA[l] = rigidityA[cell[l] + e.ai];
            rigB[l] = rigidityB[cell[l] + e.bi];
            if constexpr (Mapped) {
                oriA[l] = orientationA[cell[l] + e.ai];
                oriB[l] = orientationB[cell[l] + e.bi];
            }
        }
        alignas(32) float endAx[kLaneBlock], endAy[kLaneBlock], endBx[kLaneBlock], endBy[kLaneBlock];
#pragma omp simd
        for (int32_t l = 0; l < lanes; ++l) {
            const float ra = rigA[l], rb = rigB[l];
            // Both ends movable: projected when either is rigid (§4.2). Both fixed (kFixed - R: masked or on
            // the border): nothing to do. One end fixed: the paper does not project it; here a segment rigid
            // at both ends (R >= 0.5) is projected with the whole correction on its free end (the fixed end's
            // mass is infinite), so rigid detail that a pinned chart border cuts keeps its lengths to the
            // border instead of tearing from it (docs/decisions.md, UV-15). segmentProjected decides it;
            // the correction uses the ends' fixedness and the larger rigidity of its movable ends.
            const bool fixedA = ra < 0.0f, fixedB = rb < 0.0f;
            const float rig = fixedA ? rb : (fixedB ? ra : (ra > rb ? ra : rb));
            const bool live = liveLane[l] != 0;
            const bool active = live & segmentProjected(ra, rb, least);
            Ring ringA, ringB;  // B's slot for A is filled once A has moved
#pragma GCC unroll 8
            for (int32_t q = 0; q < 8; ++q) {
                ringA.u[q] = wu[ringRow(rowA, q)][ringCol(colA, q)][l];
                ringA.v[q] = wv[ringRow(rowA, q)][ringCol(colA, q)][l];
                if (q != slotA) {
                    ringB.u[q] = wu[ringRow(rowB, q)][ringCol(colB, q)][l];
                    ringB.v[q] = wv[ringRow(rowB, q)][ringCol(colB, q)][l];
                }
            }
            const float pax = wu[rowA][colA][l], pay = wv[rowA][colA][l];
            const float pbx = wu[rowB][colB][l], pby = wv[rowB][colB][l];
            const float d0 = xb0[l] - xa0[l], d1 = xb1[l] - xa1[l], d2 = xb2[l] - xa2[l];
            const float lDef = sqrtOf(d0 * d0 + d1 * d1 + d2 * d2);
            const float dx = pbx - pax, dy = pby - pay;
            const float length = sqrtOf(dx * dx + dy * dy);
            // l_org (Eq. 1) through f_O at the rest grid points (Eq. 6).
            const float r0 = rb0[l] - ra0[l], r1 = rb1[l] - ra1[l], r2 = rb2[l] - ra2[l];
            const float lOrg = sqrtOf(r0 * r0 + r1 * r1 + r2 * r2);
            const bool valid = active & (lDef > 1e-12f) & (length > 1e-12f) & (lOrg > 0.0f);
            // Along the segment f_D is taken as linear, so the UV length that gives l_def = l_org is
            // length * l_org / l_def; stiffness = rigidity x level factor, equal inverse masses (Müller et
            // al.). Invalid lanes divide by 1 and are dropped below.
            const float safeDef = valid ? lDef : 1.0f, safeLength = valid ? length : 1.0f;
            const float correction = stiffness * rig * length * (1.0f - lOrg / safeDef);
            const float ux = dx / safeLength, uy = dy / safeLength;
            const float shareA = fixedA ? 0.0f : (fixedB ? 1.0f : 0.5f);
            const float shareB = fixedB ? 0.0f : (fixedA ? 1.0f : 0.5f);
            float nax = pax + shareA * correction * ux, nay = pay + shareA * correction * uy;
            float nbx = pbx - shareB * correction * ux, nby = pby - shareB * correction * uy;
            const float preserve = Mapped ? preservation * 0.5f * (oriA[l] + oriB[l]) : preservation;
            // Turn the segment about its centre towards its canonical direction (normalised lerp of
            // directions).
            const float mx = 0.5f * (nax + nbx), my = 0.5f * (nay + nby);
            const float hx = 0.5f * (nbx - nax), hy = 0.5f * (nby - nay);
            const float half = sqrtOf(hx * hx + hy * hy);
            const float safeHalf = half > 0.0f ? half : 1.0f;
            float tx = hx / safeHalf + preserve * (e.canonicalU - hx / safeHalf);
            float ty = hy / safeHalf + preserve * (e.canonicalV - hy / safeHalf);
            const float tl = sqrtOf(tx * tx + ty * ty);
            const bool turn = (preserve > 0.0f) & (half > 0.0f) & (tl > 1e-6f) & !fixedA & !fixedB;
            const float scale = half / (turn ? tl : 1.0f);
            tx *= scale;
            ty *= scale;
            nax = turn ? mx - tx : nax;
            nay = turn ? my - ty : nay;
            nbx = turn ? mx + tx : nbx;
            nby = turn ? my + ty : nby;
            // Both ends' rings are read before either end is stored; B's check sees where A ended up, as
            // when the segment's ends move one after the other.
            const bool moveA = valid & !fixedA & clampKeepsOrientation(ringA, nax, nay);
            endAx[l] = moveA ? nax : pax;
            endAy[l] = moveA ? nay : pay;
            ringB.u[slotA] = endAx[l];
            ringB.v[slotA] = endAy[l];
            const bool moveB = valid & !fixedB & clampKeepsOrientation(ringB, nbx, nby);
            endBx[l] = moveB ? nbx : pbx;
            endBy[l] = moveB ? nby : pby;
        }
        // Stored one lane after another: the lanes' points are not evenly spaced (four pairs), and AVX2 has
        // no scatter, so a store in the loop above would keep GCC from vectorising it.
        for (int32_t l = 0; l < lanes; ++l) {
            const int32_t ka = (cell[l] + e.ai) * s, kb = (cell[l] + e.bi) * s;  // offsets in rows of u, v
            uA[ka] = endAx[l];
            vA[ka] = endAy[l];
            uB[kb] = endBx[l];
            vB[kb] = endBy[l];
        }
    };

    // The pairs, in order, kPairs to a block.
    alignas(32) int32_t cell[kLaneBlock];
    int32_t pairStart[kPairs];
    int32_t pairs = 0;
    uint32_t blockMask = 0;
    const auto fillPair = [&](int32_t* slot, int32_t g) {
        for (int32_t l = 0; l < kPair; ++l)
            slot[l] = first + (g + l) * step;
    };
    const auto addPair = [&](int32_t g, uint32_t mask) {  // segments g, g + 1, mask of the live ones
        fillPair(cell + pairs * kPair, g);
        pairStart[pairs] = g;
        blockMask |= mask << (pairs * kPair);
        if (++pairs < kPairs) return;
        project(cell, kLaneBlock, true, blockMask);
        pairs = 0;
        blockMask = 0;
    };
    // The lanes [a, b) of run r (inside [gMin, gMax): Level::setRuns).
    const auto runLanes = [&](int32_t r, int32_t& a, int32_t& b) {
        a = runs[2 * r];
        b = runs[2 * r + 1];
    };
    // The live lanes among segments [g, g + count), from run r on.
    const auto liveLanes = [&](int32_t r, int32_t g, int32_t count) {
        uint32_t mask = 0;
        for (; r < runCount; ++r) {
            int32_t a = 0, b = 0;
            runLanes(r, a, b);
            if (a >= g + count) break;
            for (int32_t l = 0; l < count; ++l)
                if (g + l >= a && g + l < b) mask |= 1u << l;
        }
        return mask;
    };
    int32_t next = gMin;  // the first segment not yet in a pair
    for (int32_t r = 0; r < runCount; ++r) {
        int32_t a = 0, b = 0;
        runLanes(r, a, b);
        for (a = maxOf(a, next); a < b && a + kPair <= gMax; a = next) {
            addPair(a, liveLanes(r, a, kPair));
            next = a + kPair;
        }
        if (a < b) {
            // The last segment before the grid's edge, alone: with the pending pairs, in one last block.
            const int32_t lanes = pairs * kPair;
            fillPair(cell + lanes, a);  // the segment at gMax is not read
            project(cell, lanes + 1, false, blockMask | (liveLanes(r, a, 1) << lanes));
            return;
        }
    }
    if (pairs == 0) return;
    // A last block of fewer pairs: filled with pairs that overlap none in it, their lanes not live.
    const int32_t used = pairs;
    for (int32_t g = gMin; pairs < kPairs && g + kPair <= gMax; ++g) {
        bool free = true;
        for (int32_t q = 0; q < pairs; ++q)
            free = free && (g + kPair <= pairStart[q] || g >= pairStart[q] + kPair);
        if (!free) continue;
        fillPair(cell + pairs * kPair, g);
        pairStart[pairs++] = g;
    }
    if (pairs == kPairs) {
        project(cell, kLaneBlock, true, blockMask);
    } else {
        project(cell, used * kPair, false, blockMask);
    }
}

// Eq. 4-5 on the points i = first, first + 2, ... in [begin, end) of row j of a level: blend with K_G by
// b = M((1 - R) + R s), then the clamp to the 8-neighbourhood's box and the fold check.
// Points two apart are not neighbours, so the lanes of one call are independent: the loop is written
// branch-free for SIMD, and gives the same bytes as one point after another. Fine: points one apart (step 1),
// a compile-time constant then, so the neighbour loads of lanes two apart are vector
// loads and shuffles instead of one scalar load per lane.
template <class Ops, bool Fine>
[[gnu::noinline]] void regulariseRun(const KernelGrid& grid, const KernelLevel& level, int32_t j,
                                     int32_t first, int32_t begin, int32_t end) {
    const int32_t c = level.cells;
    const int32_t s = Fine ? 1 : level.step;
    const ptrdiff_t row = level.row;
    const float smoothing = grid.smoothing;
    float* __restrict u = level.u;
    float* __restrict v = level.v;
    const ptrdiff_t centre = static_cast<ptrdiff_t>(j) * row;
    const Rows3 rows = rowsAround(u, v, centre, row);
    float* uC = u + centre;
    float* vC = v + centre;
    const float* rigidity = level.rigidity + levelIndex(level, 0, j);
    // The points of the run with first's parity, inside the grid's border: i = first + 2m, m in [0, lanes).
    begin = maxOf(begin, 1);
    end = minOf(end, c);
    first = begin + ((first - begin) % 2 + 2) % 2;
    const int32_t lanes = first < end ? (end - first + 1) / 2 : 0;
    // GCC would read the rigidity map at its constant stride as one interleaved load with gaps, which forces
    // a scalar epilogue of up to 8 lanes on every call; a stride it cannot see (1, hidden by an empty asm)
    // makes it a plain strided load, with no epilogue.
    int32_t unit = 1;
    asm("" : "+r"(unit));
    int32_t lane = 0;
    if constexpr (Fine) {
        // Whole blocks of kLaneBlock points: the 3x3 windows around them (columns i - 1, i, i + 1 of rows
        // j - 1, j, j + 1) read as contiguous stretches and transposed, and the moved points written back
        // interleaved with the untouched ones between them.
        const float* rowU[3] = {rows.uS, rows.uC, rows.uN};
        const float* rowV[3] = {rows.vS, rows.vC, rows.vN};
        for (; lane + kLaneBlock <= lanes; lane += kLaneBlock) {
            const int32_t i0 = first + 2 * lane;
            alignas(32) float wu[3][3][kLaneBlock], wv[3][3][kLaneBlock];
            for (int32_t r = 0; r < 3; ++r) {
                Ops::loadWindows(rowU[r] + i0 - 1, rowU[r] + i0 - 1 + 2 * kQuad, &wu[r][0][0]);
                Ops::loadWindows(rowV[r] + i0 - 1, rowV[r] + i0 - 1 + 2 * kQuad, &wv[r][0][0]);
            }
            alignas(32) float movedU[kLaneBlock], movedV[kLaneBlock];
#pragma omp simd
            for (int32_t l = 0; l < kLaneBlock; ++l) {
                Ring ring;
#pragma GCC unroll 8
                for (int32_t q = 0; q < 8; ++q) {
                    ring.u[q] = wu[1 + kRingDj[q]][1 + kRingDi[q]][l];
                    ring.v[q] = wv[1 + kRingDj[q]][1 + kRingDi[q]][l];
                }
                regularisePoint(ring, wu[1][1][l], wv[1][1][l], rigidity[(i0 + 2 * l) * unit], smoothing,
                                movedU[l], movedV[l]);
            }
            Ops::storeInterleaved(uC + i0 - 1, wu[1][0], movedU);
            Ops::storeInterleaved(vC + i0 - 1, wv[1][0], movedV);
        }
    }
#pragma omp simd
    for (int32_t m = lane; m < lanes; ++m) {
        const int32_t k = (first + 2 * m) * s;
        regularisePoint(ringAround(rows, k, s), uC[k], vC[k], rigidity[(first + 2 * m) * unit], smoothing,
                        uC[k], vC[k]);
    }
}

// One sweep over the 8 parallel sets (paper Fig. 8) on row of cells j: each edge type split by the parity
// of its cell column, so no two segments of a set share a point (kSets, in kSetType and kSetFirst's order).
// The sets are interleaved row by row: for each row of cells, the horizontal segments of its lower point row,
// then its vertical, then its two diagonal segments, each set by parity. A set's segments on one row are
// independent (one SIMD or GPU pass each); running all of them on a row while it is in cache streams the
// grid once per sweep, not once per set. Within a set, segments `step` cells apart: ends of different
// segments are then never neighbours, so the fold checks of one projectRow are independent (SIMD lanes).
// Only the runs of segments the row projects (Level::setRuns, from the maps) are visited; what is skipped
// would not move.
template <class Ops, bool Mapped>
void sweepRowSets(const KernelGrid& grid, const KernelLevel& level, int32_t j, float stiffness) {
    const int32_t* begin = level.setRunBegin + static_cast<size_t>(j) * kSets;
    const auto runsOf = [&](int32_t set) { return level.setRuns + 2 * static_cast<size_t>(begin[set]); };
    const auto countOf = [&](int32_t set) { return begin[set + 1] - begin[set]; };
    for (int32_t set = 0; set < kSets; ++set) {
        const int32_t count = countOf(set);
        if (count == 0) continue;
        const int32_t first = kSetFirst[set];
        switch (kSetType[set]) {
            case 0:
                projectRow<Ops, 0, Mapped>(grid, level, j, first, runsOf(set), count, stiffness);
                break;
            case 1:
                projectRow<Ops, 1, Mapped>(grid, level, j, first, runsOf(set), count, stiffness);
                break;
            case 2:
                projectRow<Ops, 2, Mapped>(grid, level, j, first, runsOf(set), count, stiffness);
                break;
            default:
                projectRow<Ops, 3, Mapped>(grid, level, j, first, runsOf(set), count, stiffness);
                break;
        }
    }
}

template <class Ops>
void sweepRow(const KernelGrid& grid, const KernelLevel& level, int32_t j, float stiffness) {
    if (level.orientation != nullptr) {
        sweepRowSets<Ops, true>(grid, level, j, stiffness);
    } else {
        sweepRowSets<Ops, false>(grid, level, j, stiffness);
    }
}

// Odd points of the row, then even ones (after a propagation only the level's new points: every point of an
// odd row, the odd points of an even row), in the row's runs of points that may move: a fixed point keeps its
// place (regularisePoint), so the points outside them are not visited.
template <class Ops, bool Fine>
void regulariseRowAt(const KernelGrid& grid, const KernelLevel& level, int32_t j, bool onlyNew) {
    const int32_t* run = level.movableRuns + 2 * static_cast<size_t>(level.movableBegin[j]);
    const int32_t runs = level.movableBegin[j + 1] - level.movableBegin[j];
    for (int32_t r = 0; r < runs; ++r)
        regulariseRun<Ops, Fine>(grid, level, j, 1, run[2 * r], run[2 * r + 1]);
    if (onlyNew && (j % 2) == 0) return;
    for (int32_t r = 0; r < runs; ++r)
        regulariseRun<Ops, Fine>(grid, level, j, 2, run[2 * r], run[2 * r + 1]);
}

template <class Ops>
void regulariseRow(const KernelGrid& grid, const KernelLevel& level, int32_t j, bool onlyNew) {
    if (level.step == 1) {
        regulariseRowAt<Ops, true>(grid, level, j, onlyNew);
    } else {
        regulariseRowAt<Ops, false>(grid, level, j, onlyNew);
    }
}

}  // namespace
}  // namespace deformkit::uvwarp::detail
