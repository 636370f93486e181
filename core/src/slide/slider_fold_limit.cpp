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
    // The largest scale that flips nothing, to a precision relative to itself (a drag a hundred times the
    // radius keeps a hundredth of itself, not 0): halvings from 1 (which folds) until nothing flips, then
    // bisection between that scale and the one before it. Both assume the flip-free scales are an interval
    // from 0. 0 when even 2^-kHalvings folds (the slide folds for any drag).
    constexpr int kHalvings = 60;
    constexpr int kBisections = 12;
    std::vector<double> scales(base.size());
    const auto foldsAt = [&](double scale) {
        for (size_t h = 0; h < base.size(); ++h)
            scales[h] = base[h] * scale;
        slideOnce(restDisplacement, scales, drives, in, weights, envelope);
        return countFlips(triangles, in) > 0;
    };
    double lo = 0.0, hi = 1.0;
    for (int step = 0; step < kHalvings && lo == 0.0; ++step)
        (foldsAt(0.5 * hi) ? hi : lo) = 0.5 * hi;
    if (lo == 0.0) return 0.0;
    for (int step = 0; step < kBisections; ++step) {
        const double mid = 0.5 * (lo + hi);
        (foldsAt(mid) ? hi : lo) = mid;
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
