#include "deformkit/slide/slider.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/slide/exp_map.h"
#include "slider_impl.h"

namespace deformkit::slide {

Slider::Impl::Counts Slider::Impl::slideOnce(std::span<const glm::dvec3> restDisplacement,
                                             std::span<const double> scales,
                                             std::span<const SlideDrive> drives,
                                             std::span<const glm::vec3> in, std::span<const float> weights,
                                             double envelope) {
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
#pragma omp parallel for schedule(static) if (count >= detail::kParallelFrom)
        for (int32_t k = 0; k < count; ++k) {
            const double f = painted ? 1.0 : falloff(region.normalizedDistance[k]);
            if (f != 0.0) displacement[slots[k]] += f * (s * region.a1Local[k] + t * region.a2Local[k]);
        }
    }

    const auto count = static_cast<int32_t>(active.size());
    Counts counts;
    int32_t moved = 0, boundaryStopped = 0, walkLimitStopped = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : moved, boundaryStopped, walkLimitStopped) if (count >= detail::kParallelFrom)
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
        walkLimitStopped += landing.stop == Stop::WalkLimit ? 1 : 0;
        if (!limit) {  // on the cage: the landing's combination of the incoming corners
            const int32_t t = landing.triangle;
            slid[i] = landing.barycentric.x * glm::dvec3(in[surface.vertex(3 * t)]) +
                      landing.barycentric.y * glm::dvec3(in[surface.vertex(3 * t + 1)]) +
                      landing.barycentric.z * glm::dvec3(in[surface.vertex(3 * t + 2)]);
        }
    }
    counts = {moved, boundaryStopped, walkLimitStopped};
    if (!limit) return counts;

    // On the limit surface: once every landing's face is in the part, the incoming limit surface's
    // offset from the point under the vertex to the point under its landing.
    coverLandings();
    prepareLimit(in);
#pragma omp parallel for schedule(dynamic, 256) if (count >= detail::kParallelFrom)
    for (int32_t i = 0; i < count; ++i) {
        const Landing& landing = landings[i];
        if (landing.stop == Stop::None) continue;
        const int32_t v = active[i];
        slid[i] = glm::dvec3(in[v]) + (limitPoint(landing) - limitOrigin(v));
    }
    return counts;
}

