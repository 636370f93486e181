#include "deformkit/warp/engine.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/envelope.h"
#include "warp/checks.h"
#include "warp/weighted_mean.h"

namespace deformkit::warp {
namespace {

// (s . T_i)<p> for one field entry.
glm::vec3 applyScaled(const Transformations& t, int32_t i, float s, const glm::vec3& p) {
    if (t.method == ScaleMethod::Displacement) {
        const glm::vec3 moved = t.affine[i].apply(p);
        return p + s * (moved - p);
    }
    return toAffine(scaleByComposition(t.components[i], s)).apply(p);
}

}  // namespace

void evaluateWarp(std::span<const glm::vec3> points, const SparseFields& fields,
                  const Transformations& transforms, std::span<glm::vec3> out, const EngineOptions& options) {
    const size_t n = points.size();
    detail::requireCount("warp engine", "output points", out.size(), n);
    detail::requireCount("warp engine", "field offsets", fields.offsets.size(), n + 1);
    const size_t entries = static_cast<size_t>(fields.offsets.back());
    detail::requireCount("warp engine", "field transformation indices", fields.transform.size(), entries);
    detail::requireCount("warp engine", "strength field", fields.strength.size(), entries);
    detail::requireCount("warp engine", "weighting field", fields.weight.size(), entries);
    if (transforms.method == ScaleMethod::Composition) {
        detail::requireCount("warp engine", "transformations", transforms.components.size(),
                             static_cast<size_t>(transforms.size()));
    }
    const int32_t numTransforms = transforms.size();
    for (size_t e = 0; e < entries; ++e) {
        if (fields.transform[e] < 0 || fields.transform[e] >= numTransforms) {
            throw InvalidInput(formatError("warp engine", "field entry " + std::to_string(e),
                                           "names transformation " + std::to_string(fields.transform[e]),
                                           "an index in [0, " + std::to_string(numTransforms) + ")"));
        }
    }
    const auto m = static_cast<double>(options.displacementWeightExponent);

#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(n); ++u) {
        const glm::vec3 p = points[u];
        // Eq. (3) with the weighted sum taken over displacements (matrix addition, §3.3), in double so
        // the result does not depend on how many entries a point has. All-zero weights: the identity
        // (paper footnote 6).
        glm::dvec3 mean;
        const bool moved = detail::weightedMeanDisplacement(
            fields.offsets[u], fields.offsets[u + 1], m,
            [&](int32_t e) {
                return applyScaled(transforms, fields.transform[e], fields.strength[e], p) - p;
            },
            [&](int32_t e) { return static_cast<double>(fields.weight[e]); },
            [](double x, double y) { return std::pow(x, y); }, mean);
        out[u] = moved ? p + glm::vec3(mean) : p;
    }
}

void WarpDeformer::bind(std::span<const glm::vec3> restPoints) {
    bound_ = false;
    fields_.clear();
    warp_.bind(restPoints, fields_);
    if (fields_.numPoints() != static_cast<int32_t>(restPoints.size())) {
        throw InvalidInput(formatError(
            "warp", "bind", "produced fields for " + std::to_string(fields_.numPoints()) + " points",
            std::to_string(restPoints.size()) + " points, one entry list per point"));
    }
    deformed_.resize(restPoints.size());
    bound_ = true;
}

void WarpDeformer::requireBound(size_t points) const {
    if (!bound_) {
        throw InvalidInput(formatError(source_, "evaluate", "called before bind", "bind(restPoints) first"));
    }
    detail::requireCount(source_.c_str(), "points", points, deformed_.size());
}

void WarpDeformer::update() {
    warp_.transformations(transforms_);
}

void WarpDeformer::apply(std::span<const glm::vec3> in, std::span<glm::vec3> out) const {
    requireBound(in.size());
    evaluateWarp(in, fields_, transforms_, out, warp_.engineOptions());
}

void WarpDeformer::evaluate(std::span<glm::vec3> points, std::span<const float> weights, float envelope) {
    requireBound(points.size());
    requireFiniteEnvelope(source_, weights, envelope);
    update();
    evaluateWarp(points, fields_, transforms_, deformed_, warp_.engineOptions());
    // Blended into the deformed copy while the input is still there, so that a point refused is named as it
    // came in (not finite) or as it was deformed from, then copied back: the points change only when every
    // one is finite.
    requireFiniteResult(source_, points, deformed_,
                        applyEnvelope(points, deformed_, weights, envelope, deformed_));
    std::copy(deformed_.begin(), deformed_.end(), points.begin());
}

}  // namespace deformkit::warp
