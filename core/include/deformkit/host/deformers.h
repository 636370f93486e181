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
// "ffdframes" FFD with coordinate-frame controls (warp/ffd_frames.h, the fast path): each control carries a
//         target frame, so rotating or scaling a control turns or scales the model about it, which plain
//         FFD cannot do. The source frames are (P_ijk, identity), hence T_ijk<p> = B*_ijk (p - P_ijk) +
//         P*_ijk; with every basis the identity this is "ffd" exactly.
//         basis, outside, divisions, origin, axes [bind]: as "ffd".
//         points 3 (l+1)(m+1)(n+1): the target frame origins P*_ijk, as "ffd"'s points.
//         frames 9 (l+1)(m+1)(n+1): the target frame bases B*_ijk in the order of points, 9 values per
//           control: the images of the unit X, Y, Z axes (x, y, z of each), rotation x scale, any finite
//           matrix. points and frames reset to the rest lattice and identity bases when divisions, origin
//           or axes change. Default: the unit cube at the origin, one cell, at rest.
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
// "wires" Singh and Fiume's Wires (warp/wires.h, the fast path), one wire or several; curves are polylines
//         (sample a cubic curve with warp::sampleCurve first).
//         smooth [bind] 1: 0 the original variant, 1 the smooth variant (sample count automatic).
//         restCurve [bind] 3k, k >= 2: the reference curves' points, the wires one after the other.
//         curveSizes [bind] n: points per wire, whole numbers >= 2 summing to k (checked at bind); a single
//           0 (the default) is one wire through all of restCurve.
//         curve 3k: the wire curves' points, as many as restCurve and split as it is; reset to restCurve
//           when it changes. Every wire's reference curve needs a non-zero length (checked at bind).
//         dropoff [bind] 1 or n: the radius r, > 0 (default 1): one value for every wire or one per wire.
//         scale [bind] 1 or n: x, > 0 (default 1; the core fixes it at construction, hence [bind]), one
//           value or one per wire.
//         exponent [bind] 1: m >= 0 (default 1): each wire's weight at a point is multiplied by the length
//           of the displacement it gives the point to the power m, so where wires overlap the one that
//           moves a point more dominates and a wire that does not move it has no say.
// "beierneely" Beier and Neely's feature-based warp (warp/beier_neely.h, through the generic engine) in the
//         XY plane of the scene; z is kept. A feature is a directed segment P -> Q; a point moves with
//         the frame of every feature, weighted by (|Q - P|^p / (a + distance to the rest feature))^b,
//         the weights taken on the rest mesh at bind.
//         global [bind] 1: 0 the original warp (each feature maps its perpendicular rigidly), 1 the
//           global variant (perpendiculars turned by the weighted average of all features' rotations).
//         restFeatures [bind] 4s, s >= 1: P.x, P.y, Q.x, Q.y of each rest feature, each longer than 1e-6.
//           Default: one feature (0, 0) -> (1, 0).
//         a [bind] 1: > 0, scene units (default 1): the larger, the smoother and the less exact near a
//           feature. b [bind] 1: >= 0 (default 2): how fast influence falls with distance. p [bind] 1:
//           >= 0 (default 0.5): how much longer features dominate. Beier and Neely use b in [0.5, 2],
//           p in [0, 1].
//         features 4s: the deformed features, as many as restFeatures, each longer than 1e-6; reset to
//           restFeatures when it changes.
// "meshwarp" The coarse-mesh warp (warp/mesh_warp.h, through the generic engine): the vertices of a
//         control cage (any polygon mesh near the surface, boundaries allowed) with their edge stars move
//         the surface; a vertex's weight reaches beta times its longest edge around it and, along each
//         edge, up to mu of the edge.
//         restCage [bind] 3c, c >= 3: the rest cage points. cageFaceCounts [bind] f >= 1: vertices per
//           face, whole numbers >= 3. cageFaceIndices [bind] sum(cageFaceCounts): indices into restCage,
//           face by face; an oriented 2-manifold with every point on an edge of non-zero length (checked
//           at bind). Default: the unit cube [0, 1]^3, six quads facing outwards.
//         alpha, beta [bind] 1 each: full weight within alpha, none beyond beta times a vertex's longest
//           edge, 0 <= alpha < beta (defaults 0, 1). gamma, mu [bind] 1 each: along each edge full weight
//           up to gamma, none from mu of the edge on, gamma < mu (defaults 0, 1). The orders are checked
//           at bind.
//         cage 3c: the deformed cage points, as many as restCage; reset to restCage when it changes.
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
