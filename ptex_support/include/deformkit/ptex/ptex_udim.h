#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/ptex/ptex_file.h"

namespace deformkit::ptex {

class PtexMesh;  // ptex_mesh.h

// Ptex -> UDIM: renders the file into one image per UDIM tile through the mesh's UVs. Each Ptex face is
// drawn as a grid of small triangles carrying its (u, v), mapped into UV space with the same bilinear
// interpolation of the corner UVs as PtexMesh::cornerWeights(). Every texel whose centre lies in a UV face
// of the tile is covered (where the cell grids of two faces meet, a texel takes the nearest point of a
// neighbouring cell), and `padding` rings of texels around the charts take the value at the nearest chart
// border (edge padding), so bilinear look-ups at a chart's edge read the chart's own values; texels
// farther out are 0. The coverage channel (a last channel added when `coverageChannel`) is 1 exactly on
// the charts. Throws InvalidInput naming the mesh when it has no UVs, and the tile when a tile number is
// not valid.
struct UdimTile {
    int tile = 1001;
    io::Image image;
    std::string source;  // the image's file, named in errors ("UDIM tile 1001" when empty)
};
struct ToUdimOptions {
    int32_t resolution = 1024;  // each tile resolution × resolution
    std::vector<int> tiles;     // empty: every tile the mesh's UV faces touch
    bool coverageChannel = false;
    int32_t padding = 8;  // texels of edge padding around the charts (0: none)
    // Cap on the file's texels and their float copy for filtering (PtexSampler), as when reading the file.
    uint64_t maxDecodedBytes = ReadOptions{}.maxDecodedBytes;
};
[[nodiscard]] std::vector<UdimTile> ptexToUdim(const PtexMesh& ptexMesh, const geom::Mesh& mesh,
                                               const PtexFile& file, const std::string& fileSource,
                                               const ToUdimOptions& options = {});

// UDIM -> Ptex: every texel centre of every Ptex face is mapped to UV space (bilinear over the corner UVs)
// and takes the bilinear sample of the tile image there (clamped at the tile's border). `tiles` holds one
// image per tile, all with the same channel count. Face resolution: fixed (ulog2/vlog2 >= 0) or, with -1,
// per face the power of two nearest the face's extent in texels of its tile (each axis, in [0, 12]).
// A face without UVs (Mesh::faceHasUVs) is in no tile: its Ptex faces are written 0. Throws InvalidInput
// naming the mesh (no UVs), the face whose UVs fall in a tile that is not given, or the first texel of an
// image that is not finite (NaN or infinite: a Ptex file holds none).
struct FromUdimOptions {
    int8_t ulog2 = -1;
    int8_t vlog2 = -1;
    DataType dataType = DataType::Float;
};
[[nodiscard]] PtexFile udimToPtex(const PtexMesh& ptexMesh, const geom::Mesh& mesh,
                                  std::span<const UdimTile> tiles, const FromUdimOptions& options = {});

}  // namespace deformkit::ptex
