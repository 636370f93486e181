#include "deformkit/slide/surface.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/triangulation.h"

namespace deformkit::slide {

namespace {

// Twice the area below which a triangle counts as degenerate, relative to the squared mesh scale:
// far below any modelled detail, far above the rounding of float positions.
constexpr double kDegenerateArea2 = 1e-14;

}  // namespace

SlideSurface::SlideSurface(const geom::Mesh& mesh, const std::string& source) {
    const int32_t nv = mesh.numVertices();
    points_.resize(nv);
    for (int32_t v = 0; v < nv; ++v)
        points_[v] = glm::dvec3(mesh.points()[v]);
    const geom::Box3 box = mesh.bounds();
    scale_ = nv > 0 ? std::max(static_cast<double>(glm::length(box.max - box.min)), 1e-30) : 1.0;
    if (!std::isfinite(scale_)) {  // every triangle would count as degenerate against it
        throw InvalidInput(
            formatError(source, "bounding box",
                        "diagonal " + numberText(glm::length(glm::dvec3(box.max) - glm::dvec3(box.min))) +
                            " overflows single precision",
                        "a mesh extent below 1e19 scene units"));
    }

    const geom::Triangulation tris = geom::triangulate(mesh);
    const int32_t nt = tris.size();
    face_ = tris.face;
    faceCorners_.resize(static_cast<size_t>(nt) * 3);
    vertices_.resize(static_cast<size_t>(nt) * 3);
    for (int32_t t = 0; t < nt; ++t) {
        for (int k = 0; k < 3; ++k) {
            faceCorners_[3 * t + k] = tris.corners[t][k];
            vertices_[3 * t + k] = mesh.faceIndices()[tris.corners[t][k]];
        }
    }

    degenerate_.assign(nt, 0);
    std::vector<glm::dvec3> triangleNormals(nt);
    const double minArea2 = kDegenerateArea2 * scale_ * scale_;
    for (int32_t t = 0; t < nt; ++t) {
        const glm::dvec3& a = points_[vertices_[3 * t]];
        const glm::dvec3 n = glm::cross(points_[vertices_[3 * t + 1]] - a, points_[vertices_[3 * t + 2]] - a);
        if (glm::length(n) <= minArea2) {
            degenerate_[t] = 1;
            ++numDegenerate_;
        } else {
            triangleNormals[t] = n;  // length = twice the area: area weighting
        }
    }

    // Adjacency: corners sorted by undirected edge; a pair running in opposite directions between two
    // sound triangles is a manifold interior edge.
    std::vector<std::pair<uint64_t, int32_t>> edges(vertices_.size());
    for (int32_t c = 0; c < static_cast<int32_t>(vertices_.size()); ++c) {
        const auto a = static_cast<uint32_t>(vertices_[c]);
        const auto b = static_cast<uint32_t>(vertices_[next(c)]);
        edges[c] = {(static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b), c};
    }
    std::sort(edges.begin(), edges.end());
    opposite_.assign(vertices_.size(), -1);
    for (size_t i = 0; i < edges.size();) {
        size_t j = i + 1;
        while (j < edges.size() && edges[j].first == edges[i].first)
            ++j;
        if (j - i == 2) {
            const int32_t c0 = edges[i].second, c1 = edges[i + 1].second;
            const bool opposed = vertices_[c0] == vertices_[next(c1)] && vertices_[c1] == vertices_[next(c0)];
            if (opposed && !degenerate_[triangleOf(c0)] && !degenerate_[triangleOf(c1)]) {
                opposite_[c0] = c1;
                opposite_[c1] = c0;
            }
        }
        i = j;
    }

    vertexOffsets_.assign(nv + 1, 0);
    for (int32_t v : vertices_)
        ++vertexOffsets_[v + 1];
    for (int32_t v = 0; v < nv; ++v)
        vertexOffsets_[v + 1] += vertexOffsets_[v];
    vertexCorners_.resize(vertices_.size());
    {
        std::vector<int32_t> fill(vertexOffsets_.begin(), vertexOffsets_.end() - 1);
        for (int32_t c = 0; c < static_cast<int32_t>(vertices_.size()); ++c)
            vertexCorners_[fill[vertices_[c]]++] = c;
    }

    neighborOffsets_.assign(nv + 1, 0);
    std::vector<int32_t> scratch;
    for (int32_t v = 0; v < nv; ++v) {
        scratch.clear();
        for (int32_t c : vertexCorners(v)) {
            scratch.push_back(vertices_[next(c)]);
            scratch.push_back(vertices_[prev(c)]);
        }
        std::sort(scratch.begin(), scratch.end());
        scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
        neighbors_.insert(neighbors_.end(), scratch.begin(), scratch.end());
        neighborOffsets_[v + 1] = static_cast<int32_t>(neighbors_.size());
    }

    normals_.assign(nv, glm::dvec3(0.0));
    b1_.assign(nv, glm::dvec3(0.0));
    for (int32_t v = 0; v < nv; ++v) {
        glm::dvec3 n(0.0);
        for (int32_t c : vertexCorners(v))
            n += triangleNormals[triangleOf(c)];
        const double length = glm::length(n);
        if (!(length > 0.0)) continue;
        n /= length;
        normals_[v] = n;
        for (int32_t w : neighbors(v)) {
            const glm::dvec3 e = points_[w] - points_[v];
            const glm::dvec3 tangent = e - glm::dot(e, n) * n;
            const double tl = glm::length(tangent);
            if (tl > 1e-9 * glm::length(e)) {
                b1_[v] = tangent / tl;
                break;
            }
        }
    }
}

bool SlideSurface::areNeighbors(int32_t v, int32_t w) const {
    const auto ring = neighbors(v);
    return std::binary_search(ring.begin(), ring.end(), w);
}

glm::dvec3 SlideSurface::tangent2(int32_t v) const {
    return glm::cross(normals_[v], b1_[v]);
}

bool SlideSurface::hasFrame(int32_t v) const {
    return b1_[v] != glm::dvec3(0.0);
}

}  // namespace deformkit::slide
