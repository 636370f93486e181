#include "deformkit/geom/half_edge.h"

#include <algorithm>
#include <numeric>

#include "deformkit/error.h"
#include "deformkit/geom/mesh.h"

namespace deformkit::geom {
namespace {

struct UnionFind {
    std::vector<int32_t> parent;
    explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
    int32_t find(int32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    }
    void unite(int32_t a, int32_t b) {
        a = find(a);
        b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
};

// Turns per-item keys into CSR offsets + items grouped by key (stable: items ascending inside a group).
void bucket(const std::vector<int32_t>& keyOfItem, int32_t numKeys, std::vector<int32_t>& offsets,
            std::vector<int32_t>& items) {
    offsets.assign(numKeys + 1, 0);
    for (int32_t k : keyOfItem)
        ++offsets[k + 1];
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    items.resize(keyOfItem.size());
    std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
    for (int32_t i = 0; i < static_cast<int32_t>(keyOfItem.size()); ++i)
        items[fill[keyOfItem[i]]++] = i;
}

}  // namespace

HalfEdgeMesh::HalfEdgeMesh(const Mesh& mesh) {
    const int32_t numCorners = mesh.numCorners();
    const int32_t numVerts = mesh.numVertices();
    const auto offsets = mesh.faceOffsets();
    const auto indices = mesh.faceIndices();

    face_.resize(numCorners);
    next_.resize(numCorners);
    prev_.resize(numCorners);
    tail_.assign(indices.begin(), indices.end());
    twin_.assign(numCorners, -1);
    edge_.resize(numCorners);
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const int32_t begin = offsets[f], end = offsets[f + 1];
        for (int32_t h = begin; h < end; ++h) {
            face_[h] = f;
            next_[h] = h + 1 < end ? h + 1 : begin;
            prev_[h] = h > begin ? h - 1 : end - 1;
        }
    }

    // Edges: sort half-edges by their undirected vertex pair (deterministic, no hashing).
    auto key = [&](int32_t h) {
        const uint32_t a = static_cast<uint32_t>(tail_[h]), b = static_cast<uint32_t>(tail_[next_[h]]);
        return (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
    };
    std::vector<int32_t> order(numCorners);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int32_t x, int32_t y) {
        const uint64_t kx = key(x), ky = key(y);
        return kx != ky ? kx < ky : x < y;
    });
    edgeOffsets_.push_back(0);
    edgeHalfEdges_.reserve(numCorners);
    for (int32_t i = 0; i < numCorners;) {
        int32_t j = i;
        const uint64_t k = key(order[i]);
        while (j < numCorners && key(order[j]) == k)
            ++j;
        const int32_t e = static_cast<int32_t>(edgeVertices_.size());
        edgeVertices_.push_back({static_cast<int32_t>(k >> 32), static_cast<int32_t>(k & 0xffffffffu)});
        for (int32_t t = i; t < j; ++t) {
            edge_[order[t]] = e;
            edgeHalfEdges_.push_back(order[t]);
        }
        edgeOffsets_.push_back(static_cast<int32_t>(edgeHalfEdges_.size()));
        const int32_t count = j - i;
        if (count == 1) {
            ++report_.boundaryEdges;
        } else if (count == 2) {
            const int32_t h0 = order[i], h1 = order[i + 1];
            if (tail_[h0] == tail_[h1]) {
                report_.inconsistentEdges.push_back(e);
            } else {
                twin_[h0] = h1;
                twin_[h1] = h0;
            }
        } else {
            report_.nonManifoldEdges.push_back(e);
        }
        i = j;
    }

    bucket(tail_, numVerts, vertexCornerOffsets_, vertexCorners_);

    // Boundary vertices: any edge at the vertex without a twin (boundary, non-manifold or flipped).
    boundaryVertex_.assign(numVerts, 0);
    for (int32_t h = 0; h < numCorners; ++h) {
        if (twin_[h] < 0) boundaryVertex_[tail_[h]] = boundaryVertex_[tail_[next_[h]]] = 1;
    }

