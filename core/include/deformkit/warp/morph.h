#pragma once

#include <span>

#include <glm/vec3.hpp>

#include "deformkit/warp/engine.h"

namespace deformkit::warp {

// Varying a warp over time for morphing (paper §8.1). t = 0 is the undeformed model, t = 1 the full
// warp. The four ways of the paper:
//   1. blend the deformed model with the identity:                      morphByEnvelope
//   2. interpolate each transformation towards the identity, each with  morphTransformations
//      its own parameter t_i if wanted (schedule parts of the model):   morphSchedule
//   3. scale the strength fields by t:                                  morphStrengths
//   4. animate the target features from the sources to the targets: the host's job (keyframe the
//      cage/lattice/curve controls); morphTargets is the linear version for point features.
// With the displacement method 2 (uniform t) and 3 give the same deformation as 1: every displacement
// in Eq. (3) is scaled by t and the normalised weights do not change. With the composition method 2
// and 3 follow the components (rotations swing through the arc) and differ from 1.

// 1: out = in + t (deformed - in). All spans #points; out may alias in. Throws InvalidInput on size
// mismatch, a non-finite t, or a point the blend takes beyond float range (requireFiniteResult).
void morphByEnvelope(std::span<const glm::vec3> in, std::span<const glm::vec3> deformed, float t,
                     std::span<glm::vec3> out);

// 2: out_i = t_i . T_i (the transformation's own scaling method: displacement t T + (1 - t) I, or
// each component scaled). t holds 1 value (all transformations) or one per transformation. out is
// resized; it must not alias `in`.
void morphTransformations(const Transformations& in, std::span<const float> t, Transformations& out);

// Per-transformation parameters for a scheduled morph: t_i = clamp((time - start_i) / (end_i - start_i),
// 0, 1), so transformation i morphs during [start_i, end_i]. Throws InvalidInput if sizes differ or
// end_i <= start_i.
void morphSchedule(float time, std::span<const float> start, std::span<const float> end,
                   std::span<float> out);

// 3: fields with every strength multiplied by t (weights and sparsity unchanged). out must not alias in.
void morphStrengths(const SparseFields& in, float t, SparseFields& out);

// 4 (helper): target feature points moved linearly from source to target: out = source + t (target - source).
void morphTargets(std::span<const glm::vec3> source, std::span<const glm::vec3> target, float t,
                  std::span<glm::vec3> out);

}  // namespace deformkit::warp
