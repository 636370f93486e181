#pragma once

#include <cstdint>

#include "deformkit/io/image.h"
#include "deformkit/io/sampling.h"

namespace deformkit::uvwarp {

// Baking a texture through a UV redirect map (paper §5): the warped texture, read with the mesh's
// original UVs, shows what the unwarped texture shows when read through uv' = W^-1(uv).
//
//   out(texel) = texture(W^-1(uv of the texel's centre))
//
// One UDIM tile at a time: sampling clamps to the tile's edge texels, never reading a neighbouring tile.
struct BakeOptions {
    // Bilinear (2 x 2 taps, exact for textures linear in u and v) or Bicubic: Catmull-Rom, i.e. Keys'
    // cubic convolution with a = -0.5 (4 x 4 taps, interpolating, may overshoot near sharp edges; not
    // clamped). io::sampleImage's filters, with the same results.
    io::SampleFilter filter = io::SampleFilter::Bilinear;
    // Output size in texels; 0 takes the texture's. When it differs from the redirect map's size, the
    // redirect is sampled bilinearly (clamped to its edge texels) at each output texel's uv.
    int32_t width = 0;
    int32_t height = 0;
};

// Bakes `texture` (H x W x C, any size and channel count, conventions of grid.h) through `redirect`
// (R x R x >= 2: channel 0 = u', channel 1 = v', tile-local, as invertWarp writes it) into `out`, resized
// only when its size differs. OpenMP over rows; bit-identical for any thread count. Throws InvalidInput
// for an empty texture or redirect, a non-square redirect or one with fewer than 2 channels, or a
// non-finite texel of either (naming it).
void bakeTexture(const io::Image& texture, const io::Image& redirect, io::Image& out,
                 const BakeOptions& options = {});
[[nodiscard]] io::Image bakeTexture(const io::Image& texture, const io::Image& redirect,
                                    const BakeOptions& options = {});

}  // namespace deformkit::uvwarp