    // One-ring neighbours from the edge list (already sorted by vertex pair).
    std::vector<int32_t> counts(numVerts + 1, 0);
    for (const auto& ev : edgeVertices_) {
        ++counts[ev[0] + 1];
        ++counts[ev[1] + 1];
    }
    std::partial_sum(counts.begin(), counts.end(), counts.begin());
    neighborOffsets_ = counts;
    neighbors_.resize(neighborOffsets_.back());
    for (const auto& ev : edgeVertices_) {
        neighbors_[counts[ev[0]]++] = ev[1];
        neighbors_[counts[ev[1]]++] = ev[0];
    }
    for (int32_t v = 0; v < numVerts; ++v) {
        std::sort(neighbors_.begin() + neighborOffsets_[v], neighbors_.begin() + neighborOffsets_[v + 1]);
    }

    // Fans around each vertex: corners at v are joined when their faces share an edge at v through a
    // twin. More than one fan makes v non-manifold (two surfaces touching at a point).
    UnionFind cornerSets(numCorners);
    for (int32_t h = 0; h < numCorners; ++h) {
        const int32_t t = twin_[prev_[h]];  // prev(h) arrives at tail(h); its twin leaves tail(h)
        if (t >= 0) cornerSets.unite(h, t);
    }
    for (int32_t v = 0; v < numVerts; ++v) {
        const auto corners = vertexHalfEdges(v);
        if (corners.empty()) {
            report_.isolatedVertices.push_back(v);
            continue;
        }
        const int32_t root = cornerSets.find(corners[0]);
        for (int32_t c : corners.subspan(1)) {
            if (cornerSets.find(c) != root) {
                report_.nonManifoldVertices.push_back(v);
                break;
            }
        }
    }

    UnionFind vertexSets(numVerts);
    for (int32_t h = 0; h < numCorners; ++h)
        vertexSets.unite(tail_[h], tail_[next_[h]]);
    for (int32_t v = 0; v < numVerts; ++v) {
        if (vertexCornerOffsets_[v + 1] > vertexCornerOffsets_[v] && vertexSets.find(v) == v)
            ++report_.components;
    }
}

void requireManifold(const Mesh& mesh, const std::string& source) {
    const HalfEdgeMesh& he = mesh.halfEdges();
    const ManifoldReport& r = he.report();
    auto edgeName = [&](int32_t e) {
        const auto ev = he.edgeVertices(e);
        return "edge (" + std::to_string(ev[0]) + ", " + std::to_string(ev[1]) + ")";
    };
    if (!r.nonManifoldEdges.empty()) {
        const int32_t e = r.nonManifoldEdges.front();
        throw TopologyError(formatError(source, edgeName(e),
                                        "is shared by " + std::to_string(he.edgeHalfEdges(e).size()) +
                                            " faces (" + std::to_string(r.nonManifoldEdges.size()) +
                                            " non-manifold edges in all)",
                                        "a manifold mesh: at most two faces per edge"));
    }
    if (!r.inconsistentEdges.empty()) {
        const int32_t e = r.inconsistentEdges.front();
        const auto hs = he.edgeHalfEdges(e);
        throw TopologyError(formatError(source, edgeName(e),
                                        "faces " + std::to_string(he.face(hs[0])) + " and " +
                                            std::to_string(he.face(hs[1])) + " have opposite orientations",
                                        "consistently oriented faces"));
    }
    if (!r.nonManifoldVertices.empty()) {
        throw TopologyError(formatError(source, "vertex " + std::to_string(r.nonManifoldVertices.front()),
                                        "joins surfaces that touch only at this vertex (" +
                                            std::to_string(r.nonManifoldVertices.size()) +
                                            " non-manifold vertices in all)",
                                        "a manifold mesh: one fan of faces around each vertex"));
    }
}

}  // namespace deformkit::geom
