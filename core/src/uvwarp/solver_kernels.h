#pragma once

// Private to the UV-warp solver: the interface of its SIMD kernels (solver_kernels_<isa>.cpp, one build per
// instruction set, simd/cpu.h), and what they share with the rest of the solver: K_G and the orientation
// test.

#include <cstddef>
#include <cstdint>

#include "simd/cpu.h"

namespace deformkit::uvwarp::detail {

// What the kernels read and write, as plain pointers into the solver's state (solver_state.h). Aggregates
// without member functions or initialisers: the kernel files then emit no function the linker could share
// between an AVX2 and a baseline object (docs/decisions.md, "SIMD kernels").
struct KernelGrid {
    int32_t cells;                  // n, cells per side of the fine grid
    const float* rest;              // f_O, 3 floats per fine point
    const float* deformed;          // f_D of the current solve, 3 floats per fine point
    float orientationPreservation;  // SolverOptions
    float smoothing;                // SolverOptions
};

// One level of the hierarchy (Level): its points are every stride-th fine point of every stride-th row.
// The kernels move them where u and v say: point (i, j) at u[j * row + i * step], either in place in the
// warp (step = stride) or in a compact copy of the level's points (step 1).
struct KernelLevel {
    int32_t cells;
    int32_t stride;  // fine points between the level's points: where f_O is read
    float *u, *v;
    int32_t step;
    ptrdiff_t row;
    const float* rigidity;        // R, or kFixed: (cells + 1)^2 points
    const float* orientation;     // null without an orientation map
    const int32_t* spanBegin;     // per row of cells, its first run of cells to project
    const int32_t* spans;         // runs [spans[2r], spans[2r + 1])
    const int32_t* movableBegin;  // per row of points, its first run of points that may move
    const int32_t* movableRuns;   // runs [movableRuns[2r], movableRuns[2r + 1])
};

// One instruction set's kernels. Both builds give the same bytes.
struct SolverKernels {
    // The 8 parallel sets of constraints (Eq. 1-3 and orientation preservation) on row of cells j.
    void (*sweepRow)(const KernelGrid& grid, const KernelLevel& level, int32_t j, float stiffness);
    // Eq. 4-5 on the points of row j that may move: odd points, then even ones (onlyNew: after a propagation,
    // only the level's points that the coarser level does not have).
    void (*regulariseRow)(const KernelGrid& grid, const KernelLevel& level, int32_t j, bool onlyNew);
};

extern const SolverKernels kBaselineKernels;
#ifdef DEFORMKIT_SIMD_X86
extern const SolverKernels kAvx2Kernels;
#endif

// Level rigidity of a point that may not move is kFixed - R: negative (every test of "may move" is a sign
// test) and still telling its R, so that a rigid segment pinned at one end can keep its length (UV-15).
constexpr float kFixed = -1.0f;

// 3x3 Gaussian kernel K_G (Eq. 5 and 7): (1 2 1) x (1 2 1) / 16.
constexpr float kGauss[3] = {0.25f, 0.5f, 0.25f};

namespace {

// Twice the signed area of triangle (a, b, c): > 0 counter-clockwise.
inline float orient(float ax, float ay, float bx, float by, float cx, float cy) {
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

}  // namespace

}  // namespace deformkit::uvwarp::detail
