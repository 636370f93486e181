#include "deformkit/slide/slider.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include <Eigen/LU>
#include <Eigen/SVD>
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

// The Catmull-Clark limit surface over the part of the mesh the slide can reach: the faces landings may
// fall on ("covered") and every face sharing a vertex with them, so that the patches of covered faces see
// their whole one-ring and equal those of the whole mesh. Grows when a landing leaves the covered faces.
struct LocalLimit {
    std::vector<int32_t> vertexFaceOffsets, vertexFaces;  // the mesh's faces at each vertex (CSR)
    std::vector<uint8_t> covered;                         // per mesh face
    std::vector<int32_t> localFace;                       // per mesh face: its face in the part, or -1
    std::vector<int32_t> vertices;                        // the part's vertices (mesh indices), ascending
    std::vector<int32_t> localVertex;                     // per mesh vertex: its vertex in the part, or -1
    std::unique_ptr<geom::LimitSurface> rest;             // over the rest positions
    std::unique_ptr<geom::LimitSurface> incoming;         // over the last incoming positions
    std::vector<glm::vec3> incomingCage;                  // those positions, per part vertex
    const geom::LimitSurface* current = nullptr;          // rest or incoming, for this evaluation
};

}  // namespace detail
using detail::Landing;
using detail::Stop;

namespace {

// Loops over fewer items than this run on the calling thread: waking a second thread costs more than the
// work (a 500-vertex slide takes ~0.2 ms), and far more when the other core is busy (a host's own threads).
constexpr int32_t kParallelFrom = 4096;

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
    std::vector<int32_t> slotOf;                    // per vertex: its slot in `active`, -1 when inactive
    std::vector<glm::dvec3> slid;                   // per slot: the slid position, scratch
    std::vector<glm::dvec3> restDisplacement;       // per handle: its displacement in its rest frame, scratch
    std::vector<double> scales;                     // per handle: its fold-limit scale, scratch
    // Triangles with an active corner (not degenerate at rest), ascending: where folds are counted. Per
    // handle: the triangles with a corner in its region.
    std::vector<int32_t> regionTriangles;
    std::vector<std::vector<int32_t>> handleTriangles;
    std::unique_ptr<detail::LocalLimit> limit;
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
            // Strictly inside the sector: a direction along one of its edges (a slide along a ring of edges
            // or a boundary) is turned a hair (1e-9 of the sector's angle) into it, so the line passes
            // beside the edge's far vertex on the sector's side, as the walk below assumes (its first exit
            // edge, a -> b, has a on the right and b on the left).
            constexpr double kInside = 1e-9;
            const double share =
                mapAngle > 0.0 ? std::clamp(std::atan2(cross2(ca, inMap), glm::dot(ca, inMap)) / mapAngle,
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
            if (isLeft(e0) || !isLeft(e1)) return onEdge(edge, mu, Stop::Limit);
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
        return limit->current->evaluate(limit->localFace[f], weights);
    }

    // The limit point under vertex v, taken through the same face evaluation as its landings so that a
    // vanishing slide moves it by a vanishing amount.
    glm::dvec3 limitOrigin(int32_t v) const {
        return limitPoint(onEdge(surface.vertexCorners(v)[0], 0.0, Stop::Reached));
    }

