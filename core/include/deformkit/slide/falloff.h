#pragma once

#include <span>
#include <string_view>
#include <vector>

namespace deformkit::slide {

// The slide's fallOff() (paper §3): a decreasing damping factor in [0, 1] of the normalised distance
// x = distance / radius from the handle. 1 at the handle, 0 at and beyond the region's edge (x >= 1).
class Falloff {
  public:
    // The default curve: the smoothstep ramp 1 - 3x^2 + 2x^3, flat at both ends so the slid region
    // blends into the still surface without a crease.
    [[nodiscard]] static Falloff smooth();
    // 1 - x: a cone, for tests and for riggers who want a sharp centre.
    [[nodiscard]] static Falloff linear();
    // A user ramp: `samples` are the values at x = i / (n - 1), i = 0..n-1 (n >= 2), each finite and in
    // [0, 1]; linear in between. Throws InvalidInput naming `name` and the offending sample.
    [[nodiscard]] static Falloff ramp(std::span<const float> samples, std::string_view name = "falloff ramp");

    [[nodiscard]] double operator()(double x) const;
    [[nodiscard]] bool isSmooth() const { return samples_.empty() && !linear_; }

  private:
    Falloff() = default;
    std::vector<double> samples_;  // empty: a built-in curve
    bool linear_ = false;
};

}  // namespace deformkit::slide
