#include "deformkit/warp/morph.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "deformkit/error.h"
#include "deformkit/warp/envelope.h"
#include "warp/checks.h"

namespace deformkit::warp {
namespace {

void requireFiniteParameter(const char* what, float t) {
    if (!std::isfinite(t)) {
        throw InvalidInput(formatError("morph", what, "is " + std::to_string(t), "a finite number"));
    }
}

}  // namespace

void morphByEnvelope(std::span<const glm::vec3> in, std::span<const glm::vec3> deformed, float t,
                     std::span<glm::vec3> out) {
    requireFiniteParameter("t", t);
    requireFiniteResult("morph", in, out, applyEnvelope(in, deformed, {}, t, out));
}

void morphTransformations(const Transformations& in, std::span<const float> t, Transformations& out) {
    const size_t n = static_cast<size_t>(in.size());
    if (t.size() != 1) detail::requireCount("morph", "morph parameters t", t.size(), n);
    for (size_t i = 0; i < t.size(); ++i) {
        if (!std::isfinite(t[i])) {
            throw InvalidInput(formatError("morph", "parameter t[" + std::to_string(i) + "]",
                                           "is " + std::to_string(t[i]), "a finite number"));
        }
    }
    out.method = in.method;
    if (in.method == ScaleMethod::Displacement) {
        out.affine.resize(n);
        out.components.clear();
        for (size_t i = 0; i < n; ++i)
            out.affine[i] = scaleByDisplacement(in.affine[i], t.size() == 1 ? t[0] : t[i]);
    } else {
        out.components.resize(n);
        out.affine.clear();
        for (size_t i = 0; i < n; ++i) {
            out.components[i] = scaleByComposition(in.components[i], t.size() == 1 ? t[0] : t[i]);
        }
    }
}

void morphSchedule(float time, std::span<const float> start, std::span<const float> end,
                   std::span<float> out) {
    requireFiniteParameter("time", time);
    detail::requireCount("morph", "schedule ends", end.size(), start.size());
    detail::requireCount("morph", "schedule output", out.size(), start.size());
    for (size_t i = 0; i < start.size(); ++i) {
        if (!(std::isfinite(start[i]) && std::isfinite(end[i]) && end[i] > start[i])) {
            throw InvalidInput(
                formatError("morph", "schedule entry " + std::to_string(i),
                            "runs from " + std::to_string(start[i]) + " to " + std::to_string(end[i]),
                            "finite start < end"));
        }
        out[i] = std::clamp((time - start[i]) / (end[i] - start[i]), 0.0f, 1.0f);
    }
}

void morphStrengths(const SparseFields& in, float t, SparseFields& out) {
    requireFiniteParameter("t", t);
    out.offsets = in.offsets;
    out.transform = in.transform;
    out.weight = in.weight;
    out.strength.resize(in.strength.size());
    for (size_t e = 0; e < in.strength.size(); ++e)
        out.strength[e] = t * in.strength[e];
}

void morphTargets(std::span<const glm::vec3> source, std::span<const glm::vec3> target, float t,
                  std::span<glm::vec3> out) {
    requireFiniteParameter("t", t);
    detail::requireCount("morph", "targets", target.size(), source.size());
    detail::requireCount("morph", "output", out.size(), source.size());
    for (size_t i = 0; i < source.size(); ++i)
        out[i] = source[i] + t * (target[i] - source[i]);
}

}  // namespace deformkit::warp
