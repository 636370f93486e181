#include "deformkit/uvwarp/solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include <immintrin.h>

#include "deformkit/error.h"

namespace deformkit::uvwarp {

namespace {

// The four constraint directions of the 8-connected grid (paper §4.2, V_horz, V_vert, V_shear0, V_shear1),
// as the level-grid offsets of the segment's two ends from the cell corner (I, J), and the segment's
// canonical (rest) direction.
struct EdgeType {
    int32_t ai, aj, bi, bj;
    float canonicalU, canonicalV;
};
constexpr float kHalfSqrt2 = 0.70710678f;
constexpr std::array<EdgeType, 4> kEdgeTypes = {{
    {0, 0, 1, 0, 1.0f, 0.0f},               // horizontal, 0°
    {0, 0, 0, 1, 0.0f, 1.0f},               // vertical, 90°
    {0, 0, 1, 1, kHalfSqrt2, kHalfSqrt2},   // shear0, 45°
    {1, 0, 0, 1, -kHalfSqrt2, kHalfSqrt2},  // shear1, 135°
}};

// Loops over fewer rows than this run on one thread: coarse levels are tiny, and a fork and barrier per
// tiny loop costs more than the loop (badly so when the machine is oversubscribed).
constexpr int64_t kParallelRows = 64;
// Lanes per vector iteration of the SIMD kernels: 8 floats per AVX2 register (two SSE ones in the baseline
// build). The projection pads its runs to a multiple of it.
constexpr int32_t kLaneBlock = 8;

// Rows per block of the row-wavefront schedule (sweep, regularise). A block's rows are processed in order;
// blocks of one parity never touch a point another block of that parity reads or moves (a row reads at most
// one row beyond its block on each side), so they run in parallel. Blocks depend on the grid size alone, so
// the result does not depend on the thread count, nor on which thread runs a block: blocks (and the rows
// of the other parallel loops) are handed out dynamically, so a thread the machine delays or a row block
// with more rigid detail does not hold the other threads at the next barrier.
constexpr int32_t kBlockRows = 16;
// Points per chunk of the loops over every point (prediction, integration).
constexpr size_t kPointChunk = 32768;

// Runs rowFn(j) for j in [first, last): blocks of kBlockRows rows, even blocks (in parallel), then odd ones.
template <class RowFn>
void forRowBlocks(int32_t first, int32_t last, const RowFn& rowFn) {
    const int32_t rows = last - first;
    if (rows <= 0) return;
    const int32_t blocks = (rows + kBlockRows - 1) / kBlockRows;
    for (int32_t parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1) if (kParallelRows < static_cast <int64_t>(rows))
        for (int32_t b = parity; b < blocks; b += 2) {
            const int32_t end = std::min(last, first + (b + 1) * kBlockRows);
            for (int32_t j = first + b * kBlockRows; j < end; ++j)
                rowFn(j);
        }
    }
}

// Largest grid: f_D offsets fit 32 bits (imageCell).
constexpr int32_t kMaxCells = 32768;

// Level::rigidity of a point that may not move.
constexpr float kFixed = -1.0f;

// 3x3 Gaussian kernel K_G (Eq. 5 and 7): (1 2 1) x (1 2 1) / 16.
constexpr std::array<float, 3> kGauss = {0.25f, 0.5f, 0.25f};

struct Level {
    int32_t cells = 0;   // cells per side at this level
    int32_t stride = 1;  // fine-grid points between neighbouring points of this level
    // R (Eq. 7 on coarser levels) where the point may move; kFixed where it may not (masked, Eq. 8, or on
    // the tile border). One float map rather than a float and a byte map: the SIMD kernels then hold only
    // 32-bit values, so their vector loops run 8 lanes per AVX2 iteration, not 32 (a byte map made GCC
    // choose 32 lanes, which left every run shorter than 32 segments to the scalar remainder loop).
    std::vector<float> rigidity;
    std::vector<float> orientation;           // empty without an orientation map (1 everywhere)
    std::vector<float> snapshotU, snapshotV;  // positions before this level's sweeps (for propagation)
    // Per row of cells j, runs [spans[2r], spans[2r + 1]) of cells, r in [spanBegin[j], spanBegin[j + 1]),
    // outside which no cell has a movable corner of rigidity > 0: no segment there is projected (§4.2), so
    // sweeps skip them. Runs closer than kSpanGap cells are merged.
    std::vector<int32_t> spanBegin, spans;

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t index(int32_t i, int32_t j) const { return static_cast<size_t>(j) * side() + i; }
    [[nodiscard]] bool movable(size_t k) const { return rigidity[k] >= 0.0f; }
};

constexpr int32_t kSpanGap = 8;

// The SIMD loops are compiled twice, for AVX2 (8 lanes) and for the baseline (SSE2, 4 lanes); the CPU
// picks at run time. No FMA: both give the same bits, so a farm of mixed CPUs writes identical maps.
const bool kHasAvx2 = __builtin_cpu_supports("avx2");

float orient(float ax, float ay, float bx, float by, float cx, float cy) {
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

// Rows j - 1, j, j + 1 of a level in the fine warp arrays (south, centre, north).
struct Rows3 {
    const float *uS, *uC, *uN, *vS, *vC, *vN;
};

Rows3 rowsAround(const float* u, const float* v, ptrdiff_t centre, ptrdiff_t row) {
    return {u + centre - row, u + centre, u + centre + row, v + centre - row, v + centre, v + centre + row};
}

// The 8 neighbours of a point, counter-clockwise from east: E, NE, N, NW, W, SW, S, SE.
struct Ring {
    float u[8], v[8];
};
constexpr std::array<int32_t, 8> kRingDi = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr std::array<int32_t, 8> kRingDj = {0, 1, 1, 1, 0, -1, -1, -1};

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
    const float minU = std::min(std::min(std::min(eu, neu), std::min(nu, nwu)),
                                std::min(std::min(wu, swu), std::min(su, seu)));
    const float maxU = std::max(std::max(std::max(eu, neu), std::max(nu, nwu)),
                                std::max(std::max(wu, swu), std::max(su, seu)));
    const float minV = std::min(std::min(std::min(ev, nev), std::min(nv, nwv)),
                                std::min(std::min(wv, swv), std::min(sv, sev)));
    const float maxV = std::max(std::max(std::max(ev, nev), std::max(nv, nwv)),
                                std::max(std::max(wv, swv), std::max(sv, sev)));
    x = std::min(std::max(x, minU), maxU);
    y = std::min(std::max(y, minV), maxV);
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
    const int32_t i = std::min(static_cast<int32_t>(x), cells - 1);
    const int32_t j = std::min(static_cast<int32_t>(y), cells - 1);
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

// blendCell for kLaneBlock look-ups, lane l of every array one look-up (the baseline kernels' version).
void blendCellsBase(const float* image, int32_t cells, const uint32_t* p00, const float* fx, const float* fy,
                    float* x0, float* x1, float* x2) {
#pragma omp simd
    for (int32_t l = 0; l < kLaneBlock; ++l)
        blendCell(image, cells, p00[l], fx[l], fy[l], x0[l], x1[l], x2[l]);
}

#define DEFORMKIT_AVX2 __attribute__((target("avx2,prefer-vector-width=256"), always_inline)) inline

// One register from two 4-float loads: lo in lanes 0-3, hi in lanes 4-7.
DEFORMKIT_AVX2 __m256 loadHalves(const float* lo, const float* hi) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1);
}

