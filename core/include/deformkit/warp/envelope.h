#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include <glm/vec3.hpp>

namespace deformkit::warp {

// Maya's painted-weight and envelope rule, the one blend of a deformer's result into its input: per point
// u with k = envelope w_u (w_u = 1 when weights is empty),
//   out_u = in_u + k (deformed_u - in_u),
// computed in double and rounded to float once, so k = 1 gives deformed_u and k = 0 gives in_u bit for bit.
// in, deformed, out: #points positions; out may alias in or deformed. weights: #points or empty. OpenMP
// over points, bit-identical for any thread count. Throws InvalidInput when a size differs. Returns the
// first point whose output is not finite (an envelope of 1e38 takes a finite point beyond float range), or
// #points: hand it to requireFiniteResult.
[[nodiscard]] int64_t applyEnvelope(std::span<const glm::vec3> in, std::span<const glm::vec3> deformed,
                                    std::span<const float> weights, double envelope,
                                    std::span<glm::vec3> out);

// Throws InvalidInput naming `source` and point `bad` when bad < out.size(): a deformer's output is never
// handed on with NaN or infinite coordinates. `bad` is the first point a deformer's loop found not finite in
// its output. `in` is the deformer's input: named in the message (its point not finite, or the point it was
// deformed from) unless it is empty or the output overwrote it (the same span); then the message gives the
// result, which may be a point that came in not finite.
void requireFiniteResult(std::string_view source, std::span<const glm::vec3> in,
                         std::span<const glm::vec3> out, int64_t bad);

// Throws InvalidInput naming `source` and the envelope, or the first painted weight, that is not finite
// (NaN or infinite would make every point it scales NaN). Every deformer's evaluate checks its inputs so.
void requireFiniteEnvelope(std::string_view source, std::span<const float> weights, double envelope);

}  // namespace deformkit::warp
