#pragma once

#include <span>
#include <string_view>

#include <glm/vec3.hpp>

namespace deformkit::warp {

// Maya's painted-weight and envelope rule, the one blend of a deformer's result into its input: per point
// u with k = envelope w_u (w_u = 1 when weights is empty),
//   out_u = in_u + k (deformed_u - in_u),
// computed in double and rounded to float once, so k = 1 gives deformed_u and k = 0 gives in_u bit for bit.
// in, deformed, out: #points positions; out may alias in or deformed. weights: #points or empty. OpenMP
// over points, bit-identical for any thread count. Throws InvalidInput when a size differs.
void applyEnvelope(std::span<const glm::vec3> in, std::span<const glm::vec3> deformed,
                   std::span<const float> weights, double envelope, std::span<glm::vec3> out);

// Throws InvalidInput naming `source` and the envelope, or the first painted weight, that is not finite
// (NaN or infinite would make every point it scales NaN). Every deformer's evaluate checks its inputs so.
void requireFiniteEnvelope(std::string_view source, std::span<const float> weights, double envelope);

}  // namespace deformkit::warp
