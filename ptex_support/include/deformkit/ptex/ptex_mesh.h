#pragma once

// Included here, so that this header gives all of the Ptex support over meshes: filtered look-ups
// (ptex_sampler.h), per-vertex values and baking (ptex_vertex_values.h), and the conversions between Ptex
// and UDIM images (ptex_udim.h), one header per concept.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "deformkit/geom/mesh.h"
#include "deformkit/ptex/ptex_file.h"
#include "deformkit/ptex/ptex_sampler.h"
#include "deformkit/ptex/ptex_udim.h"
#include "deformkit/ptex/ptex_vertex_values.h"

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
// Built once from the mesh's connectivity, on its welded vertices (geom/weld.h: split copies of a vertex, as
// glTF and FBX have them, are one vertex, so faces across a seam are neighbours); queries are const and
// thread-safe.
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
    // The welded vertices (split copies as one), numWeldedVertices() of them, and a file vertex's.
    [[nodiscard]] int32_t numWeldedVertices() const { return numWelded_; }
    [[nodiscard]] int32_t weldedVertex(int32_t vertex) const {
        return weldedOf_[static_cast<size_t>(vertex)];
    }

    // The mesh point at (u, v) of a Ptex face as weights over its mesh face's corners (count = the face's
    // corner count, in corner order, summing to 1): bilinear over the quad, or over the sub-face quad whose
    // midpoints and centre are averages of the corners. `weights` must hold the face's corner count.
    void cornerWeights(int32_t ptexFace, double u, double v, std::span<double> weights) const;

    // Face records for a file of this mesh: every face at 2^ulog2 × 2^vlog2, adjacency, sub-face flags.
    [[nodiscard]] std::vector<FaceInfo> faceInfos(int8_t ulog2, int8_t vlog2) const;

    // Throws InvalidInput naming `fileSource` when `file` does not belong to this mesh: a triangle-mesh
    // file, another face count (naming both counts and the mesh), mesh metadata of other polygons
    // (requireSameMesh), or a face's adjacency pointing outside the file.
    void requireMatches(const PtexFile& file, const std::string& fileSource) const;
    // Where `file` carries the standard mesh metadata (PtexFaceVertCounts and PtexFaceVertIndices, as
    // DeformKit, Mudbox and Mari write them): its polygons must be this mesh's, in this mesh's order, their
    // vertices possibly numbered otherwise (one-to-one with the welded vertices). A file painted on the same
    // polygons in another order has the same face count and would put every face's texels on another face.
    void requireSameMesh(const PtexFile& file, const std::string& fileSource) const;

  private:
    std::string source_;
    int32_t numVertices_ = 0;
    std::vector<int32_t> faceCounts_;  // per mesh face
    std::vector<int32_t> faceOffsets_;
    std::vector<int32_t> faceIndices_;   // the file's vertices (per-vertex values are the file's)
    std::vector<int32_t> connectivity_;  // the same corners on welded vertices: adjacency, mesh metadata
    std::vector<int32_t> weldedOf_;      // per file vertex
    int32_t numWelded_ = 0;
    std::vector<int32_t> firstPtex_;  // #mesh faces + 1
    std::vector<int32_t> meshFace_;   // per Ptex face
    std::vector<int32_t> subFace_;
    std::vector<std::array<int32_t, 4>> adjFaces_;
    std::vector<std::array<uint8_t, 4>> adjEdges_;
};

// The standard mesh metadata of a mesh (face vertex counts and indices, positions), for WriteOptions::mesh:
// its polygons on welded vertices, each at its first copy's position, as a painter's shared-vertex mesh has
// them. Throws InvalidInput naming `source` and the vertex when a position is not finite.
[[nodiscard]] MeshData meshData(const geom::Mesh& mesh, const std::string& source = "mesh");

}  // namespace deformkit::ptex