    // (Re)builds the limit surface of the covered faces and their one-ring of faces.
    void buildLocalLimit() {
        detail::LocalLimit& L = *limit;
        std::vector<uint8_t> inPart(L.covered.size(), 0);
        for (size_t f = 0; f < L.covered.size(); ++f) {
            if (!L.covered[f]) continue;
            for (int32_t v : mesh.face(static_cast<int32_t>(f))) {
                for (int32_t k = L.vertexFaceOffsets[v]; k < L.vertexFaceOffsets[v + 1]; ++k)
                    inPart[L.vertexFaces[k]] = 1;
            }
        }
        geom::Mesh::Data data;
        std::fill(L.localFace.begin(), L.localFace.end(), -1);
        std::fill(L.localVertex.begin(), L.localVertex.end(), -1);
        L.vertices.clear();
        for (size_t f = 0; f < inPart.size(); ++f) {
            if (!inPart[f]) continue;
            L.localFace[f] = static_cast<int32_t>(data.faceCounts.size());
            const auto corners = mesh.face(static_cast<int32_t>(f));
            data.faceCounts.push_back(static_cast<int32_t>(corners.size()));
            for (int32_t v : corners) {
                data.faceIndices.push_back(v);
                L.localVertex[v] = 0;
            }
        }
        // Vertices in ascending mesh order, so a face's neighbourhood is ordered alike in every part that
        // holds it: its limit patch comes out bit for bit the same however far the part has grown.
        for (int32_t v = 0; v < mesh.numVertices(); ++v) {
            if (L.localVertex[v] < 0) continue;
            L.localVertex[v] = static_cast<int32_t>(L.vertices.size());
            L.vertices.push_back(v);
            data.points.push_back(mesh.points()[v]);
        }
        for (int32_t& v : data.faceIndices)
            v = L.localVertex[v];
        geom::LimitSurfaceOptions options;
        options.deformable = true;
        for (size_t f = 0; f < inPart.size(); ++f) {  // the one-ring faces only support the covered ones
            if (inPart[f] && !L.covered[f]) options.holes.push_back(L.localFace[f]);
        }
        L.rest = std::make_unique<geom::LimitSurface>(geom::Mesh(std::move(data), source), options, source);
        L.incoming.reset();
        L.incomingCage.clear();
        L.current = L.rest.get();
    }

    void bindLimit() {
        limit = std::make_unique<detail::LocalLimit>();
        detail::LocalLimit& L = *limit;
        const int32_t nv = mesh.numVertices(), nf = mesh.numFaces();
        L.vertexFaceOffsets.assign(nv + 1, 0);
        for (int32_t v : mesh.faceIndices())
            ++L.vertexFaceOffsets[v + 1];
        for (int32_t v = 0; v < nv; ++v)
            L.vertexFaceOffsets[v + 1] += L.vertexFaceOffsets[v];
        L.vertexFaces.resize(mesh.faceIndices().size());
        std::vector<int32_t> fill(L.vertexFaceOffsets.begin(), L.vertexFaceOffsets.end() - 1);
        for (int32_t f = 0; f < nf; ++f) {
            for (int32_t v : mesh.face(f))
                L.vertexFaces[fill[v]++] = f;
        }
        L.covered.assign(nf, 0);
        L.localFace.assign(nf, -1);
        L.localVertex.assign(nv, -1);
        for (int32_t v : active) {
            for (int32_t k = L.vertexFaceOffsets[v]; k < L.vertexFaceOffsets[v + 1]; ++k)
                L.covered[L.vertexFaces[k]] = 1;
        }
        buildLocalLimit();
    }

    // Makes every landing's face covered, growing the limit part when one is not; true when it grew.
    bool coverLandings() {
        bool grew = false;
        for (const Landing& landing : landings) {
            if (landing.stop == Stop::None) continue;
            const int32_t f = surface.face(landing.triangle);
            if (!limit->covered[f]) {
                limit->covered[f] = 1;
                grew = true;
            }
        }
        if (grew) buildLocalLimit();
        return grew;
    }

    // The limit surface over the incoming positions: the rest one when they equal the rest positions on
    // the part, the last one when they have not changed since.
    void prepareLimit(std::span<const glm::vec3> in) {
        detail::LocalLimit& L = *limit;
        bool atRest = true;
        for (int32_t v : L.vertices)
            atRest = atRest && in[v] == mesh.points()[v];
        if (atRest) {
            L.current = L.rest.get();
            return;
        }
        bool same = L.incoming && L.incomingCage.size() == L.vertices.size();
        for (size_t i = 0; same && i < L.vertices.size(); ++i)
            same = L.incomingCage[i] == in[L.vertices[i]];
        if (!same) {
            L.incomingCage.resize(L.vertices.size());
            for (size_t i = 0; i < L.vertices.size(); ++i)
                L.incomingCage[i] = in[L.vertices[i]];
            L.incoming = std::make_unique<geom::LimitSurface>(L.rest->withPoints(L.incomingCage));
        }
        L.current = L.incoming.get();
    }

