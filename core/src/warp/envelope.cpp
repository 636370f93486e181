#include "deformkit/warp/envelope.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"
#include "warp/checks.h"

namespace deformkit::warp {

int64_t applyEnvelope(std::span<const glm::vec3> in, std::span<const glm::vec3> deformed,
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
    int64_t bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (int64_t u = 0; u < n; ++u) {
        const double k = painted ? envelope * static_cast<double>(weights[u]) : envelope;
        glm::vec3 r;
        if (k == 1.0) {
            r = deformed[u];
        } else if (k == 0.0) {
            r = in[u];
        } else {
            const glm::dvec3 a(in[u]);
            r = glm::vec3(a + k * (glm::dvec3(deformed[u]) - a));
        }
        out[u] = r;
        bad = std::min(bad, detail::finiteBits(r) != 0 ? n : u);
    }
    return bad;
}

namespace {

// "(x, y, z)", each coordinate as numberText prints it (1e+38, inf): a point beyond float range stays short.
std::string coordinates(const glm::vec3& p) {
    std::string text = "(";
    text += numberText(p.x);
    text += ", ";
    text += numberText(p.y);
    text += ", ";
    text += numberText(p.z);
    text += ")";
    return text;
}

}  // namespace

void requireFiniteResult(std::string_view source, std::span<const glm::vec3> in,
                         std::span<const glm::vec3> out, int64_t bad) {
    if (bad < 0 || static_cast<size_t>(bad) >= out.size()) return;
    const auto u = static_cast<size_t>(bad);
    const std::string element = "point " + std::to_string(bad);
    const bool known = u < in.size() && in.data() != out.data();
    if (known && !geom::isFinite(in[u])) {
        throw InvalidInput(
            formatError(std::string(source), element, "is " + coordinates(in[u]), "finite coordinates"));
    }
    if (!known) {  // the output overwrote the input: a point that came in so, or one taken beyond range
        throw InvalidInput(formatError(std::string(source), element,
                                       "is " + coordinates(out[u]) + " once deformed",
                                       "finite points, and parameters that keep the deformation within "
                                       "float range"));
    }
    throw InvalidInput(formatError(
        std::string(source), element, "is deformed from " + coordinates(in[u]) + " to " + coordinates(out[u]),
        "finite positions: parameters that keep the deformation within float range"));
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
