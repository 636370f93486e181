#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"

namespace deformkit::slide {

// The rest surface the slide moves vertices over: the mesh's fan triangles (geom/triangulation.h) with
// their adjacency, positions in double, and a tangent frame per vertex. Vertices land on these
// triangles, so a slid vertex lies exactly on the surface the mesh's triangulation describes.
//
// Triangle t's corners are 3t, 3t+1, 3t+2; corner c runs from vertex(c) to vertex(next(c)) and
// opposite(c) is the corner of the neighbouring triangle across that edge, -1 across a boundary, a
// non-manifold edge or an edge of a degenerate (zero-area) triangle, so a walk treats all three alike.
class SlideSurface {
  public:
    // Throws InvalidInput naming `source` for a mesh whose extent single precision cannot measure (a
    // bounding-box diagonal beyond about 1e19 scene units): degenerate triangles are found relative to it.
    explicit SlideSurface(const geom::Mesh& mesh, const std::string& source = "mesh");

    [[nodiscard]] int32_t numVertices() const { return static_cast<int32_t>(points_.size()); }
    [[nodiscard]] int32_t numTriangles() const { return static_cast<int32_t>(face_.size()); }

    [[nodiscard]] const glm::dvec3& point(int32_t v) const { return points_[v]; }
    [[nodiscard]] int32_t vertex(int32_t corner) const { return vertices_[corner]; }
    [[nodiscard]] static int32_t next(int32_t corner) { return corner % 3 == 2 ? corner - 2 : corner + 1; }
    [[nodiscard]] static int32_t prev(int32_t corner) { return corner % 3 == 0 ? corner + 2 : corner - 1; }
    [[nodiscard]] static int32_t triangleOf(int32_t corner) { return corner / 3; }
    [[nodiscard]] int32_t opposite(int32_t corner) const { return opposite_[corner]; }
    // The polygon of the input mesh that triangle t belongs to, and the face-corner index (into
    // Mesh::faceIndices()) of each triangle corner.
    [[nodiscard]] int32_t face(int32_t t) const { return face_[t]; }
    [[nodiscard]] int32_t faceCorner(int32_t corner) const { return faceCorners_[corner]; }
    [[nodiscard]] bool isDegenerate(int32_t t) const { return degenerate_[t] != 0; }
    [[nodiscard]] int32_t numDegenerateTriangles() const { return numDegenerate_; }

    // Corners at vertex v (one per incident triangle), ascending.
    [[nodiscard]] std::span<const int32_t> vertexCorners(int32_t v) const {
        return std::span<const int32_t>(vertexCorners_)
            .subspan(vertexOffsets_[v], vertexOffsets_[v + 1] - vertexOffsets_[v]);
    }
    // Vertices sharing a triangle edge with v, ascending.
    [[nodiscard]] std::span<const int32_t> neighbors(int32_t v) const {
        return std::span<const int32_t>(neighbors_)
            .subspan(neighborOffsets_[v], neighborOffsets_[v + 1] - neighborOffsets_[v]);
    }
    [[nodiscard]] bool areNeighbors(int32_t v, int32_t w) const;

    // Unit normal at v: the area-weighted mean of its non-degenerate triangles' normals; (0,0,0) when it
    // has none. Tangent basis {b1, b2} of v's tangent plane (paper Eq. 3): b1 is v's first neighbour's
    // edge projected on the plane, b2 = normal x b1, so the basis is right-handed about the normal.
    [[nodiscard]] const glm::dvec3& normal(int32_t v) const { return normals_[v]; }
    [[nodiscard]] const glm::dvec3& tangent1(int32_t v) const { return b1_[v]; }
    [[nodiscard]] glm::dvec3 tangent2(int32_t v) const;
    [[nodiscard]] bool hasFrame(int32_t v) const;

    // Length scale of the mesh (bounding-box diagonal) for relative tolerances.
    [[nodiscard]] double scale() const { return scale_; }

  private:
    std::vector<glm::dvec3> points_, normals_, b1_;
    std::vector<int32_t> vertices_, opposite_, face_, faceCorners_;
    std::vector<uint8_t> degenerate_;
    std::vector<int32_t> vertexOffsets_, vertexCorners_, neighborOffsets_, neighbors_;
    int32_t numDegenerate_ = 0;
    double scale_ = 1.0;
};

}  // namespace deformkit::slide
