// The AVX2 build of the FFD kernels: compiled with -mavx2 (core/CMakeLists.txt), called only when
// simd::activeIsa() says so. Empty on other architectures.
#include "ffd_kernels.h"

#ifdef DEFORMKIT_SIMD_X86
#ifndef __AVX2__
#error "compile with -mavx2 (core/CMakeLists.txt)"
#endif

namespace deformkit::warp::detail {

void bernstein444Avx2(const LocalBlock& in, const float* translations, DisplacementBlock& out) {
    bernstein444(in, translations, out);
}

void window444Avx2(const WeightBlock& in, const float* translations, DisplacementBlock& out) {
    window444(in, translations, out);
}

void frames444Avx2(const WeightBlock& in, const float* affine, AffineBlock& out) {
    frames444(in, affine, out);
}

void bernsteinWeights444Avx2(const LocalBlock& in, WeightBlock& out) {
    bernsteinWeights444(in, out);
}

}  // namespace deformkit::warp::detail
#endif
