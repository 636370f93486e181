#include "deformkit/warp/profile_curve.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "deformkit/error.h"

namespace deformkit::warp {

ProfileCurve ProfileCurve::constant(float value) {
    return ProfileCurve({0.0f}, {value}, "constant profile");
}

ProfileCurve::ProfileCurve(std::vector<float> z, std::vector<float> values, std::string_view name) {
    check(z, values, name);
    z_ = std::move(z);
    values_ = std::move(values);
    computeTangents();
}

void ProfileCurve::assign(std::span<const float> z, std::span<const float> values, std::string_view name) {
    check(z, values, name);
    z_.assign(z.begin(), z.end());
    values_.assign(values.begin(), values.end());
    computeTangents();
}

void ProfileCurve::check(std::span<const float> z, std::span<const float> values, std::string_view name) {
    const auto source = [&] { return std::string(name); };  // made only for an error
    if (z.empty()) throw InvalidInput(formatError(source(), "z_samples", "is empty", "at least one sample"));
    if (values.size() != z.size()) {
        throw InvalidInput(formatError(source(), "value_samples",
                                       "has " + std::to_string(values.size()) + " entries",
                                       std::to_string(z.size()) + " entries, one per z sample"));
    }
    for (size_t i = 0; i < z.size(); ++i) {
        if (!std::isfinite(z[i])) {
            throw InvalidInput(
                formatError(source(), "z_samples[" + std::to_string(i) + "]", "is not finite", "a number"));
        }
        if (!std::isfinite(values[i])) {
            throw InvalidInput(formatError(source(), "value_samples[" + std::to_string(i) + "]",
                                           "is not finite", "a number"));
        }
        if (i > 0 && !(z[i] > z[i - 1])) {
            throw InvalidInput(formatError(
                source(), "z_samples[" + std::to_string(i) + "]",
                "is " + std::to_string(z[i]) + ", not above the previous sample " + std::to_string(z[i - 1]),
                "strictly ascending z samples"));
        }
    }
}

void ProfileCurve::computeTangents() {
    // Fritsch-Carlson: secant slopes, three-point averages (0 at a local extremum), one-sided at the ends,
    // then each interval's pair of tangents pulled inside the circle alpha^2 + beta^2 <= 9 that keeps the
    // cubic monotone on that interval.
    const size_t n = z_.size();
    tangents_.assign(n, 0.0f);
    if (n < 2) return;
    work_.assign(2 * n - 1, 0.0);
    double* secant = work_.data();       // n - 1
    double* m = work_.data() + (n - 1);  // n
    for (size_t k = 0; k + 1 < n; ++k) {
        secant[k] = (double(values_[k + 1]) - values_[k]) / (double(z_[k + 1]) - z_[k]);
    }
    m[0] = secant[0];
    m[n - 1] = secant[n - 2];
    for (size_t k = 1; k + 1 < n; ++k) {
        m[k] = secant[k - 1] * secant[k] > 0.0 ? 0.5 * (secant[k - 1] + secant[k]) : 0.0;
    }
    for (size_t k = 0; k + 1 < n; ++k) {
        if (secant[k] == 0.0) {
            m[k] = m[k + 1] = 0.0;
            continue;
        }
        const double a = m[k] / secant[k], b = m[k + 1] / secant[k];
        const double r = a * a + b * b;
        if (r > 9.0) {
            const double t = 3.0 / std::sqrt(r);
            m[k] = t * a * secant[k];
            m[k + 1] = t * b * secant[k];
        }
    }
    for (size_t k = 0; k < n; ++k)
        tangents_[k] = static_cast<float>(m[k]);
}

float ProfileCurve::operator()(float z) const {
    if (!(z > z_.front())) return values_.front();  // also NaN: the caller validates its inputs
    if (z >= z_.back()) return values_.back();
    const size_t k = static_cast<size_t>(std::upper_bound(z_.begin(), z_.end(), z) - z_.begin()) - 1;
    const double h = double(z_[k + 1]) - z_[k];
    const double t = (double(z) - z_[k]) / h;
    const double t2 = t * t, t3 = t2 * t;
    // Cubic Hermite basis on [z_k, z_k+1].
    const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
    return static_cast<float>(h00 * values_[k] + h10 * h * tangents_[k] + h01 * values_[k + 1] +
                              h11 * h * tangents_[k + 1]);
}

}  // namespace deformkit::warp
