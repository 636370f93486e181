// The AVX2 build of the UV-warp solver's kernels (solver_kernel_loops.h): compiled with -mavx2
// (core/CMakeLists.txt), run only when simd::activeIsa() says so. Empty on other architectures.
#include "solver_kernel_loops.h"

#ifdef DEFORMKIT_SIMD_X86
#ifndef __AVX2__
#error "compile with -mavx2 (core/CMakeLists.txt)"
#endif

#include <immintrin.h>

namespace deformkit::uvwarp::detail {
namespace {

// One register from two 4-float loads: lo in lanes 0-3, hi in lanes 4-7.
[[gnu::always_inline]] inline __m256 loadHalves(const float* lo, const float* hi) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1);
}

// m[k] holds lane k's 4 values in its low half and lane k + 4's in its high half; out[c] = value c of
// lanes 0..7, in order (a 4x4 transpose in each half: 8 shuffles).
[[gnu::always_inline]] inline void transposeHalves(const __m256* m, __m256* out) {
    const __m256 lo01 = _mm256_unpacklo_ps(m[0], m[1]), hi01 = _mm256_unpackhi_ps(m[0], m[1]);
    const __m256 lo23 = _mm256_unpacklo_ps(m[2], m[3]), hi23 = _mm256_unpackhi_ps(m[2], m[3]);
    out[0] = _mm256_shuffle_ps(lo01, lo23, _MM_SHUFFLE(1, 0, 1, 0));
    out[1] = _mm256_shuffle_ps(lo01, lo23, _MM_SHUFFLE(3, 2, 3, 2));
    out[2] = _mm256_shuffle_ps(hi01, hi23, _MM_SHUFFLE(1, 0, 1, 0));
    out[3] = _mm256_shuffle_ps(hi01, hi23, _MM_SHUFFLE(3, 2, 3, 2));
}

// The 4 floats at image + at[l] of 8 lanes, one 128-bit load each, transposed: c[f] = float f of lanes 0..7.
[[gnu::always_inline]] inline void loadTransposed(const float* image, const uint32_t* at, __m256* c) {
    __m256 m[4];
    for (int32_t k = 0; k < 4; ++k)
        m[k] = loadHalves(image + at[k], image + at[k + 4]);
    transposeHalves(m, c);
}

// One cell row of 8 look-ups: `image` points at the row's left corners (minus the lanes' offsets p00),
// c[0..5] = x, y, z of the left corner, then of the right one.
[[gnu::always_inline]] inline void cellRowValues(const float* image, const uint32_t* p00, __m256* c) {
    __m256 shifted[4];
    loadTransposed(image, p00, c);            // x00 y00 z00 x10
    loadTransposed(image + 2, p00, shifted);  // z00 x10 y10 z10: the right corner's y and z
    c[4] = shifted[2];
    c[5] = shifted[3];
}

