#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "deformkit/host/deformer.h"

namespace deformkit::host {

// Host adapters over the core deformers, by type name. Each holds no deformation code: bind builds the
// core object from the bind-time parameters and binds it to the rest mesh; evaluation pushes changed
// controls into it and runs its evaluation path. Positions, lengths and handle vectors are in scene
// units (world space of the mesh), angles in radians, flags and enumerations whole numbers. Parameters
// marked [bind] rebind when they change; the others are animatable. Every type lists its parameters in
// this order, which is a good order to set them in: changing a rest shape ([bind]) resets its animated
// counterpart to it (the identity deformation).
//
// "ffd"   Free-form deformation, Bernstein or B-spline lattice (warp/ffd.h, the fast path).
//         basis [bind] 1: 0 Bernstein (divisions <= 64), 1 uniform cubic B-spline.
//         outside [bind] 1: 0 points outside the lattice stay put (Maya's default), 1 extrapolate.
//         divisions [bind] 3: l, m, n cells along X, Y, Z, whole numbers in [1, 1024].
//         origin [bind] 3: the rest lattice's corner.
//         axes [bind] 9: the rest lattice's edge vectors X, Y, Z (x, y, z of each), linearly independent.
//         points 3 (l+1)(m+1)(n+1): the deformed control points P*_ijk, x, y, z each, C order over
//           (i, j, k) (index (i (m+1) + j) (n+1) + k); reset to the rest lattice when divisions, origin or
//           axes change. Default: the unit cube at the origin, one cell, points at rest.
// "twist" Maya's nonLinear twist (warp/barr_host.h fromMayaTwist) on Barr's twist.
//         handleOrigin [bind] 3; handleY [bind] 3: the handle's world Y axis (rotation x scale), non-zero.
//         startAngle, endAngle 1 each: radians at lowBound and highBound; lowBound, highBound 1 each: in
//           handle units along handle Y, lowBound < highBound (checked when used). Defaults 0, 0, -1, 1.
// "bend"  Maya's nonLinear bend (fromMayaBend) on Barr's bend, bending along handle Y towards handle +X.
//         handleOrigin [bind] 3; handleX [bind] 3; handleY [bind] 3: perpendicular, equal lengths (checked
//           at bind). curvature 1: radians; lowBound, highBound 1 each: handle units, lowBound <= highBound.
// "taper" Barr's taper with a handle in the Maya style (the core has no Maya taper; this is its flare
//         with equal X and Z scales and no curve): the two coordinates across handle Y are scaled by
//         startScale at lowBound and endScale at highBound, linearly in between, held beyond.
//         handleOrigin [bind] 3; handleY [bind] 3; startScale, endScale 1 each (1 = unchanged, defaults
//         1); lowBound, highBound 1 each: handle units along handle Y, lowBound < highBound.
// "wires" One wire of Singh and Fiume's Wires (warp/wires.h, the fast path); curves are polylines (sample
//         a cubic curve with warp::sampleCurve first).
//         smooth [bind] 1: 0 the original variant, 1 the smooth variant (sample count automatic).
//         restCurve [bind] 3k, k >= 2: the reference curve's points, of non-zero total length.
//         curve 3k: the wire curve's points, as many as restCurve; reset to restCurve when it changes.
//         dropoff [bind] 1: the radius r, > 0 (default 1). scale [bind] 1: x, > 0 (default 1; the core
//           fixes it at construction, hence [bind]).
// "slide" Pinskiy's sliding deformer, one handle (slide/slider.h). Weights and envelope scale the tangent
//         displacement before the walk (WeightMode::Native), so slid vertices stay on the rest surface.
//         vertex [bind] 1: the handle vertex, below the rest mesh's vertex count (checked at bind).
//         radius [bind] 1: support radius, > 0 (default 1). geodesic [bind] 1: 0 Euclidean region, 1
//           geodesic. limitSurface [bind] 1: 0 slide over the mesh, 1 over its Catmull-Clark limit.
//         displacement 3: end locator minus start locator. falloff 1: 0 smooth, 1 linear, 2 falloffRamp.
//         falloffRamp n >= 2: samples in [0, 1] at x = i / (n - 1), linear between (default 1, 0).

// The type names makeDeformer knows, in alphabetical order.
[[nodiscard]] std::span<const std::string_view> deformerTypes();

// A new, unbound deformer of `type` with default parameters. Throws InvalidInput for an unknown type
// (listing the known ones) or an empty label.
[[nodiscard]] std::unique_ptr<Deformer> makeDeformer(std::string_view type, const std::string& label);

}  // namespace deformkit::host
