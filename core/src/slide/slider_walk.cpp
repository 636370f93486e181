#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "slider_impl.h"

namespace deformkit::slide {

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) {
    return a.x * b.y - a.y * b.x;
}

// Barycentric coordinates of x in the 2D triangle (a, b, c); false when the triangle has no area.
bool barycentric(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& x,
                 glm::dvec3& out) {
    const double area = cross2(b - a, c - a);
    if (!(std::abs(area) > 0.0)) return false;
    out = glm::dvec3(cross2(b - x, c - x), cross2(c - x, a - x), cross2(a - x, b - x)) / area;
    return true;
}

// Whether barycentric coordinates put the point in the triangle: none below -1e-12, and summing to 1. A
// target far beyond the triangle (a drag of 1e24 radii) loses every digit to cancellation, and all three
// come out 0: not inside, the walk goes on (to its limit).
bool inside(const glm::dvec3& b) {
    return glm::all(glm::greaterThanEqual(b, glm::dvec3(-1e-12))) && std::abs(b.x + b.y + b.z - 1.0) < 1e-6;
}

glm::dvec3 clampBarycentric(glm::dvec3 b) {
    b = glm::max(b, glm::dvec3(0.0));
    const double sum = b.x + b.y + b.z;
    return sum > 0.0 ? b / sum : glm::dvec3(1.0 / 3.0);
}

detail::Landing inTriangle(int32_t triangle, const glm::dvec3& bary) {
    detail::Landing landing;
    landing.triangle = triangle;
    landing.barycentric = bary;
    landing.stop = detail::Stop::Reached;
    return landing;
}

}  // namespace

glm::dvec2 Slider::Impl::ringImage(int32_t slot, int32_t p, int32_t q) const {
    const auto corners = surface.vertexCorners(p);
    const int32_t base = ringOffsets[slot];
    for (size_t k = 0; k < corners.size(); ++k) {
        if (surface.vertex(SlideSurface::next(corners[k])) == q) return ringNext[base + k];
        if (surface.vertex(SlideSurface::prev(corners[k])) == q) return ringPrev[base + k];
    }
    return glm::dvec2(0.0);  // q == p
}

bool Slider::Impl::isInteriorVertex(int32_t p) const {
    for (int32_t c : surface.vertexCorners(p)) {
        if (surface.opposite(c) < 0 || surface.opposite(SlideSurface::prev(c)) < 0) return false;
    }
    return true;
}

glm::dvec2 Slider::Impl::alongBoundary(int32_t slot, int32_t p, const glm::dvec2& target) const {
    constexpr double kParallel = 1e-6, kInward = 1e-9;
    const double length = glm::length(target);
    const glm::dvec2 direction = target / length;
    auto turned = [&](const glm::dvec2& ray, double angle) {
        const glm::dvec2 r = glm::normalize(ray);
        const double c = std::cos(angle), s = std::sin(angle);
        return glm::dvec2(c * r.x - s * r.y, s * r.x + c * r.y) * length;
    };
    auto parallel = [&](const glm::dvec2& ray) {
        const glm::dvec2 r = glm::normalize(ray);
        return glm::dot(r, direction) > 0.0 && std::abs(cross2(r, direction)) < kParallel;
    };
    for (int32_t c : surface.vertexCorners(p)) {
        if (surface.isDegenerate(SlideSurface::triangleOf(c))) continue;
        if (surface.opposite(c) < 0) {  // boundary edge p -> a: the surface lies counter-clockwise of it
            const glm::dvec2 a = ringImage(slot, p, surface.vertex(SlideSurface::next(c)));
            if (parallel(a)) return turned(a, kInward);
        }
        if (surface.opposite(SlideSurface::prev(c)) < 0) {
            // boundary edge b -> p: the surface lies clockwise
            const glm::dvec2 b = ringImage(slot, p, surface.vertex(SlideSurface::prev(c)));
            if (parallel(b)) return turned(b, -kInward);
        }
    }
    return target;
}

