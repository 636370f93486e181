#include "ffd_kernels.h"

namespace deformkit::warp::detail {

void bernstein444Baseline(const LocalBlock& in, const float* translations, DisplacementBlock& out) {
    bernstein444(in, translations, out);
}

void window444Baseline(const WeightBlock& in, const float* translations, DisplacementBlock& out) {
    window444(in, translations, out);
}

void frames444Baseline(const WeightBlock& in, const float* affine, AffineBlock& out) {
    frames444(in, affine, out);
}

void bernsteinWeights444Baseline(const LocalBlock& in, WeightBlock& out) {
    bernsteinWeights444(in, out);
}

}  // namespace deformkit::warp::detail
