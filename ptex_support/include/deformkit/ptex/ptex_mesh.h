#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/ptex/ptex_file.h"

namespace deformkit::ptex {

// The Ptex faces of a polygon mesh in OpenSubdiv's convention (Far::PtexIndices), with their adjacency.
//
// A quad is one Ptex face with corners 0..3 at (u, v) = (0,0), (1,0), (1,1), (0,1). An N-gon (N != 4,
// triangles included) is N sub-faces in corner order; sub-face k covers the quad (corner k, midpoint of
// edge k, face centre, midpoint of edge k - 1) at (0,0), (1,0), (1,1), (0,1), edge k running from corner k
// to corner k + 1. Ptex edges are numbered bottom (v = 0), right (u = 1), top (v = 1), left (u = 0).
// Adjacency (neighbour face and the neighbour's edge across each edge, -1 on a boundary) is OpenSubdiv's
// Far::PtexIndices::GetAdjacency.
//
// Built once from the mesh's connectivity; queries are const and thread-safe.
class PtexMesh {
  public:
    // Throws InvalidInput naming `source` for a mesh without faces and TopologyError when OpenSubdiv cannot
    // build its topology.
    explicit PtexMesh(const geom::Mesh& mesh, const std::string& source = "mesh");

    [[nodiscard]] int32_t numVertices() const { return numVertices_; }
    [[nodiscard]] int32_t numMeshFaces() const { return static_cast<int32_t>(firstPtex_.size()) - 1; }
    [[nodiscard]] int32_t numPtexFaces() const { return static_cast<int32_t>(meshFace_.size()); }
    // The first Ptex face of mesh face `face`; an N-gon's sub-face k is firstPtexFace(face) + k.
    [[nodiscard]] int32_t firstPtexFace(int32_t face) const { return firstPtex_[face]; }
    // The mesh face of a Ptex face, and its sub-face index (-1 for a quad).
    [[nodiscard]] int32_t meshFace(int32_t ptexFace) const { return meshFace_[ptexFace]; }
    [[nodiscard]] int32_t subFace(int32_t ptexFace) const { return subFace_[ptexFace]; }
    [[nodiscard]] const std::array<int32_t, 4>& adjFaces(int32_t ptexFace) const {
        return adjFaces_[ptexFace];
    }
    [[nodiscard]] const std::array<uint8_t, 4>& adjEdges(int32_t ptexFace) const {
        return adjEdges_[ptexFace];
    }
    [[nodiscard]] const std::string& source() const { return source_; }
    // The vertex indices of mesh face `face`, in corner order.
    [[nodiscard]] std::span<const int32_t> faceVertices(int32_t face) const {
        return std::span<const int32_t>(faceIndices_).subspan(faceOffsets_[face], faceCounts_[face]);
    }

    // The mesh point at (u, v) of a Ptex face as weights over its mesh face's corners (count = the face's
    // corner count, in corner order, summing to 1): bilinear over the quad, or over the sub-face quad whose
    // midpoints and centre are averages of the corners. `weights` must hold the face's corner count.
    void cornerWeights(int32_t ptexFace, double u, double v, std::span<double> weights) const;

    // Face records for a file of this mesh: every face at 2^ulog2 × 2^vlog2, adjacency, sub-face flags.
    [[nodiscard]] std::vector<FaceInfo> faceInfos(int8_t ulog2, int8_t vlog2) const;

    // Throws InvalidInput naming `fileSource` when `file` does not belong to this mesh: its face count
    // differs (naming both counts and the mesh), or a face's adjacency points outside the file.
    void requireMatches(const PtexFile& file, const std::string& fileSource) const;

  private:
    std::string source_;
    int32_t numVertices_ = 0;
    std::vector<int32_t> faceCounts_;  // per mesh face
    std::vector<int32_t> faceOffsets_;
    std::vector<int32_t> faceIndices_;
    std::vector<int32_t> firstPtex_;  // #mesh faces + 1
    std::vector<int32_t> meshFace_;   // per Ptex face
    std::vector<int32_t> subFace_;
    std::vector<std::array<int32_t, 4>> adjFaces_;
    std::vector<std::array<uint8_t, 4>> adjEdges_;
};

// The standard mesh metadata of a mesh (face vertex counts and indices, positions), for WriteOptions::mesh.
[[nodiscard]] MeshData meshData(const geom::Mesh& mesh);

// Filtered look-ups into a Ptex file's level-0 texels, decoded once to float (u8 and u16 normalised to
// [0, 1], half widened). Texel (i, j) of a face is centred at ((i + 0.5) / ures, (j + 0.5) / vres).
//
// sample() filters bilinearly between the four texel centres around (u, v). Centres beyond an edge of the
// face are read from the neighbour across it through the file's adjacency (at the neighbour's own
// resolution, the texel under the mirrored centre), so a map is continuous across face edges; a centre
// beyond a corner is extrapolated from the two edge neighbours and the corner texel (exact for a linear
// painting); beyond a boundary edge the face's own edge texel is repeated (clamp).
class PtexSampler {
  public:
    // Throws InvalidInput naming `source` when the file's adjacency points outside it.
    PtexSampler(const PtexFile& file, const std::string& source);

