// The AVX2 build of the FFD kernels: compiled with -mavx2 (core/CMakeLists.txt), called only when
// simd::activeIsa() says so. Empty on other architectures.
#include "ffd_kernels.h"

#ifdef DEFORMKIT_SIMD_X86
#ifndef __AVX2__
#error "compile with -mavx2 (core/CMakeLists.txt)"
#endif

namespace deformkit::warp::detail {

const FfdKernels kAvx2FfdKernels = {bernstein444,        window444,         frames444,
                                    bernsteinWeights444, bsplineWeights444, bsplineRepeatWeights444,
                                    bspline444,          bsplineRepeat444};

}  // namespace deformkit::warp::detail
#endif
