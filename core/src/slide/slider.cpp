#include "deformkit/slide/slider.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/limit_surface.h"
#include "deformkit/slide/exp_map.h"

namespace deformkit::slide {

// Types Slider::Impl holds, in a named namespace: a class's fields must not have types of an anonymous
// namespace when the source is compiled as part of a unity batch (-Wsubobject-linkage).
namespace detail {

enum class Stop : uint8_t { None, Reached, Boundary, Limit };

struct Landing {
    int32_t triangle = -1;
    glm::dvec3 barycentric{0.0};  // on the triangle's corners 3t, 3t+1, 3t+2
    Stop stop = Stop::None;
};

}  // namespace detail
using detail::Landing;
using detail::Stop;

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

glm::dvec3 clampBarycentric(glm::dvec3 b) {
    b = glm::max(b, glm::dvec3(0.0));
    const double sum = b.x + b.y + b.z;
    return sum > 0.0 ? b / sum : glm::dvec3(1.0 / 3.0);
}

// A landing on the edge of `corner` (from vertex(corner) to vertex(next(corner))) at parameter mu.
Landing onEdge(int32_t corner, double mu, Stop stop) {
    Landing landing;
    landing.triangle = SlideSurface::triangleOf(corner);
    landing.barycentric[corner % 3] = 1.0 - mu;
    landing.barycentric[SlideSurface::next(corner) % 3] = mu;
    landing.stop = stop;
    return landing;
}

Landing inTriangle(int32_t triangle, const glm::dvec3& bary) {
    Landing landing;
    landing.triangle = triangle;
    landing.barycentric = bary;
    landing.stop = Stop::Reached;
    return landing;
}

}  // namespace

struct Slider::Impl {
    std::string source;
    geom::Mesh mesh;
    SlideOptions options;
    std::vector<SlideHandle> handles;
    SlideSurface surface;
    std::vector<SupportRegion> regions;
    std::vector<std::vector<int32_t>> regionSlots;  // per region, per active vertex: its slot in `active`
    std::vector<int32_t> active;                    // union of active vertices, ascending
    std::vector<glm::dvec2> displacement;           // per slot: d_P in the vertex's basis (Eq. 7), scratch
    std::vector<Landing> landings;                  // per slot, scratch
    std::unique_ptr<geom::LimitSurface> limit;
    std::vector<glm::dvec3> limitOrigin;  // per slot: the limit point under the vertex's rest position
    int32_t degenerateTriangles = 0;
    std::mutex mutex;

    Impl(const geom::Mesh& rest, std::vector<SlideHandle> h, const SlideOptions& o, std::string s)
        : source(std::move(s)), mesh(rest), options(o), handles(std::move(h)), surface(rest, source) {}

    // The one-ring part of a vertex's local map (Eq. 1-2 for the vertices sharing a triangle with it),
    // computed at bind: per corner c at the vertex, the images of vertex(next(c)) and vertex(prev(c)).
    std::vector<int32_t> ringOffsets;  // per slot, into ringNext / ringPrev; corners in vertexCorners order
    std::vector<glm::dvec2> ringNext, ringPrev;
    std::vector<uint8_t> interior;  // per slot: no boundary edge at the vertex

    // The image of one-ring neighbour q in p's tangent space (Eq. 1-2, computed at bind).
    glm::dvec2 ringImage(int32_t slot, int32_t p, int32_t q) const {
        const auto corners = surface.vertexCorners(p);
        const int32_t base = ringOffsets[slot];
        for (size_t k = 0; k < corners.size(); ++k) {
            if (surface.vertex(SlideSurface::next(corners[k])) == q) return ringNext[base + k];
            if (surface.vertex(SlideSurface::prev(corners[k])) == q) return ringPrev[base + k];
        }
        return glm::dvec2(0.0);  // q == p
    }

    bool isInteriorVertex(int32_t p) const {
        for (int32_t c : surface.vertexCorners(p)) {
            if (surface.opposite(c) < 0 || surface.opposite(SlideSurface::prev(c)) < 0) return false;
        }
        return true;
    }