// m[k] holds lane k's 4 values in its low half and lane k + 4's in its high half; out[c] = value c of
// lanes 0..7, in order (a 4x4 transpose in each half: 8 shuffles).
DEFORMKIT_AVX2 void transposeHalves(const __m256* m, __m256* out) {
    const __m256 lo01 = _mm256_unpacklo_ps(m[0], m[1]), hi01 = _mm256_unpackhi_ps(m[0], m[1]);
    const __m256 lo23 = _mm256_unpacklo_ps(m[2], m[3]), hi23 = _mm256_unpackhi_ps(m[2], m[3]);
    out[0] = _mm256_shuffle_ps(lo01, lo23, _MM_SHUFFLE(1, 0, 1, 0));
    out[1] = _mm256_shuffle_ps(lo01, lo23, _MM_SHUFFLE(3, 2, 3, 2));
    out[2] = _mm256_shuffle_ps(hi01, hi23, _MM_SHUFFLE(1, 0, 1, 0));
    out[3] = _mm256_shuffle_ps(hi01, hi23, _MM_SHUFFLE(3, 2, 3, 2));
}

// One cell row of 8 look-ups: `image` points at the row's left corners (minus the lanes' offsets p00),
// c[0..5] = x, y, z of the left corner, then of the right one.
DEFORMKIT_AVX2 void cellRowValues(const float* image, const uint32_t* p00, __m256* c) {
    __m256 m[4], shifted[4];
    for (int32_t k = 0; k < 4; ++k)
        m[k] = loadHalves(image + p00[k], image + p00[k + 4]);
    transposeHalves(m, c);  // x00 y00 z00 x10
    for (int32_t k = 0; k < 4; ++k)
        m[k] = loadHalves(image + p00[k] + 2, image + p00[k + 4] + 2);
    transposeHalves(m, shifted);  // z00 x10 y10 z10: the right corner's y and z
    c[4] = shifted[2];
    c[5] = shifted[3];
}

