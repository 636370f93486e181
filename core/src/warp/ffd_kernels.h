#pragma once

// Private to the FFD (ffd.cpp and ffd_kernels_<isa>.cpp): the kernels of the 4x4x4 lattice (divisions 3, 3,
// 3; translations), one per instruction set (simd/cpu.h): the Bernstein cubic, whose weights the kernel
// computes, and any basis whose weights the caller gives per point (the B-splines).
//
// The cubic lattice of the FFD benchmark (tests/bench/ffd_bench.cpp). Every point is reached by all 64
// controls, so every point reads the same translations: eight points are evaluated together in SoA form (one
// lane per point), each translation component broadcast once per block. The sum order is the per-point path's
// (ffd.cpp, windowSum): over (i, j) first, with the k weights applied at the end, so both give the same bits.

#include <cstring>

#include "simd/cpu.h"

namespace deformkit::warp::detail {

constexpr int kBlock = 8;  // points per SoA block: one AVX register of floats

// Eight points' local coordinates (lattice units, x = s l) in SoA; lanes past the end are 0.
struct LocalBlock {
    alignas(32) float x[kBlock], y[kBlock], z[kBlock];
};
// Eight points' weights of the 4 controls along each axis: w[axis][control][lane].
struct WeightBlock {
    alignas(32) float w[3][4][kBlock];
};
// Their displacements D(p), SoA.
struct DisplacementBlock {
    alignas(32) float x[kBlock], y[kBlock], z[kBlock];
};
// Their summed affine maps (FFD with frames: 12 floats per control, the sum before it is applied), SoA.
struct AffineBlock {
    alignas(32) float a[12][kBlock];
};

// One instruction set's kernels (as the UV-warp solver's SolverKernels). translations: 64 controls x 3 floats
// in Lattice::index order; affine: 64 controls x 12 floats. Every build gives the same bytes.
struct FfdKernels {
    void (*bernstein444)(const LocalBlock& in, const float* translations, DisplacementBlock& out);
    void (*window444)(const WeightBlock& in, const float* translations, DisplacementBlock& out);
    void (*frames444)(const WeightBlock& in, const float* affine, AffineBlock& out);
    void (*bernsteinWeights444)(const LocalBlock& in, WeightBlock& out);
    void (*bsplineWeights444)(const LocalBlock& in, WeightBlock& out);
    void (*bsplineRepeatWeights444)(const LocalBlock& in, WeightBlock& out);
    // The B-spline sums with their weights computed in registers (either end rule), as bernstein444.
    void (*bspline444)(const LocalBlock& in, const float* translations, DisplacementBlock& out);
    void (*bsplineRepeat444)(const LocalBlock& in, const float* translations, DisplacementBlock& out);
};

extern const FfdKernels kBaselineFfdKernels;
#ifdef DEFORMKIT_SIMD_X86
extern const FfdKernels kAvx2FfdKernels;
#endif

namespace {

// The kernel's one source, compiled into each ISA's file; internal linkage, so the linker never merges the
// AVX2 file's copy with the baseline's (docs/decisions.md, "SIMD kernels"). GCC/Clang vector extension of 8
// floats: one AVX register, two SSE2 operations per line on the baseline x86-64, whatever the target has
// elsewhere.
typedef float Float8 __attribute__((vector_size(32)));

// D = sum_ijk w0_i w1_j w2_k delta_ijk over the 64 controls, for eight lanes.
[[gnu::always_inline]] inline void sum444(const Float8 (&w)[3][4], const float* deltas,
                                          DisplacementBlock& out) {
    Float8 acc[12] = {};  // control k of the (i, j) run, component e: acc[3 k + e]
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
            const Float8 wij = w[0][i] * w[1][j];
            const float* row = deltas + (i * 4 + j) * 12;
            for (int v = 0; v < 12; ++v)
                acc[v] += wij * row[v];
        }
    }
    const Float8 d[3] = {w[2][0] * acc[0] + w[2][1] * acc[3] + w[2][2] * acc[6] + w[2][3] * acc[9],
                         w[2][0] * acc[1] + w[2][1] * acc[4] + w[2][2] * acc[7] + w[2][3] * acc[10],
                         w[2][0] * acc[2] + w[2][1] * acc[5] + w[2][2] * acc[8] + w[2][3] * acc[11]};
    std::memcpy(out.x, &d[0], sizeof(out.x));
    std::memcpy(out.y, &d[1], sizeof(out.y));
    std::memcpy(out.z, &d[2], sizeof(out.z));
}

