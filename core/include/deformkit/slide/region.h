#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/slide/surface.h"

namespace deformkit::slide {

// How the support region SR around the handle is measured.
enum class RegionMetric {
    Euclidean,  // the paper's: |P0 P| <= r in 3D
    Geodesic,   // distance over the surface <= r (geom/geodesic_distance.h), so a radius cannot jump a gap
};

// The support region of one handle, with the region basis {a1, a2} carried to every active vertex
// (paper §3.2). Depends only on the rest surface, the handle, the radius and the metric: computed at bind.
struct SupportRegion {
    int32_t handle = -1;
    double radius = 0.0;
    RegionMetric metric = RegionMetric::Euclidean;
    // The region basis at the handle: the handle's own tangent basis {b1, b2}, in 3D.
    glm::dvec3 a1{0.0}, a2{0.0};

    // Active vertices the propagation reached, in breadth-first order (the handle first).
    std::vector<int32_t> vertices;
    // Per active vertex: its distance to the handle divided by the radius (the falloff's argument), and
    // {a'1, a'2}, the region basis represented in that vertex's tangent space, as coordinates in the
    // vertex's own basis {b1, b2} (Eq. 4).
    std::vector<float> normalizedDistance;
    std::vector<glm::dvec2> a1Local, a2Local;

    // Vertices within the radius that the propagation cannot reach through active vertices (another
    // part of the mesh, or one joined only through vertices outside the region): left unmoved by this
    // handle (another handle's region may move them).
    int32_t unreachable = 0;
    std::vector<int32_t> unreachableVertices;
    // Vertices within the radius whose triangles are all degenerate: no tangent plane, left unmoved.
    int32_t withoutTangentPlane = 0;
    std::vector<int32_t> verticesWithoutTangentPlane;
};

// Builds the support region of `handle` with radius `radius` (scene units). The caller validates the
// handle and radius. Breadth-first propagation of Eq. 4 (reconstructed, docs/decisions.md): the vertex's
// a'_i is the normalised sum of the processed neighbours' a_i projected on its tangent plane, then
// Gram-Schmidt makes {a'1, a'2} orthonormal. Neighbours count as processed when they lie in the previous
// breadth-first layer, so every vertex of a layer sees the same inputs whatever the thread count.
[[nodiscard]] SupportRegion buildSupportRegion(const SlideSurface& surface, const geom::Mesh& mesh,
                                               int32_t handle, double radius, RegionMetric metric);

}  // namespace deformkit::slide
