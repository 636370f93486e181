#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "deformkit/geom/mesh.h"
#include "deformkit/ptex/ptex_file.h"

namespace deformkit::ptex {

class PtexMesh;  // ptex_mesh.h

// Per-vertex values of a Ptex map: for each vertex the mean, over the Ptex faces that have a corner at it
// (a quad's corner k, a sub-face's corner 0), of the face's texel at that corner; #vertices × channels,
// vertex-major. Vertices no face uses get 0. Throws InvalidInput (PtexMesh::requireMatches) for a file of
// another mesh.
[[nodiscard]] std::vector<float> vertexValues(const PtexMesh& mesh, const PtexFile& file,
                                              const std::string& fileSource);

// Painted weights of `mesh` (named `meshName` in messages: its file) from channel `channel` of a Ptex file:
// vertexValues of that channel, for the falloff weights of the slide and the weights of every warp. Errors
// name `source` (where the file was named: a command-line option, a scene's JSON path; empty: the file
// alone) and the file once: IoError / ParseError for the file, InvalidInput for a file of another mesh
// (naming the mesh) or a channel it does not have.
[[nodiscard]] std::vector<float> weightsFromPtex(const geom::Mesh& mesh, const std::string& meshName,
                                                 const std::filesystem::path& file, int32_t channel,
                                                 const std::string& source);

struct BakeOptions {
    int8_t ulog2 = 4;  // every face 2^ulog2 × 2^vlog2 texels
    int8_t vlog2 = 4;
    DataType dataType = DataType::Float;
};

// Bakes per-vertex values (#vertices × channels, vertex-major) into a Ptex file of the mesh: each texel
// centre takes the values interpolated with PtexMesh::cornerWeights(); faces with adjacency and sub-face
// flags. Throws InvalidInput for a value count that is not #vertices × channels, a channel count outside
// [1, 64], a resolution outside [0, 15], or a non-finite value (naming the vertex).
[[nodiscard]] PtexFile bakeVertexValues(const PtexMesh& mesh, std::span<const float> values, int32_t channels,
                                        const BakeOptions& options = {});

}  // namespace deformkit::ptex
