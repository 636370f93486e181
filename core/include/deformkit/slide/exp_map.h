#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec2.hpp>

#include "deformkit/slide/surface.h"

namespace deformkit::slide {

// Length of the normal curve from vertex p to vertex q (paper §3.1, Fig. 3): the polyline where the plane
// through p spanned by p's normal and the direction pq cuts the triangles, from p to q. It approximates the
// geodesic distance |alpha_pq| on a locally smooth surface. The cut is followed triangle by triangle; it
// fails (nullopt) when it meets a boundary or takes more than `maxSteps` triangles, which happens only
// where the surface is far from locally smooth.
[[nodiscard]] std::optional<double> normalCurveLength(const SlideSurface& surface, int32_t p, int32_t q,
                                                      int32_t maxSteps = 256);

// The exponential map of p (Eq. 1-2): the image q' of vertex q in p's tangent space, as coordinates in p's
// basis {b1, b2}: |alpha_pq| times the unit direction of the plane's cut with the tangent plane, which is pq
// projected on that plane. One-ring neighbours are joined to p by a triangle edge, so |alpha_pq| = |pq|.
// Where the normal curve fails, the chord |pq| stands in and *fellBack is set.
[[nodiscard]] glm::dvec2 expMap(const SlideSurface& surface, int32_t p, int32_t q, bool* fellBack = nullptr);

}  // namespace deformkit::slide
