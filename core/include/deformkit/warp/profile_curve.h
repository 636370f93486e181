#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace deformkit::warp {

// A user profile curve y(z) given as samples, as Barr's taper f(z) and twist theta(z) take them
// (paper §4.3.1: "a user-defined function from scalar values to scalar values"). Between samples it is
// the monotone-preserving piecewise cubic Hermite interpolant of Fritsch and Carlson (1980): C1, exact
// for linear data, and never overshooting the samples, so a taper profile that stays positive in its
// samples stays positive everywhere. Outside [z.front(), z.back()] the end value is held (constant
// extension). One sample gives a constant curve.
class ProfileCurve {
  public:
    // The constant curve y = value (one sample at z = 0).
    [[nodiscard]] static ProfileCurve constant(float value);

    // z: sample positions along the axis, scene units, strictly ascending; values: one per z.
    // `name` labels the curve in error messages ("taper profile"). Throws InvalidInput naming the
    // offending sample for: no samples, a count mismatch, a non-finite z or value, z not strictly ascending.
    ProfileCurve(std::vector<float> z, std::vector<float> values, std::string_view name = "profile curve");
    // The same samples in place, reusing this curve's storage: a curve of the same length is updated without
    // allocating (a host pushing an animated angle every frame). Checks as the constructor; on a throw the
    // curve is unchanged.
    void assign(std::span<const float> z, std::span<const float> values,
                std::string_view name = "profile curve");

    [[nodiscard]] float operator()(float z) const;
    [[nodiscard]] const std::vector<float>& z() const { return z_; }
    [[nodiscard]] const std::vector<float>& values() const { return values_; }
    // The Hermite tangents dy/dz at the samples, after the Fritsch-Carlson limiter.
    [[nodiscard]] const std::vector<float>& tangents() const { return tangents_; }

  private:
    static void check(std::span<const float> z, std::span<const float> values, std::string_view name);
    void computeTangents();

    std::vector<float> z_, values_, tangents_;
    std::vector<double> work_;  // secants and tangents in double while computing, kept for reuse
};

}  // namespace deformkit::warp
