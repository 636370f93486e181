// The baseline build of the UV-warp solver's kernels (solver_kernel_loops.h): plain loops where the AVX2
// build shuffles registers.
#include "solver_kernel_loops.h"

namespace deformkit::uvwarp::detail {
namespace {

struct BaselineOps {
    // The regularisation's windows of a block of kLaneBlock points two apart, one window row: two quads of
    // kQuad lanes, lo and hi at column i - 1 of their first lane's point, and out[col * kLaneBlock + l] =
    // lo[2 l + col] (hi[2 (l - kQuad) + col] for the second quad) for the columns i - 1 .. i + 1. Reads lo
    // and hi [0, 2 kQuad + 1) at most.
    static void loadWindows(const float* lo, const float* hi, float* out) {
        for (int32_t col = 0; col < 3; ++col) {
            for (int32_t l = 0; l < kQuad; ++l) {
                out[col * kLaneBlock + l] = lo[2 * l + col];
                out[col * kLaneBlock + kQuad + l] = hi[2 * l + col];
            }
        }
    }

    // The windows of a block of kPairs pairs of segments at points one apart, one window row: lane l is
    // segment l % kPair of the pair at cell[kPair (l / kPair)] (Step points apart), and
    // out[col * kLaneBlock + l] = row[cell[l] - 1 + col] for the columns i - 1 .. i + 2 (Step 4) or
    // i - 1 .. i + 1 (Step 2).
    template <int32_t Step>
    static void loadPairWindows(const float* row, const int32_t* cell, float* out) {
        constexpr int32_t cols = Step == 4 ? 4 : 3;
        for (int32_t col = 0; col < cols; ++col)
            for (int32_t l = 0; l < kLaneBlock; ++l)
                out[col * kLaneBlock + l] = row[cell[l] - 1 + col];
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

    // The kLaneBlock points of a 3-float image at offsets at[l]: x0[l], x1[l], x2[l].
    static void loadPoints(const float* image, const uint32_t* at, float* x0, float* x1, float* x2) {
        for (int32_t l = 0; l < kLaneBlock; ++l) {
            x0[l] = image[at[l]];
            x1[l] = image[at[l] + 1];
            x2[l] = image[at[l] + 2];
        }
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
