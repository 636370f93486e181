#include "tile_uvs.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "deformkit/error.h"
#include "deformkit/geom/triangulation.h"
#include "memory/large_buffers.h"

namespace deformkit::uvwarp::detail {
namespace {

// One use of a UV edge by a face: welded endpoint ids (low, high), whether the face runs low -> high.
struct EdgeUse {
    uint64_t key;
    int32_t face;
    int32_t corner;  // the edge runs from this face corner to the next
    bool forward;
};

}  // namespace

std::string tileSource(std::string_view label, int tile) {
    std::string source(label);
    source += ", UDIM tile ";
    source += std::to_string(tile);
    return source;
}

glm::vec2 tileOrigin(int tile, std::string_view label) {
    if (tile < 1001 || tile > 9999) {
        throw InvalidInput(formatError(label, "tile " + std::to_string(tile), "is not a UDIM tile number",
                                       "1001 to 9999 (1001 + u index 0..9 + 10 * v index)"));
    }
    return {static_cast<float>((tile - 1001) % 10), static_cast<float>((tile - 1001) / 10)};
}

TileUVs collectTileUVs(const geom::Mesh& mesh, int tile, std::string_view label) {
    TileUVs out;
    out.tile = tile;
    out.origin = tileOrigin(tile, label);
    const std::string source = tileSource(label, tile);
    if (!mesh.hasUVs()) {
        throw InvalidInput(formatError(label, "", "has no UVs", "a mesh with texture coordinates"));
    }
    const auto uvs = mesh.uvs();
    const auto uvIndices = mesh.uvIndices();
    const auto faceIndices = mesh.faceIndices();
    // A mesh's UVs may have been written after it was made (Python's Mesh.uvs is writable): a NaN would
    // reach the rasteriser as a triangle's corner, not as the UV it is.
    for (size_t i = 0; i < uvs.size(); ++i) {
        if (!std::isfinite(uvs[i].x) || !std::isfinite(uvs[i].y)) {
            throw InvalidInput(formatError(label, "UV " + std::to_string(i),
                                           "is (" + numberText(uvs[i].x) + ", " + numberText(uvs[i].y) + ")",
                                           "finite texture coordinates"));
        }
    }

    // The tile's faces (Mesh::faceUdimTile), refusing those that overhang it by more than kMaxOverhang.
    geom::requireUdimFacesInTile(
        mesh, tile, [&](int) { return source; }, kTileTolerance);
    std::vector<uint8_t> inTile(static_cast<size_t>(mesh.numFaces()), 0);
    for (int32_t f = 0; f < mesh.numFaces(); ++f)
        inTile[f] = mesh.faceUdimTile(f) == tile ? 1 : 0;

    const geom::Triangulation tris = geom::triangulate(mesh);
    // Sized once: grown by push_back, these buffers' copies and first-touched pages cost more than the rest.
    deformkit::detail::reserveLarge(out.vertices, static_cast<size_t>(tris.size()));
    deformkit::detail::reserveLarge(out.uvs, static_cast<size_t>(tris.size()));
    deformkit::detail::reserveLarge(out.face, static_cast<size_t>(tris.size()));
    std::vector<int32_t> firstTriangle(static_cast<size_t>(mesh.numFaces()), -1);
    for (int32_t t = 0; t < tris.size(); ++t) {
        const int32_t f = tris.face[t];
        if (!inTile[f]) continue;
        if (firstTriangle[f] < 0) firstTriangle[f] = static_cast<int32_t>(out.face.size());
        const auto& c = tris.corners[t];
        out.vertices.push_back({faceIndices[c[0]], faceIndices[c[1]], faceIndices[c[2]]});
        out.uvs.push_back({uvs[uvIndices[c[0]]] - out.origin, uvs[uvIndices[c[1]]] - out.origin,
                           uvs[uvIndices[c[2]]] - out.origin});
        out.face.push_back(f);
    }

    // Weld UV indices by value: equal coordinates get one id, the smallest index holding them.
    std::vector<int32_t> used;
    used.reserve(mesh.faceIndices().size());
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        if (!inTile[f]) continue;
        for (int32_t t : mesh.faceUVIndices(f))
            used.push_back(t);
    }
    // Each index once (a UV index is shared by the corners of several faces), then ordered by value.
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    std::sort(used.begin(), used.end(), [&](int32_t a, int32_t b) {
        if (uvs[a].x != uvs[b].x) return uvs[a].x < uvs[b].x;
        if (uvs[a].y != uvs[b].y) return uvs[a].y < uvs[b].y;
        return a < b;
    });
    std::vector<int32_t> weld(static_cast<size_t>(mesh.numUVs()), -1);
    for (size_t k = 0; k < used.size(); ++k) {
        const bool same = k > 0 && uvs[used[k]] == uvs[used[k - 1]];
        weld[used[k]] = same ? weld[used[k - 1]] : used[k];
    }

    std::vector<EdgeUse> edges;
    edges.reserve(mesh.faceIndices().size());
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        if (!inTile[f]) continue;
        const auto corners = mesh.faceUVIndices(f);
        const auto n = static_cast<int32_t>(corners.size());
        for (int32_t k = 0; k < n; ++k) {
            const int32_t a = weld[corners[k]], b = weld[corners[(k + 1) % n]];
            if (a == b) continue;  // zero-length UV edge: borders nothing
            const auto lo = static_cast<uint64_t>(std::min(a, b)), hi = static_cast<uint64_t>(std::max(a, b));
            edges.push_back({(lo << 32) | hi, f, k, a < b});
        }
    }
    std::sort(edges.begin(), edges.end(), [](const EdgeUse& x, const EdgeUse& y) {
        if (x.key != y.key) return x.key < y.key;
        if (x.face != y.face) return x.face < y.face;
        return x.corner < y.corner;
    });
    for (size_t begin = 0; begin < edges.size();) {
        size_t end = begin + 1;
        while (end < edges.size() && edges[end].key == edges[begin].key)
            ++end;
        size_t forward = 0;
        for (size_t e = begin; e < end; ++e)
            forward += edges[e].forward ? 1 : 0;
        const bool interior = 2 * forward == end - begin;
        for (size_t e = begin; e < end && !interior; ++e) {
            const EdgeUse& use = edges[e];
            const auto corners = mesh.faceUVIndices(use.face);
            const auto n = static_cast<int32_t>(corners.size());
            // Fan triangle m = 0..n-3 holds corners (0, m + 1, m + 2): edge k lies in triangle k - 1,
            // except the first (triangle 0) and the closing one (triangle n - 3).
            const int32_t m = use.corner == 0 ? 0 : (use.corner == n - 1 ? n - 3 : use.corner - 1);
            out.borderEdges.push_back(
                {uvs[corners[use.corner]] - out.origin, uvs[corners[(use.corner + 1) % n]] - out.origin});
            out.borderTriangle.push_back(firstTriangle[use.face] + m);
            const auto points = mesh.face(use.face);
            out.borderPoints.push_back({points[use.corner], points[(use.corner + 1) % n]});
        }
        begin = end;
    }
    return out;
}

}  // namespace deformkit::uvwarp::detail
