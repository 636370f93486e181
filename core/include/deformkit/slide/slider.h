#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/slide/falloff.h"
#include "deformkit/slide/region.h"

namespace deformkit::slide {

// Which surface slid vertices travel over.
enum class SurfaceMode {
    Cage,   // the mesh itself (its fan triangles): slid vertices stay exactly on it (the paper)
    Limit,  // the Catmull-Clark limit surface of the rest mesh (OpenSubdiv): a vertex moves by how far the
            // limit point under it travels, so a mesh subdivided at render time slides over its smooth shape
};

// What a rigger sets up per handle; fixed at bind.
struct SlideHandle {
    int32_t vertex = 0;                             // the handle vertex P0
    double radius = 1.0;                            // support radius r, scene units, > 0
    RegionMetric region = RegionMetric::Euclidean;  // how r is measured
};

// What drives a handle at evaluation; one per handle.
struct SlideDrive {
    glm::dvec3 displacement{0.0};  // d = end locator - start locator, scene units (world space of the mesh)
    Falloff falloff = Falloff::smooth();  // of distance / radius
};

// What painted per-vertex weights (in [0, 1]) do.
enum class PaintedWeights {
    ScaleFalloff,  // weight x falloff(distance / radius): the radius shapes the slide, the paint masks it
    AreFalloff,    // the paper's rule (Pinskiy §3): the painted map is the falloff; the radius only bounds
                   // the region (vertices beyond it never move), the falloff curve is not used
};

struct SlideOptions {
    SurfaceMode surface = SurfaceMode::Cage;
    PaintedWeights weights = PaintedWeights::ScaleFalloff;
    // Stop the drag at the fold limit: each handle's displacement is scaled down (never up) so that no
    // triangle of its region flips, then all of them together if overlapping regions still fold. For a
    // slide that never tears; SlideResult::foldScale says how much of each drag was applied.
    bool foldLimit = false;
    // Triangles one vertex's walk may cross in one evaluation before it stops (counted in
    // SlideResult::walkLimitStopped): the expansion limit for displacements many times larger than the
    // region.
    int32_t maxWalkTriangles = 4096;
    // Vertices within this distance of each other (scene units) are one vertex of the surface: split
    // vertices, as glTF, FBX and game-engine files have them at UV seams and hard edges, are welded
    // (geom/weld.h) so the slide walks across seams, and every copy moves as the others. 0: exactly equal
    // positions.
    double weldTolerance = 0.0;
};

// Where a moved vertex landed: a triangle of the rest mesh's fan triangulation, given by its polygon and
// its three vertices, and barycentric coordinates on them (Eq. 8).
struct SlideLanding {
    int32_t vertex = -1;
    int32_t face = -1;
    std::array<int32_t, 3> triangle{-1, -1, -1};
    std::array<double, 3> barycentric{0.0, 0.0, 0.0};
};

struct SlideResult {
    std::vector<SlideLanding> landings;  // one per moved vertex, ascending vertex index
    int32_t moved = 0;
    int32_t boundaryStopped = 0;  // reached a mesh boundary (or a degenerate triangle) and stopped on it
    // Stopped by the walk's own limit: after SlideOptions::maxWalkTriangles triangles, or when the walk's
    // line left the triangles it crossed.
    int32_t walkLimitStopped = 0;
    int32_t limited = 0;  // travelled less than asked: boundaryStopped + walkLimitStopped
    // Triangles with a slid corner whose orientation reversed against the incoming surface (a fold of the
    // texture); after the fold limit when it is on.
    int32_t flippedTriangles = 0;
    std::vector<double> foldScale;    // per handle: the factor applied to its displacement (1: all of it)
    int32_t unreachable = 0;          // within a radius but not reachable by the propagation: unmoved (bind)
    int32_t withoutTangentPlane = 0;  // within a radius but only degenerate triangles around: unmoved (bind)
    int32_t degenerateTriangles = 0;  // zero-area triangles touching an active vertex: skipped (bind)
    // File vertices welded onto another (split copies; SlideOptions::weldTolerance). The counts above are of
    // the welded vertices (positions): a vertex the file splits in three counts once; landings list every
    // copy.
    int32_t welded = 0;
};

// The sliding deformer (Pinskiy, "Sliding deformation"): bind once per rest mesh and handle set, evaluate
// per locator drag, on the rest mesh or on a deformed copy of it (what a deformer stack hands on). Binding
// builds the rest surface, each handle's support region and propagated region basis, and each active vertex's
// exponential map of its one-ring (Eq. 1-2). Evaluation turns each vertex's displacement d_P (Eq. 7) into a
// direction on the surface through its one-ring map and walks |d_P| along the straightest geodesic in that
// direction, unfolding each triangle it enters into the plane of the last (§3.3): a vertex travels exactly
// |d_P| over the surface, so it moves at most |d_P| in space, stays on the triangles it crossed, and never
// jumps across the mesh (docs/decisions.md).
//
// Several handles compose by adding their tangent displacements in each vertex's tangent space before the
// single walk over the surface (order-independent; on a plane exactly the sum of the translations).
//
// Over a deformed input the walks still run on the rest surface, and their landings (a triangle and
// barycentric coordinates) are applied to the incoming points, so slid vertices lie on the surface the
// slide receives. Each handle's displacement is given in the incoming space and carried into the rest
// frame through the inverse of the linear map that best takes the handle's rest one-ring onto its
// incoming one: the handle follows the locator on a stretched input, and for an input moved rigidly by
// (R, t) the result is (R, t) applied to the rest slide by R^T d.
// evaluate() may be called from several threads; calls are serialised, each one runs in parallel.
class Slider {
  public:
    // Throws InvalidInput naming `source` for: no handles, a handle index out of range, a handle that no
    // face uses or that is non-manifold, a radius <= 0 or not finite; TopologyError for a non-manifold
    // handle.
    Slider(const geom::Mesh& rest, std::vector<SlideHandle> handles, const SlideOptions& options = {},
           const std::string& source = "mesh");
    ~Slider();
    Slider(Slider&&) noexcept;
    Slider& operator=(Slider&&) noexcept;

