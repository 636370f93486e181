#pragma once

#include <cstdint>
#include <string_view>

#include <glm/vec2.hpp>

#include "deformkit/io/image.h"
#include "deformkit/uvwarp/grid.h"

namespace deformkit::uvwarp {

// Inverting the warp (paper §5, Eq. 9): W moves geometry sampling coordinates; textures need
// uv' = W^-1(uv), stored as a "UV redirection" map.
//
// W is piecewise linear over the grid's triangles, two per cell split along (i, j)-(i+1, j+1): lower
// (i, j), (i+1, j), (i+1, j+1) and upper (i, j), (i+1, j+1), (i, j+1). Its inverse is rasterised: each
// triangle is drawn at its warped position (raster coordinates x = u T, y = (1 - v) T, so raster pixels
// are image texels) carrying its rest uv (i / n, j / n) as attributes. The top-left rule gives each
// texel to exactly one triangle of a fold-free warp.

// Validates a warp grid: cells a power of two, (n + 1)^2 finite u and v. Throws InvalidInput naming
// `source` and the first bad point (i, j).
void validateWarpGrid(const WarpGrid& warp, std::string_view source = "warp grid");

// The redirect map of `warp`: a T x T x 2 image (T = `texels`, channel 0 = u', channel 1 = v', tile-local)
// with texel (x, y) = W^-1 at its centre ((x + 0.5) / T, 1 - (y + 0.5) / T). Texels no warped triangle
// covers (only at the tile border, through rounding, for a warp that maps the unit square onto itself)
// get the identity. Where triangles of a folded warp overlap, the later triangle in (j, i, lower/upper)
// order wins. `redirect` is resized only when its size differs. OpenMP over fixed bands of rows;
// bit-identical for any thread count. Throws InvalidInput for an invalid warp (validateWarpGrid) or
// texels < 1.
void invertWarp(const WarpGrid& warp, int32_t texels, io::Image& redirect);
[[nodiscard]] io::Image invertWarp(const WarpGrid& warp, int32_t texels);

// W at a rest-domain point (u, v), each clamped to [0, 1]: piecewise linear over the triangles above.
// Does not validate the warp (call validateWarpGrid once); the grid must hold (n + 1)^2 points.
[[nodiscard]] glm::vec2 evaluateWarp(const WarpGrid& warp, float u, float v);

// |W(W^-1(uv)) - uv| over texel centres, in texels of the redirect map.
struct InversionError {
    double maxTexels = 0.0;
    double meanTexels = 0.0;
    int64_t texels = 0;  // texels measured
};

// Measures a redirect map (T x T, >= 2 channels) against `warp` over every texel, or over the texels
// whose `region` value (channel 0 of a T x T image) is >= 0.5, e.g. deriveWarpMask's output for the
// covered area without chart borders. Throws
// InvalidInput for an invalid warp, a redirect or region of another size, or a non-finite redirect texel
// (naming it).
[[nodiscard]] InversionError inversionError(const WarpGrid& warp, const io::Image& redirect);
[[nodiscard]] InversionError inversionError(const WarpGrid& warp, const io::Image& redirect,
                                            const io::Image& region);

}  // namespace deformkit::uvwarp
