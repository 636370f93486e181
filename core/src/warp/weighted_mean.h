#pragma once

// Eq. (3) of the warp framework for one point: the mean of its field entries' displacements d_e, weighted
// by w_e |d_e|^m (m the displacement weight exponent, 0: the weights alone), accumulated in double. Shared
// by the generic engine (evaluateWarp) and the Wires fast path, which must agree bit for bit.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace deformkit::warp::detail {

// The weighted mean of displacement(e) over entries e in [begin, end), weight(e) each (>= 0, finite),
// times power(|d_e|, m) when m != 0. Returns false when every weight is 0 (the caller keeps the point:
// the identity, paper footnote 6).
//
// A large m takes |d|^m beyond double's range: an infinite sum (a NaN mean) or every weight underflowing to
// 0 (the point left unmoved). Only then the weights are taken relative to the longest displacement among
// the entries with a weight, w_e (|d_e| / max |d|)^m <= w_e: the same mean, within range. Points whose
// weights stay in range keep the bits of the plain sum.
// |d| in float, as the weights have always been taken, or in double where d . d overflows float (|d| beyond
// about 1.8e19): an infinite length would make every weight inf / inf and leave the point unmoved.
inline double displacementLength(const glm::vec3& d) {
    const float length = glm::length(d);
    return std::isfinite(length) ? static_cast<double>(length) : glm::length(glm::dvec3(d));
}

template <class Displacement, class Weight, class Power>
bool weightedMeanDisplacement(int32_t begin, int32_t end, double m, Displacement&& displacement,
                              Weight&& weight, Power&& power, glm::dvec3& mean) {
    glm::dvec3 sum(0.0);
    double weightSum = 0.0, plainSum = 0.0, longest = 0.0;
    for (int32_t e = begin; e < end; ++e) {
        double w = weight(e);
        // An entry of weight 0 adds nothing (+0 to sums that start at +0), and 0 |d|^m could be 0 inf.
        if (w == 0.0) continue;
        const glm::vec3 d = displacement(e);
        if (m != 0.0) {
            const double length = displacementLength(d);
            plainSum += w;
            longest = std::max(longest, length);
            w *= power(length, m);
        }
        sum += w * glm::dvec3(d);
        weightSum += w;
    }
    const bool overflow = !(weightSum <= std::numeric_limits<double>::max()) || !std::isfinite(sum.x) ||
                          !std::isfinite(sum.y) || !std::isfinite(sum.z);
    const bool underflow = weightSum == 0.0 && plainSum > 0.0 && longest > 0.0;
    if (m != 0.0 && (overflow || underflow)) {
        sum = glm::dvec3(0.0);
        weightSum = 0.0;
        for (int32_t e = begin; e < end; ++e) {
            if (weight(e) == 0.0) continue;
            const glm::vec3 d = displacement(e);
            const double w = weight(e) * power(displacementLength(d) / longest, m);
            sum += w * glm::dvec3(d);
            weightSum += w;
        }
    }
    if (!(weightSum > 0.0)) return false;
    mean = sum / weightSum;
    return true;
}

}  // namespace deformkit::warp::detail
