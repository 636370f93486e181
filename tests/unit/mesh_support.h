#pragma once

// Meshes shared by the host and harness tests: a quad tube around the Y axis, with or without UVs.

#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"

namespace deformkit::test {

// How a tube carries UVs. Wrapped: one UV per vertex, so the faces of the last column run from
// u = uvOrigin.x + uvSize.x (sides - 1) / sides back to uvOrigin.x. Seam: an extra column of vertices
// repeats the first column's positions (up to the rounding of cos and sin at 2 pi) with
// u = uvOrigin.x + uvSize.x, so every face's UVs are a rectangle.
enum class TubeUVs { None, Wrapped, Seam };

struct TubeOptions {
    int rings = 5;           // rings of vertices along the axis, ring r at y = -1 + 2 r / (rings - 1); >= 2
    int sides = 8;           // vertices per ring, side s at angle 2 pi s / sides from +X towards +Z
    float radius = 0.5f;     // scene units
    glm::vec3 center{0.0f};  // added to every position: the axis runs through it
    TubeUVs uvs = TubeUVs::None;
    glm::vec2 uvOrigin{0.0f};      // UV of ring 0, side 0
    glm::vec2 uvSize{1.0f, 1.0f};  // UV extent over the sides (u) and over the rings (v)
};

// Appends an open tube to `d`. Vertex (r, s) is d.points.size() + r * columns + s before the call, with
// columns = sides, or sides + 1 with a seam; each ring's quads (r, s), (r, s + 1), (r + 1, s + 1), (r + 1, s)
// in order of s. With UVs, one UV per vertex in the same order, indexed from d.uvs.size() before the call.
inline void appendTube(geom::Mesh::Data& d, const TubeOptions& o) {
    const bool seam = o.uvs == TubeUVs::Seam;
    const int columns = seam ? o.sides + 1 : o.sides;
    const int first = static_cast<int>(d.points.size());
    const int firstUV = static_cast<int>(d.uvs.size());
    for (int r = 0; r < o.rings; ++r) {
        const float y = -1.0f + 2.0f * static_cast<float>(r) / static_cast<float>(o.rings - 1);
        for (int s = 0; s < columns; ++s) {
            const double a = 2.0 * std::numbers::pi * s / o.sides;
            d.points.emplace_back(o.center.x + o.radius * static_cast<float>(std::cos(a)), o.center.y + y,
                                  o.center.z + o.radius * static_cast<float>(std::sin(a)));
            if (o.uvs != TubeUVs::None)
                d.uvs.emplace_back(o.uvOrigin.x + o.uvSize.x * static_cast<float>(s) / o.sides,
                                   o.uvOrigin.y + o.uvSize.y * static_cast<float>(r) / (o.rings - 1));
        }
    }
    for (int r = 0; r + 1 < o.rings; ++r) {
        for (int s = 0; s < o.sides; ++s) {
            const int s1 = seam ? s + 1 : (s + 1) % o.sides;
            const int corners[4] = {r * columns + s, r * columns + s1, (r + 1) * columns + s1,
                                    (r + 1) * columns + s};
            d.faceCounts.push_back(4);
            for (int c : corners) {
                d.faceIndices.push_back(first + c);
                if (o.uvs != TubeUVs::None) d.uvIndices.push_back(firstUV + c);
            }
        }
    }
}

// A single tube, named "tube" in error messages.
inline geom::Mesh tube(const TubeOptions& o = {}) {
    geom::Mesh::Data d;
    appendTube(d, o);
    return geom::Mesh(std::move(d), "tube");
}

// A split copy of `mesh`: the test's own splitting, written from the file formats' rule. `perCorner`: every
// face corner its own vertex (as an unindexed glTF); otherwise one vertex per (vertex, UV) pair used by a
// corner (as a glTF split at UV seams). Split vertices are numbered in the order corners first use them,
// face by face; `original` receives each one's vertex in `mesh`.
inline geom::Mesh splitCopy(const geom::Mesh& mesh, bool perCorner, std::vector<int32_t>& original) {
    geom::Mesh::Data data;
    data.faceCounts.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    data.uvs.assign(mesh.uvs().begin(), mesh.uvs().end());
    std::map<std::pair<int32_t, int32_t>, int32_t> made;
    original.clear();
    for (size_t c = 0; c < mesh.faceIndices().size(); ++c) {
        const int32_t v = mesh.faceIndices()[c];
        const int32_t uv = mesh.hasUVs() ? mesh.uvIndices()[c] : -1;
        int32_t index = -1;
        if (!perCorner) {
            const auto it = made.find({v, uv});
            if (it != made.end()) index = it->second;
        }
        if (index < 0) {
            index = static_cast<int32_t>(data.points.size());
            data.points.push_back(mesh.points()[v]);
            original.push_back(v);
            if (!perCorner) made[{v, uv}] = index;
        }
        data.faceIndices.push_back(index);
        if (mesh.hasUVs()) data.uvIndices.push_back(uv);
    }
    return geom::Mesh(std::move(data), perCorner ? "split per corner" : "split at UV seams");
}

// `mesh` with its vertices renumbered by `order` (new vertex i is old vertex order[i]); faces, corners and
// UVs unchanged. The slide depends on vertex numbering (its propagation visits vertices in index order), so
// the reference of a split mesh is the shared-vertex mesh numbered as the weld numbers it: by first copy.
inline geom::Mesh renumbered(const geom::Mesh& mesh, const std::vector<int32_t>& order,
                             std::vector<int32_t>& newIndex) {
    geom::Mesh::Data data;
    newIndex.assign(order.size(), -1);
    for (size_t i = 0; i < order.size(); ++i) {
        newIndex[static_cast<size_t>(order[i])] = static_cast<int32_t>(i);
        data.points.push_back(mesh.points()[order[i]]);
    }
    data.faceCounts.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    for (int32_t v : mesh.faceIndices())
        data.faceIndices.push_back(newIndex[static_cast<size_t>(v)]);
    data.uvs.assign(mesh.uvs().begin(), mesh.uvs().end());
    data.uvIndices.assign(mesh.uvIndices().begin(), mesh.uvIndices().end());
    return geom::Mesh(std::move(data), "renumbered");
}

// The order in which `splitCopy`'s copies first appear, as original vertices: the weld's numbering.
inline std::vector<int32_t> firstCopyOrder(const std::vector<int32_t>& original, int32_t vertices) {
    std::vector<uint8_t> seen(static_cast<size_t>(vertices), 0);
    std::vector<int32_t> order;
    for (int32_t v : original) {
        if (!seen[static_cast<size_t>(v)]) {
            seen[static_cast<size_t>(v)] = 1;
            order.push_back(v);
        }
    }
    return order;
}

}  // namespace deformkit::test
