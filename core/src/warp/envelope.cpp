#include "deformkit/warp/envelope.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <glm/vec3.hpp>

#include "deformkit/error.h"

namespace deformkit::warp {

void applyEnvelope(std::span<const glm::vec3> in, std::span<const glm::vec3> deformed,
                   std::span<const float> weights, double envelope, std::span<glm::vec3> out) {
    const auto requireSize = [&](const char* what, size_t got) {
        if (got != in.size()) {
            throw InvalidInput(formatError("envelope", what, "has " + std::to_string(got) + " entries",
                                           std::to_string(in.size()) + ", one per point"));
        }
    };
    requireSize("deformed points", deformed.size());
    requireSize("output points", out.size());
    if (!weights.empty()) requireSize("painted weights", weights.size());
    const auto n = static_cast<int64_t>(in.size());
    const bool painted = !weights.empty();
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < n; ++u) {
        const double k = painted ? envelope * static_cast<double>(weights[u]) : envelope;
        if (k == 1.0) {
            out[u] = deformed[u];
        } else if (k == 0.0) {
            out[u] = in[u];
        } else {
            const glm::dvec3 a(in[u]);
            out[u] = glm::vec3(a + k * (glm::dvec3(deformed[u]) - a));
        }
    }
}

void requireFiniteEnvelope(std::string_view source, std::span<const float> weights, double envelope) {
    if (!std::isfinite(envelope)) {
        throw InvalidInput(formatError(std::string(source), "envelope", "is " + numberText(envelope),
                                       "a finite number, usually in [0, 1]"));
    }
    const auto n = static_cast<int64_t>(weights.size());
    int64_t bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad) if (n >= 65536)
    for (int64_t u = 0; u < n; ++u) {
        if (!(std::abs(weights[u]) <= std::numeric_limits<float>::max())) bad = std::min(bad, u);
    }
    if (bad < n) {
        throw InvalidInput(formatError(std::string(source), "painted weight of point " + std::to_string(bad),
                                       "is " + numberText(weights[bad]),
                                       "a finite number, usually in [0, 1]"));
    }
}

}  // namespace deformkit::warp
