#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"

namespace deformkit::geom {

struct LimitSurfaceOptions {
    // How open boundaries are treated (OpenSubdiv's vertex boundary interpolation).
    enum class Boundary {
        EdgesAndCorners,  // boundary edges sharp, vertices with a single face sharp corners (Maya, RenderMan)
        EdgesOnly,        // boundary edges sharp, single-face vertices smooth (the corner is rounded off)
    };
    Boundary boundary = Boundary::EdgesAndCorners;
    // Adaptive refinement depth around extraordinary vertices, in [1, 10]. Faces away from them are exact
    // bicubic B-spline patches; within 2^-isolationLevel of a face around one, the surface is approximated
    // by Gregory patches, which still pass through the exact limit position and tangents at the vertex.
    // Each level halves the approximation's parameter drift and divides its shape error by ~3.5; at 6,
    // compared with 10 on a cage with unit edges and valence 3 and 5 vertices, a (u, v) lands up to 2e-3
    // away along the surface and 2e-6 off it. Each level adds a ring of patches per extraordinary vertex.
    int isolationLevel = 6;
    // Keep the refined topology so that withPoints() can move the cage (a deformed copy of it) without
    // rebuilding the patches. Costs the refiner's memory for the surface's lifetime.
    bool deformable = false;
    // Faces left out of the surface (OpenSubdiv holes, ascending or not): they get no patches and are not
    // refined, but their vertices still shape the faces around them. Evaluating a hole throws InvalidInput.
    // For the part of a mesh around a region: the region's faces exact, their neighbours only support.
    std::vector<int32_t> holes;
};

// A point of the limit surface with its first derivatives with respect to the Ptex face's (u, v).
struct LimitSample {
    glm::dvec3 position{0.0};  // scene units
    glm::dvec3 dPdu{0.0};      // scene units per unit u of the Ptex face
    glm::dvec3 dPdv{0.0};
    // Unit, on the side of the face winding (along dPdu x dPdv). Where the surface is singular (at a smooth
    // corner of an EdgesOnly boundary dPdu and dPdv are parallel) the normal of a point just inside the face.
    glm::dvec3 normal{0.0};
};

// OpenSubdiv refuses a face with more corners, or a vertex of higher valence (the larger of its face and
// edge counts), than its limit of 65535: it prints to stdout and builds nothing. Throws TopologyError
// naming `source` and the first such face or vertex, before OpenSubdiv is asked.
void requireSubdivisionLimits(const Mesh& rest, const std::string& source);

// The Catmull-Clark limit surface of a polygon cage (OpenSubdiv feature-adaptive patches), evaluated at
// points given the way a projection onto the cage finds them: a face and weights over its corners.
//
// Built once from the cage's connectivity and positions (bind); queries are const, thread-safe and
// allocate nothing. Copies share the immutable patch data.
class LimitSurface {
  public:
    // Catmull-Clark limit surface of `rest` (the cage). Throws InvalidInput naming `source` for bad
    // options, a mesh without faces, and TopologyError (an InvalidInput) when OpenSubdiv cannot build the
    // topology (a face or vertex beyond its valence limit of 65535). Non-manifold edges and vertices are
    // accepted: OpenSubdiv makes them infinitely sharp.
    explicit LimitSurface(const Mesh& rest, const LimitSurfaceOptions& options = {},
                          const std::string& source = "mesh");

    // A location on the surface in OpenSubdiv's Ptex face convention (Far::PtexIndices): a quad is one
    // Ptex face with corners 0..3 at (u, v) = (0,0), (1,0), (1,1), (0,1); an N-gon (N != 4, triangles
    // included) is N Ptex faces, sub-face k covering the quad (corner k, midpoint of edge k, face centre,
    // midpoint of edge k - 1) at (0,0), (1,0), (1,1), (0,1), where edge k runs from corner k to corner k + 1.
    struct PtexLocation {
        int32_t ptexFace = 0;
        double u = 0.0, v = 0.0;
    };

    [[nodiscard]] int32_t numVertices() const;
    [[nodiscard]] int32_t numFaces() const;
    [[nodiscard]] int32_t numPtexFaces() const;
    // The first Ptex face of cage face `face` (an N-gon's sub-face k is firstPtexFace(face) + k).
    [[nodiscard]] int32_t firstPtexFace(int32_t face) const;

    // A point of face `face` given as weights over its corners (one per corner, >= 0, summing to 1 up to a
    // round-off tolerance of 1e-5; e.g. barycentric coordinates in one of the face's fan triangles spread
    // onto its corners) -> the Ptex face and (u, v). Quads: (u, v) = sum_k w_k uv_k with the corner (u, v)
    // above. N-gons: the weights place a point in a regular N-gon with the same corner order; the sub-face
    // quad containing it is inverted bilinearly. Corners, edges (linearly in the edge parameter) and the
    // centre (equal weights) map to the matching Ptex points, so neighbouring faces agree along shared edges.
    // Throws InvalidInput for a face out of range, the wrong weight count or weights that are not
    // non-negative and summing to 1.
    [[nodiscard]] PtexLocation ptexLocation(int32_t face, std::span<const double> cornerWeights) const;

    // The limit point at a face point given by corner weights (see ptexLocation).
    [[nodiscard]] glm::dvec3 evaluate(int32_t face, std::span<const double> cornerWeights) const;
    // The same with first derivatives and the unit normal.
    [[nodiscard]] LimitSample evaluateWithDerivatives(int32_t face,
                                                      std::span<const double> cornerWeights) const;
    // The limit point at a Ptex location. Throws InvalidInput for a Ptex face out of range or (u, v) outside
    // [0, 1]^2.
    [[nodiscard]] LimitSample evaluateAt(const PtexLocation& location) const;

    // Limit position of cage vertex `vertex` (the cage position for a vertex no face uses). Throws
    // InvalidInput for an index out of range.
    [[nodiscard]] glm::dvec3 limitPosition(int32_t vertex) const;

    // The same connectivity with the cage moved to `cage` (#V positions): patches, Ptex faces and locations
    // are shared, control points and limit positions are recomputed. Requires options.deformable; throws
    // InvalidInput for a wrong count.
    [[nodiscard]] LimitSurface withPoints(std::span<const glm::vec3> cage) const;

  private:
    struct Impl;
    std::shared_ptr<const Impl> impl_;
};

}  // namespace deformkit::geom
