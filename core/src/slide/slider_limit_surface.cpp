#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "deformkit/error.h"
#include "slider_impl.h"

namespace deformkit::slide {

glm::dvec3 Slider::Impl::limitPoint(const Landing& landing) const {
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

glm::dvec3 Slider::Impl::limitOrigin(int32_t v) const {
    return limitPoint(detail::onEdge(surface.vertexCorners(v)[0], 0.0, Stop::Reached));
}

void Slider::Impl::buildLocalLimit() {
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

void Slider::Impl::bindLimit() {
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

bool Slider::Impl::coverLandings() {
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

void Slider::Impl::prepareLimit(std::span<const glm::vec3> in) {
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
        for (size_t i = 0; i < L.vertices.size(); ++i) {
            // The limit patches read the points around the region's faces too: a non-finite one would make
            // the limit points of every patch it touches NaN.
            const glm::vec3& p = in[L.vertices[i]];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
                throw InvalidInput(
                    formatError(source, "point of vertex " + std::to_string(L.vertices[i]), "not finite",
                                "finite x, y, z (the limit surface reads the points around the "
                                "region's faces)"));
            }
            L.incomingCage[i] = p;
        }
        L.incoming = std::make_unique<geom::LimitSurface>(L.rest->withPoints(L.incomingCage));
    }
    L.current = L.incoming.get();
}

}  // namespace deformkit::slide
