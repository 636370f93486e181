#include "deformkit/geom/mesh.h"
#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>
#include <span>
#include <unordered_set>

#include <glm/common.hpp>
#include <glm/vec2.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"

namespace deformkit::geom {

struct Mesh::TopologyCache {
    std::once_flag once;
    std::unique_ptr<const HalfEdgeMesh> value;
};

namespace {}  // namespace

Mesh::Mesh() : faceOffsets_{0}, topology_(std::make_shared<TopologyCache>()) {}

Mesh::Mesh(Data data, const std::string& source)
    : points_(std::move(data.points)),
      faceCounts_(std::move(data.faceCounts)),
      faceIndices_(std::move(data.faceIndices)),
      uvs_(std::move(data.uvs)),
      uvIndices_(std::move(data.uvIndices)),
      topology_(std::make_shared<TopologyCache>()) {
    for (size_t v = 0; v < points_.size(); ++v) {
        if (!geom::isFinite(points_[v])) {
            throw InvalidInput(formatError(source, "vertex " + std::to_string(v),
                                           "has a NaN or infinite coordinate", "finite coordinates"));
        }
    }
    for (size_t t = 0; t < uvs_.size(); ++t) {
        if (!geom::isFinite(uvs_[t])) {
            throw InvalidInput(formatError(source, "uv " + std::to_string(t),
                                           "has a NaN or infinite coordinate", "finite texture coordinates"));
        }
    }
    faceOffsets_.resize(faceCounts_.size() + 1);
    faceOffsets_[0] = 0;
    int64_t total = 0;
    for (size_t f = 0; f < faceCounts_.size(); ++f) {
        if (faceCounts_[f] < 3) {
            throw InvalidInput(formatError(source, "face " + std::to_string(f),
                                           "has " + std::to_string(faceCounts_[f]) + " vertices",
                                           "at least 3 vertices per face"));
        }
        total += faceCounts_[f];  // summed to the end, so that a mismatch names the whole sum
        if (total <= static_cast<int64_t>(faceIndices_.size()))
            faceOffsets_[f + 1] = static_cast<int32_t>(total);
    }
    if (total != static_cast<int64_t>(faceIndices_.size())) {
        throw InvalidInput(formatError(source, "face indices",
                                       "count " + std::to_string(faceIndices_.size()) +
                                           " does not match the face vertex counts, which sum to " +
                                           std::to_string(total),
                                       "one vertex index per face corner"));
    }
    const int32_t nv = numVertices();
    std::unordered_set<int32_t> used;  // a long polygon's corners: checked in one pass, not pair by pair
    for (int32_t f = 0; f < numFaces(); ++f) {
        const auto corners = face(f);
        const bool longFace = corners.size() > 16;
        if (longFace) used.clear();
        for (size_t k = 0; k < corners.size(); ++k) {
            const int32_t v = corners[k];
            if (v < 0 || v >= nv) {
                throw InvalidInput(formatError(source,
                                               "face " + std::to_string(f) + " corner " + std::to_string(k),
                                               "vertex index " + std::to_string(v) + " is out of range",
                                               "an index in [0, " + std::to_string(nv) + ")"));
            }
            const bool twice =
                longFace ? !used.insert(v).second
                         : std::find(corners.begin(), corners.begin() + k, v) != corners.begin() + k;
            if (twice) {
                throw InvalidInput(formatError(source, "face " + std::to_string(f),
                                               "uses vertex " + std::to_string(v) + " twice",
                                               "distinct vertices per face"));
            }
        }
    }
    if (!uvIndices_.empty()) {
        if (uvIndices_.size() != faceIndices_.size()) {
            throw InvalidInput(formatError(source, "uv indices",
                                           "count " + std::to_string(uvIndices_.size()) +
                                               " does not match the face corner count " +
                                               std::to_string(faceIndices_.size()),
                                           "one UV index per face corner, or none"));
        }
        const int32_t nt = numUVs();
        for (int32_t f = 0; f < numFaces(); ++f) {
            const bool without = uvIndices_[faceOffsets_[f]] == -1;
            facesWithoutUVs_ += without ? 1 : 0;
            for (int32_t c = faceOffsets_[f]; c < faceOffsets_[f + 1]; ++c) {
                const int32_t t = uvIndices_[c];
                if (without && t != -1) {
                    throw InvalidInput(formatError(
                        source, "face " + std::to_string(f),
                        "has UVs on some corners only (corner " + std::to_string(c - faceOffsets_[f]) +
                            " has uv index " + std::to_string(t) + ", corner 0 has none)",
                        "a UV index on every corner of a face, or -1 on every corner"));
                }
                if (!without && (t < 0 || t >= nt)) {
                    throw InvalidInput(formatError(source, "face corner " + std::to_string(c),
                                                   "uv index " + std::to_string(t) + " is out of range",
                                                   "an index in [0, " + std::to_string(nt) + ")"));
                }
            }
        }
        if (facesWithoutUVs_ == numFaces()) {
            uvIndices_.clear();  // no face has UVs: the mesh has none
            facesWithoutUVs_ = 0;
        }
    }
}

void Mesh::setPoints(std::span<const glm::vec3> points) {
    if (points.size() != points_.size()) {
        throw InvalidInput(formatError("mesh", "points",
                                       "got " + std::to_string(points.size()) + " positions",
                                       std::to_string(points_.size()) + " positions, one per vertex"));
    }
    for (size_t v = 0; v < points.size(); ++v) {
        if (!geom::isFinite(points[v])) {
            throw InvalidInput(formatError("mesh", "vertex " + std::to_string(v),
                                           "has a NaN or infinite coordinate", "finite coordinates"));
        }
    }
    std::copy(points.begin(), points.end(), points_.begin());
}

Box3 Mesh::bounds() const {
    Box3 box;
    for (const auto& p : points_)
        box.extend(p);
    return box;
}

namespace {

// The UDIM cell (column, row) of a uv, clamped in float before the cast (a UV of 1e30 would not fit an int):
// columns 0 to 9, rows 0 to 899 (tiles 9991 to 9999, the last UDIM row); not finite: 0.
glm::ivec2 tileCell(glm::vec2 uv) {
    const auto cell = [](float c, float last) {
        return std::isfinite(c) ? static_cast<int>(std::clamp(std::floor(c), 0.0f, last)) : 0;
    };
    return {cell(uv.x, 9.0f), cell(uv.y, 899.0f)};
}

// (column, row) of face f's tile: its UV centroid's, clamped into the UDIM range.
glm::ivec2 faceTileCell(std::span<const glm::vec2> uvs, std::span<const int32_t> corners) {
    glm::vec2 centroid(0.0f);
    for (int32_t t : corners)
        centroid += uvs[t];
    centroid /= static_cast<float>(corners.size());
    return tileCell(centroid);
}

}  // namespace

int udimTileOf(const glm::vec2& uv) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return 0;
    // Not clamped into the UDIM range (a point off the tiles names no tile of them: u = -0.3 is 1000), but
    // within +-1e6 before the cast, so that a UV of 1e30 does not overflow the int.
    const auto cell = [](float c) { return static_cast<int>(std::clamp(std::floor(c), -1.0e6f, 1.0e6f)); };
    return 1001 + cell(uv.x) + 10 * cell(uv.y);
}

