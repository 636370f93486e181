#pragma once

// Helpers shared by the warp tests.

#include <algorithm>
#include <random>
#include <span>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/warp/engine.h"
#include "deformkit/warp/ffd.h"

namespace deformkit::test {

// Points at lattice-local coordinates uniform in [lo, hi]^3.
inline std::vector<glm::vec3> samplePoints(const warp::Lattice& l, std::mt19937& rng, int count, float lo,
                                           float hi) {
    std::uniform_real_distribution<float> uni(lo, hi);
    std::vector<glm::vec3> pts(count);
    for (auto& p : pts)
        p = l.origin + l.axes * glm::vec3(uni(rng), uni(rng), uni(rng));
    return pts;
}

// The generic engine path: bind `warp` to `pts` and evaluate at the same points.
inline std::vector<glm::vec3> viaEngine(warp::Warp& warp, std::vector<glm::vec3> pts,
                                        std::span<const float> weights = {}, float envelope = 1.0f) {
    warp::WarpDeformer deformer(warp);
    deformer.bind(pts);
    deformer.evaluate(pts, weights, envelope);
    return pts;
}

// Largest distance between corresponding points.
inline float maxError(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    float e = 0.0f;
    for (size_t i = 0; i < a.size(); ++i)
        e = std::max(e, glm::length(a[i] - b[i]));
    return e;
}

}  // namespace deformkit::test
