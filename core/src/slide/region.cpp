#include "deformkit/slide/region.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "deformkit/geom/geodesic_distance.h"

namespace deformkit::slide {

namespace {

glm::dvec3 projectOnPlane(const glm::dvec3& a, const glm::dvec3& n) {
    return a - glm::dot(a, n) * n;
}

bool normalizeInPlace(glm::dvec3& a) {
    const double length = glm::length(a);
    if (!(length > 1e-12)) return false;
    a /= length;
    return true;
}

}  // namespace

SupportRegion buildSupportRegion(const SlideSurface& surface, const geom::Mesh& mesh, int32_t handle,
                                 double radius, RegionMetric metric) {
    SupportRegion region;
    region.handle = handle;
    region.radius = radius;
    region.metric = metric;
    const int32_t nv = surface.numVertices();

    std::vector<double> distance;
    if (metric == RegionMetric::Geodesic) {
        geom::GeodesicOptions options;
        options.maxDistance = radius;
        distance = geom::geodesicDistances(mesh, handle, options);
    } else {
        distance.resize(nv);
        const glm::dvec3 p0 = surface.point(handle);
#pragma omp parallel for schedule(static)
        for (int32_t v = 0; v < nv; ++v)
            distance[v] = glm::length(surface.point(v) - p0);
    }
    auto inside = [&](int32_t v) { return distance[v] <= radius; };

    // Breadth-first layers over active vertices; slot[v] = index into region.vertices, -1 if not reached.
    std::vector<int32_t> slot(nv, -1);
    std::vector<glm::dvec3> a1, a2;  // 3D region basis per slot
    region.a1 = surface.tangent1(handle);
    region.a2 = surface.tangent2(handle);
    slot[handle] = 0;
    region.vertices.push_back(handle);
    a1.push_back(region.a1);
    a2.push_back(region.a2);

    size_t layerBegin = 0;
    std::vector<int32_t> layer;
    while (layerBegin < region.vertices.size()) {
        const size_t layerEnd = region.vertices.size();
        layer.clear();
        for (size_t i = layerBegin; i < layerEnd; ++i) {
            for (int32_t w : surface.neighbors(region.vertices[i])) {
                if (slot[w] < 0 && inside(w) && surface.hasFrame(w)) layer.push_back(w);
            }
        }
        std::sort(layer.begin(), layer.end());
        layer.erase(std::unique(layer.begin(), layer.end()), layer.end());
        for (int32_t w : layer) {
            slot[w] = static_cast<int32_t>(region.vertices.size());
            region.vertices.push_back(w);
        }
        a1.resize(region.vertices.size());
        a2.resize(region.vertices.size());
        const auto count = static_cast<int32_t>(layer.size());
#pragma omp parallel for schedule(static)
        for (int32_t i = 0; i < count; ++i) {
            const int32_t v = layer[i];
            const glm::dvec3& n = surface.normal(v);
            glm::dvec3 s1(0.0), s2(0.0), first1(0.0), first2(0.0);
            bool haveFirst = false;
            for (int32_t w : surface.neighbors(v)) {
                const int32_t j = slot[w];
                if (j < 0 || static_cast<size_t>(j) < layerBegin || static_cast<size_t>(j) >= layerEnd)
                    continue;
                const glm::dvec3 p1 = projectOnPlane(a1[j], n), p2 = projectOnPlane(a2[j], n);
                s1 += p1;
                s2 += p2;
                if (!haveFirst) {
                    first1 = p1;
                    first2 = p2;
                    haveFirst = true;
                }
            }
            // Opposite neighbours cancelling out happens only on folded geometry; one neighbour's
            // projection is then the best available estimate.
            if (!normalizeInPlace(s1)) {
                s1 = first1;
                s2 = first2;
                if (!normalizeInPlace(s1)) s1 = surface.tangent1(v);
            }
            s2 -= glm::dot(s2, s1) * s1;
            if (!normalizeInPlace(s2)) s2 = glm::cross(n, s1);
            const size_t k = layerEnd + static_cast<size_t>(i);
            a1[k] = s1;
            a2[k] = s2;
        }
        layerBegin = layerEnd;
    }

    const size_t active = region.vertices.size();
    region.normalizedDistance.resize(active);
    region.a1Local.resize(active);
    region.a2Local.resize(active);
    for (size_t k = 0; k < active; ++k) {
        const int32_t v = region.vertices[k];
        const glm::dvec3 b1 = surface.tangent1(v), b2 = surface.tangent2(v);
        // Stored in float: a vertex strictly inside the radius whose ratio rounds up to 1 would take the
        // falloff's outside value (0), not its last; it keeps the largest float below 1.
        const float ratio = static_cast<float>(distance[v] / radius);
        region.normalizedDistance[k] =
            ratio >= 1.0f && distance[v] < radius ? std::nextafter(1.0f, 0.0f) : ratio;
        region.a1Local[k] = glm::dvec2(glm::dot(a1[k], b1), glm::dot(a1[k], b2));
        region.a2Local[k] = glm::dvec2(glm::dot(a2[k], b1), glm::dot(a2[k], b2));
    }
    for (int32_t v = 0; v < nv; ++v) {
        if (!inside(v) || slot[v] >= 0) continue;
        if (surface.hasFrame(v)) {
            ++region.unreachable;
            region.unreachableVertices.push_back(v);
        } else {
            ++region.withoutTangentPlane;
            region.verticesWithoutTangentPlane.push_back(v);
        }
    }
    return region;
}

}  // namespace deformkit::slide
