#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "deformkit/geom/mesh.h"

namespace deformkit::scene {

// Painted weights from texture maps, sampled through a mesh's UVs: what a rigger paints in texture space
// (Mari, Substance, a DCC's texture paint mode) driving a deformer's per-vertex weights.
//
// `pattern` names one image per UDIM tile (a UDIM token: <UDIM>, <UVTILE>, %(UDIM)d, _MAPID_) or, without a
// token, one image for tile 1001. Every face corner is sampled in the image of its face's tile (the tile of
// the face's UV centroid, as geom::Mesh::udimTiles) at its tile-local uv: pixel position x = u W,
// y = (1 - v) H (row 0 at the top, pixel centres at half-integers), bilinear, clamped to the edge pixels
// (io::sampleImage). A vertex's weight is the mean of its corners' samples (UV seams give a vertex
// several corners), in double, rounded to float once; a vertex on no face with UVs gets 0.
//
// Throws InvalidInput naming `source` (how the caller names the weights, e.g. a scene's JSON path) for a
// mesh without UVs, a channel the image does not have, a face in a tile other than 1001 with a pattern
// without a UDIM token, or a non-finite sample (naming the vertex); IoError / ParseError naming the file
// for a missing or unreadable image.
[[nodiscard]] std::vector<float> weightsFromMaps(const geom::Mesh& mesh, const std::filesystem::path& pattern,
                                                 int32_t channel, const std::string& source);

}  // namespace deformkit::scene
