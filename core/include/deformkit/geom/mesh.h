#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/box.h"

namespace deformkit::geom {

class HalfEdgeMesh;

// A polygon mesh: float32 positions, faces as counts + offsets + vertex indices (triangles, quads,
// n-gons), optional face-varying UVs (values + one index per face corner).
//
// Connectivity (faces, UV indices) is fixed at construction and validated there; positions may change
// (a deformer writes them), which is why the half-edge structure, built on demand and cached, depends
// on connectivity alone and is shared by copies of the mesh.
class Mesh {
  public:
    struct Data {
        std::vector<glm::vec3> points;     // #V positions, scene units
        std::vector<int32_t> faceCounts;   // #F vertex counts, each >= 3
        std::vector<int32_t> faceIndices;  // sum(faceCounts) vertex indices in [0, #V), face by face
        std::vector<glm::vec2> uvs;  // #UV texture coordinates (UDIM: tile 1001 + floor(u) + 10 floor(v))
        // Empty, or one index into uvs per face corner; -1 on every corner of a face without UVs (OBJ files
        // mix such faces with UV'd ones: they belong to no UDIM tile).
        std::vector<int32_t> uvIndices;
    };

    Mesh();
    // Validates `data` and throws InvalidInput naming `source` (a file path or a label) and the first
    // bad element: a face with fewer than 3 vertices or a repeated vertex, an index out of range, a
    // NaN or infinite coordinate, UV indices that do not match the corners, a face with UVs on some corners
    // only.
    explicit Mesh(Data data, const std::string& source = "mesh");

    [[nodiscard]] int32_t numVertices() const { return static_cast<int32_t>(points_.size()); }
    [[nodiscard]] int32_t numFaces() const { return static_cast<int32_t>(faceCounts_.size()); }
    [[nodiscard]] int32_t numCorners() const { return static_cast<int32_t>(faceIndices_.size()); }
    [[nodiscard]] int32_t numUVs() const { return static_cast<int32_t>(uvs_.size()); }
    // True when some face has UVs.
    [[nodiscard]] bool hasUVs() const { return !uvIndices_.empty(); }
    // Faces without UVs in a mesh that has UVs (0 without UVs at all).
    [[nodiscard]] int32_t numFacesWithoutUVs() const { return facesWithoutUVs_; }
    [[nodiscard]] bool faceHasUVs(int32_t f) const {
        return !uvIndices_.empty() && uvIndices_[faceOffsets_[f]] >= 0;
    }

    [[nodiscard]] std::span<const glm::vec3> points() const { return points_; }
    // Mutable positions for deformers; the vertex count cannot change.
    [[nodiscard]] std::span<glm::vec3> points() { return points_; }
    // Replaces every position; throws InvalidInput if the count differs or a value is not finite.
    void setPoints(std::span<const glm::vec3> points);

    [[nodiscard]] std::span<const int32_t> faceCounts() const { return faceCounts_; }
    // #F + 1 offsets into faceIndices(); face f spans [faceOffsets()[f], faceOffsets()[f + 1]).
    [[nodiscard]] std::span<const int32_t> faceOffsets() const { return faceOffsets_; }
    [[nodiscard]] std::span<const int32_t> faceIndices() const { return faceIndices_; }
    [[nodiscard]] std::span<const int32_t> face(int32_t f) const {
        return std::span<const int32_t>(faceIndices_).subspan(faceOffsets_[f], faceCounts_[f]);
    }
    [[nodiscard]] std::span<const glm::vec2> uvs() const { return uvs_; }
    [[nodiscard]] std::span<glm::vec2> uvs() { return uvs_; }
    [[nodiscard]] std::span<const int32_t> uvIndices() const { return uvIndices_; }
    // The UV indices of face f's corners; empty when the face has no UVs.
    [[nodiscard]] std::span<const int32_t> faceUVIndices(int32_t f) const {
        if (!faceHasUVs(f)) return {};
        return std::span<const int32_t>(uvIndices_).subspan(faceOffsets_[f], faceCounts_[f]);
    }

    [[nodiscard]] Box3 bounds() const;
    // The sorted UDIM tile numbers of the faces with UVs (faceUdimTile). Empty without UVs.
    [[nodiscard]] std::vector<int> udimTiles() const;
    // The UDIM tile face f belongs to: the tile of its UV centroid, the centroid's column clamped to 0..9
    // and its row to >= 0, so a face overhanging the left or bottom edge of the UV space stays in the tile
    // it overhangs. 0 for a face without UVs.
    [[nodiscard]] int faceUdimTile(int32_t f) const;
    // How far face f's UV corners reach outside its tile (faceUdimTile), in tile widths (UV units): 0 for
    // a face inside its tile, and without UVs.
    [[nodiscard]] float faceUdimOverhang(int32_t f) const;

    // The half-edge connectivity, built on first use and cached (thread-safe).
    [[nodiscard]] const HalfEdgeMesh& halfEdges() const;

  private:
    struct TopologyCache;

    std::vector<glm::vec3> points_;
    std::vector<int32_t> faceCounts_;
    std::vector<int32_t> faceOffsets_;
    std::vector<int32_t> faceIndices_;
    std::vector<glm::vec2> uvs_;
    std::vector<int32_t> uvIndices_;
    int32_t facesWithoutUVs_ = 0;
    std::shared_ptr<TopologyCache> topology_;
};

// UDIM tile number of a UV coordinate: 1001 + floor(u) + 10 floor(v), each floor kept within +-1e6 (a tile
// number for u in [0, 10), v >= 0; off the tiles, a number no tile has); 0 for a non-finite coordinate.
[[nodiscard]] int udimTileOf(const glm::vec2& uv);

// Faces whose UV corners reach outside their UDIM tile by more than `tolerance` (UV units): how many, the
// one that reaches farthest and how far. Only faces of `tile`, or of every tile when tile is 0.
struct UdimOverhang {
    int32_t faces = 0;
    int32_t worstFace = -1;
    float worst = 0.0f;
};
[[nodiscard]] UdimOverhang udimOverhang(const Mesh& mesh, int tile = 0, float tolerance = 1e-5f);

// How far (UV units, tile widths) a face's corners may overhang its tile (Mesh::faceUdimTile): the overhang
// of artists' layouts (a few corners past a tile edge), drawn as far as the tile reaches; beyond it a face
// lies in two tiles, or off every tile (u < 0, u >= 10, v < 0), and no tile's image holds it.
inline constexpr float kUdimMaxOverhang = 0.1f;
// Throws InvalidInput naming `source` (a function of the tile), the face, its corner farthest out and the
// tile that corner lies in, for the first face of `tile` (every tile: 0) that overhangs its tile by more
// than kUdimMaxOverhang (plus `tolerance`, for UVs rounded on a tile border).
void requireUdimFacesInTile(const Mesh& mesh, int tile, const std::function<std::string(int tile)>& source,
                            float tolerance = 1e-5f);

}  // namespace deformkit::geom