// blendCellsBase for AVX2, with the same arithmetic (so the same bits). A vectorised blendCell reads its 24
// corner values one lane at a time (12 emulated gathers of 8 scalar loads and inserts each); here each
// lane's two cell rows are read as 128-bit loads, (x00 y00 z00 x10) and (z00 x10 y10 z10) on each row, and
// transposed into one vector per corner and channel: 32 loads and 28 shuffles instead of 96 and 96.
// [p00 + 2, p00 + 6) ends at the last float of the corner p10 (p11 on the upper row): never past the image.
__attribute__((target("avx2,prefer-vector-width=256"))) void blendCellsAvx2(const float* image, int32_t cells,
                                                                            const uint32_t* p00,
                                                                            const float* fx, const float* fy,
                                                                            float* x0, float* x1, float* x2) {
    static_assert(kLaneBlock == 8, "one AVX2 register of lanes");
    __m256 lower[6], upper[6];
    cellRowValues(image, p00, lower);
    cellRowValues(image + 3 * (static_cast<size_t>(cells) + 1), p00, upper);
    const __m256 one = _mm256_set1_ps(1.0f);
    const __m256 vx = _mm256_loadu_ps(fx), vy = _mm256_loadu_ps(fy);
    const __m256 ox = _mm256_sub_ps(one, vx), oy = _mm256_sub_ps(one, vy);
    const __m256 w00 = _mm256_mul_ps(ox, oy), w10 = _mm256_mul_ps(vx, oy);
    const __m256 w01 = _mm256_mul_ps(ox, vy), w11 = _mm256_mul_ps(vx, vy);
    float* out[3] = {x0, x1, x2};
    for (int32_t ch = 0; ch < 3; ++ch) {
        __m256 sum = _mm256_mul_ps(w00, lower[ch]);
        sum = _mm256_add_ps(sum, _mm256_mul_ps(w10, lower[3 + ch]));
        sum = _mm256_add_ps(sum, _mm256_mul_ps(w01, upper[ch]));
        sum = _mm256_add_ps(sum, _mm256_mul_ps(w11, upper[3 + ch]));
        _mm256_storeu_ps(out[ch], sum);
    }
}

// The windows of a block of kLaneBlock segments on the finest level (points one apart), one window row:
// p points at column i - 1 of lane 0's segment, lanes are Step points apart, and out[col * kLaneBlock + l]
// = p[l * Step + col] for the columns i - 1 .. i + 2 (Step 4) or i - 1 .. i + 1 (Step 2, vertical
// segments; lane l's column i + 1 is lane l + 1's i - 1). Reads p[0, kLaneBlock * Step + 1) at most.
template <int32_t Step>
void loadWindowsBase(const float* p, float* out) {
    constexpr int32_t cols = Step == 4 ? 4 : 3;
    for (int32_t col = 0; col < cols; ++col)
        for (int32_t l = 0; l < kLaneBlock; ++l)
            out[col * kLaneBlock + l] = p[l * Step + col];
}

// The same with 128-bit loads and in-register transposes (8 shuffles for 4 columns) instead of one scalar
// load and insert per value.
template <int32_t Step>
DEFORMKIT_AVX2 void loadWindowsAvx2(const float* p, float* out) {
    if constexpr (Step == 4) {
        // Lane l's 4 columns are p[4l, 4l + 4).
        __m256 m[4], column[4];
        for (int32_t k = 0; k < 4; ++k)
            m[k] = loadHalves(p + 4 * k, p + 16 + 4 * k);
        transposeHalves(m, column);
        for (int32_t col = 0; col < 4; ++col)
            _mm256_store_ps(out + col * kLaneBlock, column[col]);
    } else {
        static_assert(Step == 2);
        // Lane l's columns i - 1, i are p[2l], p[2l + 1]; its column i + 1 is p[2l + 2].
        const __m256 m0 = loadHalves(p, p + 8), m1 = loadHalves(p + 4, p + 12);
        const __m256 west = _mm256_shuffle_ps(m0, m1, _MM_SHUFFLE(2, 0, 2, 0));
        _mm256_store_ps(out, west);
        _mm256_store_ps(out + 8, _mm256_shuffle_ps(m0, m1, _MM_SHUFFLE(3, 1, 3, 1)));
        const __m256 next = _mm256_permutevar8x32_ps(west, _mm256_setr_epi32(1, 2, 3, 4, 5, 6, 7, 7));
        _mm256_store_ps(out + 16, _mm256_blend_ps(next, _mm256_broadcast_ss(p + 16), 0x80));
    }
}

// p[2l] = even[l], p[2l + 1] = odd[l] for the kLaneBlock lanes.
inline void storeInterleavedBase(float* p, const float* even, const float* odd) {
    for (int32_t l = 0; l < kLaneBlock; ++l) {
        p[2 * l] = even[l];
        p[2 * l + 1] = odd[l];
    }
}

