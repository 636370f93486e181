#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/warp/engine.h"

namespace deformkit::warp {

// Parameters of the weighting field (paper §6):
//   w_i(P) = f_{alpha,beta}(|P - P_i| / |E_im|) * prod_j f_{gamma,mu}(((P - P_i) . E_ij) / (E_ij . E_ij))
// where f_ab(t) = 1 for t <= a, 0 for t >= b and 1 - smoothstep((t - a) / (b - a)) between, E_ij the rest
// edge vectors leaving control vertex i and E_im the longest of them. With the defaults a control vertex
// reaches one longest-edge length around it and, along each edge, stops at the edge's far end, so it does
// not compete with its neighbours there (docs/decisions.md).
struct MeshWarpOptions {
    float alpha = 0.0f;  // radial: full weight within alpha * |E_im| of P_i; 0 <= alpha < beta
    float beta = 1.0f;   // radial: zero weight beyond beta * |E_im|
    float gamma = 0.0f;  // along each edge: full weight up to gamma of the edge; gamma < mu
    float mu =
        1.0f;  // along each edge: zero weight from mu of the edge on (1 = the neighbour vertex); mu > 0
    // Singular values of a control vertex's edge matrix below this fraction of the largest are treated
    // as zero (a planar or collinear star); see A_i in MeshWarp.
    double rankTolerance = 1e-6;
    // Cage vertices within this distance (scene units) are one control vertex: a cage with split vertices
    // (glTF, FBX) is welded (geom/weld.h). 0: exactly coincident ones.
    double weldTolerance = 0.0;
};

// f_ab(t) of §6: 1 for t <= a, 0 for t >= b, the C1 cubic 1 - (3x^2 - 2x^3), x = (t - a) / (b - a), between.
[[nodiscard]] float meshWarpFalloff(float t, float a, float b);

// The coarse-mesh warp of paper §6: the vertices of a control mesh (the cage, any topology and genus,
// boundaries allowed, near the surface) are point features with their incident edges. For control
// vertex i with rest position P_i, target P*_i and rest/target edge vectors E_ij, E*_ij (j over its
// neighbours, in the same order):
//   T_i = A_i o X_i : P -> P*_i + L_i (P - P_i),
// X_i the translation P*_i - P_i applied first, then the linear map L_i about the target vertex, so P_i
// maps to P*_i exactly (interpolation, §7.2). L_i is the least-squares map of the edge stars,
// E L_i^T ~ E* (E: k x 3 rows E_ij), solved as L_i^T = I + E^+ (E* - E): equal to the paper's E^+ E* when
// the star spans 3-space, and the minimal-norm *change* from the identity when it does not (a planar
// or collinear star), so a direction no edge constrains is left unchanged rather than collapsed.
// Strength 1 (displacement method), weights above, computed once on the rest surface at bind().
//
// Usage: construct with the rest cage, bind(surface rest points) through WarpDeformer or the engine,
// then setTarget(cage points) and evaluate as often as the controls move; bind work is never redone.
class MeshWarp : public Warp {
  public:
    // Validates the cage and options and precomputes each control vertex's pseudo-inverse E^+. Throws
    // InvalidInput (naming `source` and the element) for an empty cage, a vertex without edges, a
    // zero-length edge, bad options; TopologyError for a non-manifold cage.
    explicit MeshWarp(const geom::Mesh& cage, const MeshWarpOptions& options = {},
                      const std::string& source = "mesh warp");

    // #cage vertices target positions (same order and topology as the rest cage). Throws InvalidInput
    // if the count differs or a coordinate is not finite. Until called, the target is the rest cage. A cage
    // with split vertices (coincident copies, geom/weld.h) is welded at construction: its control vertices
    // are its positions, each target the mean of its copies' targets. Copies farther apart than twice the
    // weld tolerance plus 1% of their shortest cage edge (a torn cage) throw InvalidInput naming both;
    // nothing is set when it throws.
    void setTarget(std::span<const glm::vec3> targetCagePoints);

    // Fields on the rest surface (#points positions): only control vertices with non-zero weight at a
    // point get an entry, found through a uniform grid over the control vertices' supports. Throws
    // InvalidInput on a non-finite point.
    void bind(std::span<const glm::vec3> restPoints, SparseFields& fields) override;
    // T_i for the current target, displacement method; allocates only the first time.
    void transformations(Transformations& out) const override;

    // The least-squares linear part L_i (column-vector convention) for the current target.
    [[nodiscard]] glm::mat3 linearMap(int32_t controlVertex) const;
    // The weight w_i(P) of control vertex i at rest position P (the same code bind() uses).
    [[nodiscard]] float weight(int32_t controlVertex, const glm::vec3& p) const;
    // Rank of the rest edge matrix of control vertex i (3 for a star spanning space).
    [[nodiscard]] int32_t starRank(int32_t controlVertex) const { return rank_[controlVertex]; }

    // Control vertices: the cage's vertices, or its positions when it has split vertices.
    [[nodiscard]] int32_t numControlVertices() const { return static_cast<int32_t>(rest_.size()); }
    [[nodiscard]] int32_t numCageVertices() const { return cageVertices_; }
    // The control vertex of cage vertex v (v itself unless the cage was welded).
    [[nodiscard]] int32_t controlVertexOf(int32_t v) const { return controlOf_.empty() ? v : controlOf_[v]; }
    [[nodiscard]] const MeshWarpOptions& options() const { return options_; }
    [[nodiscard]] std::span<const glm::vec3> restCage() const { return rest_; }
    [[nodiscard]] std::span<const glm::vec3> targetCage() const { return target_; }
    // Neighbours of control vertex i in edge order (the rows of E).
    [[nodiscard]] std::span<const int32_t> neighbors(int32_t controlVertex) const {
        return std::span<const int32_t>(neighbors_)
            .subspan(neighborOffsets_[controlVertex],
                     neighborOffsets_[controlVertex + 1] - neighborOffsets_[controlVertex]);
    }

  private:
    MeshWarpOptions options_;
    std::string source_;
    std::vector<glm::vec3> rest_, target_;
    std::vector<int32_t> neighborOffsets_, neighbors_;
    std::vector<glm::vec3> edges_;    // per neighbour entry: rest E_ij = P_j - P_i
    std::vector<float> invLengthSq_;  // per neighbour entry: 1 / (E_ij . E_ij)
    std::vector<double> pinv_;        // per neighbour entry: the 3 column entries of E^+ (3 x k), column j
    std::vector<float> longest_;      // |E_im| per control vertex
    std::vector<int32_t> rank_;
    int32_t cageVertices_ = 0;
    std::vector<int32_t> controlOf_;  // per cage vertex: its control vertex (empty: the identity)
    std::vector<int32_t> firstCopy_;  // per control vertex: its first cage vertex (empty: the identity)
    [[nodiscard]] int32_t cageVertexOf(int32_t control) const {
        return firstCopy_.empty() ? control : firstCopy_[control];
    }
};

// One-off: bind `cage` to `points` and deform them towards `targetCagePoints` in place, with Maya's
// painted weights (#points or empty) and envelope.
void meshWarp(std::span<glm::vec3> points, const geom::Mesh& cage,
              std::span<const glm::vec3> targetCagePoints, const MeshWarpOptions& options = {},
              std::span<const float> weights = {}, float envelope = 1.0f);

}  // namespace deformkit::warp
