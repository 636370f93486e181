#pragma once

// Private to core/src/uvwarp: the UV triangles and chart borders of one UDIM tile, shared by the geometry
// images and the derived warp mask.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>

#include "deformkit/geom/mesh.h"

namespace deformkit::uvwarp::detail {

// How far (in UV units) a face's corner may lie outside the tile of the face's UV centroid before the
// face counts as straddling two tiles: absorbs float rounding of UVs placed on a tile border.
inline constexpr float kTileTolerance = 1e-5f;
// How far (UV units, tile widths) a face's corners may overhang its tile (geom::Mesh::faceUdimTile): the
// overhang of artists' layouts (a few corners past a tile edge), rasterised as far as the tile reaches and
// reported; beyond it a face is refused as lying in two tiles.
inline constexpr float kMaxOverhang = geom::kUdimMaxOverhang;

struct TileUVs {
    int tile = 0;
    glm::vec2 origin{0.0f};                        // (floor(u), floor(v)) of the tile
    std::vector<std::array<int32_t, 3>> vertices;  // #T vertex indices (into Mesh::points()) per triangle
    std::vector<std::array<glm::vec2, 3>> uvs;     // #T tile-local UVs of each triangle's corners
    std::vector<int32_t> face;                     // #T source face of each triangle
    // Chart borders: UV edges of the tile's faces not used as often in one direction as in the other
    // (UVs welded by value, so per-corner UV indices of one chart still share their edges, and an edge
    // inside stacked copies of a shell stays interior while their outlines stay borders).
    std::vector<std::array<glm::vec2, 2>> borderEdges;  // tile-local UV segments
    std::vector<int32_t> borderTriangle;                // #borderEdges: the triangle holding each edge
    std::vector<std::array<int32_t, 2>> borderPoints;   // #borderEdges: the mesh points at its two ends
};

// "mesh 'x'" style label for errors about tile `tile` of input `label`.
[[nodiscard]] std::string tileSource(std::string_view label, int tile);

// Checks that `tile` is a UDIM number (1001..9999, u index 0..9) and returns its origin; throws
// InvalidInput naming `label` otherwise.
[[nodiscard]] glm::vec2 tileOrigin(int tile, std::string_view label);

// The fan triangles (geom::triangulate) of the faces of `tile` (geom::Mesh::faceUdimTile), with their
// chart borders; corners overhanging the tile (up to kMaxOverhang) keep their tile-local UVs outside
// [0, 1]. Throws InvalidInput naming `label` for a mesh without UVs, and naming the face and the tile for
// a face of this tile that overhangs it farther.
[[nodiscard]] TileUVs collectTileUVs(const geom::Mesh& mesh, int tile, std::string_view label);

}  // namespace deformkit::uvwarp::detail
