#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/warp/engine.h"
#include "deformkit/warp/profile_curve.h"
#include "deformkit/warp/transform.h"

namespace deformkit::warp {

// Barr's (1984) global deformations, taper (TaperWarp), twist (TwistWarp) and bend (BendWarp), cast in the
// framework (paper §4.3); as Maya and Blender parameterise them: barr_dcc.h. One parameterised
// transformation T(v) selected per point by the point's coordinate z along a deformation axis, strength 1,
// weight 1 on that point's own sample (the per-point sampling of footnote 13). Binding caches each rest
// point's z; evaluation builds the transformations from the current controls (profile, bend rate...).
// Each warp also has a direct evaluate path, equal to the engine's (tests/unit/warp/barr_test.cpp).

// The deformation axis. The paper puts it on the unit z axis and notes it "can be easily extended to
// other axes"; here it is any line with a reference direction.
struct AxisFrame {
    glm::vec3 origin{0.0f};            // a point on the axis, scene units; z = 0 there
    glm::vec3 axis{0.0f, 0.0f, 1.0f};  // direction of increasing z, any non-zero length
    glm::vec3 up{0.0f, 1.0f, 0.0f};    // reference direction, need not be perpendicular to axis; the bend
                                       // bends towards it (taper and twist ignore it)
};

// Orthonormal right-handed frame (side, up, axis) = local (x, y, z) built from an AxisFrame:
// axis normalised, up made perpendicular to it (Gram-Schmidt), side = up x axis.
struct OrthoFrame {
    glm::vec3 origin{0.0f};
    glm::vec3 side{1.0f, 0.0f, 0.0f}, up{0.0f, 1.0f, 0.0f}, axis{0.0f, 0.0f, 1.0f};

    [[nodiscard]] glm::vec3 toLocal(const glm::vec3& p) const;
    [[nodiscard]] glm::vec3 toWorld(const glm::vec3& local) const;
};

// Validates and orthonormalises `frame`. With needUp false (taper, twist) an up direction that is zero or
// parallel to the axis is replaced by any perpendicular. Throws InvalidInput naming `source` and the
// element for a non-finite origin, a zero or non-finite axis, and (needUp) a zero or parallel up.
[[nodiscard]] OrthoFrame orthonormalFrame(const AxisFrame& frame, bool needUp, std::string_view source);

// Common part of the three warps: the axis frame, the per-point z cached at bind, the one-entry-per-point
// fields, and Maya's painted weights and envelope over the direct path.
class AxialWarp : public Warp {
  public:
    // restPoints: #points rest positions, scene units. Throws InvalidInput for a non-finite point.
    // Fields: point u -> transformation u, strength 1, weight 1 (paper §4.3.1: w = 1 only where
    // M(u) . z = v). Changing the frame requires binding again; changing the controls does not.
    void bind(std::span<const glm::vec3> restPoints, SparseFields& fields) override;
    // The direct path's bind: the rest axis coordinates only, no engine fields (what evaluate() and
    // deform() need; the Python functions bind this way).
    void bind(std::span<const glm::vec3> restPoints);
    // Per-point transformations T(z_u) for the engine (Eq. 3 with one entry per point).
    void transformations(Transformations& out) const override;

    // The direct path: out[u] = T(z_u)<points[u]>, the same as evaluateWarp over the fields and
    // transformations above (to float rounding). points: the bound rest points or current upstream
    // points of the same count; out may alias points.
    virtual void evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const = 0;
    // The transformation selected for axis coordinate z (the paper's T(v)), in world space.
    [[nodiscard]] virtual Affine transformationAt(float z) const = 0;

    // Deformer over the direct path: points deformed in place, P + envelope * weight * (T<P> - P);
    // weights: #points painted weights or empty for 1. Throws InvalidInput if not bound, on a count
    // mismatch, a non-finite point, or a point deformed beyond float range (then `points` holds partial
    // results).
    void deform(std::span<glm::vec3> points, std::span<const float> weights = {}, float envelope = 1.0f);
    // The same into `out` (as many points, not aliasing `points`): no copy of the input, read once (the
    // output's finiteness checked as it is written, which also finds an input point that is not finite; on
    // that error `out` holds partial results).
    void deform(std::span<const glm::vec3> points, std::span<glm::vec3> out, std::span<const float> weights,
                float envelope);

    void setFrame(const AxisFrame& frame);
    [[nodiscard]] const OrthoFrame& frame() const { return frame_; }
    [[nodiscard]] bool isBound() const { return bound_; }
    [[nodiscard]] const std::vector<float>& restZ() const { return restZ_; }

