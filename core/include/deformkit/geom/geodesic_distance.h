#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"

namespace deformkit::geom {

struct GeodesicOptions {
    // Stop marching beyond this distance (scene units, >= 0); every vertex farther gets +infinity. The
    // march still finishes vertices up to one incident edge beyond it (those can update a vertex
    // inside), so values inside match the unbounded march on well-shaped meshes.
    double maxDistance = std::numeric_limits<double>::infinity();
};

// Approximate geodesic distances from one vertex over the surface of a polygon mesh, by fast marching on
// its fan triangulation.
//
// - The source's one-ring (every vertex sharing a triangle with it) starts at its exact Euclidean
//   distance, which no surface path can beat.
// - A vertex C of triangle ABC whose other two vertices are known is updated from them as in Kimmel &
//   Sethian 1998, but with a circular instead of a planar wavefront (Novotni & Klein 2002): the triangle
//   is unfolded into a plane, the source is placed at distance d(A) from A and d(B) from B on the far
//   side of AB, and d(C) is its distance to C. On a flat (or developable) polyhedral surface this is
//   exact once d(A) and d(B) are; the planar wavefront is not near the source, where it matters most.
// - The update is used only when the straight line from the unfolded source to C crosses the edge AB,
//   i.e. the path actually runs through the triangle. Otherwise (obtuse triangles, inconsistent
//   distances, paths around a saddle vertex) C gets the Dijkstra edge updates d(A) + |AC| and
//   d(B) + |BC|, which are always taken as candidates too.
// - Obtuse triangles break the ordering fast marching relies on (C can be finished before A or B is
//   known). Instead of Kimmel & Sethian's unfolding into virtual acute triangles, a vertex whose value
//   drops after it was finished goes back into the queue (label correcting), so the march settles on
//   the best update from every triangle. A vertex is re-finished at most a few times, so the work stays
//   bounded on any input.
// - Results never fall below the Euclidean distance from the source (a hard lower bound).
//
// Sequential and deterministic: ties are broken by vertex index, so the result does not depend on the
// machine's thread count. Works on any connectivity (non-manifold edges, boundaries, several
// components); unreached vertices (other components, beyond maxDistance) get +infinity.
class GeodesicDistanceSolver {
  public:
    // Triangulates `mesh` (fan per face) and builds the vertex-to-triangle adjacency once. Positions are
    // copied; after a deformation call setPoints().
    explicit GeodesicDistanceSolver(const Mesh& mesh);

    // Positions changed, connectivity did not: #V positions, scene units. Throws InvalidInput on a count
    // mismatch.
    void setPoints(std::span<const glm::vec3> points);

    // Writes #V distances (scene units) from vertex `source` into `out`. Throws InvalidInput if `source`
    // is not in [0, #V), `out` does not hold #V entries, or options.maxDistance is negative or NaN.
    void compute(int32_t source, std::span<double> out, const GeodesicOptions& options = {}) const;

    [[nodiscard]] int32_t numVertices() const { return static_cast<int32_t>(points_.size()); }

  private:
    void updateReach();

    std::vector<glm::dvec3> points_;
    std::vector<std::array<int32_t, 3>> triangles_;
    std::vector<int32_t> vertexTriangleOffsets_;  // #V + 1 offsets into vertexTriangles_
    std::vector<int32_t> vertexTriangles_;        // triangles around each vertex, ascending
    // Longest edge of the triangles around each vertex: a vertex this much beyond maxDistance can
    // still improve a neighbour within it, so the march finishes it too.
    std::vector<double> reach_;
};

// One-off variant of GeodesicDistanceSolver::compute: #V distances from vertex `source`.
[[nodiscard]] std::vector<double> geodesicDistances(const Mesh& mesh, int32_t source,
                                                    const GeodesicOptions& options = {});

}  // namespace deformkit::geom
