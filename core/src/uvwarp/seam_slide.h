#pragma once

// Private to core/src/uvwarp: content slid along seams, the same way on both sides (TileWarpOptions::
// seamSlide, docs/decisions.md UV-42).
//
// The derived warp mask fixes the points on chart borders, so rigid detail next to a seam keeps the stretch
// the pose gives it along the seam. A seam is a chain of mesh edges of which the tile holds two UV copies,
// one in each chart. Along each chain the stretch is undone in one dimension: content at chain parameter t
// (edge index + fraction along it) is shown at parameter phi(t), and both copies read the same phi, so the
// two charts show the same 3D point at each seam point and the seam stays continuous in a render. phi
// minimises, over sub-segments of about a texel, sum_j w_j (y_{j+1} - y_j - c_j)^2 + mu sum_b y_b^2 with y
// the displacements of the sub-segment ends along the deformed chain: rigid content (the rigidity within a
// few texels across the seam) asks for its rest 3D length with weight rho, elastic content for its deformed
// length with a small weight, and mu keeps a slide local. Chains end, fixed, where charts meet (a mesh point
// on three or more border copies, or where the copies change) and at borders that are not seams of the tile
// (open borders, seams into another UDIM tile); a closed loop of seam is held at its lowest-numbered point.
//
// A grid's points nearest to a chain copy then sit where the content they hold is shown: point p, nearest to
// the copy at parameter t, moves along the copy from uv(t) to uv(t + w (phi(t) - t)), w its share: 1 within
// kBand cells of it (the derived mask's default band of one texel fixes points within about 1.5), fading to
// 0 over kFade more cells into the chart and half-way to another border. Fixed
// points stay there; the others start there when a solve starts from the identity (Solver::placePoints).
// Where that folds a grid cell, the chains of its slid corners slide half as far around them, on both copies
// at once, until no cell folds: the placement is fold-free by construction. phi and the repair are shared by
// a seam's two copies; a point's share w depends on its own side's distances, so where a seam's UV outline
// turns near another border its two sides may differ by a few texels (docs/uvwarp.md, limits).

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "tile_uvs.h"

namespace deformkit::uvwarp::detail {

// The points of one grid that slide, and where the last frame puts them (Solver::placePoints).
struct SlidPoints {
    std::vector<int64_t> index;  // k = j * (n + 1) + i, ascending
    std::vector<float> u, v;     // tile-local UV
};

class SeamSlide {
  public:
    // Rigid content asks for its rest length with weight rho, elastic content for its deformed length with
    // this weight (relative to rho = 1).
    static constexpr double kElasticWeight = 0.03;
    // Sub-segments (about a texel each) over which a slide fades in elastic content: mu = kElasticWeight /
    // kReach^2.
    static constexpr double kReach = 16.0;
    // Texels across a seam whose rigidity its content takes: the map's texels / kNearShare (6 at 1024^2), at
    // least kLeastNear.
    static constexpr int32_t kNearShare = 170;
    static constexpr int32_t kLeastNear = 2;
    // Grid cells into a chart over which a point's share of the slide fades from 1 to 0, past the band.
    static constexpr float kFade = 6.0f;
    static constexpr float kBand = 2.0f;

    // rest: the bound mesh; uvs: its tile's UV triangles and chart borders; rigidity: the T x T map.
    SeamSlide(const geom::Mesh& rest, const TileUVs& uvs, const io::Image& rigidity);

    // The rigidity along the chains from a new map of the same size (a painter's edit).
    void setRigidity(const io::Image& rigidity);
    // Registers a grid of `cells` cells; returns its id.
    int addGrid(int32_t cells);
    // A frame: phi of every chain from the deformed positions of the mesh's points, and every grid's points.
    void update(std::span<const glm::vec3> deformed);
    [[nodiscard]] const SlidPoints& points(int id) const { return grids_[static_cast<size_t>(id)].slid; }
    [[nodiscard]] int32_t chains() const { return static_cast<int32_t>(chains_.size()); }
    // Where the content at parameter t of chain c is shown (phi), for tests.
    [[nodiscard]] float shownAt(int32_t c, float t) const {
        return chains_[static_cast<size_t>(c)].shownAt(t);
    }
    [[nodiscard]] std::span<const int32_t> chainPoints(int32_t c) const {
        return chains_[static_cast<size_t>(c)].points;
    }

  private:
    struct Chain {
        std::vector<int32_t> points;               // mesh points p_0 .. p_k
        std::array<std::vector<glm::vec2>, 2> uv;  // per copy: UV of p_0 .. p_k
        std::vector<int32_t> firstSub;             // per edge: its first sub-segment; k + 1 entries
        std::vector<float> restLength;             // per sub-segment: rest 3D length
        std::vector<float> rigidity;               // per sub-segment: the most within the window, both copies
        std::vector<float> phi;                    // per sub-segment end: the parameter it is shown at
        [[nodiscard]] int32_t edges() const { return static_cast<int32_t>(points.size()) - 1; }
        [[nodiscard]] glm::vec2 at(size_t copy, float t) const;
        [[nodiscard]] float shownAt(float t) const;
        [[nodiscard]] int32_t subOf(float t) const;  // the sub-segment parameter t lies in
    };
    struct Anchor {
        int32_t chain, copy;
        float t;         // chain parameter of the point's nearest point on the copy
        int32_t sub;     // the sub-segment t lies in
        float weight;    // the share of the slide it takes
        glm::vec2 rest;  // the point's rest position
    };
    struct Grid {
        int32_t cells = 0;
        std::vector<Anchor> anchors;                // one per slid point, in the order of slid.index
        std::vector<int32_t> rowBegin;              // per grid row j: its first anchor; n + 2 entries
        std::vector<std::vector<int32_t>> byChain;  // per chain: its anchors (both copies) by t
        SlidPoints slid;
    };

    static void sampleRigidity(Chain& chain, const io::Image& rigidity);
    void solveChain(Chain& chain, std::span<const glm::vec3> deformed);
    void place(Grid& grid);

    std::vector<Chain> chains_;
    std::vector<std::array<glm::vec2, 2>> still_;  // border copies that do not slide
    std::vector<Grid> grids_;
    // A frame's working buffers (solveChain, place), kept between frames.
    struct Scratch {
        std::vector<double> length, delta, w, c, y, upper, rhs, shown;
        std::vector<std::vector<float>> scale;
        std::vector<std::vector<uint8_t>> halvings;
        std::vector<glm::vec2> shift;
        std::vector<int32_t> lowerRow, upperRow;
        std::vector<uint8_t> checked;
        std::vector<int64_t> folded, around;
        std::vector<std::pair<int32_t, int32_t>> subs;
    } scratch_;
};

}  // namespace deformkit::uvwarp::detail
