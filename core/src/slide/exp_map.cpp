#include "deformkit/slide/exp_map.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace deformkit::slide {

namespace {

// Side of the cutting plane, with points on it counted as positive (symbolic perturbation), so every
// triangle the plane meets has exactly one edge pair with differing sides and the walk cannot stall.
bool positiveSide(double signedDistance) {
    return signedDistance >= 0.0;
}

}  // namespace

std::optional<double> normalCurveLength(const SlideSurface& surface, int32_t p, int32_t q, int32_t maxSteps) {
    const glm::dvec3& origin = surface.point(p);
    const glm::dvec3& target = surface.point(q);
    if (surface.areNeighbors(p, q)) return glm::length(target - origin);  // the cut runs along their edge
    const glm::dvec3& n = surface.normal(p);
    const glm::dvec3 pq = target - origin;
    glm::dvec3 planeNormal = glm::cross(n, pq);
    const double pl = glm::length(planeNormal);
    if (!(pl > 1e-12 * glm::length(pq))) return std::nullopt;  // q straight above p: no unique plane
    planeNormal /= pl;
    const glm::dvec3 forward = pq - glm::dot(pq, n) * n;  // the cut's direction in the tangent plane
    auto side = [&](int32_t v) { return glm::dot(planeNormal, surface.point(v) - origin); };
    auto crossing = [&](int32_t a, int32_t b) {
        const double sa = side(a), sb = side(b);
        const double t = sa / (sa - sb);
        return surface.point(a) + t * (surface.point(b) - surface.point(a));
    };

    // The triangle at p that the cut leaves p through, towards q.
    int32_t exitCorner = -1;  // corner whose edge the cut crosses
    glm::dvec3 x;
    for (int32_t c : surface.vertexCorners(p)) {
        if (surface.isDegenerate(SlideSurface::triangleOf(c))) continue;
        const int32_t edge = SlideSurface::next(c);  // the edge opposite p
        const int32_t a = surface.vertex(edge), b = surface.vertex(SlideSurface::next(edge));
        if (positiveSide(side(a)) == positiveSide(side(b))) continue;
        const glm::dvec3 y = crossing(a, b);
        if (glm::dot(y - origin, forward) <= 0.0) continue;
        exitCorner = edge;
        x = y;
        break;
    }
    if (exitCorner < 0) return std::nullopt;
    double length = glm::length(x - origin);
    const double giveUp = 4.0 * glm::length(pq) + 1e-300;

    for (int32_t step = 0; step < maxSteps; ++step) {
        const int32_t entry = surface.opposite(exitCorner);
        if (entry < 0) return std::nullopt;  // the cut leaves the surface before reaching q
        // The entered triangle runs entry -> next(entry) along the shared edge; w is its third vertex.
        const int32_t u = surface.vertex(entry), v = surface.vertex(SlideSurface::next(entry));
        const int32_t wCorner = SlideSurface::prev(entry);
        const int32_t w = surface.vertex(wCorner);
        if (u == q || v == q || w == q) return length + glm::length(target - x);
        const bool wPositive = positiveSide(side(w));
        // Leave through the edge whose ends lie on different sides: (v, w) or (w, u).
        if (wPositive == positiveSide(side(u))) {
            exitCorner = SlideSurface::next(entry);  // edge v -> w
            const glm::dvec3 y = crossing(v, w);
            length += glm::length(y - x);
            x = y;
        } else {
            exitCorner = wCorner;  // edge w -> u
            const glm::dvec3 y = crossing(w, u);
            length += glm::length(y - x);
            x = y;
        }
        if (length > giveUp) return std::nullopt;
    }
    return std::nullopt;
}

glm::dvec2 expMap(const SlideSurface& surface, int32_t p, int32_t q, bool* fellBack) {
    if (fellBack) *fellBack = false;
    const glm::dvec3& n = surface.normal(p);
    const glm::dvec3 pq = surface.point(q) - surface.point(p);
    const glm::dvec3 tangent = pq - glm::dot(pq, n) * n;
    const double tl = glm::length(tangent);
    if (!(tl > 0.0)) return glm::dvec2(0.0);
    double distance = glm::length(pq);
    if (!surface.areNeighbors(p, q)) {
        if (const auto traced = normalCurveLength(surface, p, q)) {
            distance = *traced;
        } else if (fellBack) {
            *fellBack = true;
        }
    }
    const double scale = distance / tl;
    return glm::dvec2(glm::dot(tangent, surface.tangent1(p)), glm::dot(tangent, surface.tangent2(p))) * scale;
}

}  // namespace deformkit::slide
