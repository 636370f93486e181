#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "deformkit/geom/mesh.h"

namespace deformkit::geom {

// Triangles of a polygon mesh, each remembering its face. Triangle corners are *face-corner* indices
// (into Mesh::faceIndices() and Mesh::uvIndices()), so both positions and UVs can be looked up.
struct Triangulation {
    std::vector<std::array<int32_t, 3>> corners;  // #T face-corner index triples, face winding kept
    std::vector<int32_t> face;                    // #T source face of each triangle

    [[nodiscard]] int32_t size() const { return static_cast<int32_t>(face.size()); }
};

// Fan triangulation from each face's first corner: n - 2 triangles per n-gon (exact for convex faces,
// which quad-dominant production meshes are in practice).
[[nodiscard]] Triangulation triangulate(const Mesh& mesh);

// The vertex indices of a triangulation's triangles: #T triples into Mesh::points().
[[nodiscard]] std::vector<std::array<int32_t, 3>> triangleVertices(const Mesh& mesh,
                                                                   const Triangulation& tris);

}  // namespace deformkit::geom
