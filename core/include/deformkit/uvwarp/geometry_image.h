#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/finite.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/uvwarp/grid.h"

namespace deformkit::uvwarp {

namespace detail {
struct TileUVs;  // a tile's UV triangles (uvwarp/tile_uvs.h, private to the library)
}  // namespace detail

// Geometry images f_O and f_D (paper §3): the 3D positions of a mesh sampled at the warp grid's points in
// one UDIM tile's UV space, so that f(uv) can be looked up bilinearly anywhere in the unit square.
//
// Covered points: the tile's faces (those whose UV centroid lies in the tile) are fan-triangulated
// (geom::triangulate) and rasterised at the (n + 1)^2 grid points, point (i, j) being the raster pixel
// centre of tile-local uv (i / n, j / n) (raster coordinates uv * n + 0.5, top-left rule). Points within
// 1/1000 of a cell of a chart border count as covered too, so a chart's outline is sampled. Where UV
// triangles overlap, the last one in face order wins. A covered point's value is the barycentric blend of
// its triangle's 3D corners; the imager keeps the covering triangles as runs per row and computes the
// barycentrics each frame as the rasteriser does (a few bytes a row, not 12 a point).
//
// Dilation past chart borders, so bilinear look-ups near seams read valid data: uncovered points are
// filled ring by ring (ring r: Chebyshev distance r from the covered points), each from points of earlier
// rings. A point continues the data linearly (2 f(q) - f(q2) with q = p + d and q2 = p + 2d both filled
// by earlier rings, d a grid direction), averaged over the axis directions where that is possible, else
// over the diagonal ones; where no direction has two such points it copies the average of its filled
// neighbours (axis first, then diagonal). Every weight set sums to 1, so the geometry image of an
// affinely moved mesh is the moved image, and data affine in uv continue exactly wherever a linear
// continuation exists (past straight and convex chart borders). Points beyond `dilationRings` copy the
// nearest covered point (Euclidean, exact distance transform; ties go to the lower column, then the lower
// row). The rings and weights are computed once at bind; each frame only re-applies them.
// The largest coordinate magnitude a surface sampled for the UV warp may have: the solver measures squared
// lengths in float (a mesh scaled to 1e18 gave NaN positions).
inline constexpr float kMaxCoordinate = geom::kMaxSquaredCoordinate;

// The first of `points` with a coordinate that is not finite or beyond kMaxCoordinate in magnitude, or
// points.size() when there is none.
[[nodiscard]] size_t firstUnusablePoint(std::span<const glm::vec3> points);

struct GeometryImageOptions {
    int32_t dilationRings = 4;   // rings of linear continuation past chart borders, 0..64
    std::string label = "mesh";  // names the mesh in errors, e.g. "rest.obj" or "mesh 'body'"
};

class GeometryImager {
  public:
    // Binds the rest mesh's UV layout in `tile` on a grid of `cells` x `cells` cells (n, a power of two,
    // at most 32768). Throws InvalidInput naming the mesh label for: a mesh without UVs, a tile number
    // that is not a UDIM tile, a face of this tile (geom::Mesh::faceUdimTile) whose UV corners overhang it
    // by more than 0.1 of a tile (naming the face), a tile holding no UV triangle, cells not a power of
    // two, dilationRings out of range.
    GeometryImager(const geom::Mesh& rest, int tile, int32_t cells, const GeometryImageOptions& options = {});
    // The same from the tile's UV triangles already collected from `rest` (uvwarp/tile_uvs.h).
    GeometryImager(const geom::Mesh& rest, const detail::TileUVs& uvs, int32_t cells,
                   const GeometryImageOptions& options = {});

    [[nodiscard]] int tile() const { return tile_; }
    [[nodiscard]] int32_t cells() const { return cells_; }
    [[nodiscard]] int32_t side() const { return cells_ + 1; }
    [[nodiscard]] int32_t numVertices() const { return numVertices_; }
    // (n + 1)^2 flags, point (i, j) at j * (n + 1) + i: 1 where a UV triangle of the tile covers the point.
    // Made on each call from the imager's runs (it keeps no per-point data).
    [[nodiscard]] std::vector<uint8_t> coverage() const;
    // How many points are covered, reached by the dilation rings, and filled by the nearest covered point.
    [[nodiscard]] int64_t numCovered() const { return numCovered_; }
    [[nodiscard]] int64_t numDilated() const { return static_cast<int64_t>(dilatedPoint_.size()); }
    [[nodiscard]] int64_t numFar() const { return static_cast<int64_t>(farPoint_.size()); }

    // Fills `out` (cells n, 3 channels, (n + 1)^2 points) with the geometry image of `positions`: #V 3D
    // positions with the rest mesh's topology (the rest positions give f_O, a deformed frame f_D). Scene
    // units. Allocates only when `out` is not yet sized; OpenMP over rows, bit-identical for any thread
    // count. Throws InvalidInput naming the mesh label for a vertex count other than the rest mesh's or a
    // position not finite or beyond kMaxCoordinate (naming the vertex).
    void sample(std::span<const glm::vec3> positions, PointField& out) const;
    [[nodiscard]] PointField sample(std::span<const glm::vec3> positions) const;

  private:
    GeometryImager(const geom::Mesh& rest, int tile, int32_t cells, const GeometryImageOptions& options,
                   const detail::TileUVs* collected);

    int tile_ = 0;
    int32_t cells_ = 0;
    int32_t numVertices_ = 0;
    std::string label_;
    // Tile triangles, structure of arrays: vertex indices into the positions.
    std::vector<int32_t> cornerA_, cornerB_, cornerC_;
    // Raster coordinates of each triangle's UV corners (uv * n + 0.5), 3 per triangle: a covered point's
    // barycentrics are computed again from them each frame, as the rasteriser computed them.
    std::vector<glm::vec2> rasterCorners_;
    // The rasterised triangles, run-length coded per row of points (a few bytes a row, not 12 a point): row j
    // holds runs r in [rowRunBegin_[j], rowRunBegin_[j + 1]), run r covering points [runStart_[r], the next
    // run's start or the row's end) with triangle runTriangle_[r] (-1: not covered by the rasteriser).
    std::vector<int64_t> rowRunBegin_;
    std::vector<int32_t> runStart_, runTriangle_;
    // Points on a chart's outline covered by the border walk (not the rasteriser), with their triangle and
    // the barycentrics of corners B and C.
    std::vector<int32_t> outlinePoint_, outlineTriangle_;
    std::vector<float> outlineB_, outlineC_;
    int64_t numCovered_ = 0;
    // Dilation rings: ring r holds dilatedPoint_[ringBegin_[r - 1], ringBegin_[r]); dilated point d is
    // sum_k weight_[k] * value(source_[k]) over k in [entryBegin_[d], entryBegin_[d + 1]).
    std::vector<int64_t> ringBegin_;
    std::vector<int32_t> dilatedPoint_;
    std::vector<int64_t> entryBegin_;
    std::vector<int32_t> source_;
    std::vector<float> weight_;
    // Points beyond the rings and the covered point each copies.
    std::vector<int32_t> farPoint_, farSource_;
};

// Bilinear look-up of a 3-channel point field at tile-local (u, v), each clamped to [0, 1]: the reference
// for f_D(W(p)) look-ups. At a grid point it returns the point's value exactly. Throws InvalidInput if
// the field is not a 3-channel field with (cells + 1)^2 points.
[[nodiscard]] glm::vec3 bilinearLookup(const PointField& field, float u, float v);

}  // namespace deformkit::uvwarp
