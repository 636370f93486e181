#include "deformkit/slide/falloff.h"

#include <cmath>
#include <string>

#include "deformkit/error.h"

namespace deformkit::slide {

Falloff Falloff::smooth() {
    return Falloff();
}

Falloff Falloff::linear() {
    Falloff f;
    f.linear_ = true;
    return f;
}

Falloff Falloff::ramp(std::span<const float> samples, std::string_view name) {
    if (samples.size() < 2) {
        throw InvalidInput(formatError(name, "", std::to_string(samples.size()) + " samples",
                                       "at least 2 values, at x = 0 and x = 1 of distance / radius"));
    }
    Falloff f;
    f.samples_.reserve(samples.size());
    for (size_t i = 0; i < samples.size(); ++i) {
        const float v = samples[i];
        if (!std::isfinite(v) || v < 0.0f || v > 1.0f) {
            throw InvalidInput(formatError(name, "sample " + std::to_string(i), "is " + numberText(v),
                                           "a finite value in [0, 1]"));
        }
        f.samples_.push_back(v);
    }
    return f;
}

double Falloff::operator()(double x) const {
    if (!(x < 1.0)) return 0.0;  // also NaN
    if (x <= 0.0) x = 0.0;
    if (linear_) return 1.0 - x;
    if (samples_.empty()) return 1.0 - x * x * (3.0 - 2.0 * x);
    const double position = x * static_cast<double>(samples_.size() - 1);
    const auto i = static_cast<size_t>(position);
    if (i + 1 >= samples_.size()) return samples_.back();
    const double t = position - static_cast<double>(i);
    return samples_[i] + t * (samples_[i + 1] - samples_[i]);
}

}  // namespace deformkit::slide
