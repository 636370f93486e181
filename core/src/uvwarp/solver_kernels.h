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
    const float* deformed;          // f_D of the current solve, 3 floats per point of its geometry image
    int32_t imageCells;             // the geometry images' cells per side: n, or n / 2 (Solver)
    float orientationPreservation;  // SolverOptions
    float smoothing;                // SolverOptions
};

// One level of the hierarchy (Level): its points are every stride-th fine point of every stride-th row.
// The kernels move them where u and v say: point (i, j) at u[j * row + i * step], either in place in the
// warp (step = stride) or in a compact copy of the level's points (step 1).
struct KernelLevel {
    int32_t cells;
    // f_O at the level's points: point (i, j) at rest[j * restRow + i * restStep] (3 floats), in the rest
    // geometry image (restStep 3 stride, or 3 stride / 2 in an image of half the fine grid's cells) or in a
    // compact copy of the level's points (restStep 3). restBetween: the finest level over an image of half
    // its cells; rest is that image (restRow 3 (imageCells + 1)), and f_O at a point between the image's is
    // its bilinear look-up (the mean of 2 or 4 image points).
    const float* rest;
    ptrdiff_t restRow;
    int32_t restStep;
    int32_t restBetween;
    float *u, *v;
    int32_t step;
    ptrdiff_t row;
    const float* rigidity;        // R, or kFixed: (cells + 1)^2 points
    const float* orientation;     // null without an orientation map
    const int32_t* setRunBegin;   // per row of cells and set (kSets of them), its first run of segments
    const int32_t* setRuns;       // runs [setRuns[2r], setRuns[2r + 1]) of segment numbers g
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

// The four constraint directions of the 8-connected grid (paper §4.2, V_horz, V_vert, V_shear0, V_shear1),
// as the level-grid offsets of the segment's two ends from the cell corner (I, J), and the segment's
// canonical (rest) direction.
struct EdgeType {
    int32_t ai, aj, bi, bj;
    float canonicalU, canonicalV;
};
constexpr float kHalfSqrt2 = 0.70710678f;
constexpr EdgeType kEdgeTypes[4] = {
    {0, 0, 1, 0, 1.0f, 0.0f},               // horizontal, 0°
    {0, 0, 0, 1, 0.0f, 1.0f},               // vertical, 90°
    {0, 0, 1, 1, kHalfSqrt2, kHalfSqrt2},   // shear0, 45°
    {1, 0, 0, 1, -kHalfSqrt2, kHalfSqrt2},  // shear1, 135°
};

// The parallel sets of a row of cells, in the order a sweep runs them (paper Fig. 8: each edge type split by
// the parity of its cell column; 4 columns apart for the types whose ends lie in different columns, so that
// no two segments of a set are neighbours): set s is the segments of type kSetType[s] at cells i =
// kSetFirst[s] (mod the type's step), numbered g by i = first + g step.
constexpr int32_t kSets = 14;
constexpr int32_t kSetType[kSets] = {0, 0, 0, 0, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3};
constexpr int32_t kSetFirst[kSets] = {0, 1, 2, 3, 0, 1, 0, 1, 2, 3, 0, 1, 2, 3};
constexpr int32_t setStep(int32_t type) {
    return type == 1 ? 2 : 4;
}

// The segments g in [gMin, gMax) of a set (type, first) on row of cells j of a level of `cells` cells that
// lie inside the grid: a segment with an end on the tile border is never projected (border points do not
// move), so both ends and their 8 neighbours must be inside. Empty (gMin >= gMax) on rows without any.
inline void setLanes(int32_t type, int32_t first, int32_t j, int32_t cells, int32_t& gMin, int32_t& gMax) {
    const EdgeType e = kEdgeTypes[type];
    const int32_t step = setStep(type);
    const int32_t limit = type == 1 ? cells : cells - 1;  // segments at cells i in [1, limit) are inside
    gMin = (step - first) / step;                         // the first g with first + g step >= 1
    gMax = limit - 1 >= first ? (limit - 1 - first) / step + 1 : 0;
    if (j + e.aj < 1 || j + e.bj > cells - 1) gMax = 0;
}

// Coarse levels project a segment only where the larger blurred rigidity (Eq. 7) of its movable ends exceeds
// this (the finest level: any rigidity above 0). The blur spreads a little rigidity over the free skin around
// rigid detail; projected there, a coarse level pulled that skin towards its rest lengths, which the finest
// level then had to undo (UV-36).
constexpr float kCoarseLeastRigidity = 0.3f;

// The least rigidity (exceeded) of a projected segment on a level of `cells` cells of a `fineCells` grid.
inline float leastRigidity(int32_t cells, int32_t fineCells) {
    return cells < fineCells ? kCoarseLeastRigidity : 0.0f;
}

// Whether a segment with ends of level rigidity ra and rb is projected (§4.2): both ends movable and either
// more rigid than `least` (leastRigidity), or one end fixed (kFixed - R) and both painted rigid (R >= 0.5:
// UV-15, the whole correction on the free end). Written without branches or library calls (the SIMD kernels
// inline it).
inline bool segmentProjected(float ra, float rb, float least) {
    const bool fixedA = ra < 0.0f, fixedB = rb < 0.0f;
    // The painted R of an end, fixed (kFixed - R) or not (R), as a max: GCC does not vectorise the kernel's
    // loop with a select here.
    const float paintedA = ra < kFixed - ra ? kFixed - ra : ra,
                paintedB = rb < kFixed - rb ? kFixed - rb : rb;
    const bool pinned = (fixedA != fixedB) & (paintedA >= 0.5f) & (paintedB >= 0.5f);
    const float rig = fixedA ? rb : (fixedB ? ra : (ra > rb ? ra : rb));
    return (!fixedA & !fixedB & (rig > least)) | pinned;
}

// Twice the signed area of triangle (a, b, c): > 0 counter-clockwise.
inline float orient(float ax, float ay, float bx, float by, float cx, float cy) {
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

}  // namespace

}  // namespace deformkit::uvwarp::detail
