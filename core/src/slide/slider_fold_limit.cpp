#include <glm/geometric.hpp>

#include "slider_impl.h"

namespace deformkit::slide {

glm::dvec3 Slider::Impl::slidPoint(int32_t v, std::span<const glm::vec3> in) const {
    const int32_t i = slotOf[v];
    return i >= 0 && landings[i].stop != Stop::None ? glm::vec3(slid[i]) : in[v];
}

int32_t Slider::Impl::countFlips(std::span<const int32_t> triangles, std::span<const glm::vec3> in) const {
    const auto count = static_cast<int32_t>(triangles.size());
    int32_t flipped = 0;
#pragma omp parallel for schedule(static) reduction(+ : flipped) if (count >= detail::kParallelFrom)
    for (int32_t k = 0; k < count; ++k) {
        const int32_t t = triangles[k];
        const int32_t a = surface.vertex(3 * t), b = surface.vertex(3 * t + 1), c = surface.vertex(3 * t + 2);
        const glm::dvec3 before =
            glm::cross(glm::dvec3(in[b]) - glm::dvec3(in[a]), glm::dvec3(in[c]) - glm::dvec3(in[a]));
        const glm::dvec3 pa = slidPoint(a, in);
        const glm::dvec3 after = glm::cross(slidPoint(b, in) - pa, slidPoint(c, in) - pa);
        if (glm::dot(before, before) > 0.0 && glm::dot(before, after) <= 0.0) ++flipped;
    }
    return flipped;
}

double Slider::Impl::foldLimitScale(std::span<const glm::dvec3> restDisplacement, std::vector<double> base,
                                    std::span<const int32_t> triangles, std::span<const SlideDrive> drives,
                                    std::span<const glm::vec3> in, std::span<const float> weights,
                                    double envelope) {
    constexpr int kSteps = 14;
    double lo = 0.0, hi = 1.0;
    std::vector<double> scales(base.size());
    for (int step = 0; step < kSteps; ++step) {
        const double mid = 0.5 * (lo + hi);
        for (size_t h = 0; h < base.size(); ++h)
            scales[h] = base[h] * mid;
        slideOnce(restDisplacement, scales, drives, in, weights, envelope);
        (countFlips(triangles, in) == 0 ? lo : hi) = mid;
    }
    return lo;
}

Slider::Impl::Counts Slider::Impl::limitFolds(std::span<const glm::dvec3> restDisplacement,
                                              std::vector<double>& scales, std::span<const SlideDrive> drives,
                                              std::span<const glm::vec3> in, std::span<const float> weights,
                                              double envelope, int32_t& flipped) {
    const auto numHandles = handles.size();
    for (size_t h = 0; h < numHandles; ++h) {
        std::vector<double> alone(numHandles, 0.0);
        alone[h] = 1.0;
        if (numHandles > 1) {
            slideOnce(restDisplacement, alone, drives, in, weights, envelope);
            if (countFlips(handleTriangles[h], in) == 0) continue;
        }
        scales[h] =
            foldLimitScale(restDisplacement, alone, handleTriangles[h], drives, in, weights, envelope);
    }
    Counts counts = slideOnce(restDisplacement, scales, drives, in, weights, envelope);
    flipped = countFlips(regionTriangles, in);
    if (flipped > 0) {
        const double common =
            foldLimitScale(restDisplacement, scales, regionTriangles, drives, in, weights, envelope);
        for (double& scale : scales)
            scale *= common;
        counts = slideOnce(restDisplacement, scales, drives, in, weights, envelope);
        flipped = countFlips(regionTriangles, in);
    }
    return counts;
}

}  // namespace deformkit::slide
