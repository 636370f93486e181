#pragma once

#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"

namespace deformkit::geom {

enum class NormalWeighting {
    Area,   // each face contributes its Newell normal, whose length is twice its area
    Angle,  // each face contributes its unit normal times the corner angle at the vertex
};

struct NormalOptions {
    NormalWeighting weighting = NormalWeighting::Area;
};

// Unit face normals by Newell's method (robust for non-planar n-gons); #F entries. A degenerate face
// gets (0, 0, 0).
void computeFaceNormals(const Mesh& mesh, std::span<glm::vec3> out);

// Unit vertex normals, #V entries, written into `out` (no allocation, for evaluation loops). A vertex
// with no face or only degenerate faces gets (0, 0, 0).
void computeVertexNormals(const Mesh& mesh, std::span<glm::vec3> out, const NormalOptions& options = {});

[[nodiscard]] std::vector<glm::vec3> vertexNormals(const Mesh& mesh, const NormalOptions& options = {});

}  // namespace deformkit::geom