    // A drag given in the incoming space, carried back into handle h's rest frame: through the inverse of
    // the linear map that best takes the handle's rest one-ring edges and normal (scaled to the ring) onto
    // the incoming ones (least squares), so the handle follows the locator on a stretched or compressed
    // input; for a ring moved rigidly by (R, t) that map is R, up to rounding. Where the incoming ring has
    // collapsed (the map is not invertible) the best rotation (Kabsch) of the same data is used instead.
    // The identity when the ring did not move.
    glm::dvec3 toRestFrame(size_t h, std::span<const glm::vec3> in, const glm::dvec3& d) const {
        const int32_t p = handles[h].vertex;
        bool moved = in[p] != mesh.points()[p];
        for (int32_t q : surface.neighbors(p))
            moved = moved || in[q] != mesh.points()[q];
        if (!moved) return d;
        const glm::dvec3 p0 = surface.point(p), p1(in[p]);
        auto column = [](const glm::dvec3& v) { return Eigen::Vector3d(v.x, v.y, v.z); };
        Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();  // sum of incoming x rest^T
        Eigen::Matrix3d gram = Eigen::Matrix3d::Zero();   // sum of rest x rest^T
        double scale2 = 0.0;
        for (int32_t q : surface.neighbors(p)) {
            const glm::dvec3 e = surface.point(q) - p0, f = glm::dvec3(in[q]) - p1;
            cross += column(f) * column(e).transpose();
            gram += column(e) * column(e).transpose();
            scale2 += glm::dot(e, e);
        }
        glm::dvec3 normal(0.0);  // area-weighted incoming normal
        for (int32_t c : surface.vertexCorners(p)) {
            const glm::dvec3 a(in[surface.vertex(c)]), b(in[surface.vertex(SlideSurface::next(c))]),
                e(in[surface.vertex(SlideSurface::prev(c))]);
            normal += glm::cross(b - a, e - a);
        }
        const double length = glm::length(normal);
        const double ring = std::sqrt(scale2 / static_cast<double>(surface.neighbors(p).size()));
        if (length > 0.0) {
            const Eigen::Vector3d n0 = column(surface.normal(p)) * ring, n1 = column(normal / length) * ring;
            cross += n1 * n0.transpose();
            gram += n0 * n0.transpose();
        }
        const Eigen::Vector3d v = column(d);
        Eigen::Vector3d out;
        const Eigen::Matrix3d map = cross * gram.inverse();  // gram is positive definite: the ring spans
        const double det = map.determinant();
        if (std::isfinite(det) && det > 1e-6) {
            out = map.inverse() * v;
        } else {
            const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
            Eigen::Matrix3d U = svd.matrixU();
            if ((U * svd.matrixV().transpose()).determinant() < 0.0) U.col(2) = -U.col(2);
            out = (U * svd.matrixV().transpose()).transpose() * v;
        }
        return {out.x(), out.y(), out.z()};
    }

    struct Counts {
        int32_t moved = 0, boundaryStopped = 0, limitStopped = 0;
    };