struct Avx2Ops {
    // BaselineOps::loadWindows with 128-bit loads and in-register shuffles instead of one scalar load and
    // insert per value: a quad is one 128-bit half of each register.
    [[gnu::always_inline]] static void loadWindows(const float* lo, const float* hi, float* out) {
        static_assert(kQuad == 4, "a quad is a 128-bit half");
        // Lane l's columns i - 1, i are lo[2l], lo[2l + 1]; its column i + 1 is lo[2l + 2] (hi for lanes
        // 4-7).
        const __m256 m0 = loadHalves(lo, hi), m1 = loadHalves(lo + 4, hi + 4);
        const __m256 west = _mm256_shuffle_ps(m0, m1, _MM_SHUFFLE(2, 0, 2, 0));
        _mm256_store_ps(out, west);
        _mm256_store_ps(out + 8, _mm256_shuffle_ps(m0, m1, _MM_SHUFFLE(3, 1, 3, 1)));
        const __m256 next = _mm256_permutevar8x32_ps(west, _mm256_setr_epi32(1, 2, 3, 3, 5, 6, 7, 7));
        const __m256 ends = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_broadcast_ss(lo + 8)),
                                                 _mm_broadcast_ss(hi + 8), 1);
        _mm256_store_ps(out + 16, _mm256_blend_ps(next, ends, 0x88));
    }

    // BaselineOps::loadPairWindows as 128-bit loads, each half one lane's window (so a block is read as in
    // loadWindows, and the same in-register transpose follows): the first lane of pair q at p[q], the second
    // Step points on (for Step 2 read from one point on and shifted down a float, so that no load reaches
    // past the last column of the second window, p[q] + 4).
    template <int32_t Step>
    [[gnu::always_inline]] static void loadPairWindows(const float* row, const int32_t* cell, float* out) {
        static_assert(kPair == 2 && kPairs == 4, "four pairs of two lanes");
        const float* p[kPairs];
        for (int32_t q = 0; q < kPairs; ++q)
            p[q] = row + cell[kPair * q] - 1;
        // m[k]: lane k (pair k / 2) in the low half, lane k + 4 (pair k / 2 + 2) in the high half.
        __m256 m[4];
        for (int32_t k = 0; k < 4; k += 2) {
            const float* lo = p[k / 2];
            const float* hi = p[k / 2 + 2];
            m[k] = loadHalves(lo, hi);
            if constexpr (Step == 4) {
                m[k + 1] = loadHalves(lo + 4, hi + 4);
            } else {
                static_assert(Step == 2);
                m[k + 1] = _mm256_permute_ps(loadHalves(lo + 1, hi + 1), _MM_SHUFFLE(3, 3, 2, 1));
            }
        }
        __m256 column[4];
        transposeHalves(m, column);
        constexpr int32_t cols = Step == 4 ? 4 : 3;
        for (int32_t col = 0; col < cols; ++col)
            _mm256_store_ps(out + col * kLaneBlock, column[col]);
    }

    // BaselineOps::blendCells with the same arithmetic (so the same bits). A vectorised blendCell reads its
    // 24 corner values one lane at a time (12 emulated gathers of 8 scalar loads and inserts each); here each
    // lane's two cell rows are read as 128-bit loads, (x00 y00 z00 x10) and (z00 x10 y10 z10) on each row,
    // and transposed into one vector per corner and channel: 32 loads and 28 shuffles instead of 96 and 96.
    // [p00 + 2, p00 + 6) ends at the last float of the corner p10 (p11 on the upper row): never past the
    // image. Out of line: inlined into the projection it measured slower (UV-14).
    [[gnu::noinline]] static void blendCells(const float* image, int32_t cells, const uint32_t* p00,
                                             const float* fx, const float* fy, float* x0, float* x1,
                                             float* x2) {
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

    // BaselineOps::loadPoints as one 128-bit load per lane, (x0 x1 x2, and the next float), transposed:
    // 8 loads and 8 shuffles instead of 24 scalar loads and inserts. The fourth float is never past the
    // image: the points are inside the grid, never its last one.
    [[gnu::always_inline]] static void loadPoints(const float* image, const uint32_t* at, float* x0,
                                                  float* x1, float* x2) {
        __m256 c[4];
        loadTransposed(image, at, c);
        _mm256_store_ps(x0, c[0]);
        _mm256_store_ps(x1, c[1]);
        _mm256_store_ps(x2, c[2]);
    }

    [[gnu::always_inline]] static void storeInterleaved(float* p, const float* even, const float* odd) {
        const __m256 e = _mm256_load_ps(even), o = _mm256_load_ps(odd);
        // lo: lanes 0 1 | 4 5, hi: lanes 2 3 | 6 7.
        const __m256 lo = _mm256_unpacklo_ps(e, o), hi = _mm256_unpackhi_ps(e, o);
        _mm_storeu_ps(p, _mm256_castps256_ps128(lo));
        _mm_storeu_ps(p + 4, _mm256_castps256_ps128(hi));
        _mm_storeu_ps(p + 8, _mm256_extractf128_ps(lo, 1));
        _mm_storeu_ps(p + 12, _mm256_extractf128_ps(hi, 1));
    }
};

}  // namespace

const SolverKernels kAvx2Kernels = {sweepRow<Avx2Ops>, regulariseRow<Avx2Ops>};

}  // namespace deformkit::uvwarp::detail
#endif
