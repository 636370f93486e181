#include "deformkit/geom/weld.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <tuple>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "deformkit/error.h"

namespace deformkit::geom {

namespace {

int32_t findRoot(std::vector<int32_t>& parent, int32_t v) {
    while (parent[v] != v) {
        parent[v] = parent[parent[v]];
        v = parent[v];
    }
    return v;
}

// Whether file vertices u and v are corners of one face (a collapsed edge, not a split copy).
class FaceSharing {
  public:
    explicit FaceSharing(const Mesh& mesh) : offsets_(static_cast<size_t>(mesh.numVertices()) + 1, 0) {
        const auto counts = mesh.faceCounts();
        const auto indices = mesh.faceIndices();
        for (int32_t v : indices)
            ++offsets_[static_cast<size_t>(v) + 1];
        std::partial_sum(offsets_.begin(), offsets_.end(), offsets_.begin());
        faces_.resize(indices.size());
        std::vector<int32_t> fill(offsets_.begin(), offsets_.end() - 1);
        size_t corner = 0;
        for (size_t f = 0; f < counts.size(); ++f) {
            for (int32_t k = 0; k < counts[f]; ++k, ++corner)
                faces_[static_cast<size_t>(fill[static_cast<size_t>(indices[corner])]++)] =
                    static_cast<int32_t>(f);
        }
    }
    [[nodiscard]] bool share(int32_t u, int32_t v) const {
        for (int32_t i = offsets_[u]; i < offsets_[u + 1]; ++i)
            for (int32_t j = offsets_[v]; j < offsets_[v + 1]; ++j)
                if (faces_[i] == faces_[j]) return true;
        return false;
    }