DEFORMKIT_AVX2 void storeInterleavedAvx2(float* p, const float* even, const float* odd) {
    const __m256 e = _mm256_load_ps(even), o = _mm256_load_ps(odd);
    const __m256 lo = _mm256_unpacklo_ps(e, o), hi = _mm256_unpackhi_ps(e, o);  // lanes 0 1 | 4 5, 2 3 | 6 7
    _mm_storeu_ps(p, _mm256_castps256_ps128(lo));
    _mm_storeu_ps(p + 4, _mm256_castps256_ps128(hi));
    _mm_storeu_ps(p + 8, _mm256_extractf128_ps(lo, 1));
    _mm_storeu_ps(p + 12, _mm256_extractf128_ps(hi, 1));
}

#undef DEFORMKIT_AVX2

}  // namespace

struct Solver::Impl {
    std::string source;
    SolverOptions options;
    int32_t cells = 0;
    std::vector<Level> levels;
    WarpGrid grid;
    // Velocities; between prediction and integration they hold the positions before the prediction.
    std::vector<float> velU, velV;
    PointField rest;                    // f_O: rest lengths (Eq. 1) are measured through it when needed
    const float* deformed = nullptr;    // f_D of the current solve, 3 floats per fine point
    std::vector<int32_t> untangleWork;  // scratch of untangle(), sized at construction, kept between calls
    std::vector<int32_t> untangleNext;
    std::vector<int32_t> rowFolds;  // per cell row of the scan: triangles at or near zero area
    SolveStats stats;

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t fine(const Level& level, int32_t i, int32_t j) const {
        return static_cast<size_t>(j) * level.stride * side() + static_cast<size_t>(i) * level.stride;
    }

    // l_org (Eq. 1) of the segment between fine points a and b, through f_O at the rest grid points (Eq. 6).
    [[nodiscard]] float restLength(size_t a, size_t b) const {
        const float* pa = rest.values.data() + 3 * a;
        const float* pb = rest.values.data() + 3 * b;
        float d2 = 0.0f;
        for (int c = 0; c < 3; ++c) {
            const float d = pb[c] - pa[c];
            d2 += d * d;
        }
        return std::sqrt(d2);
    }

    // True when moving level point (i, j) to (x, y) keeps all 12 triangles around it (both splittings of
    // its four cells) positively oriented. Only called for movable points, which are never on the border.
    bool keepsOrientation(const Level& level, int32_t i, int32_t j, float x, float y) const {
        const size_t s = static_cast<size_t>(level.stride);
        const size_t row = s * static_cast<size_t>(side());
        const size_t k = fine(level, i, j);
        const float* u = grid.u.data();
        const float* v = grid.v.data();
        // Neighbours counter-clockwise from east.
        const size_t n[8] = {k + s, k + s + row, k + row, k - s + row,
                             k - s, k - s - row, k - row, k + s - row};
        for (int q = 0; q < 4; ++q) {  // cell between neighbours 2q (edge), 2q+1 (diagonal), 2q+2 (edge)
            const size_t a = n[2 * q], d = n[2 * q + 1], b = n[(2 * q + 2) % 8];
            if (orient(x, y, u[a], v[a], u[d], v[d]) <= 0.0f) return false;
            if (orient(x, y, u[d], v[d], u[b], v[b]) <= 0.0f) return false;
            if (orient(x, y, u[a], v[a], u[b], v[b]) <= 0.0f) return false;
        }
        return true;
    }

    // One sweep over the 8 parallel sets (paper Fig. 8): each edge type split by the parity of its cell
    // column, so no two segments of a set share a point. The sets are interleaved row by row: for each row
    // of cells, the horizontal segments of its lower point row, then its vertical, then its two diagonal
    // segments, each set by parity. A set's segments on one row are independent (one SIMD or GPU pass
    // each); running all 8 on a row while it is in cache streams the grid once per sweep, not 8 times.
    void sweepRow(const Level& level, int32_t j, float stiffness) {
        // Within a set, segments `step` cells apart: ends of different segments are then never
        // neighbours, so the fold checks of one projectRun are independent (SIMD lanes). Only the runs of
        // cells that can hold a projected segment are visited; what is skipped would not move.
        const int32_t* span = level.spans.data() + 2 * static_cast<size_t>(level.spanBegin[j]);
        const int32_t runs = level.spanBegin[j + 1] - level.spanBegin[j];
        for (int32_t first = 0; first < 4; ++first)
            for (int32_t r = 0; r < runs; ++r)
                projectRun<0>(level, j, first, span[2 * r], span[2 * r + 1], stiffness);
        for (int32_t first = 0; first < 2; ++first)
            for (int32_t r = 0; r < runs; ++r)  // vertical segments on both sides of the run's cells
                projectRun<1>(level, j, first, span[2 * r], span[2 * r + 1] + 1, stiffness);
        for (int32_t first = 0; first < 4; ++first)
            for (int32_t r = 0; r < runs; ++r)
                projectRun<2>(level, j, first, span[2 * r], span[2 * r + 1], stiffness);
        for (int32_t first = 0; first < 4; ++first)
            for (int32_t r = 0; r < runs; ++r)
                projectRun<3>(level, j, first, span[2 * r], span[2 * r + 1], stiffness);
    }

#define DEFORMKIT_KERNEL(name) name##Avx2
#define DEFORMKIT_KERNEL_ATTR __attribute__((target("avx2,prefer-vector-width=256")))
#include "solver_kernels.inc"
#undef DEFORMKIT_KERNEL
#undef DEFORMKIT_KERNEL_ATTR
#define DEFORMKIT_KERNEL(name) name##Base
#define DEFORMKIT_KERNEL_ATTR
#include "solver_kernels.inc"
#undef DEFORMKIT_KERNEL
#undef DEFORMKIT_KERNEL_ATTR

