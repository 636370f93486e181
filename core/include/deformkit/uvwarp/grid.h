#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace deformkit::uvwarp {

// Conventions of the UV warp (Koniaris et al.), shared by every uvwarp header:
//
// * One UDIM tile at a time, in tile-local UV: (u, v) in [0, 1]^2, v up.
// * The warp grid W has n x n cells, n a power of two, so (n + 1) x (n + 1) points; point (i, j) rests at
//   (i / n, j / n), j = 0 on the v = 0 edge. Storage is row-major by j, structure-of-arrays.
// * Maps (rigidity R, mask M, redirect W^-1, textures) are images of T x T texels, image row 0 at the top
//   (v = 1); texel (x, y) is centred at u = (x + 0.5) / T, v = 1 - (y + 0.5) / T. By default n = T.
// * Per-point fields (rigidity and mask at grid points, geometry images f_O and f_D) live on the grid points.

// A scalar or vector field on the (n + 1)^2 grid points, channels interleaved per point.
struct PointField {
    int32_t cells = 0;          // n
    int32_t channels = 0;       // 1 (rigidity, mask) or 3 (geometry images: 3D positions)
    std::vector<float> values;  // (n + 1)^2 * channels, point (i, j) at ((j * (n + 1)) + i) * channels

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t index(int32_t i, int32_t j) const {
        return (static_cast<size_t>(j) * static_cast<size_t>(cells + 1) + static_cast<size_t>(i)) *
               static_cast<size_t>(channels);
    }
};

// The warp W: grid point (i, j) sits at (u[k], v[k]), k = j * (n + 1) + i, tile-local UV. The identity warp
// has u = i / n, v = j / n. W maps the unit square onto itself piecewise-linearly over the grid's triangles
// (each cell split along its (i, j)-(i+1, j+1) diagonal).
struct WarpGrid {
    int32_t cells = 0;
    std::vector<float> u, v;

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t numPoints() const { return u.size(); }
    [[nodiscard]] static WarpGrid identity(int32_t cells);
    // Makes this grid the identity warp of `cells` cells, in the storage it already has where it is large
    // enough (a solve from the identity every frame then allocates nothing).
    void setIdentity(int32_t cells);
};

[[nodiscard]] bool isPowerOfTwo(int32_t n);

// The largest grid the UV warp takes, cells per side: (n + 1)^2 point indices stay within int32.
inline constexpr int32_t kMaxGridCells = 32768;

}  // namespace deformkit::uvwarp
