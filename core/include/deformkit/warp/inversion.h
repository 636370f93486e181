#pragma once

#include "deformkit/warp/engine.h"

namespace deformkit::warp {

// Inverting a warp by inverting its transformations (paper §7.4): for a feature-based warp this is
// what swapping source and target features does to each T_i. Each transformation is replaced by its
// inverse; the fields stay the ones computed on the *undeformed* model (precomputed, §7.1/§7.4), so
// the inverse warp is evaluated on the deformed points with the forward warp's weights and strengths.
//
// The result is exactly D(u)^-1 wherever the weighted average of (s_i . T_i) at u commutes with
// inversion: every active T_i a translation (FFD, point-feature warps), all active T_i equal (a rigid
// motion of a whole mesh-warp cage), or a single active T_i with strength 1 (a point at a mesh-warp
// control vertex). Elsewhere the average of inverses is not the inverse of the average and the result
// is only approximate (docs/decisions.md, INV-1).
//
// Displacement method: Affine inverse. Composition method: the inverse affine map re-decomposed about
// the image of the pivot (T<pivot> = pivot + translation), so its components (-translation, the
// inverse rotation, ...) scale back towards the identity. Throws InvalidInput naming the
// transformation if one is singular.
[[nodiscard]] Transformations invertedTransformations(const Transformations& transforms);
// The same into `out`, reusing its storage (no allocation once sized); out must not alias transforms.
void invertedTransformations(const Transformations& transforms, Transformations& out);

// The inverse warp of `forward` as a Warp of its own: bind() computes the forward warp's fields on the
// rest (undeformed) model; transformations() inverts the forward warp's current transformations. Bind
// a WarpDeformer over it to the rest points, then evaluate it on the deformed points.
class InvertedWarp : public Warp {
  public:
    explicit InvertedWarp(Warp& forward) : forward_(forward) {}

    void bind(std::span<const glm::vec3> restPoints, SparseFields& fields) override {
        forward_.bind(restPoints, fields);
    }
    void transformations(Transformations& out) const override;
    [[nodiscard]] EngineOptions engineOptions() const override { return forward_.engineOptions(); }

  private:
    Warp& forward_;
    mutable Transformations forwardTransforms_;  // scratch, reused between evaluations
};

}  // namespace deformkit::warp
