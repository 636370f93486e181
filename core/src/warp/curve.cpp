#include "deformkit/warp/curve.h"

#include <cmath>
#include <string>

#include "deformkit/error.h"

namespace deformkit::warp {
namespace {

// Uniform Catmull-Rom span between b and c with neighbours a and d, at t in [0, 1].
glm::vec3 catmullRom(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
                     float t) {
    const float t2 = t * t, t3 = t2 * t;
    return 0.5f * ((2.0f * b) + (c - a) * t + (2.0f * a - 5.0f * b + 4.0f * c - d) * t2 +
                   (3.0f * b - a - 3.0f * c + d) * t3);
}

glm::vec3 bezier(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d, float t) {
    const float u = 1.0f - t;
    return (u * u * u) * a + (3.0f * u * u * t) * b + (3.0f * u * t * t) * c + (t * t * t) * d;
}

}  // namespace

std::vector<glm::vec3> sampleCurve(std::span<const glm::vec3> controls, CurveType type,
                                   int32_t samplesPerSpan, std::string_view name) {
    const size_t n = controls.size();
    if (n < 2) {
        throw InvalidInput(
            formatError("curve", name, "has " + std::to_string(n) + " control points", "at least 2 points"));
    }
    for (size_t i = 0; i < n; ++i) {
        const glm::vec3& p = controls[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            throw InvalidInput(formatError("curve", std::string(name) + " point " + std::to_string(i),
                                           "is not finite", "finite coordinates"));
        }
    }
    if (type == CurveType::Polyline) return {controls.begin(), controls.end()};
    if (samplesPerSpan < 1 || samplesPerSpan > 4096) {
        throw InvalidInput(formatError("curve", name, "samples per span is " + std::to_string(samplesPerSpan),
                                       "an integer in [1, 4096]"));
    }
    if (type == CurveType::Bezier && (n - 1) % 3 != 0) {
        throw InvalidInput(formatError("curve", name, "has " + std::to_string(n) + " Bezier control points",
                                       "3k + 1 control points (k cubic spans)"));
    }
    const size_t spans = type == CurveType::Bezier ? (n - 1) / 3 : n - 1;
    std::vector<glm::vec3> out;
    out.reserve(spans * static_cast<size_t>(samplesPerSpan) + 1);
    for (size_t s = 0; s < spans; ++s) {
        for (int32_t k = 0; k < samplesPerSpan; ++k) {
            const float t = static_cast<float>(k) / static_cast<float>(samplesPerSpan);
            if (type == CurveType::Bezier) {
                out.push_back(bezier(controls[3 * s], controls[3 * s + 1], controls[3 * s + 2],
                                     controls[3 * s + 3], t));
            } else {
                const glm::vec3 a = s == 0 ? 2.0f * controls[0] - controls[1] : controls[s - 1];
                const glm::vec3 d = s + 2 == n ? 2.0f * controls[n - 1] - controls[n - 2] : controls[s + 2];
                out.push_back(catmullRom(a, controls[s], controls[s + 1], d, t));
            }
        }
    }
    out.push_back(controls[n - 1]);  // both cubic types end exactly at the last control
    return out;
}

}  // namespace deformkit::warp