Slider::Slider(const geom::Mesh& rest, std::vector<SlideHandle> handles, const SlideOptions& options,
               const std::string& source) {
    if (handles.empty())
        throw InvalidInput(formatError(source, "slide", "no handle", "at least one handle vertex"));
    if (options.maxWalkTriangles < 1) {
        throw InvalidInput(
            formatError(source, "maxWalkTriangles", std::to_string(options.maxWalkTriangles), "at least 1"));
    }
    for (size_t h = 0; h < handles.size(); ++h) {
        const SlideHandle& handle = handles[h];
        const std::string element =
            "handle " + std::to_string(h) + " (vertex " + std::to_string(handle.vertex) + ")";
        if (handle.vertex < 0 || handle.vertex >= rest.numVertices()) {
            throw InvalidInput(formatError(source, element, "vertex index out of range",
                                           "a vertex in [0, " + std::to_string(rest.numVertices()) + ")"));
        }
        if (!std::isfinite(handle.radius) || !(handle.radius > 0.0)) {
            throw InvalidInput(
                formatError(source, element, "radius " + numberText(handle.radius), "a finite radius > 0"));
        }
    }
    // Split vertices (coincident copies, as glTF and FBX files have them) are welded: the slide binds on the
    // welded mesh and hands its results back to every copy.
    auto weld = std::make_unique<geom::Welding>(geom::weldVertices(rest, options.weldTolerance, source));
    if (weld->merged() == 0) weld.reset();
    const geom::Mesh& surfaceMesh = weld ? weld->mesh : rest;
    const std::vector<SlideHandle> fileHandles = handles;
    if (weld) {
        for (SlideHandle& handle : handles)
            handle.vertex = weld->weldedOf[static_cast<size_t>(handle.vertex)];
    }
    const geom::ManifoldReport& report = surfaceMesh.halfEdges().report();
    for (size_t h = 0; h < handles.size(); ++h) {
        const SlideHandle& handle = handles[h];
        const std::string element =
            "handle " + std::to_string(h) + " (vertex " + std::to_string(fileHandles[h].vertex) + ")";
        if (std::find(report.isolatedVertices.begin(), report.isolatedVertices.end(), handle.vertex) !=
            report.isolatedVertices.end()) {
            throw InvalidInput(formatError(source, element, "no face uses this vertex",
                                           "a handle on the surface (a vertex of at least one face)"));
        }
        bool nonManifold = std::find(report.nonManifoldVertices.begin(), report.nonManifoldVertices.end(),
                                     handle.vertex) != report.nonManifoldVertices.end();
        for (int32_t e : report.nonManifoldEdges) {
            const auto ends = surfaceMesh.halfEdges().edgeVertices(e);
            nonManifold = nonManifold || ends[0] == handle.vertex || ends[1] == handle.vertex;
        }
        if (nonManifold) {
            throw TopologyError(formatError(source, element, "the handle vertex is non-manifold",
                                            "a vertex whose faces form one fan"));
        }
    }

    impl_ = std::make_unique<Impl>(surfaceMesh, std::move(handles), options, source);
    Impl& m = *impl_;
    for (const SlideHandle& handle : m.handles) {
        if (!m.surface.hasFrame(handle.vertex)) {
            throw InvalidInput(formatError(
                source,
                "handle vertex " + std::to_string(weld ? weld->firstOf[handle.vertex] : handle.vertex),
                "every face around the handle is degenerate (zero area)", "a handle with a tangent plane"));
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
    // The result's counts, of distinct vertices: one a handle cannot reach but another's region moves is
    // not unreachable, and one in several regions counts once.
    {
        std::vector<uint8_t> seen(static_cast<size_t>(m.surface.numVertices()), 0);
        for (const SupportRegion& region : m.regions) {
            for (const int32_t v : region.unreachableVertices) {
                if (slotOf[v] >= 0 || seen[v] != 0) continue;
                seen[v] = 1;
                ++m.unreachable;
            }
            for (const int32_t v : region.verticesWithoutTangentPlane) {
                if (seen[v] == 2) continue;
                seen[v] = 2;
                ++m.withoutTangentPlane;
            }
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

    if (weld) {
        // The file's view: every copy of a welded vertex, in the welded vertex's place.
        m.fileHandles = fileHandles;
        for (const SupportRegion& region : m.regions) {
            SupportRegion file = region;
            file.handle = weld->firstOf[static_cast<size_t>(region.handle)];
            file.vertices.clear();
            file.normalizedDistance.clear();
            file.a1Local.clear();
            file.a2Local.clear();
            for (size_t k = 0; k < region.vertices.size(); ++k) {
                for (int32_t copy : weld->copiesOf(region.vertices[k])) {
                    file.vertices.push_back(copy);
                    file.normalizedDistance.push_back(region.normalizedDistance[k]);
                    file.a1Local.push_back(region.a1Local[k]);
                    file.a2Local.push_back(region.a2Local[k]);
                }
            }
            m.fileRegions.push_back(std::move(file));
        }
        for (int32_t v : m.active) {
            for (int32_t copy : weld->copiesOf(v))
                m.fileActive.push_back(copy);
        }
        std::sort(m.fileActive.begin(), m.fileActive.end());
        m.fileFaceOffsets.assign(1, 0);
        for (int32_t count : rest.faceCounts())
            m.fileFaceOffsets.push_back(m.fileFaceOffsets.back() + count);
        m.fileFaceIndices.assign(rest.faceIndices().begin(), rest.faceIndices().end());
        m.weldedPoints.resize(weld->firstOf.size());
        m.weldedIn.resize(weld->firstOf.size());
        m.weld = std::move(weld);
    }
}

Slider::~Slider() = default;
Slider::Slider(Slider&&) noexcept = default;
Slider& Slider::operator=(Slider&&) noexcept = default;

int32_t Slider::numVertices() const {
    return impl_->weld ? static_cast<int32_t>(impl_->weld->weldedOf.size()) : impl_->surface.numVertices();
}
int32_t Slider::numHandles() const {
    return static_cast<int32_t>(impl_->handles.size());
}
const std::vector<SlideHandle>& Slider::handles() const {
    return impl_->weld ? impl_->fileHandles : impl_->handles;
}
const SupportRegion& Slider::region(int32_t handle) const {
    return impl_->weld ? impl_->fileRegions.at(handle) : impl_->regions.at(handle);
}
std::span<const int32_t> Slider::activeVertices() const {
    return impl_->weld ? impl_->fileActive : impl_->active;
}
int32_t Slider::weldedVertices() const {
    return impl_->weld ? impl_->weld->merged() : 0;
}

void Slider::evaluate(std::span<const SlideDrive> drives, std::span<glm::vec3> points,
                      std::span<const float> weights, double envelope, SlideResult* result) {
    Impl& m = *impl_;
    const std::lock_guard<std::mutex> lock(m.mutex);
    if (!m.weld) {
        m.evaluateSurface(drives, points, weights, envelope, result);
        if (result) result->welded = 0;
        return;
    }
    const geom::Welding& weld = *m.weld;
    m.requireCounts(static_cast<int32_t>(weld.weldedOf.size()), points.size(), weights.size());
    // The copies the slide reads must be finite, named by their file index (the welded vertex reads its first
    // copy; the others follow it).
    const auto requireFinite = [&](int32_t v) {
        const glm::vec3& p = points[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            throw InvalidInput(formatError(m.source, "point of vertex " + std::to_string(v), "not finite",
                                           "finite x, y, z"));
        }
    };
    for (int32_t v : m.fileActive)
        requireFinite(v);
    for (const SlideHandle& handle : m.handles) {  // the handles' rings, as read: their first copies
        for (int32_t q : m.surface.neighbors(handle.vertex))
            requireFinite(weld.firstOf[static_cast<size_t>(q)]);
    }
    for (size_t w = 0; w < weld.firstOf.size(); ++w)
        m.weldedIn[w] = m.weldedPoints[w] = points[static_cast<size_t>(weld.firstOf[w])];
    // Every file vertex's weight is checked, named by its file index; a welded vertex takes the mean of its
    // copies' weights (equal where a DCC painted the one vertex they split from).
    std::span<const float> weldedWeights;
    if (!weights.empty()) {
        for (size_t i = 0; i < weights.size(); ++i) {
            if (!std::isfinite(weights[i])) {
                throw InvalidInput(formatError(m.source, "weight of vertex " + std::to_string(i),
                                               "not finite", "a finite weight, normally in [0, 1]"));
            }
        }
        m.weldedWeights.resize(weld.firstOf.size());
        for (size_t w = 0; w < weld.firstOf.size(); ++w) {
            double sum = 0.0;
            const auto copies = weld.copiesOf(static_cast<int32_t>(w));
            for (const int32_t copy : copies)
                sum += weights[static_cast<size_t>(copy)];
            m.weldedWeights[w] = static_cast<float>(sum / static_cast<double>(copies.size()));
        }
        weldedWeights = m.weldedWeights;
    }
    m.evaluateSurface(drives, m.weldedPoints, weldedWeights, envelope, result);
    // Every copy of a moved vertex moves as it does: to the same position when it came in at the first
    // copy's position, by the same displacement otherwise (a tolerance weld).
    for (int32_t w : m.active) {
        const glm::vec3 in = m.weldedIn[w], out = m.weldedPoints[w];
        if (in == out) continue;
        for (int32_t copy : weld.copiesOf(w)) {
            glm::vec3& p = points[static_cast<size_t>(copy)];
            p = p == in ? out : p + (out - in);
        }
    }
    if (result) {
        // Landings per file vertex, on the file's faces and their corners' file vertices.
        std::vector<SlideLanding> landings;
        for (const SlideLanding& landing : result->landings) {
            const int32_t fileFace = weld.fileFaceOf[static_cast<size_t>(landing.face)];
            for (int32_t copy : weld.copiesOf(landing.vertex)) {
                SlideLanding out = landing;
                out.vertex = copy;
                out.face = fileFace;
                for (int k = 0; k < 3; ++k)
                    out.triangle[k] = m.fileCornerVertex(fileFace, landing.triangle[k]);
                landings.push_back(out);
            }
        }
        std::sort(landings.begin(), landings.end(),
                  [](const SlideLanding& a, const SlideLanding& b) { return a.vertex < b.vertex; });
        result->landings = std::move(landings);
        result->welded = weld.merged();
    }
}

void Slider::Impl::requireCounts(int32_t vertices, size_t points, size_t weights) const {
    if (points != static_cast<size_t>(vertices)) {
        throw InvalidInput(formatError(source, "points", std::to_string(points) + " given",
                                       std::to_string(vertices) + ", one per vertex"));
    }
    if (weights != 0 && weights != static_cast<size_t>(vertices)) {
        throw InvalidInput(formatError(source, "weights", std::to_string(weights) + " given",
                                       std::to_string(vertices) + ", one per vertex"));
    }
}

void Slider::Impl::evaluateSurface(std::span<const SlideDrive> drives, std::span<glm::vec3> points,
                                   std::span<const float> weights, double envelope, SlideResult* result) {
    Impl& m = *this;
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
        // Within float range, as every position is (the walk squares lengths in double).
        constexpr float kLargest = std::numeric_limits<float>::max();
        const double length = std::hypot(d.x, d.y, d.z);  // without squaring past double's range
        if (!(length <= kLargest)) {
            throw InvalidInput(formatError(
                m.source, "handle " + std::to_string(h) + " displacement", "has length " + numberText(length),
                "a length within float range (at most " + numberText(kLargest) + " scene units)"));
        }
    }
    m.requireCounts(nv, points.size(), weights.size());
    for (size_t i = 0; i < weights.size(); ++i) {
        if (!std::isfinite(weights[i])) {
            throw InvalidInput(formatError(m.source, "weight of vertex " + std::to_string(i), "not finite",
                                           "a finite weight, normally in [0, 1]"));
        }
    }
    if (!std::isfinite(envelope) || std::abs(envelope) > std::numeric_limits<float>::max()) {
        throw InvalidInput(formatError(m.source, "envelope", "is " + numberText(envelope),
                                       "a finite envelope within float range, normally in [0, 1]"));
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
    if (m.options.foldLimit && flipped > 0)
        counts = m.limitFolds(restDisplacement, scales, drives, in, weights, envelope, flipped);

    const auto count = static_cast<int32_t>(m.active.size());
    if (m.options.surface != SurfaceMode::Limit) {
        // On the cage a landed point is its triangle's combination of the incoming corners: a corner outside
        // the points checked above that is not finite would make a finite vertex not finite. Named by file
        // index (a welded vertex by its first copy), the first landing in order whatever the schedule.
        const auto fileIndex = [&](int32_t q) {
            return m.weld ? m.weld->firstOf[static_cast<size_t>(q)] : q;
        };
        for (int32_t i = 0; i < count; ++i) {
            const detail::Landing& landing = m.landings[i];
            if (landing.stop == detail::Stop::None) continue;
            for (int k = 0; k < 3; ++k) {
                const int32_t q = m.surface.vertex(3 * landing.triangle + k);
                const glm::vec3& p = in[q];
                if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) continue;
                throw InvalidInput(formatError(m.source, "point of vertex " + std::to_string(fileIndex(q)),
                                               "not finite",
                                               "finite x, y, z: a corner of the triangle vertex " +
                                                   std::to_string(fileIndex(m.active[i])) + " lands on"));
            }
        }
    }
#pragma omp parallel for schedule(static) if (count >= detail::kParallelFrom)
    for (int32_t i = 0; i < count; ++i) {
        if (m.landings[i].stop != detail::Stop::None) points[m.active[i]] = glm::vec3(m.slid[i]);
    }

    if (result) {
        result->landings.clear();
        for (int32_t i = 0; i < count; ++i) {
            const detail::Landing& landing = m.landings[i];
            if (landing.stop == detail::Stop::None) continue;
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
        result->walkLimitStopped = counts.walkLimitStopped;
        result->limited = counts.boundaryStopped + counts.walkLimitStopped;
        result->flippedTriangles = flipped;
        result->foldScale = scales;
        result->unreachable = m.unreachable;
        result->withoutTangentPlane = m.withoutTangentPlane;
        result->degenerateTriangles = m.degenerateTriangles;
    }
}

std::vector<glm::vec3> slide(const geom::Mesh& mesh, std::span<const SlideHandle> handles,
                             std::span<const SlideDrive> drives, std::span<const float> weights,
                             double envelope, const SlideOptions& options, SlideResult* result) {
    Slider slider(mesh, std::vector<SlideHandle>(handles.begin(), handles.end()), options);
    std::vector<glm::vec3> points(mesh.points().begin(), mesh.points().end());
    slider.evaluate(drives, points, weights, envelope, result);
    return points;
}

}  // namespace deformkit::slide