Slider::Impl::Landing Slider::Impl::walk(int32_t slot, int32_t p, const glm::dvec2& requested) const {
    const glm::dvec2 inMap = interior[slot] ? requested : alongBoundary(slot, p, requested);
    glm::dvec2 developed(0.0);
    // The sector at p that contains the direction in the map.
    int32_t start = -1;
    glm::dvec2 ca(0.0), cb(0.0);
    double bestScore = -1e300;
    int32_t best = -1;
    glm::dvec2 bestA(0.0), bestB(0.0);
    const auto corners = surface.vertexCorners(p);
    for (size_t k = 0; k < corners.size(); ++k) {
        const int32_t c = corners[k];
        if (surface.isDegenerate(SlideSurface::triangleOf(c))) continue;
        const glm::dvec2 a = ringNext[ringOffsets[slot] + k];
        const glm::dvec2 b = ringPrev[ringOffsets[slot] + k];
        const double sa = cross2(a, inMap), sb = cross2(inMap, b);
        if (sa >= 0.0 && sb >= 0.0 && cross2(a, b) > 0.0) {
            start = c;
            ca = a;
            cb = b;
            break;
        }
        const double score = std::min(sa / glm::length(a), sb / glm::length(b));
        if (score > bestScore) {
            bestScore = score;
            best = c;
            bestA = a;
            bestB = b;
        }
    }
    if (start < 0) {
        // The direction leaves the surface at a boundary vertex: the vertex stays on the boundary.
        if (best < 0 || !interior[slot])
            return detail::onEdge(surface.vertexCorners(p).empty() ? 0 : surface.vertexCorners(p)[0], 0.0,
                                  Stop::Boundary);
        start = best;  // rounding at an interior vertex: the nearest sector
        ca = bestA;
        cb = bestB;
    }

    // Develop the start triangle isometrically (p at the origin, a on +x) and turn the target into it
    // by the share of the sector's map angle it makes with a: from here on the walk unfolds each
    // triangle it enters into this plane, so its path is a straight line of the target's length on
    // the surface (a straightest geodesic), whatever the map of far vertices would say.
    {
        const glm::dvec3 P = surface.point(p);
        const glm::dvec3 A = surface.point(surface.vertex(SlideSurface::next(start)));
        const glm::dvec3 B = surface.point(surface.vertex(SlideSurface::prev(start)));
        const double la = glm::length(A - P), lb = glm::length(B - P);
        const double gamma = std::atan2(glm::length(glm::cross(A - P, B - P)), glm::dot(A - P, B - P));
        const double mapAngle = std::atan2(cross2(ca, cb), glm::dot(ca, cb));
        // Strictly inside the sector: a direction along one of its edges (a slide along a ring of edges
        // or a boundary) is turned a hair (1e-9 of the sector's angle) into it, so the line passes
        // beside the edge's far vertex on the sector's side, as the walk below assumes (its first exit
        // edge, a -> b, has a on the right and b on the left).
        constexpr double kInside = 1e-9;
        const double share = mapAngle > 0.0
                                 ? std::clamp(std::atan2(cross2(ca, inMap), glm::dot(ca, inMap)) / mapAngle,
                                              kInside, 1.0 - kInside)
                                 : 0.5;
        const double length = glm::length(inMap);
        ca = glm::dvec2(la, 0.0);
        cb = lb * glm::dvec2(std::cos(gamma), std::sin(gamma));
        developed = length * glm::dvec2(std::cos(share * gamma), std::sin(share * gamma));
    }
    const glm::dvec2& target = developed;

    // Corner order of the start triangle is (p, a, b) from corner `start`.
    glm::dvec3 bary(0.0);
    if (barycentric(glm::dvec2(0.0), ca, cb, target, bary) && inside(bary)) {
        glm::dvec3 ordered(0.0);
        ordered[start % 3] = bary.x;
        ordered[SlideSurface::next(start) % 3] = bary.y;
        ordered[SlideSurface::prev(start) % 3] = bary.z;
        return inTriangle(SlideSurface::triangleOf(start), clampBarycentric(ordered));
    }
    int32_t edge = SlideSurface::next(start);  // a -> b
    glm::dvec2 e0 = ca, e1 = cb;
    const double targetLength2 = glm::dot(target, target);
    // A vertex exactly on the line counts as left of it, everywhere along the walk: the line is taken
    // as shifted a hair to the right, so it passes each such vertex on the same side.
    auto isLeft = [&](const glm::dvec2& x) { return cross2(target, x) >= 0.0; };
    auto crossingParameter = [&](const glm::dvec2& from, const glm::dvec2& to) {
        const double s0 = cross2(target, from), s1 = cross2(target, to);
        return s0 == s1 ? 0.0 : std::clamp(s0 / (s0 - s1), 0.0, 1.0);
    };
    for (int32_t step = 0;; ++step) {
        const double mu = crossingParameter(e0, e1);
        // The edge the walk leaves by has e0 right of the line and e1 left of it: the line crosses it.
        // Each step keeps that (one of the entered triangle's two other edges crosses too); a start
        // that broke it would send the walk through triangles the line never meets, so it stops here
        // (counted) rather than wander.
        if (isLeft(e0) || !isLeft(e1)) return detail::onEdge(edge, mu, Stop::WalkLimit);
        const int32_t entry = surface.opposite(edge);
        if (entry < 0) return detail::onEdge(edge, mu, Stop::Boundary);
        if (step + 1 >= options.maxWalkTriangles) return detail::onEdge(edge, mu, Stop::WalkLimit);
        // The entered triangle: entry runs from e1's vertex to e0's vertex; w is the third vertex.
        const int32_t wCorner = SlideSurface::prev(entry);
        // Unfold the entered triangle across the edge e0 -> e1: its third vertex lies right of it.
        const glm::dvec3 E0 = surface.point(surface.vertex(edge));
        const glm::dvec3 u = surface.point(surface.vertex(SlideSurface::next(edge))) - E0;
        const glm::dvec3 toW = surface.point(surface.vertex(wCorner)) - E0;
        const double edgeLength2 = glm::dot(u, u);
        const glm::dvec2 along = e1 - e0;
        const double alongLength = glm::length(along);
        if (!(edgeLength2 > 0.0) || !(alongLength > 0.0)) return detail::onEdge(edge, mu, Stop::Boundary);
        const double t = glm::dot(toW, u) / edgeLength2;
        const double h = glm::length(glm::cross(toW, u)) / std::sqrt(edgeLength2);
        const glm::dvec2 cw = e0 + t * along + (h / alongLength) * glm::dvec2(along.y, -along.x);
        const glm::dvec2 cEntry = e1, cNext = e0;  // vertex(entry), vertex(next(entry))
        if (barycentric(cEntry, cNext, cw, target, bary) && inside(bary)) {
            glm::dvec3 ordered(0.0);
            ordered[entry % 3] = bary.x;
            ordered[SlideSurface::next(entry) % 3] = bary.y;
            ordered[wCorner % 3] = bary.z;
            return inTriangle(SlideSurface::triangleOf(entry), clampBarycentric(ordered));
        }
        // Leave through the edge whose ends lie on different sides of the line through p and target.
        if (isLeft(cw) == isLeft(cNext)) {
            edge = wCorner;  // w -> vertex(entry)
            e0 = cw;
            e1 = cEntry;
        } else {
            edge = SlideSurface::next(entry);  // vertex(next(entry)) -> w
            e0 = cNext;
            e1 = cw;
        }
        // A crossing beyond the target (only by rounding: the unfolded strip is flat) means the target
        // is as good as reached in this triangle.
        const glm::dvec2 crossing = e0 + crossingParameter(e0, e1) * (e1 - e0);
        if (glm::dot(crossing, target) >= targetLength2) {
            if (!barycentric(cEntry, cNext, cw, target, bary)) bary = glm::dvec3(1.0 / 3.0);
            glm::dvec3 ordered(0.0);
            ordered[entry % 3] = bary.x;
            ordered[SlideSurface::next(entry) % 3] = bary.y;
            ordered[wCorner % 3] = bary.z;
            return inTriangle(SlideSurface::triangleOf(entry), clampBarycentric(ordered));
        }
    }
}

}  // namespace deformkit::slide