    // The kernels for this CPU (same bytes either way). The point spacing stays a run-time value: with a
    // constant 1 on the finest level the compiler trades gathers for shuffles, which measured slower.
    template <int32_t Type>
    void projectRun(const Level& level, int32_t j, int32_t first, int32_t begin, int32_t end,
                    float stiffness) {
        const bool mapped = !level.orientation.empty();
        if (kHasAvx2) {
            if (mapped) {
                projectRunAvx2<Type, true>(level, j, first, begin, end, stiffness);
            } else {
                projectRunAvx2<Type, false>(level, j, first, begin, end, stiffness);
            }
        } else if (mapped) {
            projectRunBase<Type, true>(level, j, first, begin, end, stiffness);
        } else {
            projectRunBase<Type, false>(level, j, first, begin, end, stiffness);
        }
    }

    void regulariseRun(const Level& level, int32_t j, int32_t first) {
        const bool fine = level.stride == 1;
        if (kHasAvx2) {
            fine ? regulariseRunAvx2<true>(level, j, first) : regulariseRunAvx2<false>(level, j, first);
        } else {
            fine ? regulariseRunBase<true>(level, j, first) : regulariseRunBase<false>(level, j, first);
        }
    }

    // Rows of cells j moves points on rows j and j + 1 and reads rows j - 1 .. j + 2 (the clamp and the
    // fold check read 8-neighbours): forRowBlocks' blocks keep parallel rows apart.
    void sweep(const Level& level, float stiffness) {
        forRowBlocks(0, level.cells, [&](int32_t j) { sweepRow(level, j, stiffness); });
    }

    // Odd points of the row, then even ones (after a propagation only the level's new points: every point
    // of an odd row, the odd points of an even row).
    void regulariseRow(const Level& level, int32_t j, bool onlyNew) {
        regulariseRun(level, j, 1);
        if (!onlyNew || (j % 2) == 1) regulariseRun(level, j, 2);
    }

    // A row of points moves only itself and reads one row either side.
    void regulariseAll(const Level& level, bool onlyNew) {
        forRowBlocks(1, level.cells, [&](int32_t j) { regulariseRow(level, j, onlyNew); });
    }

    // Repairs folds a propagation or prediction step may have made: a point with a non-positive triangle
    // around it moves to the mean of its 8 neighbours.
    bool isFolded(const Level& level, int32_t i, int32_t j) const {
        const size_t k = fine(level, i, j);
        return !keepsOrientation(level, i, j, grid.u[k], grid.v[k]);
    }