    [[nodiscard]] int32_t numVertices() const;
    [[nodiscard]] int32_t numHandles() const;
    [[nodiscard]] const std::vector<SlideHandle>& handles() const;
    [[nodiscard]] const SupportRegion& region(int32_t handle) const;
    // Vertices in at least one handle's region (union), ascending; every copy of a welded vertex.
    [[nodiscard]] std::span<const int32_t> activeVertices() const;
    // File vertices welded onto another at bind (SlideOptions::weldTolerance); 0 for a mesh without split
    // vertices.
    [[nodiscard]] int32_t weldedVertices() const;

    // points: #V positions of the surface to slide over (the rest positions, or a deformed copy with the
    // rest mesh's connectivity), replaced in place by the slid positions. drives: one per handle, the
    // displacements in the space of `points`. weights: #V painted weights in [0, 1] (empty: all 1), acting
    // as options.weights says (a welded vertex takes the mean of its copies' weights). envelope scales every
    // slide. Throws InvalidInput for a wrong count or a non-finite value, naming it, before anything is
    // written.
    void evaluate(std::span<const SlideDrive> drives, std::span<glm::vec3> points,
                  std::span<const float> weights = {}, double envelope = 1.0, SlideResult* result = nullptr);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// One-off: bind and evaluate once, returning the slid copy of the mesh's points.
[[nodiscard]] std::vector<glm::vec3> slide(const geom::Mesh& mesh, std::span<const SlideHandle> handles,
                                           std::span<const SlideDrive> drives,
                                           std::span<const float> weights = {}, double envelope = 1.0,
                                           const SlideOptions& options = {}, SlideResult* result = nullptr);

}  // namespace deformkit::slide
