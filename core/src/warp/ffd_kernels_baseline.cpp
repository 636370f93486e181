#include "ffd_kernels.h"

namespace deformkit::warp::detail {

void bernstein444Baseline(const LocalBlock& in, const float* translations, DisplacementBlock& out) {
    bernstein444(in, translations, out);
}

}  // namespace deformkit::warp::detail
