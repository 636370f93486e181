#include "deformkit/warp/envelope.h"

#include <cstdint>
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

}  // namespace deformkit::warp
