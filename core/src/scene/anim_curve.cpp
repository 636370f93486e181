#include "deformkit/scene/anim_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "deformkit/error.h"

namespace deformkit::scene {
namespace {

std::string keyName(size_t k) {
    return "key " + std::to_string(k);
}

void validate(const std::vector<Key>& keys, const std::string& label) {
    if (keys.empty()) {
        throw InvalidInput(
            formatError(label, "keys", "none given", "at least one key (a curve with no key has no value)"));
    }
    for (size_t k = 0; k < keys.size(); ++k) {
        const Key& key = keys[k];
        if (!std::isfinite(key.time)) {
            throw InvalidInput(
                formatError(label, keyName(k), "time " + numberText(key.time), "a finite time"));
        }
        if (!std::isfinite(key.value)) {
            throw InvalidInput(
                formatError(label, keyName(k), "value " + numberText(key.value), "a finite value"));
        }
        if (k > 0 && !(key.time > keys[k - 1].time)) {
            throw InvalidInput(formatError(label, keyName(k),
                                           "time " + numberText(key.time) + " is not after key " +
                                               std::to_string(k - 1) + "'s time " +
                                               numberText(keys[k - 1].time),
                                           "strictly increasing key times"));
        }
        switch (key.interpolation) {
            case Interpolation::Constant:
            case Interpolation::Linear:
            case Interpolation::Bezier:
                break;
            default:
                throw InvalidInput(formatError(
                    label, keyName(k), "interpolation " + std::to_string(static_cast<int>(key.interpolation)),
                    "Constant, Linear or Bezier"));
        }
        switch (key.tangent) {
            case TangentMode::Auto:
            case TangentMode::Flat:
                break;
            case TangentMode::Explicit:
                if (!std::isfinite(key.inSlope) || !std::isfinite(key.outSlope)) {
                    throw InvalidInput(formatError(
                        label, keyName(k),
                        "explicit slopes in " + numberText(key.inSlope) + ", out " + numberText(key.outSlope),
                        "finite slopes"));
                }
                break;
            default:
                throw InvalidInput(formatError(
                    label, keyName(k), "tangent mode " + std::to_string(static_cast<int>(key.tangent)),
                    "Auto, Flat or Explicit"));
        }
    }
    // Differences of times and of values must be finite too, for the slopes and the segment parameter.
    const auto [lowest, highest] = std::minmax_element(
        keys.begin(), keys.end(), [](const Key& a, const Key& b) { return a.value < b.value; });
    if (!std::isfinite(keys.back().time - keys.front().time) ||
        !std::isfinite(highest->value - lowest->value)) {
        throw InvalidInput(formatError(label, "keys",
                                       "times span " + numberText(keys.front().time) + " to " +
                                           numberText(keys.back().time) + ", values " +
                                           numberText(lowest->value) + " to " + numberText(highest->value),
                                       "spans whose width is a finite double"));
    }
}

// The auto-clamped slope of interior key k (0 < k < n - 1); see the header.
double autoSlope(const std::vector<Key>& keys, size_t k) {
    const Key& prev = keys[k - 1];
    const Key& key = keys[k];
    const Key& next = keys[k + 1];
    const bool maximum = key.value >= prev.value && key.value >= next.value;
    const bool minimum = key.value <= prev.value && key.value <= next.value;
    if (maximum || minimum) return 0.0;
    // Not an extremum: both neighbours differ from the key, on opposite sides, so the two secants and
    // the centred slope share one sign.
    const double slope = (next.value - prev.value) / (next.time - prev.time);
    // Bezier handles at one third of each interval stay within the neighbour's value.
    const double limitBefore = 3.0 * std::abs(key.value - prev.value) / (key.time - prev.time);
    const double limitAfter = 3.0 * std::abs(next.value - key.value) / (next.time - key.time);
    const double limit = std::min(limitBefore, limitAfter);
    return std::clamp(slope, -limit, limit);
}

}  // namespace

AnimCurve::AnimCurve(std::vector<Key> keys, std::string label) {
    validate(keys, label);
    keys_ = std::move(keys);
    const size_t n = keys_.size();
    inSlopes_.assign(n, 0.0);
    outSlopes_.assign(n, 0.0);
    for (size_t k = 0; k < n; ++k) {
        const Key& key = keys_[k];
        if (key.tangent == TangentMode::Explicit) {
            inSlopes_[k] = key.inSlope;
            outSlopes_[k] = key.outSlope;
        } else if (key.tangent == TangentMode::Auto && k > 0 && k + 1 < n) {
            inSlopes_[k] = outSlopes_[k] = autoSlope(keys_, k);
        }
    }
    constant_ = true;
    for (size_t k = 0; k + 1 < n; ++k) {
        if (keys_[k + 1].value != keys_[0].value) constant_ = false;
        if (keys_[k].interpolation == Interpolation::Bezier &&
            (outSlopes_[k] != 0.0 || inSlopes_[k + 1] != 0.0))
            constant_ = false;
    }
}

AnimCurve AnimCurve::constant(double value) {
    return AnimCurve({Key{.time = 0.0, .value = value}}, "constant curve");
}

double AnimCurve::evaluate(double time) const {
    if (keys_.empty()) return 0.0;
    if (std::isnan(time)) return std::numeric_limits<double>::quiet_NaN();
    if (time <= keys_.front().time) return keys_.front().value;
    if (time >= keys_.back().time) return keys_.back().value;
    // The segment [t0, t1) holding `time`: key k is the last key at or before it (0 <= k < n - 1 here).
    const auto after = std::upper_bound(keys_.begin(), keys_.end(), time,
                                        [](double t, const Key& key) { return t < key.time; });
    const size_t k = static_cast<size_t>(after - keys_.begin()) - 1;
    const Key& k0 = keys_[k];
    const Key& k1 = keys_[k + 1];
    const double dt = k1.time - k0.time;
    const double s = (time - k0.time) / dt;
    switch (k0.interpolation) {
        case Interpolation::Constant:
            return k0.value;
        case Interpolation::Linear:
            return (1.0 - s) * k0.value + s * k1.value;
        case Interpolation::Bezier:
            break;
    }
    const double s2 = s * s;
    const double s3 = s2 * s;
    const double h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    const double h10 = s3 - 2.0 * s2 + s;
    const double h01 = -2.0 * s3 + 3.0 * s2;
    const double h11 = s3 - s2;
    return h00 * k0.value + h10 * dt * outSlopes_[k] + h01 * k1.value + h11 * dt * inSlopes_[k + 1];
}

}  // namespace deformkit::scene
