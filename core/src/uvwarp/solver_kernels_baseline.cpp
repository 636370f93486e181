// The baseline build of the UV-warp solver's kernels (solver_kernel_loops.h): plain loops where the AVX2
// build shuffles registers.
#include "solver_kernel_loops.h"

namespace deformkit::uvwarp::detail {
namespace {

struct BaselineOps {
    // The windows of a block of kLaneBlock segments on the finest level (points one apart), one window row:
    // p points at column i - 1 of lane 0's segment, lanes are Step points apart, and out[col * kLaneBlock +
    // l] = p[l * Step + col] for the columns i - 1 .. i + 2 (Step 4) or i - 1 .. i + 1 (Step 2, vertical
    // segments; lane l's column i + 1 is lane l + 1's i - 1). Reads p[0, kLaneBlock * Step + 1) at most.
    template <int32_t Step>
    static void loadWindows(const float* p, float* out) {
        constexpr int32_t cols = Step == 4 ? 4 : 3;
        for (int32_t col = 0; col < cols; ++col)
            for (int32_t l = 0; l < kLaneBlock; ++l)
                out[col * kLaneBlock + l] = p[l * Step + col];
    }

    // blendCell for kLaneBlock look-ups, lane l of every array one look-up. Out of line: inlined into the
    // projection it measured slower (UV-14).
    [[gnu::noinline]] static void blendCells(const float* image, int32_t cells, const uint32_t* p00,
                                             const float* fx, const float* fy, float* x0, float* x1,
                                             float* x2) {
#pragma omp simd
        for (int32_t l = 0; l < kLaneBlock; ++l)
            blendCell(image, cells, p00[l], fx[l], fy[l], x0[l], x1[l], x2[l]);
    }

    // p[2l] = even[l], p[2l + 1] = odd[l] for the kLaneBlock lanes.
    static void storeInterleaved(float* p, const float* even, const float* odd) {
        for (int32_t l = 0; l < kLaneBlock; ++l) {
            p[2 * l] = even[l];
            p[2 * l + 1] = odd[l];
        }
    }
};

}  // namespace

const SolverKernels kBaselineKernels = {sweepRow<BaselineOps>, regulariseRow<BaselineOps>};

}  // namespace deformkit::uvwarp::detail