    // Pushes the interior corners of cell (i, j)'s triangles (both splittings) at or below `nearZero` area.
    void collectFolded(const Level& level, int32_t i, int32_t j, float nearZero,
                       std::vector<int32_t>& out) const {
        const int32_t c = level.cells;
        const size_t s = static_cast<size_t>(level.stride);
        const size_t a = fine(level, i, j), b = a + s, d = a + s * static_cast<size_t>(side()), e = d + s;
        const float* u = grid.u.data();
        const float* v = grid.v.data();
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
    static int32_t countNearZero(const float* u, const float* v, size_t rowStep, size_t spacing,
                                 int32_t cells, float nearZero) {
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

    // One scan over the level's cells (4 orientation tests per cell, vectorisable) finds the triangles at
    // or near zero area; their corners are the candidates, each checked exactly before it moves. After
    // that only the neighbourhoods of moved points are looked at again, in ascending order (deterministic,
    // serial: the list is short in normal use).
    int32_t untangle(const Level& level) {
        const int32_t c = level.cells;
        const size_t s = static_cast<size_t>(level.stride);
        const size_t rowStep = s * static_cast<size_t>(side());
        // Below a thousandth of a cell's area a triangle is a candidate: far above the rounding of orient()
        // on unit-square coordinates, far below any triangle of a sound grid.
        const float cellSize = static_cast<float>(level.stride) / static_cast<float>(cells);
        const float nearZero = 1e-3f * cellSize * cellSize;
        const float* u = grid.u.data();
        const float* v = grid.v.data();
        int32_t* counts = rowFolds.data();
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(c))
        for (int32_t j = 0; j < c; ++j) {
            const size_t base = static_cast<size_t>(j) * rowStep;
            // The finest level's points are contiguous: a constant spacing gives vector loads.
            counts[j] = s == 1 ? countNearZero<1>(u + base, v + base, rowStep, 1, c, nearZero)
                               : countNearZero<0>(u + base, v + base, rowStep, s, c, nearZero);
        }
        std::vector<int32_t>& work = untangleWork;
        work.clear();
        for (int32_t j = 0; j < c; ++j) {
            if (counts[j] == 0) continue;
            for (int32_t i = 0; i < c; ++i)
                collectFolded(level, i, j, nearZero, work);
        }
        std::sort(work.begin(), work.end());
        work.erase(std::unique(work.begin(), work.end()), work.end());
        int32_t moved = 0;
        const size_t row = rowStep;
        std::vector<int32_t>& next = untangleNext;
        for (int pass = 0; pass < 64 && !work.empty(); ++pass) {
            next.clear();
            for (int32_t id : work) {
                const int32_t i = id % (c + 1), j = id / (c + 1);
                if (!level.movable(level.index(i, j)) || !isFolded(level, i, j)) continue;
                const size_t k = fine(level, i, j);
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
                if (isFolded(level, id % (c + 1), id / (c + 1))) work.push_back(id);
            }
        }
        return moved;
    }

    // §4.4: coarse-level displacements interpolated to the in-between points of the next finer level:
    // the mean of the displacements of the 2 or 4 coarse points around each (bilinear at the midpoints).
    void propagate(const Level& coarse, const Level& finer) {
        const int32_t c = coarse.cells;
#pragma omp parallel for schedule(dynamic, kBlockRows) if (kParallelRows < static_cast <int64_t>(finer.cells))
        for (int32_t jj = 0; jj <= finer.cells; ++jj) {
            const int32_t j0 = jj >> 1, j1 = std::min(j0 + (jj & 1), c);
            // Coarse rows j0 and j1: positions in the fine arrays, and their snapshots.
            const ptrdiff_t coarseRow = static_cast<ptrdiff_t>(coarse.stride) * side();
            const float* u0 = grid.u.data() + j0 * coarseRow;
            const float* v0 = grid.v.data() + j0 * coarseRow;
            const float* u1 = grid.u.data() + j1 * coarseRow;
            const float* v1 = grid.v.data() + j1 * coarseRow;
            const float* su0 = coarse.snapshotU.data() + coarse.index(0, j0);
            const float* sv0 = coarse.snapshotV.data() + coarse.index(0, j0);
            const float* su1 = coarse.snapshotU.data() + coarse.index(0, j1);
            const float* sv1 = coarse.snapshotV.data() + coarse.index(0, j1);
            const int32_t cs = coarse.stride;
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
            // points are new.
            if (jj & 1) {
#pragma omp simd
                for (int32_t m = 0; m <= c; ++m)
                    move(2 * m, m, m);
            }
#pragma omp simd
            for (int32_t m = 0; m < c; ++m)
                move(2 * m + 1, m, m + 1);
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

    int32_t sweepsAt(size_t level) const {
        if (options.sweepsPerLevel.empty()) return 1;
        return options.sweepsPerLevel[std::min(level, options.sweepsPerLevel.size() - 1)];
    }

    void iterate() {
        const size_t n = grid.u.size();
        const float keep = 1.0f - options.damping;
        // §4.1 steps 1-2: damping and prediction (explicit Euler, unit time step, no external force).
#pragma omp parallel for schedule(dynamic, kPointChunk) if (kParallelRows < static_cast <int64_t>(n))
        for (size_t k = 0; k < n; ++k) {
            const float du = keep * velU[k], dv = keep * velV[k];
            velU[k] = grid.u[k];  // the position before prediction, until integration
            velV[k] = grid.v[k];
            grid.u[k] += du;
            grid.v[k] += dv;
        }
        stats.untangledPoints += untangle(levels[0]);
        // Step 3, hierarchical (§4.4): coarsest level first; then propagate, smooth, and go finer.
        // Every level's points are recorded before any level moves, so the displacement a level hands down
        // includes what it received from the levels above it.
        for (size_t l = 1; l < levels.size(); ++l)
            snapshot(levels[l]);
        for (size_t l = levels.size(); l-- > 0;) {
            Level& level = levels[l];
            const float stiffness = std::pow(options.coarseStiffness, static_cast<float>(l));
            for (int32_t s = 0; s < sweepsAt(l); ++s)
                sweep(level, stiffness);
            if (l > 0) {
                Level& finer = levels[l - 1];
                propagate(level, finer);
                regulariseAll(finer, true);
                stats.untangledPoints += untangle(finer);
            }
        }
        // Step 4: regularisation (Eq. 4-5) on the finest grid.
        regulariseAll(levels[0], false);
        // Step 5: integration.
#pragma omp parallel for schedule(dynamic, kPointChunk) if (kParallelRows < static_cast <int64_t>(n))
        for (size_t k = 0; k < n; ++k) {
            velU[k] = grid.u[k] - velU[k];
            velV[k] = grid.v[k] - velV[k];
        }
    }

    void buildMaps(const PointField& rigidity, const PointField& mask, const PointField& orientation);
    static void findSpans(Level& level);
};

namespace {

void requireField(const PointField& field, int32_t cells, int32_t channels, const std::string& source,
                  const char* name) {
    if (field.cells != cells || field.channels != channels ||
        field.values.size() != static_cast<size_t>(cells + 1) * (cells + 1) * channels) {
        throw InvalidInput(formatError(source, name,
                                       std::to_string(field.cells) + " cells x " +
                                           std::to_string(field.channels) + " channels, " +
                                           std::to_string(field.values.size()) + " values",
                                       std::to_string(cells) + " cells x " + std::to_string(channels) +
                                           " channels on the (n + 1)^2 grid points"));
    }
}

}  // namespace

void Solver::Impl::buildMaps(const PointField& rigidity, const PointField& mask,
                             const PointField& orientation) {
    requireField(rigidity, cells, 1, source, "rigidity");
    requireField(mask, cells, 1, source, "mask");
    if (!orientation.values.empty()) requireField(orientation, cells, 1, source, "orientation map");
    for (size_t k = 0; k < rigidity.values.size(); ++k) {
        const float r = rigidity.values[k];
        if (!(r >= 0.0f && r <= 1.0f)) {
            throw InvalidInput(formatError(source, "rigidity at grid point " + std::to_string(k),
                                           std::to_string(r), "a value in [0, 1]"));
        }
    }
    for (Level& level : levels) {
        const size_t count = static_cast<size_t>(level.side()) * level.side();
        level.rigidity.assign(count, 0.0f);
        if (orientation.values.empty()) {
            level.orientation.clear();
            level.orientation.shrink_to_fit();
        } else {
            level.orientation.assign(count, 1.0f);
        }
    }
    // Per point of the level being built from: may it move (mask, Eq. 8, and not on the tile border)?
    // Written into Level::rigidity as kFixed once the next level's blur (Eq. 7) has read the level's R.
    std::vector<uint8_t> movable(static_cast<size_t>(side()) * side()), coarser;
    const auto markFixed = [](Level& level, const std::vector<uint8_t>& canMove) {
        for (size_t k = 0; k < canMove.size(); ++k)
            if (canMove[k] == 0) level.rigidity[k] = kFixed;
    };
    Level& finest = levels[0];
    for (int32_t j = 0; j <= cells; ++j) {
        for (int32_t i = 0; i <= cells; ++i) {
            const size_t k = finest.index(i, j);
            const bool border = i == 0 || j == 0 || i == cells || j == cells;
            finest.rigidity[k] = rigidity.values[k];
            movable[k] = (!border && mask.values[k] >= 0.5f) ? 1 : 0;
            if (!finest.orientation.empty())
                finest.orientation[k] = std::clamp(orientation.values[k], 0.0f, 1.0f);
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
        findSpans(level);
}

void Solver::Impl::findSpans(Level& level) {
    const int32_t c = level.cells;
    auto pointActive = [&](int32_t i, int32_t j) {
        const size_t k = level.index(i, j);
        return level.rigidity[k] > 0.0f;  // movable (kFixed < 0) and rigid
    };
    level.spanBegin.assign(static_cast<size_t>(c) + 1, 0);
    level.spans.clear();
    int32_t count = 0;
    for (int32_t j = 0; j < c; ++j) {
        level.spanBegin[j] = count;
        int32_t open = -1, last = -1;  // current run [open, last + 1)
        for (int32_t i = 0; i < c; ++i) {
            const bool active = pointActive(i, j) || pointActive(i + 1, j) || pointActive(i, j + 1) ||
                                pointActive(i + 1, j + 1);
            if (!active) continue;
            if (open >= 0 && i - (last + 1) < kSpanGap) {
                last = i;
                continue;
            }
            if (open >= 0) {
                level.spans.push_back(open);
                level.spans.push_back(last + 1);
                ++count;
            }
            open = last = i;
        }
        if (open >= 0) {
            level.spans.push_back(open);
            level.spans.push_back(last + 1);
            ++count;
        }
    }
    level.spanBegin[c] = count;
}

Solver::Solver(PointField restGeometry, const PointField& rigidity, const PointField& mask,
               const SolverOptions& options, const PointField& orientation, const std::string& source)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.source = source;
    m.options = options;
    m.cells = restGeometry.cells;
    if (!isPowerOfTwo(m.cells) || m.cells < 2) {
        throw InvalidInput(formatError(source, "grid", std::to_string(m.cells) + " cells per side",
                                       "a power of two, at least 2"));
    }
    if (m.cells > kMaxCells) {
        throw InvalidInput(formatError(source, "grid", std::to_string(m.cells) + " cells per side",
                                       "at most " + std::to_string(kMaxCells)));
    }
    requireField(restGeometry, m.cells, 3, source, "rest geometry image");
    if (options.iterations < 0 || options.damping < 0.0f || options.damping > 1.0f ||
        options.smoothing < 0.0f || options.smoothing > 1.0f || options.orientationPreservation < 0.0f ||
        options.orientationPreservation > 1.0f || !(options.coarseStiffness > 0.0f) ||
        options.coarseStiffness > 1.0f || options.levels < 0) {
        throw InvalidInput(
            formatError(source, "solver options", "out of range",
                        "iterations >= 0, levels >= 0, damping, smoothing, orientation preservation "
                        "in [0, 1], coarse stiffness in (0, 1]"));
    }
    for (int32_t s : options.sweepsPerLevel) {
        if (s < 0) throw InvalidInput(formatError(source, "sweepsPerLevel", std::to_string(s), ">= 0"));
    }
    int32_t levelCount = options.levels;
    if (levelCount == 0) {
        levelCount = 1;
        while ((m.cells >> levelCount) >= 8)
            ++levelCount;
    }
    levelCount = std::min(levelCount, static_cast<int32_t>(std::log2(m.cells)));
    levelCount = std::max(levelCount, 1);
    m.levels.resize(levelCount);
    for (int32_t l = 0; l < levelCount; ++l) {
        Level& level = m.levels[l];
        level.cells = m.cells >> l;
        level.stride = 1 << l;
        const size_t count = static_cast<size_t>(level.side()) * level.side();
        if (l > 0) {
            level.snapshotU.resize(count);
            level.snapshotV.resize(count);
        }
    }
    m.rest = std::move(restGeometry);
    m.untangleWork.reserve(8 * static_cast<size_t>(m.cells + 1));
    m.untangleNext.reserve(8 * static_cast<size_t>(m.cells + 1));
    m.rowFolds.assign(static_cast<size_t>(m.cells) + 1, 0);
    m.buildMaps(rigidity, mask, orientation);
    m.grid = WarpGrid::identity(m.cells);
    const size_t n = m.grid.numPoints();
    m.velU.assign(n, 0.0f);
    m.velV.assign(n, 0.0f);
    m.stats.levels = levelCount;
}

Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

void Solver::setMaps(const PointField& rigidity, const PointField& mask, const PointField& orientation) {
    impl_->buildMaps(rigidity, mask, orientation);
}

const WarpGrid& Solver::solve(const PointField& deformedGeometry) {
    Impl& m = *impl_;
    requireField(deformedGeometry, m.cells, 3, m.source, "deformed geometry image");
    m.deformed = deformedGeometry.values.data();
    m.stats.untangledPoints = 0;
    for (int32_t it = 0; it < m.options.iterations; ++it)
        m.iterate();
    m.stats.iterations = m.options.iterations;
    m.stats.remainingFolds = countFolds(m.grid);
    m.deformed = nullptr;
    return m.grid;
}

void Solver::reset() {
    Impl& m = *impl_;
    m.grid = WarpGrid::identity(m.cells);
    std::fill(m.velU.begin(), m.velU.end(), 0.0f);
    std::fill(m.velV.begin(), m.velV.end(), 0.0f);
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

int32_t countFolds(const WarpGrid& warp) {
    const int32_t n = warp.cells, side = n + 1;
    int32_t folds = 0;
#pragma omp parallel for schedule(static) reduction(+ : folds) if (kParallelRows < static_cast <int64_t>(n))
    for (int32_t j = 0; j < n; ++j) {
        for (int32_t i = 0; i < n; ++i) {
            const size_t a = static_cast<size_t>(j) * side + i, b = a + 1, c = a + side + 1, d = a + side;
            const float* u = warp.u.data();
            const float* v = warp.v.data();
            folds += orient(u[a], v[a], u[b], v[b], u[c], v[c]) <= 0.0f ? 1 : 0;  // (i,j)-(i+1,j+1) split
            folds += orient(u[a], v[a], u[c], v[c], u[d], v[d]) <= 0.0f ? 1 : 0;
            folds += orient(u[a], v[a], u[b], v[b], u[d], v[d]) <= 0.0f ? 1 : 0;  // (i+1,j)-(i,j+1) split
            folds += orient(u[b], v[b], u[c], v[c], u[d], v[d]) <= 0.0f ? 1 : 0;
        }
    }
    return folds;
}

}  // namespace deformkit::uvwarp
