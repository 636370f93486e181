#pragma once

// Private to the FFD (ffd.cpp and ffd_kernels_<isa>.cpp): the kernels of the Bernstein 4x4x4 lattice
// (divisions 3, 3, 3; translations), one per instruction set (simd/cpu.h).
//
// The cubic lattice of the FFD benchmark (tests/bench/ffd_bench.cpp). Every point is reached by all 64
// controls, so every point reads the same translations: eight points are evaluated together in SoA form (one
// lane per point), each translation component broadcast once per block. The sum order is the per-point path's
// (ffd.cpp, windowSum): over (i, j) first, with the k weights applied at the end.

#include <cstring>

#include "simd/cpu.h"

namespace deformkit::warp::detail {

constexpr int kBlock = 8;  // points per SoA block: one AVX register of floats

// Eight points' local coordinates (lattice units, x = s l) in SoA; lanes past the end are 0.
struct LocalBlock {
    alignas(32) float x[kBlock], y[kBlock], z[kBlock];
};
// Their displacements D(p), SoA.
struct DisplacementBlock {
    alignas(32) float x[kBlock], y[kBlock], z[kBlock];
};

// translations: 64 controls x 3 floats in Lattice::index order. The same bytes from each.
void bernstein444Baseline(const LocalBlock& in, const float* translations, DisplacementBlock& out);
#ifdef DEFORMKIT_SIMD_X86
void bernstein444Avx2(const LocalBlock& in, const float* translations, DisplacementBlock& out);
#endif

namespace {

// The kernel's one source, compiled into each ISA's file; internal linkage, so the linker never merges the
// AVX2 file's copy with the baseline's (docs/decisions.md, "SIMD kernels"). GCC/Clang vector extension of 8
// floats: one AVX register, two SSE2 operations per line on the baseline x86-64, whatever the target has
// elsewhere.
typedef float Float8 __attribute__((vector_size(32)));

[[gnu::always_inline]] inline void bernstein444(const LocalBlock& in, const float* deltas,
                                                DisplacementBlock& out) {
    Float8 w[3][4];
    const float* coords[3] = {in.x, in.y, in.z};
    for (int a = 0; a < 3; ++a) {
        Float8 x;  // copied in, not returned: an 8-float vector return is AVX ABI (-Wpsabi)
        std::memcpy(&x, coords[a], sizeof(x));
        const Float8 s = x / 3.0f, r = 1.0f - s;  // as basisWeights' closed-form cubic
        w[a][0] = r * r * r;
        w[a][1] = 3.0f * s * r * r;
        w[a][2] = 3.0f * s * s * r;
        w[a][3] = s * s * s;
    }
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

}  // namespace

}  // namespace deformkit::warp::detail
