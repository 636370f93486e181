#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace deformkit::geom {

class Mesh;

// What the half-edge build found about a mesh's connectivity. Non-manifold input is reported here,
// never silently changed; requireManifold() turns it into an error where an algorithm needs a manifold.
struct ManifoldReport {
    std::vector<int32_t> nonManifoldEdges;   // edges shared by more than two faces
    std::vector<int32_t> inconsistentEdges;  // edges two faces traverse in the same direction (flipped face)
    std::vector<int32_t> nonManifoldVertices;  // vertices whose faces form more than one fan (bow-tie)
    std::vector<int32_t> isolatedVertices;     // vertices no face uses
    int32_t boundaryEdges = 0;                 // edges with exactly one face
    int32_t components = 0;                    // connected components of faces (sharing vertices)

    [[nodiscard]] bool isManifold() const {
        return nonManifoldEdges.empty() && inconsistentEdges.empty() && nonManifoldVertices.empty();
    }
    [[nodiscard]] bool isClosed() const { return boundaryEdges == 0; }
};

// Half-edge connectivity of a polygon mesh. Half-edge h is face corner h (an index into
// Mesh::faceIndices()): it runs from that corner's vertex to the next corner's vertex of the same face.
// Works on any input: twin() is -1 across boundary, non-manifold and inconsistently oriented edges.
class HalfEdgeMesh {
  public:
    explicit HalfEdgeMesh(const Mesh& mesh);

    [[nodiscard]] int32_t numHalfEdges() const { return static_cast<int32_t>(tail_.size()); }
    [[nodiscard]] int32_t numEdges() const { return static_cast<int32_t>(edgeVertices_.size()); }
    [[nodiscard]] int32_t numVertices() const {
        return static_cast<int32_t>(vertexCornerOffsets_.size()) - 1;
    }

    [[nodiscard]] int32_t face(int32_t h) const { return face_[h]; }
    [[nodiscard]] int32_t next(int32_t h) const { return next_[h]; }
    [[nodiscard]] int32_t prev(int32_t h) const { return prev_[h]; }
    [[nodiscard]] int32_t tail(int32_t h) const { return tail_[h]; }
    [[nodiscard]] int32_t head(int32_t h) const { return tail_[next_[h]]; }
    // The opposite half-edge of a manifold, consistently oriented edge; -1 otherwise.
    [[nodiscard]] int32_t twin(int32_t h) const { return twin_[h]; }
    [[nodiscard]] int32_t edge(int32_t h) const { return edge_[h]; }

    // Vertex pair of edge e, smaller index first.
    [[nodiscard]] std::array<int32_t, 2> edgeVertices(int32_t e) const { return edgeVertices_[e]; }
    // Every half-edge along edge e: 1 on a boundary, 2 inside a manifold, more where non-manifold.
    [[nodiscard]] std::span<const int32_t> edgeHalfEdges(int32_t e) const {
        return std::span<const int32_t>(edgeHalfEdges_)
            .subspan(edgeOffsets_[e], edgeOffsets_[e + 1] - edgeOffsets_[e]);
    }
    [[nodiscard]] bool isBoundaryEdge(int32_t e) const { return edgeOffsets_[e + 1] - edgeOffsets_[e] == 1; }
    [[nodiscard]] bool isBoundaryVertex(int32_t v) const { return boundaryVertex_[v] != 0; }

    // Half-edges leaving vertex v (one per face corner at v), ascending.
    [[nodiscard]] std::span<const int32_t> vertexHalfEdges(int32_t v) const {
        return std::span<const int32_t>(vertexCorners_)
            .subspan(vertexCornerOffsets_[v], vertexCornerOffsets_[v + 1] - vertexCornerOffsets_[v]);
    }
    // Vertices sharing an edge with v, ascending, each once.
    [[nodiscard]] std::span<const int32_t> vertexNeighbors(int32_t v) const {
        return std::span<const int32_t>(neighbors_)
            .subspan(neighborOffsets_[v], neighborOffsets_[v + 1] - neighborOffsets_[v]);
    }

    [[nodiscard]] const ManifoldReport& report() const { return report_; }

  private:
    std::vector<int32_t> face_, next_, prev_, tail_, twin_, edge_;
    std::vector<std::array<int32_t, 2>> edgeVertices_;
    std::vector<int32_t> edgeOffsets_, edgeHalfEdges_;
    std::vector<int32_t> vertexCornerOffsets_, vertexCorners_;
    std::vector<int32_t> neighborOffsets_, neighbors_;
    std::vector<uint8_t> boundaryVertex_;
    ManifoldReport report_;
};

// Throws TopologyError naming `source`, the first non-manifold edge or vertex (with its vertex indices)
// and the reason, unless the mesh is an oriented 2-manifold (boundaries allowed).
void requireManifold(const Mesh& mesh, const std::string& source);

}  // namespace deformkit::geom