// Beyond the lattice (x < 0 or x > 3) the window weights continue linearly from the end face, as
// basisWeights computes them per point (slope 1): 1 - x and x on controls 0 and 1, -(x - 3) and 1 + (x - 3)
// on controls 2 and 3. Lanes inside keep w.
[[gnu::always_inline]] inline void continueBeyondEnds(const Float8& x, Float8 (&w)[4]) {
    typedef int Int8 __attribute__((vector_size(32)));
    const Float8 zero = {}, e = x - 3.0f;
    const Int8 below = x<0.0f, above = x> 3.0f;
    w[0] = below ? 1.0f - x : (above ? zero : w[0]);
    w[1] = below ? x : (above ? zero : w[1]);
    w[2] = below ? zero : (above ? -e : w[2]);
    w[3] = below ? zero : (above ? 1.0f + e : w[3]);
}

// The Bernstein cubic's weights of eight points, as basisWeights' closed form computes them per point.
[[gnu::always_inline]] inline void bernsteinWeights(const LocalBlock& in, Float8 (&w)[3][4]) {
    const float* coords[3] = {in.x, in.y, in.z};
    for (int a = 0; a < 3; ++a) {
        Float8 x;  // copied in, not returned: an 8-float vector return is AVX ABI (-Wpsabi)
        std::memcpy(&x, coords[a], sizeof(x));
        const Float8 s = x / 3.0f, r = 1.0f - s;
        w[a][0] = r * r * r;
        w[a][1] = 3.0f * s * r * r;
        w[a][2] = 3.0f * s * s * r;
        w[a][3] = s * s * s;
        continueBeyondEnds(x, w[a]);
    }
}

[[gnu::always_inline]] inline void bernstein444(const LocalBlock& in, const float* deltas,
                                                DisplacementBlock& out) {
    Float8 w[3][4];
    bernsteinWeights(in, w);
    sum444(w, deltas, out);
}

[[gnu::always_inline]] inline void bernsteinWeights444(const LocalBlock& in, WeightBlock& out) {
    Float8 w[3][4];
    bernsteinWeights(in, w);
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 4; ++c)
            std::memcpy(out.w[a][c], &w[a][c], sizeof(Float8));
}

// The uniform cubic B-spline's window weights on 3 divisions with linearly extrapolated end controls: the
// per-point path's arithmetic (ffd.cpp, basisWeights with FfdEnds::Extrapolate and splineWeights) lane by
// lane, so the same bits. The span is clamp(floor(x), 0, 2), here (x >= 1) + (x >= 2); u = x - span; the
// end spans fold the missing control into their neighbours; control c of the window takes b[c - span + 1];
// beyond the lattice, continueBeyondEnds.
[[gnu::always_inline]] inline void bsplineWeights444(const LocalBlock& in, WeightBlock& out) {
    typedef int Int8 __attribute__((vector_size(32)));
    const float* coords[3] = {in.x, in.y, in.z};
    const Float8 zero = {}, one = zero + 1.0f;
    for (int a = 0; a < 3; ++a) {
        Float8 x;
        std::memcpy(&x, coords[a], sizeof(x));
        const Int8 pastOne = x >= 1.0f, pastTwo = x >= 2.0f;  // all bits set where true
        const Int8 first = pastOne == 0, middle = pastOne & (pastTwo == 0);
        const Float8 span = (pastOne ? one : zero) + (pastTwo ? one : zero);
        const Float8 u = x - span, u2 = u * u, u3 = u2 * u, v = 1.0f - u;
        const Float8 b0 = v * v * v / 6.0f;
        const Float8 b1 = (3.0f * u3 - 6.0f * u2 + 4.0f) / 6.0f;
        const Float8 b2 = (-3.0f * u3 + 3.0f * u2 + 3.0f * u + 1.0f) / 6.0f;
        const Float8 b3 = u3 / 6.0f;
        // Span 0: b1 += 2 b0, b2 -= b0; span 2: b2 += 2 b3, b1 -= b3.
        const Float8 b1First = b1 + 2.0f * b0, b2First = b2 - b0;
        const Float8 b2Last = b2 + 2.0f * b3, b1Last = b1 - b3;
        Float8 w[4] = {first ? b1First : (middle ? b0 : zero), first ? b2First : (middle ? b1 : b0),
                       first ? b3 : (middle ? b2 : b1Last), first ? zero : (middle ? b3 : b2Last)};
        continueBeyondEnds(x, w);
        for (int c = 0; c < 4; ++c)
            std::memcpy(out.w[a][c], &w[c], sizeof(Float8));
    }
}

