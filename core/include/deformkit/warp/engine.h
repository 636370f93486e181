#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/warp/transform.h"

namespace deformkit::warp {

// Discrete strength and weighting fields (paper §3.5, Fig. 9), sparse per point: point u is influenced
// only by the entries [offsets[u], offsets[u + 1]), so a point pays only for the transformations whose
// weight is non-zero there. Built by a warp's bind() on the rest model and cached.
struct SparseFields {
    std::vector<int32_t> offsets{0};  // #points + 1
    std::vector<int32_t> transform;   // index into the warp's transformations, per entry
    std::vector<float> strength;      // s_i(u, M), per entry
    std::vector<float> weight;        // w_i(u, M) >= 0, un-normalised, per entry

    [[nodiscard]] int32_t numPoints() const { return static_cast<int32_t>(offsets.size()) - 1; }
    void clear() {
        offsets.assign(1, 0);
        transform.clear();
        strength.clear();
        weight.clear();
    }
    void add(int32_t t, float s, float w) {
        transform.push_back(t);
        strength.push_back(s);
        weight.push_back(w);
    }
    void endPoint() { offsets.push_back(static_cast<int32_t>(transform.size())); }
};

enum class ScaleMethod {
    Displacement,  // s . T = s T + (1 - s) I
    Composition,   // each component of T scaled by s, then recomposed
};

// The discrete transformations T_i of a warp for its current controls. With the displacement method
// `affine` is used; with the composition method `components` (one per transformation).
struct Transformations {
    ScaleMethod method = ScaleMethod::Displacement;
    std::vector<Affine> affine;
    std::vector<Components> components;

    [[nodiscard]] int32_t size() const {
        return static_cast<int32_t>(method == ScaleMethod::Displacement ? affine.size() : components.size());
    }
};

struct EngineOptions {
    // Multiplies each weight by |(s . T)<P> - P|^m: the Wires weighting (paper §4.4), 0 for other warps.
    float displacementWeightExponent = 0.0f;
};

// Eq. (3): D(u)<P> = P + sum_i w^_i (s_i . T_i)<P> - P), weights normalised per point; a point whose
// weights are all zero is left where it is. points and out: #points positions (they may alias).
// Deterministic for any thread count (OpenMP over points, no reductions across points). Throws
// InvalidInput if sizes disagree or a field names a transformation that does not exist.
void evaluateWarp(std::span<const glm::vec3> points, const SparseFields& fields,
                  const Transformations& transforms, std::span<glm::vec3> out,
                  const EngineOptions& options = {});

// A warp's construction function (paper §3.5): turns the user's parameters into discrete
// transformations, strength fields and weighting fields. A studio adds a warp by implementing this
// interface alone (docs/warps/custom_warp.md).
class Warp {
  public:
    virtual ~Warp() = default;
    // Fields on the rest model, computed once per rest shape; may also cache per-point data the
    // warp's transformations depend on (a point's coordinate along an axis, say).
    virtual void bind(std::span<const glm::vec3> restPoints, SparseFields& fields) = 0;
    // The transformations for the current controls; called on every evaluation after bind().
    virtual void transformations(Transformations& out) const = 0;
    [[nodiscard]] virtual EngineOptions engineOptions() const { return {}; }
};

// Maya's deformer model over any Warp: bind once (the fields on the rest model), then evaluate many times.
// update() takes the warp's current controls (recomputes its transformations); apply() runs Eq. (3) with
// them. The host layer's engine-backed deformers (beierneely, meshwarp) are this class behind parameters.
class WarpDeformer {
  public:
    // `source` names the deformer in errors ("MeshWarp", a stack entry's label).
    explicit WarpDeformer(Warp& warp, std::string source = "warp deformer")
        : warp_(warp), source_(std::move(source)) {}

    // Fields on the rest points. Throws InvalidInput when the warp's fields do not cover every point once.
    void bind(std::span<const glm::vec3> restPoints);
    [[nodiscard]] bool isBound() const { return bound_; }
    [[nodiscard]] const SparseFields& fields() const { return fields_; }

    // The warp's transformations for its current controls.
    void update();
    // Eq. (3) with the transformations of the last update(): in (the bound points, or upstream points of the
    // same count) deformed into out (#points; may alias in). Allocates nothing.
    void apply(std::span<const glm::vec3> in, std::span<glm::vec3> out) const;
    // update() and apply() in place, then painted weights (#points, or empty for 1) and the envelope as
    // applyEnvelope (warp/envelope.h) says; a point that came in not finite, or whose result is not, is
    // refused by name (requireFiniteResult), the points then unchanged.
    void evaluate(std::span<glm::vec3> points, std::span<const float> weights = {}, float envelope = 1.0f);

  private:
    void requireBound(size_t points) const;

    Warp& warp_;
    std::string source_;
    SparseFields fields_;
    Transformations transforms_;
    std::vector<glm::vec3> deformed_;
    bool bound_ = false;
};

}  // namespace deformkit::warp