    // One slide: the tangent displacements of every handle's rest-frame displacement times its scale
    // (Eq. 5-7), the walks, and the slid position of every moved vertex over the incoming points `in`.
    Counts slideOnce(std::span<const glm::dvec3> restDisplacement, std::span<const double> scales,
                     std::span<const SlideDrive> drives, std::span<const glm::vec3> in,
                     std::span<const float> weights, double envelope) {
        std::fill(displacement.begin(), displacement.end(), glm::dvec2(0.0));
        for (size_t h = 0; h < regions.size(); ++h) {
            if (scales[h] == 0.0) continue;
            const SupportRegion& region = regions[h];
            const std::vector<int32_t>& slots = regionSlots[h];
            const double s = scales[h] * glm::dot(restDisplacement[h], region.a1);
            const double t = scales[h] * glm::dot(restDisplacement[h], region.a2);
            const Falloff& falloff = drives[h].falloff;
            const bool painted = options.weights == PaintedWeights::AreFalloff;
            const auto count = static_cast<int32_t>(region.vertices.size());
#pragma omp parallel for schedule(static) if (count >= kParallelFrom)
            for (int32_t k = 0; k < count; ++k) {
                const double f = painted ? 1.0 : falloff(region.normalizedDistance[k]);
                if (f != 0.0) displacement[slots[k]] += f * (s * region.a1Local[k] + t * region.a2Local[k]);
            }
        }

        const auto count = static_cast<int32_t>(active.size());
        Counts counts;
        int32_t moved = 0, boundaryStopped = 0, limitStopped = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : moved, boundaryStopped, limitStopped) if (count >= kParallelFrom)
        for (int32_t i = 0; i < count; ++i) {
            const int32_t v = active[i];
            const double scale = (weights.empty() ? 1.0 : static_cast<double>(weights[v])) * envelope;
            const glm::dvec2 target = displacement[i] * scale;
            Landing& landing = landings[i];
            landing = Landing{};
            if (target.x == 0.0 && target.y == 0.0) continue;
            landing = walk(i, v, target);
            ++moved;
            boundaryStopped += landing.stop == Stop::Boundary ? 1 : 0;
            limitStopped += landing.stop == Stop::Limit ? 1 : 0;
            if (!limit) {  // on the cage: the landing's combination of the incoming corners
                const int32_t t = landing.triangle;
                slid[i] = landing.barycentric.x * glm::dvec3(in[surface.vertex(3 * t)]) +
                          landing.barycentric.y * glm::dvec3(in[surface.vertex(3 * t + 1)]) +
                          landing.barycentric.z * glm::dvec3(in[surface.vertex(3 * t + 2)]);
            }
        }
        counts = {moved, boundaryStopped, limitStopped};
        if (!limit) return counts;