    [[nodiscard]] int32_t channels() const { return channels_; }
    [[nodiscard]] int32_t numFaces() const { return static_cast<int32_t>(faces_.size()); }
    [[nodiscard]] const FaceInfo& face(int32_t f) const { return faces_[f]; }
    // Texel (i, j) of face f, channel c (no filtering; i, j inside the face).
    [[nodiscard]] float texel(int32_t f, int32_t i, int32_t j, int32_t c) const {
        const FaceInfo& info = faces_[f];
        return values_[offsets_[f] + ((static_cast<size_t>(j) << info.ulog2) + i) * channels_ + c];
    }
    // Bilinear value at (u, v) in [0, 1]^2 of face f (clamped into it); `out` holds channels() values.
    void sample(int32_t f, double u, double v, std::span<float> out) const;

  private:
    // Texel (i, j) with i in [-1, ures], j in [-1, vres]: outside the face read across the adjacency.
    void ghost(int32_t f, int32_t i, int32_t j, float* out) const;
    void acrossEdge(int32_t f, int edge, int32_t i, int32_t j, float* out) const;

    std::string source_;
    int32_t channels_ = 0;
    std::vector<FaceInfo> faces_;
    std::vector<size_t> offsets_;  // per face, into values_
    std::vector<float> values_;
};

// Per-vertex values of a Ptex map: for each vertex the mean, over the Ptex faces that have a corner at it
// (a quad's corner k, a sub-face's corner 0), of the face's texel at that corner; #vertices × channels,
// vertex-major. Vertices no face uses get 0. Throws InvalidInput (requireMatches) for a file of another mesh.
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
// centre takes the values interpolated with cornerWeights(); faces with adjacency and sub-face flags.
// Throws InvalidInput for a value count that is not #vertices × channels, a channel count outside
// [1, 64], a resolution outside [0, 15], or a non-finite value (naming the vertex).
[[nodiscard]] PtexFile bakeVertexValues(const PtexMesh& mesh, std::span<const float> values, int32_t channels,
                                        const BakeOptions& options = {});

// Ptex -> UDIM: renders the file into one image per UDIM tile through the mesh's UVs. Each Ptex face is
// drawn as a grid of small triangles carrying its (u, v), mapped into UV space with the same bilinear
// interpolation of the corner UVs as cornerWeights(). Every texel whose centre lies in a UV face of the
// tile is covered (where the cell grids of two faces meet, a texel takes the nearest point of a
// neighbouring cell), and `padding` rings of texels around the charts take the value at the nearest chart
// border (edge padding), so bilinear look-ups at a chart's edge read the chart's own values; texels
// farther out are 0. The coverage channel (a last channel added when `coverageChannel`) is 1 exactly on
// the charts. Throws InvalidInput naming the mesh when it has no UVs, and the tile when a tile number is
// not valid.
struct UdimTile {
    int tile = 1001;
    io::Image image;
};
struct ToUdimOptions {
    int32_t resolution = 1024;  // each tile resolution × resolution
    std::vector<int> tiles;     // empty: every tile the mesh's UV faces touch
    bool coverageChannel = false;
    int32_t padding = 8;  // texels of edge padding around the charts (0: none)
};
[[nodiscard]] std::vector<UdimTile> ptexToUdim(const PtexMesh& ptexMesh, const geom::Mesh& mesh,
                                               const PtexFile& file, const std::string& fileSource,
                                               const ToUdimOptions& options = {});

// UDIM -> Ptex: every texel centre of every Ptex face is mapped to UV space (bilinear over the corner UVs)
// and takes the bilinear sample of the tile image there (clamped at the tile's border). `tiles` holds one
// image per tile, all with the same channel count. Face resolution: fixed (ulog2/vlog2 >= 0) or, with -1,
// per face the power of two nearest the face's extent in texels of its tile (each axis, in [0, 12]).
// A face without UVs (Mesh::faceHasUVs) is in no tile: its Ptex faces are written 0. Throws InvalidInput
// naming the mesh (no UVs) or the face whose UVs fall in a tile that is not given.
struct FromUdimOptions {
    int8_t ulog2 = -1;
    int8_t vlog2 = -1;
    DataType dataType = DataType::Float;
};
[[nodiscard]] PtexFile udimToPtex(const PtexMesh& ptexMesh, const geom::Mesh& mesh,
                                  std::span<const UdimTile> tiles, const FromUdimOptions& options = {});

}  // namespace deformkit::ptex
