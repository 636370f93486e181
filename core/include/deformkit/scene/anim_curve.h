#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace deformkit::scene {

// How the segment that starts at a key is interpolated, up to the next key.
enum class Interpolation {
    Constant,  // a step: hold this key's value until the next key's time
    Linear,    // a straight line to the next key
    Bezier,    // a cubic through both keys with their slopes (AnimCurve::evaluate)
};

// How a key's slope is found; only Bezier segments use slopes.
enum class TangentMode {
    Auto,      // smooth and clamped so the curve does not overshoot its keys (AnimCurve)
    Flat,      // slope 0
    Explicit,  // the key's inSlope / outSlope
};

// One keyframe: a value at a time. Times and values are in the host's units (frames or seconds, and the
// parameter's units); slopes are value units per time unit.
struct Key {
    double time = 0.0;
    double value = 0.0;
    Interpolation interpolation = Interpolation::Bezier;  // of the segment after this key
    TangentMode tangent = TangentMode::Auto;
    double inSlope = 0.0;   // used when tangent is Explicit: slope arriving at the key
    double outSlope = 0.0;  // used when tangent is Explicit: slope leaving the key
};

// A keyframed scalar parameter, as a DCC's animation curve (Maya's animCurve, Blender's F-curve).
//
// - Keys have strictly increasing, finite times and finite values (finite slopes when Explicit), else
//   the constructor throws InvalidInput naming the label and "key N" (N counts from 0).
// - Before the first key and after the last, the curve holds the first / last value.
// - The segment [t0, t1] from key k to key k + 1 follows key k's interpolation. Constant holds v0 on
//   [t0, t1) and the curve is v1 at t1. Bezier is the cubic Hermite in time, with s = (t - t0) / (t1 - t0):
//       v(s) = h00(s) v0 + h10(s) (t1 - t0) m0 + h01(s) v1 + h11(s) (t1 - t0) m1,
//       h00 = 2s^3 - 3s^2 + 1, h10 = s^3 - 2s^2 + s, h01 = -2s^3 + 3s^2, h11 = s^3 - s^2,
//   m0 key k's out-slope, m1 key k + 1's in-slope: the cubic Bezier whose handles sit at one third of
//   the interval along those slopes (non-weighted tangents, Maya's and Blender's default).
// - Slopes. Explicit: the key's inSlope / outSlope. Flat: 0. Auto (auto-clamped): an end key gets 0; an
//   interior key gets (v[k+1] - v[k-1]) / (t[k+1] - t[k-1]), or 0 when it is a local extremum (v[k] >=
//   both neighbours or <= both). As with Blender's auto-clamped handles, that slope is then limited so
//   neither handle passes a neighbour's value: |m| <= 3 |v[k] - v[k-1]| / (t[k] - t[k-1]) and
//   |m| <= 3 |v[k+1] - v[k]| / (t[k+1] - t[k]). The Bezier then stays within its keys' values on every
//   segment between two Auto or Flat keys, also with unevenly spaced keys. Auto and Flat keys have
//   equal in- and out-slopes. Slopes are computed once, in the constructor.
//
// evaluate is const, allocates nothing and is safe to call from many threads at once.
class AnimCurve {
  public:
    // A curve with no key; it evaluates to 0 everywhere.
    AnimCurve() = default;
    // `label` names the curve in error messages, e.g. "curve 'envelope'". An empty `keys` throws: a
    // curve with no key has no value.
    explicit AnimCurve(std::vector<Key> keys, std::string label = "curve");

    // One key at time 0: `value` everywhere. Throws InvalidInput when `value` is not finite.
    [[nodiscard]] static AnimCurve constant(double value);

    // The value at `time`; NaN for a NaN time (0 for a default-constructed curve).
    [[nodiscard]] double evaluate(double time) const;

    [[nodiscard]] size_t size() const { return keys_.size(); }
    // The keys as given to the constructor (slopes of Auto and Flat keys are not filled in here).
    [[nodiscard]] const std::vector<Key>& keys() const { return keys_; }
    // The slopes evaluate uses at key k (k < size()), whatever the key's tangent mode: for drawing
    // tangent handles.
    [[nodiscard]] double inSlope(size_t k) const { return inSlopes_[k]; }
    [[nodiscard]] double outSlope(size_t k) const { return outSlopes_[k]; }
    // True when the curve has one value everywhere, so hosts can skip re-evaluation: every key has the
    // same value and every Bezier segment has slope 0 at both ends (always so for Auto and Flat keys; an
    // Explicit non-zero slope bends the curve away from equal key values). True with no key.
    [[nodiscard]] bool isConstant() const { return constant_; }

  private:
    std::vector<Key> keys_;
    std::vector<double> inSlopes_;   // per key
    std::vector<double> outSlopes_;  // per key
    bool constant_ = true;
};

}  // namespace deformkit::scene
