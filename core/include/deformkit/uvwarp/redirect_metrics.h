#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/metrics.h"

namespace deformkit::uvwarp {

namespace detail {
struct TileUVs;  // a tile's UV triangles (uvwarp/tile_uvs.h, private to the library)
}  // namespace detail

// What a redirect map delivers, measured on the map a renderer reads, not on the solver's grid. Texel q of
// the tile (its centre, tile-local uv) shows the rest-pose content at r = R(q); f_D is the deformed mesh and
// f_O the rest mesh as functions of UV (barycentric over the tile's UV triangles).
struct DeliveredMetrics {
    // Rigid-stretch error: the mean, over 4-connected texel edges (a, b) whose texels lie in one chart and
    // whose content r_a and r_b both lies where the rigidity map is >= 0.5, of
    //   | |f_D(q_b) - f_D(q_a)| / |f_O(r_b) - f_O(r_a)| - 1 |.
    // The identity's (r = q) is the stretch the texture would show without the warp. An edge whose texels
    // show one point of the map (r_a = r_b: content collapsed to a point, smeared over the edge) counts with
    // an error of 1, the error of the ratio taken the other way, rest over deformed; an edge whose rest
    // length is not measurable otherwise (at most 1e-9 of the rest mesh's bounding-box diagonal: a
    // degenerate rest surface) is left out, through the map as at the identity.
    double rigidStretchError = 0.0;
    double identityStretchError = 0.0;
    // 1 - rigidStretchError / identityStretchError: the share of the rigid stretch removed; 0 when the
    // identity has none, and when the map shows none of the rigid content the identity shows (no rigid
    // edge through the map: nothing of it is removed, it is gone).
    double removed = 0.0;
    int64_t rigidEdges = 0;          // edges averaged over, through the map
    int64_t identityRigidEdges = 0;  // and for the identity
    // Triangles of the texel-centre grid of R (every cell split along both diagonals, 4 triangles a cell)
    // whose signed area in r has the opposite sign of the identity's: where a texture shows folded.
    int64_t invertedTriangles = 0;
    // Chart texels (centres inside a UV triangle of the tile) whose r lies in no UV triangle: texels that
    // show content from outside every chart.
    int64_t offChartTexels = 0;
    int64_t chartTexels = 0;
};

// Where on the tile measure()'s figures come from, texel by texel (a shot report's heatmaps). T x T x 1
// images, rows from the top, as the redirect map.
struct DeliveredTexels {
    // Per texel: the mean of | |f_D(q_b) - f_D(q_a)| / |f_O(r_b) - f_O(r_a)| - 1 | over the edges to its
    // right and lower neighbours that measure() averages through the map; NaN where it counts none.
    io::Image stretch;
    io::Image identityStretch;  // the same for the identity (r = q)
    io::Image folds;     // 1 where the texel is the top-left corner of a cell with an inverted triangle
    io::Image offChart;  // 1 at an off-chart texel
    io::Image chart;     // 1 at a chart texel (its centre in a UV triangle of the tile)
};

// The delivered figures of one UDIM tile, bound once to the rest mesh's UV triangles of the tile and the
// rigidity map (which sets the redirect map's size, T x T), measured per frame from the deformed positions
// and the frame's redirect map. OpenMP over bands of rows, sums in a fixed order: bit-identical for any
// thread count. Memory: 4 bytes a texel (the rigidity map's channel 0); the UV triangles under the texels are
// kept as runs per row.
class RedirectMetrics {
  public:
    // rest: the mesh with UVs; rigidity: T x T, channel 0 in [0, 1] (a 1-channel map passed with std::move
    // is kept without a copy). `source` names the inputs in errors. Throws InvalidInput for a mesh without
    // UVs, a tile it has no face in, or a non-square or empty map.
    RedirectMetrics(const geom::Mesh& rest, int tile, io::Image rigidity, const std::string& source = "tile");
    // The same from the tile's UV triangles already collected from `rest` (uvwarp/tile_uvs.h).
    RedirectMetrics(const geom::Mesh& rest, detail::TileUVs uvs, io::Image rigidity,
                    const std::string& source = "tile");
    ~RedirectMetrics();
    RedirectMetrics(RedirectMetrics&&) noexcept;
    RedirectMetrics& operator=(RedirectMetrics&&) noexcept;

    // A new rigidity map of the same size (an animated map); kept as the constructor keeps it.
    void setRigidity(io::Image rigidity);
    // deformed: #V positions of the rest mesh's vertices; redirect: T x T, channels 0 and 1 the tile-local
    // r = (u', v') (invertWarp's layout, row 0 at v = 1). `texels`, when given, receives where the figures
    // come from. Throws InvalidInput for another vertex count or map size, or a non-finite redirect texel
    // (naming it).
    [[nodiscard]] DeliveredMetrics measure(std::span<const glm::vec3> deformed, const io::Image& redirect,
                                           DeliveredTexels* texels = nullptr) const;

    // Whether texel (x, y) may show the rest content at tile-local r without counting as off-chart: true for
    // a texel outside every chart, and for a chart texel when r lies in a UV triangle of the tile.
    [[nodiscard]] bool mayShow(int32_t x, int32_t y, glm::dvec2 r) const;
    // Appends the columns x of row y of `redirect` (T x T, channels 0 and 1 r) whose content mayShow
    // refuses, ascending.
    void refusedInRow(const io::Image& redirect, int32_t y, std::vector<int32_t>& refused) const;

    [[nodiscard]] int32_t texels() const;
    // The bound rigidity map's channel 0 (T x T x 1).
    [[nodiscard]] const io::Image& rigidity() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The figures of `m` as hosts report them (metrics.h): rigid_stretch_error, identity_stretch_error,
// rigid_stretch_removed, rigid_edges, identity_rigid_edges, inverted_triangles, off_chart_texels,
// chart_texels.
[[nodiscard]] std::vector<ReportedFigure> reportedFigures(const DeliveredMetrics& m);

// The inverted triangles of a redirect map alone (DeliveredMetrics::invertedTriangles).
[[nodiscard]] int64_t countInvertedTriangles(const io::Image& redirect);

}  // namespace deformkit::uvwarp
