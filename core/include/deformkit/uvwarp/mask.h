#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/grid.h"

namespace deformkit::uvwarp {

namespace detail {
struct TileUVs;  // a tile's UV triangles (uvwarp/tile_uvs.h, private to the library)
}  // namespace detail

// The per-tile maps that drive the warp (paper §3): the rigidity map R (T x T texels, 0 = infinitely
// elastic, 1 = as rigid as possible) and the warp mask M (1 = may warp, 0 = fixed), as images in the
// conventions of grid.h (row 0 at v = 1), and their values at the warp grid's points.

// Names a map in errors: "<name>, UDIM tile <tile>: texel (x, y): ...". tile 0 leaves the tile out.
struct MapLabel {
    std::string name = "map";  // a file path or a label such as "rigidity map"
    int tile = 0;
};

struct DerivedMaskOptions {
    // Chart-border band: a texel is fixed when a border edge touches its square grown by
    // (borderWidth - 1) / 2 texels on every side. 1 (the default) fixes the texels a border edge crosses
    // or touches. At least 1.
    int32_t borderWidth = 1;
    std::string label = "mesh";  // names the mesh in errors
};

// The warp mask of `tile` when none is given: a T x T x 1 image, T = `texels`, that is 0
// at texels whose centre lies outside every UV triangle of the tile (rasterised, top-left rule) and at
// texels on chart borders, 1 elsewhere. Chart borders are the UV edges of the tile's faces not used as
// often in one direction as in the other, UVs being welded by value: unwelded per-corner UVs still form
// one chart, and stacked copies of a shell keep their outlines as borders and their insides free. Throws
// InvalidInput naming the mesh label for a mesh without UVs, a bad tile number, a face of the tile
// straddling tiles (naming the face), texels < 1 or borderWidth < 1.
[[nodiscard]] io::Image deriveWarpMask(const geom::Mesh& rest, int tile, int32_t texels,
                                       const DerivedMaskOptions& options = {});
// The same from the tile's UV triangles already collected (uvwarp/tile_uvs.h).
[[nodiscard]] io::Image deriveWarpMask(const detail::TileUVs& uvs, int32_t texels,
                                       const DerivedMaskOptions& options = {});

// A user-painted warp mask made binary: channel 0 (the red channel of a colour image) thresholded at
// 0.5, values >= 0.5 becoming 1 (may warp) and values below 0.5 becoming 0. Returns a 1-channel image of
// the same size. Throws InvalidInput naming the label, tile and texel for a NaN, and for an empty or
// non-square image.
[[nodiscard]] io::Image binariseWarpMask(const io::Image& mask, const MapLabel& label = {});
// binariseWarpMask's checks alone (square, no NaN in channel 0), without making the binary image.
void validateWarpMask(const io::Image& mask, const MapLabel& label = {});

// Reads a warp mask file (any format io::readImage reads) and binarises it as above; errors name the file.
[[nodiscard]] io::Image readWarpMask(const std::filesystem::path& path, int tile = 0);

// Checks a rigidity map: non-empty, square, and channel 0 finite and within [0, 1] at every texel.
// Throws InvalidInput naming the label, tile and the first bad texel (x, y) in row-major order.
void validateRigidityMap(const io::Image& rigidity, const MapLabel& label = {});

// Reads a rigidity map file and validates it; returns channel 0 as a 1-channel image. Also reads other
// maps of values in [0, 1] (an orientation-preservation map): `role` names the map in read errors.
[[nodiscard]] io::Image readRigidityMap(const std::filesystem::path& path, int tile = 0,
                                        const std::string& role = "rigidity map");

// The paper's heuristic for severe compression (§6, "spatially-varying orientation preservation"): an
// orientation-preservation map from the rigidity map's local density, high where rigid detail is dense
// and low where it is sparse. Texel (x, y) gets the mean of channel 0 over the square window of
// 2 radius + 1 texels around it (clamped to the tile), divided by the largest such mean (all 0 when the
// map has no rigidity). Returns a T x T x 1 image in [0, 1]. Throws InvalidInput for an empty image or a
// radius < 1.
[[nodiscard]] io::Image densityOrientationMap(const io::Image& rigidity, int32_t radius);

// Rigidity at the grid points of an n-cell grid (n = `cells`, a power of two; T may differ from n):
// point (i, j) gets the bilinear sample of channel 0 at uv (i / n, j / n), texel centres as in grid.h,
// clamped to the edge texels. Validates the map as validateRigidityMap. Returns a 1-channel PointField.
[[nodiscard]] PointField rigidityAtPoints(const io::Image& rigidity, int32_t cells,
                                          const MapLabel& label = {});

// Warp mask at the grid points: point (i, j) gets the minimum of the binarised texels (channel 0 >= 0.5
// is 1, anything else is 0) whose centres lie within one texel, or one cell when the map is finer than the
// grid (T > n), of the point along u and along v: a point of a cell holding a fixed texel does not move
// (for n = T: the 2 x 2 texels around the point). Returns a 1-channel PointField of 0s and 1s. Throws
// InvalidInput for an empty or non-square image, cells not a power of two, and a NaN texel (neither side of
// 0.5), naming the label, tile and texel as binariseWarpMask does.
[[nodiscard]] PointField maskAtPoints(const io::Image& mask, int32_t cells, const MapLabel& label = {});

}  // namespace deformkit::uvwarp