  private:
    std::vector<int32_t> offsets_, faces_;
};

// Groups of file vertices: per vertex the lowest-index vertex of its group. Two vertices join when they
// lie within the tolerance and are corners of no common face.
std::vector<int32_t> groupRoots(const Mesh& mesh, double tolerance) {
    const std::span<const glm::vec3> points = mesh.points();
    const auto n = static_cast<int32_t>(points.size());
    std::vector<int32_t> parent(points.size());
    std::iota(parent.begin(), parent.end(), 0);
    std::optional<FaceSharing> sharing;  // built at the first candidate pair: most meshes have none
    auto unite = [&](int32_t a, int32_t b) {
        if (!sharing) sharing.emplace(mesh);
        if (sharing->share(a, b)) return;
        a = findRoot(parent, a);
        b = findRoot(parent, b);
        if (a == b) return;
        if (a < b) std::swap(a, b);
        parent[a] = b;  // the lower index stays the root
    };
    if (tolerance == 0.0) {
        // Exactly equal positions (+0 and -0 alike, as == compares them).
        struct Hash {
            size_t operator()(const glm::vec3& p) const {
                const auto h = [](float x) { return std::hash<float>()(x == 0.0f ? 0.0f : x); };
                return h(p.x) * 73856093u ^ h(p.y) * 19349663u ^ h(p.z) * 83492791u;
            }
        };
        std::unordered_map<glm::vec3, std::vector<int32_t>, Hash> same;
        same.reserve(points.size());
        for (int32_t v = 0; v < n; ++v) {
            std::vector<int32_t>& earlier = same[points[v]];
            for (int32_t u : earlier)
                unite(v, u);
            earlier.push_back(v);
        }
    } else {
        // Cells of the tolerance's size: a pair within the tolerance lies in the same or a neighbouring cell.
        using Cell = std::tuple<int64_t, int64_t, int64_t>;
        struct CellHash {
            size_t operator()(const Cell& c) const {
                return static_cast<size_t>(std::get<0>(c) * 73856093 ^ std::get<1>(c) * 19349663 ^
                                           std::get<2>(c) * 83492791);
            }
        };
        std::unordered_map<Cell, std::vector<int32_t>, CellHash> cells;
        auto cellOf = [&](const glm::vec3& p) {
            return Cell{static_cast<int64_t>(std::floor(p.x / tolerance)),
                        static_cast<int64_t>(std::floor(p.y / tolerance)),
                        static_cast<int64_t>(std::floor(p.z / tolerance))};
        };
        for (int32_t v = 0; v < n; ++v) {
            const auto [cx, cy, cz] = cellOf(points[v]);
            for (int64_t dz = -1; dz <= 1; ++dz)
                for (int64_t dy = -1; dy <= 1; ++dy)
                    for (int64_t dx = -1; dx <= 1; ++dx) {
                        const auto it = cells.find({cx + dx, cy + dy, cz + dz});
                        if (it == cells.end()) continue;
                        for (int32_t u : it->second) {
                            if (glm::distance(glm::dvec3(points[u]), glm::dvec3(points[v])) <= tolerance)
                                unite(v, u);
                        }
                    }
            cells[{cx, cy, cz}].push_back(v);
        }
    }
    std::vector<int32_t> root(points.size());
    for (int32_t v = 0; v < n; ++v)
        root[v] = findRoot(parent, v);
    return root;
}

}  // namespace

Welding weldVertices(const Mesh& mesh, double tolerance, const std::string& source) {
    if (!std::isfinite(tolerance) || tolerance < 0.0) {
        throw InvalidInput(formatError(source, "weld tolerance", "is " + numberText(tolerance),
                                       "a distance >= 0 (0: exactly equal positions)"));
    }
    const std::span<const glm::vec3> points = mesh.points();
    const std::vector<int32_t> root = groupRoots(mesh, tolerance);
    Welding w;
    w.weldedOf.assign(points.size(), -1);
    for (size_t v = 0; v < points.size(); ++v) {
        if (root[v] == static_cast<int32_t>(v)) {
            w.weldedOf[v] = static_cast<int32_t>(w.firstOf.size());
            w.firstOf.push_back(static_cast<int32_t>(v));
        } else {
            w.weldedOf[v] = w.weldedOf[static_cast<size_t>(root[v])];  // roots come first: lower index
        }
    }
    w.copyOffsets.assign(w.firstOf.size() + 1, 0);
    for (int32_t welded : w.weldedOf)
        ++w.copyOffsets[static_cast<size_t>(welded) + 1];
    std::partial_sum(w.copyOffsets.begin(), w.copyOffsets.end(), w.copyOffsets.begin());
    w.copies.resize(points.size());
    std::vector<int32_t> fill(w.copyOffsets.begin(), w.copyOffsets.end() - 1);
    for (size_t v = 0; v < points.size(); ++v)
        w.copies[static_cast<size_t>(fill[static_cast<size_t>(w.weldedOf[v])]++)] = static_cast<int32_t>(v);

    if (w.merged() == 0) return w;  // nothing to weld: no welded mesh (callers use the file's)
    // Corners of one face never join directly (groupRoots), but a tolerance that reaches across the mesh
    // joins them through a chain of other vertices: the edge collapses, and the mesh around it tears or turns
    // non-manifold. A tolerance meant for a split vertex's copies does not: refused. Edges of zero length
    // (slivers of coincident points) may weld so.
    if (tolerance > 0.0) {
        const auto counts = mesh.faceCounts();
        const auto indices = mesh.faceIndices();
        size_t offset = 0;
        for (size_t f = 0; f < counts.size(); ++f) {
            const auto n = static_cast<size_t>(counts[f]);
            for (size_t k = 0; k < n; ++k) {
                const auto a = static_cast<size_t>(indices[offset + k]);
                const auto b = static_cast<size_t>(indices[offset + (k + 1) % n]);
                if (w.weldedOf[a] != w.weldedOf[b] || points[a] == points[b]) continue;
                const double length = glm::distance(glm::dvec3(points[a]), glm::dvec3(points[b]));
                throw InvalidInput(formatError(source, "weld tolerance",
                                               "is " + numberText(tolerance) +
                                                   ": it welds the two ends of edge (" + std::to_string(a) +
                                                   ", " + std::to_string(b) + ") of face " +
                                                   std::to_string(f) + ", " + numberText(length) + " long",
                                               "a tolerance below the mesh's edges that must stay (about the "
                                               "gap between a split vertex's "
                                               "copies)"));
            }
            offset += n;
        }
    }
    Mesh::Data data;
    data.points.reserve(w.firstOf.size());
    for (int32_t v : w.firstOf)
        data.points.push_back(points[static_cast<size_t>(v)]);
    data.uvs.assign(mesh.uvs().begin(), mesh.uvs().end());
    const bool uvs = mesh.hasUVs();
    const auto counts = mesh.faceCounts();
    const auto indices = mesh.faceIndices();
    size_t offset = 0;
    std::vector<int32_t> corners, uvCorners;
    for (size_t f = 0; f < counts.size(); ++f) {
        const auto n = static_cast<size_t>(counts[f]);
        corners.clear();
        uvCorners.clear();
        for (size_t k = 0; k < n; ++k) {
            corners.push_back(w.weldedOf[static_cast<size_t>(indices[offset + k])]);
            if (uvs) uvCorners.push_back(mesh.uvIndices()[offset + k]);
        }
        offset += n;
        // Corners welded onto the one before (cyclically) go; a face left with a repeated vertex or fewer
        // than 3 corners goes too.
        size_t kept = 0;
        for (size_t k = 0; k < corners.size(); ++k) {
            if (kept > 0 && corners[k] == corners[kept - 1]) continue;
            corners[kept] = corners[k];
            if (uvs) uvCorners[kept] = uvCorners[k];
            ++kept;
        }
        while (kept > 1 && corners[kept - 1] == corners[0])
            --kept;
        corners.resize(kept);
        if (uvs) uvCorners.resize(kept);
        std::vector<int32_t> sorted = corners;
        std::sort(sorted.begin(), sorted.end());
        if (kept < 3 || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;
        w.fileFaceOf.push_back(static_cast<int32_t>(f));
        data.faceCounts.push_back(static_cast<int32_t>(kept));
        data.faceIndices.insert(data.faceIndices.end(), corners.begin(), corners.end());
        if (uvs) data.uvIndices.insert(data.uvIndices.end(), uvCorners.begin(), uvCorners.end());
    }
    if (data.faceCounts.empty()) {
        throw InvalidInput(formatError(source, "weld",
                                       "every face collapses when coincident vertices are welded",
                                       "a mesh whose faces span an area (or a smaller weld tolerance)"));
    }
    if (!uvs) data.uvs.clear();
    w.mesh = Mesh(std::move(data), source);
    return w;
}

}  // namespace deformkit::geom