    // At a boundary vertex, a slide along the boundary (within kParallel radians of a boundary edge) is
    // turned kInward radians into the surface, so that rounding in the propagated direction cannot start
    // its path just outside the surface, which would stop it at once.
    glm::dvec2 alongBoundary(int32_t slot, int32_t p, const glm::dvec2& target) const {
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
            if (surface.opposite(SlideSurface::prev(c)) <
                0) {  // boundary edge b -> p: the surface lies clockwise
                const glm::dvec2 b = ringImage(slot, p, surface.vertex(SlideSurface::prev(c)));
                if (parallel(b)) return turned(b, -kInward);
            }
        }
        return target;
    }

    // §3.3: the triangle F' where p lands when it slides by `requested` (d_P in p's basis): the sector of
    // p's one-ring map that holds the direction, then a straight walk of |d_P| across the triangles,
    // each unfolded into the plane of the one before across the edge the walk crosses.
    Landing walk(int32_t slot, int32_t p, const glm::dvec2& requested) const {
        const glm::dvec2 inMap = interior[slot] ? requested : alongBoundary(slot, p, requested);
        glm::dvec2 developed(0.0);
        // The sector at p that contains the direction in the map.
        int32_t start = -1;
        glm::dvec2 ca(0.0), cb(0.0);
        bool zeroIsLeft = true;
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
                // A inMap exactly along an edge (a slide along a boundary or along a ring of edges) is
                // read as turned a hair into this sector, so vertices on the line fall on the side the
                // sector lies: behind the a edge they count as right of the line, behind b as left.
                zeroIsLeft = !(sa == 0.0);
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
                return onEdge(surface.vertexCorners(p).empty() ? 0 : surface.vertexCorners(p)[0], 0.0,
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
            const double share =
                mapAngle > 0.0
                    ? std::clamp(std::atan2(cross2(ca, inMap), glm::dot(ca, inMap)) / mapAngle, 0.0, 1.0)
                    : 0.5;
            const double length = glm::length(inMap);
            ca = glm::dvec2(la, 0.0);
            cb = lb * glm::dvec2(std::cos(gamma), std::sin(gamma));
            developed = length * glm::dvec2(std::cos(share * gamma), std::sin(share * gamma));
        }
        const glm::dvec2& target = developed;

        // Corner order of the start triangle is (p, a, b) from corner `start`.
        glm::dvec3 bary(0.0);
        if (barycentric(glm::dvec2(0.0), ca, cb, target, bary) &&
            glm::all(glm::greaterThanEqual(bary, glm::dvec3(-1e-12)))) {
            glm::dvec3 ordered(0.0);
            ordered[start % 3] = bary.x;
            ordered[SlideSurface::next(start) % 3] = bary.y;
            ordered[SlideSurface::prev(start) % 3] = bary.z;
            return inTriangle(SlideSurface::triangleOf(start), clampBarycentric(ordered));
        }
        int32_t edge = SlideSurface::next(start);  // a -> b
        glm::dvec2 e0 = ca, e1 = cb;
        const double targetLength2 = glm::dot(target, target);
        auto isLeft = [&](const glm::dvec2& x) {
            const double side = cross2(target, x);
            return side > 0.0 || (side == 0.0 && zeroIsLeft);
        };
        auto crossingParameter = [&](const glm::dvec2& from, const glm::dvec2& to) {
            const double s0 = cross2(target, from), s1 = cross2(target, to);
            return s0 == s1 ? 0.0 : std::clamp(s0 / (s0 - s1), 0.0, 1.0);
        };
        for (int32_t step = 0;; ++step) {
            const double mu = crossingParameter(e0, e1);
            const int32_t entry = surface.opposite(edge);
            if (entry < 0) return onEdge(edge, mu, Stop::Boundary);
            if (step + 1 >= options.maxWalkTriangles) return onEdge(edge, mu, Stop::Limit);
            // The entered triangle: entry runs from e1's vertex to e0's vertex; w is the third vertex.
            const int32_t wCorner = SlideSurface::prev(entry);
            // Unfold the entered triangle across the edge e0 -> e1: its third vertex lies right of it.
            const glm::dvec3 E0 = surface.point(surface.vertex(edge));
            const glm::dvec3 u = surface.point(surface.vertex(SlideSurface::next(edge))) - E0;
            const glm::dvec3 toW = surface.point(surface.vertex(wCorner)) - E0;
            const double edgeLength2 = glm::dot(u, u);
            const glm::dvec2 along = e1 - e0;
            const double alongLength = glm::length(along);
            if (!(edgeLength2 > 0.0) || !(alongLength > 0.0)) return onEdge(edge, mu, Stop::Boundary);
            const double t = glm::dot(toW, u) / edgeLength2;
            const double h = glm::length(glm::cross(toW, u)) / std::sqrt(edgeLength2);
            const glm::dvec2 cw = e0 + t * along + (h / alongLength) * glm::dvec2(along.y, -along.x);
            const glm::dvec2 cEntry = e1, cNext = e0;  // vertex(entry), vertex(next(entry))
            if (barycentric(cEntry, cNext, cw, target, bary) &&
                glm::all(glm::greaterThanEqual(bary, glm::dvec3(-1e-12)))) {
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

    glm::dvec3 cagePoint(const Landing& landing) const {
        const int32_t t = landing.triangle;
        return landing.barycentric.x * surface.point(surface.vertex(3 * t)) +
               landing.barycentric.y * surface.point(surface.vertex(3 * t + 1)) +
               landing.barycentric.z * surface.point(surface.vertex(3 * t + 2));
    }

    glm::dvec3 limitPoint(const Landing& landing) const {
        const int32_t t = landing.triangle;
        const int32_t f = surface.face(t);
        const int32_t count = mesh.faceCounts()[f];
        const int32_t offset = mesh.faceOffsets()[f];
        constexpr int32_t kInline = 32;
        std::array<double, kInline> inlineWeights{};
        std::vector<double> heapWeights;  // only for polygons of more than kInline corners
        std::span<double> weights(inlineWeights.data(), static_cast<size_t>(std::min(count, kInline)));
        if (count > kInline) {
            heapWeights.assign(count, 0.0);
            weights = heapWeights;
        }
        for (int k = 0; k < 3; ++k)
            weights[surface.faceCorner(3 * t + k) - offset] += landing.barycentric[k];
        return limit->evaluate(f, weights);
    }
};

Slider::Slider(const geom::Mesh& rest, std::vector<SlideHandle> handles, const SlideOptions& options,
               const std::string& source) {
    if (handles.empty())
        throw InvalidInput(formatError(source, "slide", "no handle", "at least one handle vertex"));
    if (options.maxWalkTriangles < 1) {
        throw InvalidInput(
            formatError(source, "maxWalkTriangles", std::to_string(options.maxWalkTriangles), "at least 1"));
    }
    const geom::ManifoldReport& report = rest.halfEdges().report();
    for (size_t h = 0; h < handles.size(); ++h) {
        const SlideHandle& handle = handles[h];
        const std::string element =
            "handle " + std::to_string(h) + " (vertex " + std::to_string(handle.vertex) + ")";
        if (handle.vertex < 0 || handle.vertex >= rest.numVertices()) {
            throw InvalidInput(formatError(source, element, "vertex index out of range",
                                           "a vertex in [0, " + std::to_string(rest.numVertices()) + ")"));
        }
        if (!std::isfinite(handle.radius) || !(handle.radius > 0.0)) {
            throw InvalidInput(formatError(source, element, "radius " + std::to_string(handle.radius),
                                           "a finite radius > 0"));
        }
        if (std::binary_search(report.isolatedVertices.begin(), report.isolatedVertices.end(),
                               handle.vertex) ||
            std::find(report.isolatedVertices.begin(), report.isolatedVertices.end(), handle.vertex) !=
                report.isolatedVertices.end()) {
            throw InvalidInput(formatError(source, element, "no face uses this vertex",
                                           "a handle on the surface (a vertex of at least one face)"));
        }
        bool nonManifold = std::find(report.nonManifoldVertices.begin(), report.nonManifoldVertices.end(),
                                     handle.vertex) != report.nonManifoldVertices.end();
        for (int32_t e : report.nonManifoldEdges) {
            const auto ends = rest.halfEdges().edgeVertices(e);
            nonManifold = nonManifold || ends[0] == handle.vertex || ends[1] == handle.vertex;
        }
        if (nonManifold) {
            throw TopologyError(formatError(source, element, "the handle vertex is non-manifold",
                                            "a vertex whose faces form one fan"));
        }
    }

    impl_ = std::make_unique<Impl>(rest, std::move(handles), options, source);
    Impl& m = *impl_;
    for (const SlideHandle& handle : m.handles) {
        if (!m.surface.hasFrame(handle.vertex)) {
            throw InvalidInput(formatError(source, "handle vertex " + std::to_string(handle.vertex),
                                           "every face around the handle is degenerate (zero area)",
                                           "a handle with a tangent plane"));
        }
        m.regions.push_back(
            buildSupportRegion(m.surface, m.mesh, handle.vertex, handle.radius, handle.region));
    }

    std::vector<int32_t> slotOf(m.surface.numVertices(), -1);
    for (const SupportRegion& region : m.regions) {
        for (int32_t v : region.vertices)
            slotOf[v] = 0;
    }
    for (int32_t v = 0; v < m.surface.numVertices(); ++v) {
        if (slotOf[v] == 0) {
            slotOf[v] = static_cast<int32_t>(m.active.size());
            m.active.push_back(v);
        }
    }
    for (const SupportRegion& region : m.regions) {
        std::vector<int32_t> slots(region.vertices.size());
        for (size_t k = 0; k < slots.size(); ++k)
            slots[k] = slotOf[region.vertices[k]];
        m.regionSlots.push_back(std::move(slots));
    }
    m.ringOffsets.resize(m.active.size() + 1, 0);
    m.interior.resize(m.active.size());
    for (size_t i = 0; i < m.active.size(); ++i) {
        m.ringOffsets[i + 1] =
            m.ringOffsets[i] + static_cast<int32_t>(m.surface.vertexCorners(m.active[i]).size());
    }
    m.ringNext.resize(m.ringOffsets.back());
    m.ringPrev.resize(m.ringOffsets.back());
    {
        const auto count = static_cast<int32_t>(m.active.size());
#pragma omp parallel for schedule(static)
        for (int32_t i = 0; i < count; ++i) {
            const int32_t v = m.active[i];
            const auto corners = m.surface.vertexCorners(v);
            m.interior[i] = m.isInteriorVertex(v) ? 1 : 0;
            for (size_t k = 0; k < corners.size(); ++k) {
                m.ringNext[m.ringOffsets[i] + k] =
                    expMap(m.surface, v, m.surface.vertex(SlideSurface::next(corners[k])));
                m.ringPrev[m.ringOffsets[i] + k] =
                    expMap(m.surface, v, m.surface.vertex(SlideSurface::prev(corners[k])));
            }
        }
    }
    m.displacement.resize(m.active.size());
    m.landings.resize(m.active.size());

    std::vector<uint8_t> counted(m.surface.numTriangles(), 0);
    for (int32_t v : m.active) {
        for (int32_t c : m.surface.vertexCorners(v)) {
            const int32_t t = SlideSurface::triangleOf(c);
            if (m.surface.isDegenerate(t) && !counted[t]) {
                counted[t] = 1;
                ++m.degenerateTriangles;
            }
        }
    }

    if (options.surface == SurfaceMode::Limit) {
        m.limit = std::make_unique<geom::LimitSurface>(rest, geom::LimitSurfaceOptions{}, source);
        m.limitOrigin.resize(m.active.size());
        const auto count = static_cast<int32_t>(m.active.size());
#pragma omp parallel for schedule(static)
        for (int32_t i = 0; i < count; ++i) {
            const int32_t v = m.active[i];
            // The limit point under the vertex, taken through the same face evaluation as its landings so
            // that a vanishing slide moves it by a vanishing amount.
            const int32_t c = m.surface.vertexCorners(v)[0];
            Landing atVertex = onEdge(c, 0.0, Stop::Reached);
            m.limitOrigin[i] = m.limitPoint(atVertex);
        }
    }
}

Slider::~Slider() = default;
Slider::Slider(Slider&&) noexcept = default;
Slider& Slider::operator=(Slider&&) noexcept = default;

int32_t Slider::numVertices() const {
    return impl_->surface.numVertices();
}
int32_t Slider::numHandles() const {
    return static_cast<int32_t>(impl_->handles.size());
}
const std::vector<SlideHandle>& Slider::handles() const {
    return impl_->handles;
}
const SupportRegion& Slider::region(int32_t handle) const {
    return impl_->regions.at(handle);
}
std::span<const int32_t> Slider::activeVertices() const {
    return impl_->active;
}

void Slider::evaluate(std::span<const SlideDrive> drives, std::span<glm::vec3> points,
                      std::span<const float> weights, float envelope, SlideResult* result) {
    Impl& m = *impl_;
    const std::lock_guard<std::mutex> lock(m.mutex);
    const int32_t nv = m.surface.numVertices();
    if (drives.size() != m.handles.size()) {
        throw InvalidInput(formatError(m.source, "slide drives", std::to_string(drives.size()) + " given",
                                       std::to_string(m.handles.size()) + ", one per handle"));
    }
    for (size_t h = 0; h < drives.size(); ++h) {
        const glm::dvec3& d = drives[h].displacement;
        if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) {
            throw InvalidInput(formatError(m.source, "handle " + std::to_string(h) + " displacement",
                                           "not finite", "finite x, y, z"));
        }
    }
    if (points.size() != static_cast<size_t>(nv)) {
        throw InvalidInput(formatError(m.source, "points", std::to_string(points.size()) + " given",
                                       std::to_string(nv) + ", one per vertex"));
    }
    if (!weights.empty() && weights.size() != static_cast<size_t>(nv)) {
        throw InvalidInput(formatError(m.source, "weights", std::to_string(weights.size()) + " given",
                                       std::to_string(nv) + ", one per vertex"));
    }
    for (size_t i = 0; i < weights.size(); ++i) {
        if (!std::isfinite(weights[i])) {
            throw InvalidInput(formatError(m.source, "weight of vertex " + std::to_string(i), "not finite",
                                           "a finite weight, normally in [0, 1]"));
        }
    }
    if (!std::isfinite(envelope)) {
        throw InvalidInput(
            formatError(m.source, "envelope", "not finite", "a finite envelope, normally in [0, 1]"));
    }

    // Eq. 5-7: every handle's (s, t) carried by its region basis, summed per vertex.
    std::fill(m.displacement.begin(), m.displacement.end(), glm::dvec2(0.0));
    for (size_t h = 0; h < m.regions.size(); ++h) {
        const SupportRegion& region = m.regions[h];
        const std::vector<int32_t>& slots = m.regionSlots[h];
        const double s = glm::dot(drives[h].displacement, region.a1);
        const double t = glm::dot(drives[h].displacement, region.a2);
        const Falloff& falloff = drives[h].falloff;
        const auto count = static_cast<int32_t>(region.vertices.size());
#pragma omp parallel for schedule(static)
        for (int32_t k = 0; k < count; ++k) {
            const double f = falloff(region.normalizedDistance[k]);
            if (f != 0.0) m.displacement[slots[k]] += f * (s * region.a1Local[k] + t * region.a2Local[k]);
        }
    }

    const auto count = static_cast<int32_t>(m.active.size());
    int32_t moved = 0, boundaryStopped = 0, limitStopped = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : moved, boundaryStopped, limitStopped)
    for (int32_t i = 0; i < count; ++i) {
        const int32_t v = m.active[i];
        const double scale =
            (weights.empty() ? 1.0 : static_cast<double>(weights[v])) * static_cast<double>(envelope);
        const glm::dvec2 target = m.displacement[i] * scale;
        Landing& landing = m.landings[i];
        landing = Landing{};
        if (target.x == 0.0 && target.y == 0.0) continue;
        landing = m.walk(i, v, target);
        ++moved;
        boundaryStopped += landing.stop == Stop::Boundary ? 1 : 0;
        limitStopped += landing.stop == Stop::Limit ? 1 : 0;
        const glm::dvec3 offset =
            m.limit ? m.limitPoint(landing) - m.limitOrigin[i] : m.cagePoint(landing) - m.surface.point(v);
        points[v] = glm::vec3(glm::dvec3(points[v]) + offset);
    }

    if (result) {
        result->landings.clear();
        for (int32_t i = 0; i < count; ++i) {
            const Landing& landing = m.landings[i];
            if (landing.stop == Stop::None) continue;
            SlideLanding out;
            out.vertex = m.active[i];
            out.face = m.surface.face(landing.triangle);
            for (int k = 0; k < 3; ++k) {
                out.triangle[k] = m.surface.vertex(3 * landing.triangle + k);
                out.barycentric[k] = landing.barycentric[k];
            }
            result->landings.push_back(out);
        }
        result->moved = moved;
        result->boundaryStopped = boundaryStopped;
        result->limitStopped = limitStopped;
        result->unreachable = 0;
        result->withoutTangentPlane = 0;
        for (const SupportRegion& region : m.regions) {
            result->unreachable += region.unreachable;
            result->withoutTangentPlane += region.withoutTangentPlane;
        }
        result->degenerateTriangles = m.degenerateTriangles;
    }
}

std::vector<glm::vec3> slide(const geom::Mesh& mesh, std::span<const SlideHandle> handles,
                             std::span<const SlideDrive> drives, std::span<const float> weights,
                             float envelope, const SlideOptions& options, SlideResult* result) {
    Slider slider(mesh, std::vector<SlideHandle>(handles.begin(), handles.end()), options);
    std::vector<glm::vec3> points(mesh.points().begin(), mesh.points().end());
    slider.evaluate(drives, points, weights, envelope, result);
    return points;
}

}  // namespace deformkit::slide