// The same with the end controls repeated (FfdEnds::Repeat, Blender's Lattice): cell = floor(x), u = x -
// cell, span = clamp(cell, -2, 4); tap c of the span lands on control clamp(span - 1 + c, 0, 3), the taps
// that land on one control added in order from 0, as the per-point path does. floor by truncation: exact for
// |x| < 2^23, and beyond it x is a whole number (u = 0, the span clamped either way).
[[gnu::always_inline]] inline void bsplineRepeatWeights444(const LocalBlock& in, WeightBlock& out) {
    typedef int Int8 __attribute__((vector_size(32)));
    const float* coords[3] = {in.x, in.y, in.z};
    const Float8 zero = {}, one = zero + 1.0f;
    constexpr float kWhole = 8388608.0f;  // 2^23: every float at or beyond it is a whole number
    for (int a = 0; a < 3; ++a) {
        Float8 x;
        std::memcpy(&x, coords[a], sizeof(x));
        const Int8 huge = (x >= kWhole) | (x <= -kWhole);
        const Float8 clamped = huge ? zero : x;  // truncated below, safely within int's range
        const Float8 truncated = __builtin_convertvector(__builtin_convertvector(clamped, Int8), Float8);
        const Float8 cell = truncated - (truncated > clamped ? one : zero);
        const Float8 u = huge ? zero : x - cell, u2 = u * u, u3 = u2 * u, v = 1.0f - u;
        const Float8 b[4] = {v * v * v / 6.0f, (3.0f * u3 - 6.0f * u2 + 4.0f) / 6.0f,
                             (-3.0f * u3 + 3.0f * u2 + 3.0f * u + 1.0f) / 6.0f, u3 / 6.0f};
        // The span: from cell, or past the lattice on x's side when x is huge.
        Float8 span = huge ? (x > zero ? zero + 4.0f : zero - 2.0f) : cell;
        span = span < -2.0f ? zero - 2.0f : span;
        span = span > 4.0f ? zero + 4.0f : span;
        Float8 w[4] = {zero, zero, zero, zero};
        for (int c = 0; c < 4; ++c) {
            Float8 k = span + static_cast<float>(c - 1);
            k = k < 0.0f ? zero : k;
            k = k > 3.0f ? zero + 3.0f : k;
            for (int control = 0; control < 4; ++control)
                w[control] = k == static_cast<float>(control) ? w[control] + b[c] : w[control];
        }
        for (int control = 0; control < 4; ++control)
            std::memcpy(out.w[a][control], &w[control], sizeof(Float8));
    }
}

[[gnu::always_inline]] inline void window444(const WeightBlock& in, const float* deltas,
                                             DisplacementBlock& out) {
    Float8 w[3][4];
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 4; ++c)
            std::memcpy(&w[a][c], in.w[a][c], sizeof(Float8));
    sum444(w, deltas, out);
}

// The weights and the sum in one kernel: the weights stay in registers, as bernstein444's do. The same
// arithmetic as bsplineWeights444 then window444, so the same bits.
[[gnu::always_inline]] inline void bspline444(const LocalBlock& in, const float* deltas,
                                              DisplacementBlock& out) {
    WeightBlock w;
    bsplineWeights444(in, w);
    window444(w, deltas, out);
}

[[gnu::always_inline]] inline void bsplineRepeat444(const LocalBlock& in, const float* deltas,
                                                    DisplacementBlock& out) {
    WeightBlock w;
    bsplineRepeatWeights444(in, w);
    window444(w, deltas, out);
}

// The same sum with 12 floats per control (affine maps): one pass over (i, j) per control k of the run, so
// 12 accumulators stay in registers; each element's sum keeps the per-point path's order.
[[gnu::always_inline]] inline void frames444(const WeightBlock& in, const float* deltas, AffineBlock& out) {
    Float8 w[3][4];
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 4; ++c)
            std::memcpy(&w[a][c], in.w[a][c], sizeof(Float8));
    Float8 sum[4][12];
    for (int k = 0; k < 4; ++k) {
        Float8 acc[12] = {};
        for (int i = 0; i < 4; ++i) {
            for (int j = 0; j < 4; ++j) {
                const Float8 wij = w[0][i] * w[1][j];
                const float* row = deltas + ((i * 4 + j) * 4 + k) * 12;
                for (int v = 0; v < 12; ++v)
                    acc[v] += wij * row[v];
            }
        }
        for (int v = 0; v < 12; ++v)
            sum[k][v] = acc[v];
    }
    for (int e = 0; e < 12; ++e) {
        const Float8 d =
            w[2][0] * sum[0][e] + w[2][1] * sum[1][e] + w[2][2] * sum[2][e] + w[2][3] * sum[3][e];
        std::memcpy(out.a[e], &d, sizeof(out.a[e]));
    }
}

}  // namespace

}  // namespace deformkit::warp::detail