std::vector<int> Mesh::udimTiles() const {
    std::set<int> tiles;
    for (int32_t f = 0; f < numFaces() && hasUVs(); ++f)
        if (faceHasUVs(f)) tiles.insert(faceUdimTile(f));
    return {tiles.begin(), tiles.end()};
}

int Mesh::faceUdimTile(int32_t f) const {
    if (!faceHasUVs(f)) return 0;
    const glm::ivec2 cell = faceTileCell(uvs_, faceUVIndices(f));
    return 1001 + cell.x + 10 * cell.y;
}

float Mesh::faceUdimOverhang(int32_t f) const {
    if (!faceHasUVs(f)) return 0.0f;
    const auto corners = faceUVIndices(f);
    const glm::vec2 lo(faceTileCell(uvs_, corners));
    const glm::vec2 hi = lo + 1.0f;
    float overhang = 0.0f;
    for (int32_t t : corners) {
        const glm::vec2 outside = glm::max(lo - uvs_[t], uvs_[t] - hi);
        overhang = std::max({overhang, outside.x, outside.y});
    }
    return overhang;
}

UdimOverhang udimOverhang(const Mesh& mesh, int tile, float tolerance) {
    UdimOverhang out;
    for (int32_t f = 0; f < mesh.numFaces() && mesh.hasUVs(); ++f) {
        if (tile != 0 && mesh.faceUdimTile(f) != tile) continue;
        const float overhang = mesh.faceUdimOverhang(f);
        if (!(overhang > tolerance)) continue;
        ++out.faces;
        if (overhang > out.worst) {
            out.worst = overhang;
            out.worstFace = f;
        }
    }
    return out;
}

void requireUdimFacesInTile(const Mesh& mesh, int tile, const std::function<std::string(int tile)>& source,
                            float tolerance) {
    if (!mesh.hasUVs()) return;
    const auto uvs = mesh.uvs();
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const int faceTile = mesh.faceUdimTile(f);
        if (faceTile == 0 || (tile != 0 && faceTile != tile)) continue;
        const float overhang = mesh.faceUdimOverhang(f);
        if (!(overhang > kUdimMaxOverhang + tolerance)) continue;
        const auto corners = mesh.faceUVIndices(f);
        const glm::vec2 origin(faceTileCell(uvs, corners));
        size_t worst = 0;
        float reach = -1.0f;
        for (size_t k = 0; k < corners.size(); ++k) {
            const glm::vec2 uv = uvs[corners[k]] - origin;
            const float outside = std::max({-uv.x, uv.x - 1.0f, -uv.y, uv.y - 1.0f});
            if (outside > reach) {
                reach = outside;
                worst = k;
            }
        }
        const glm::vec2 uv = uvs[corners[worst]];
        const int corner = udimTileOf(uv);
        const bool onTile = uv.x >= 0.0f && uv.x < 10.0f && uv.y >= 0.0f;
        throw InvalidInput(formatError(
            source(faceTile), "face " + std::to_string(f),
            "overhangs the tile by " + std::to_string(overhang) + " (corner " + std::to_string(worst) +
                " at (" + std::to_string(uv.x) + ", " + std::to_string(uv.y) + "), " +
                (onTile ? "in tile " + std::to_string(corner) : std::string("off the UDIM tiles")) + ")",
            "a face whose UV corners reach at most " + std::to_string(kUdimMaxOverhang) +
                " of a tile past the tile of its UV centroid, on the UDIM tiles (0 <= u < 10, v >= 0)"));
    }
}

const HalfEdgeMesh& Mesh::halfEdges() const {
    std::call_once(topology_->once,
                   [this] { topology_->value = std::make_unique<const HalfEdgeMesh>(*this); });
    return *topology_->value;
}

}  // namespace deformkit::geom