        // On the limit surface: once every landing's face is in the part, the incoming limit surface's
        // offset from the point under the vertex to the point under its landing.
        coverLandings();
        prepareLimit(in);
#pragma omp parallel for schedule(dynamic, 256) if (count >= kParallelFrom)
        for (int32_t i = 0; i < count; ++i) {
            const Landing& landing = landings[i];
            if (landing.stop == Stop::None) continue;
            const int32_t v = active[i];
            slid[i] = glm::dvec3(in[v]) + (limitPoint(landing) - limitOrigin(v));
        }
        return counts;
    }

    glm::dvec3 slidPoint(int32_t v, std::span<const glm::vec3> in) const {
        const int32_t i = slotOf[v];
        return i >= 0 && landings[i].stop != Stop::None ? glm::vec3(slid[i]) : in[v];
    }

    // Triangles of `triangles` whose orientation after the slide opposes the incoming one.
    int32_t countFlips(std::span<const int32_t> triangles, std::span<const glm::vec3> in) const {
        const auto count = static_cast<int32_t>(triangles.size());
        int32_t flipped = 0;
#pragma omp parallel for schedule(static) reduction(+ : flipped) if (count >= kParallelFrom)
        for (int32_t k = 0; k < count; ++k) {
            const int32_t t = triangles[k];
            const int32_t a = surface.vertex(3 * t), b = surface.vertex(3 * t + 1),
                          c = surface.vertex(3 * t + 2);
            const glm::dvec3 before =
                glm::cross(glm::dvec3(in[b]) - glm::dvec3(in[a]), glm::dvec3(in[c]) - glm::dvec3(in[a]));
            const glm::dvec3 pa = slidPoint(a, in);
            const glm::dvec3 after = glm::cross(slidPoint(b, in) - pa, slidPoint(c, in) - pa);
            if (glm::dot(before, before) > 0.0 && glm::dot(before, after) <= 0.0) ++flipped;
        }
        return flipped;
    }

    // The largest scale in [0, 1] (to 2^-kSteps) at which slideOnce with scales `base` times it flips no
    // triangle of `triangles`; 0 moves nothing, so it never flips.
    double foldLimitScale(std::span<const glm::dvec3> restDisplacement, std::vector<double> base,
                          std::span<const int32_t> triangles, std::span<const SlideDrive> drives,
                          std::span<const glm::vec3> in, std::span<const float> weights, double envelope) {
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

    m.slid.resize(m.active.size());
    m.slotOf = std::move(slotOf);
    {
        std::vector<uint8_t> inRegion(m.surface.numTriangles(), 0);
        for (const SupportRegion& region : m.regions) {
            std::vector<int32_t> triangles;
            for (int32_t v : region.vertices) {
                for (int32_t c : m.surface.vertexCorners(v)) {
                    const int32_t t = SlideSurface::triangleOf(c);
                    if (!m.surface.isDegenerate(t)) triangles.push_back(t);
                }
            }
            std::sort(triangles.begin(), triangles.end());
            triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
            for (int32_t t : triangles)
                inRegion[t] = 1;
            m.handleTriangles.push_back(std::move(triangles));
        }
        for (int32_t t = 0; t < m.surface.numTriangles(); ++t) {
            if (inRegion[t]) m.regionTriangles.push_back(t);
        }
    }

    if (options.surface == SurfaceMode::Limit) m.bindLimit();
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

    // The incoming points the slide reads: the active vertices and the handles' rings (landings outside
    // them pass a non-finite corner on as any deformer does). Read in place: nothing is written until the
    // end.
    const std::span<const glm::vec3> in(points.data(), points.size());
    auto requireFinite = [&](int32_t v) {
        const glm::vec3& p = in[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            throw InvalidInput(formatError(m.source, "point of vertex " + std::to_string(v), "not finite",
                                           "finite x, y, z"));
        }
    };
    for (int32_t v : m.active)
        requireFinite(v);
    for (const SlideHandle& handle : m.handles) {
        for (int32_t q : m.surface.neighbors(handle.vertex))
            requireFinite(q);
    }

    // Each handle's displacement in its rest frame.
    // (Scratch kept in the slider: a warm evaluation allocates nothing.)
    std::vector<glm::dvec3>& restDisplacement = m.restDisplacement;
    restDisplacement.resize(drives.size());
    for (size_t h = 0; h < drives.size(); ++h)
        restDisplacement[h] = m.toRestFrame(h, in, drives[h].displacement);

    const auto numHandles = m.handles.size();
    std::vector<double>& scales = m.scales;
    scales.assign(numHandles, 1.0);
    Impl::Counts counts = m.slideOnce(restDisplacement, scales, drives, in, weights, envelope);
    // Folds are counted when someone reads the count or the fold limit needs it (a host's evaluation in a
    // stack does neither and skips the pass over the region's triangles).
    int32_t flipped = result || m.options.foldLimit ? m.countFlips(m.regionTriangles, in) : 0;
    if (m.options.foldLimit && flipped > 0) {
        // Each handle alone first (its own region), then all together while overlapping regions still fold.
        for (size_t h = 0; h < numHandles; ++h) {
            std::vector<double> alone(numHandles, 0.0);
            alone[h] = 1.0;
            if (numHandles > 1) {
                m.slideOnce(restDisplacement, alone, drives, in, weights, envelope);
                if (m.countFlips(m.handleTriangles[h], in) == 0) continue;
            }
            scales[h] = m.foldLimitScale(restDisplacement, alone, m.handleTriangles[h], drives, in, weights,
                                         envelope);
        }
        counts = m.slideOnce(restDisplacement, scales, drives, in, weights, envelope);
        flipped = m.countFlips(m.regionTriangles, in);
        if (flipped > 0) {
            const double common =
                m.foldLimitScale(restDisplacement, scales, m.regionTriangles, drives, in, weights, envelope);
            for (double& scale : scales)
                scale *= common;
            counts = m.slideOnce(restDisplacement, scales, drives, in, weights, envelope);
            flipped = m.countFlips(m.regionTriangles, in);
        }
    }

    const auto count = static_cast<int32_t>(m.active.size());
#pragma omp parallel for schedule(static) if (count >= kParallelFrom)
    for (int32_t i = 0; i < count; ++i) {
        if (m.landings[i].stop != Stop::None) points[m.active[i]] = glm::vec3(m.slid[i]);
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
        result->moved = counts.moved;
        result->boundaryStopped = counts.boundaryStopped;
        result->limitStopped = counts.limitStopped;
        result->limited = counts.boundaryStopped + counts.limitStopped;
        result->flippedTriangles = flipped;
        result->foldScale = scales;
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