  protected:
    AxialWarp(const AxisFrame& frame, bool needUp, std::string name);
    // evaluate() that also finds the first output point that is not finite (points.size() when all are), in
    // the same pass: deform() into another buffer reads its input once. A point that is not finite stays so
    // in the output.
    [[nodiscard]] virtual int64_t evaluateFinite(std::span<const glm::vec3> points,
                                                 std::span<glm::vec3> out) const = 0;
    void requireBound(size_t count, const char* what) const;
    // Both spans of an evaluate() hold as many points as were bound.
    void requireBound(std::span<const glm::vec3> points, std::span<glm::vec3> out) const;

    std::string name_;
    bool needUp_;
    OrthoFrame frame_;
    std::vector<float> restZ_;  // per rest point, the coordinate along the axis, scene units
    std::vector<glm::vec3> scratch_;
    bool bound_ = false;
};

// An axial warp driven by one curve of the axis coordinate z (taper's scale, twist's angle): the curve is
// held here, so that a host updates either the same way.
class ProfiledAxialWarp : public AxialWarp {
  public:
    void setProfile(ProfileCurve profile) { profile_ = std::move(profile); }
    // New samples in place (ProfileCurve::assign): an animated curve updated without allocating.
    void setProfile(std::span<const float> z, std::span<const float> values, std::string_view name) {
        profile_.assign(z, values, name);
    }
    [[nodiscard]] const ProfileCurve& profile() const { return profile_; }

  protected:
    ProfiledAxialWarp(const AxisFrame& frame, std::string name, ProfileCurve profile)
        : AxialWarp(frame, false, std::move(name)), profile_(std::move(profile)) {}
    ProfileCurve profile_;
};

// Barr's taper (paper §4.3.1): T(z) = scale by (f(z), f(z), 1) about the axis, i.e. the two coordinates
// across the axis are multiplied by f(z). f = the profile (1 = unchanged; 0 collapses onto the axis;
// negative values mirror through it).
class TaperWarp final : public ProfiledAxialWarp {
  public:
    explicit TaperWarp(const AxisFrame& frame, ProfileCurve profile = ProfileCurve::constant(1.0f));
    void evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const override;
    [[nodiscard]] Affine transformationAt(float z) const override;

  private:
    [[nodiscard]] int64_t evaluateFinite(std::span<const glm::vec3> points,
                                         std::span<glm::vec3> out) const override;
    template <bool Check>
    int64_t run(std::span<const glm::vec3> points, std::span<glm::vec3> out) const;
};

// Barr's twist: T(z) = rotation by theta(z) radians about the axis, right-handed about the axis direction.
// theta = the profile.
class TwistWarp final : public ProfiledAxialWarp {
  public:
    explicit TwistWarp(const AxisFrame& frame, ProfileCurve angle = ProfileCurve::constant(0.0f));
    void evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const override;
    [[nodiscard]] Affine transformationAt(float z) const override;

  private:
    [[nodiscard]] int64_t evaluateFinite(std::span<const glm::vec3> points,
                                         std::span<glm::vec3> out) const override;
    template <bool Check>
    int64_t run(std::span<const glm::vec3> points, std::span<glm::vec3> out) const;
};

// Barr's (1984) global bend, in the plane of the axis and the up direction.
struct BendParams {
    float rate = 0.0f;    // k, radians per scene unit along the axis; > 0 bends towards up, 0 = identity
    float centre = 0.0f;  // z0, the arc's fixed slice (with its tangent); outside [lo, hi] it is carried
    float lo = -1.0f;     // zmin: the bent range is [lo, hi]; outside it the shape continues rigidly
    float hi = 1.0f;      // zmax, >= lo
};

// With zc = clamp(z, lo, hi), theta = k (zc - z0) and local coordinates (x side, y up, z axis):
//   z' = z0 - sin(theta) (y - 1/k) + cos(theta) (z - zc)
//   y' = 1/k + cos(theta) (y - 1/k) + sin(theta) (z - zc),     x' = x
// (Barr 1984, bend along his y axis into z, renamed). Inside [lo, hi] the axis maps onto the circle of
// radius 1/k about (z0, 1/k) with arc length preserved; outside, the straight continuation is tangent to
// it. Evaluated in the k -> 0 stable form sin(theta)/k = (zc - z0) sinc(theta).
class BendWarp final : public AxialWarp {
  public:
    BendWarp(const AxisFrame& frame, const BendParams& params);
    // Throws InvalidInput naming the parameter for a non-finite value or lo > hi.
    void setParams(const BendParams& params);
    [[nodiscard]] const BendParams& params() const { return params_; }
    void evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const override;
    [[nodiscard]] Affine transformationAt(float z) const override;

  private:
    [[nodiscard]] int64_t evaluateFinite(std::span<const glm::vec3> points,
                                         std::span<glm::vec3> out) const override;
    template <bool Check>
    int64_t run(std::span<const glm::vec3> points, std::span<glm::vec3> out) const;
    BendParams params_;
};

}  // namespace deformkit::warp
