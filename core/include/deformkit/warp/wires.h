#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/warp/engine.h"

namespace deformkit::warp {

// "Wires" (paper §4.4, Singh and Fiume 1998) and its smooth variant (§5.3). Each wire pairs a reference
// curve C(v) (its shape at bind time) with a wire curve C*(v) (the animated shape); both are polylines
// with the same number of points, point j of one corresponding to point j of the other (sample a cubic
// curve with sampleCurve(), curve.h, to use one). A point P near the reference curve moves by the scaled
// transformation s . T(v) = X . R . S of the curve point C(v) it is attached to: S a uniform scale x about
// C(v), R the minimal rotation taking the reference tangent to the wire tangent (about C(v)), X the
// translation C*(v) - C(v); s = f(|P - C(v)| / r); transformations scaled by the composition method.
// Decisions (parameterisation, tangents, quadrature, m): docs/decisions.md.

enum class WiresVariant {
    Original,  // §4.4: each point follows only the nearest point of each reference curve (smallest
               // parameter on ties); interpolating, but discontinuous across the curve's medial set
    Smooth,    // §5.3: each point follows every sample of the curve within the dropoff radius, weighted
               // by f(|P - C(v_k)| / r) times the arc length the sample stands for; continuous
};

// The falloff f(t) on t = distance / radius: f(0) = 1, f(t) = 0 for t >= 1, f'(0) = f'(1) = 0, values in
// [0, 1]. The default is the cubic 1 - 3t^2 + 2t^3. A user ramp is given by values at uniform t_j = j/(n-1)
// and interpolated by a C1 piecewise cubic Hermite: zero slopes at both ends, interior slopes the harmonic
// mean of the neighbouring secants (zero at a local extremum), so the ramp never overshoots its samples.
class Falloff {
  public:
    Falloff() = default;  // the cubic 1 - 3t^2 + 2t^3
    // values: n >= 2 samples in [0, 1], values.front() == 1, values.back() == 0. Throws InvalidInput naming
    // the sample otherwise. `name` labels the ramp in messages ("wire 2 falloff").
    [[nodiscard]] static Falloff fromSamples(std::vector<float> values, std::string_view name = "falloff");

    [[nodiscard]] float operator()(float t) const;
    [[nodiscard]] const std::vector<float>& samples() const { return values_; }  // empty for the cubic

  private:
    std::vector<float> values_, slopes_;  // slopes in value per unit t
};

// One wire feature F_i = (C_i, C*_i, f_i, r_i, x_i) (paper §4.4). m is shared by all wires (WiresOptions).
struct Wire {
    std::vector<glm::vec3> reference;  // C: >= 2 points, scene units; its total length must be > 0
    std::vector<glm::vec3> wire;       // C*: as many points as reference
    float radius = 1.0f;               // r, the dropoff distance, scene units, > 0
    float scale = 1.0f;                // x, uniform scale about C(v) at full strength, > 0
    Falloff falloff;
};

struct WiresOptions {
    WiresVariant variant = WiresVariant::Original;
    // m >= 0: weights |(s . T)<P> - P|^m, so with m > 0 a wire that moves a point more dominates one that
    // moves it less, and a wire that does not move it has no say (the engine's displacementWeightExponent).
    float exponent = 1.0f;
    // Smooth variant: K samples per wire, uniform in the reference curve's arc length (trapezoidal rule).
    // 0 = automatic: K = ceil(8 L / r) + 1 clamped to [16, 4096], eight samples per radius of length L.
    int32_t smoothSamples = 0;
};

// Wires as a Warp for the generic engine (bind() writes the sparse fields, transformations() the
// composition-method components), plus a fast bind/evaluate path that equals the engine to 1e-5.
// Original variant: one transformation per field entry, T_i(v) sampled at the entry's nearest-point
// parameter (the parameterised transformation sampled once per point, §4.3.2). Smooth variant: K
// transformations per wire, one per sample v_k. Bind caches nearest-point parameters (original) or
// per-sample strengths and weights (smooth) on the rest model; moving a wire curve (setWire) only
// recomputes its tangents.
class Wires : public Warp {
  public:
    // Throws InvalidInput naming the wire and element: fewer than 2 reference points, a wire curve with a
    // different point count, a non-finite point, a zero-length reference curve, radius <= 0, scale <= 0,
    // any of them non-finite; exponent < 0 or non-finite; smoothSamples < 0, 1 or > 4096.
    explicit Wires(std::vector<Wire> wires, const WiresOptions& options = {});

    [[nodiscard]] int32_t numWires() const { return static_cast<int32_t>(wires_.size()); }
    // Wire i; InvalidInput naming the index for one out of range (as smoothSamples and setWire).
    [[nodiscard]] const Wire& wire(int32_t i) const { return wires_[checkedIndex(i)]; }
    [[nodiscard]] const WiresOptions& options() const { return options_; }
    // K of wire i for the smooth variant (also set for the original variant, unused there).
    [[nodiscard]] int32_t smoothSamples(int32_t i) const { return sampleCount_[checkedIndex(i)]; }

    // New wire curve C*_i (same point count as the reference). Throws on a bad index, count or NaN.
    void setWire(int32_t i, std::span<const glm::vec3> wireCurve);

    // Warp (generic engine).
    void bind(std::span<const glm::vec3> restPoints, SparseFields& fields) override;
    void transformations(Transformations& out) const override;
    [[nodiscard]] EngineOptions engineOptions() const override { return {options_.exponent}; }

    // Fast path: bind caches the fields only (throws InvalidInput naming a non-finite rest point);
    // evaluate deforms points (the bound rest points or upstream points of the same count) in place;
    // painted weights (#points, or empty for 1) and the envelope scale the displacement as in
    // WarpDeformer; a point whose result is not finite (its input, or taken beyond float range) is refused
    // by name, the points then holding partial results. OpenMP over points; allocates nothing; bit-identical
    // for any thread count.
    void bind(std::span<const glm::vec3> restPoints);
    [[nodiscard]] bool isBound() const { return bound_; }
    [[nodiscard]] const SparseFields& fields() const { return fields_; }
    void evaluate(std::span<glm::vec3> points, std::span<const float> weights = {}, float envelope = 1.0f);

    // The fast path's form of one T(v): Components with a uniform scale and the rotation split into a
    // unit axis and an angle in radians.
    struct SampleTransform {
        glm::vec3 pivot{0.0f}, translation{0.0f}, axis{0.0f};
        float angle = 0.0f, scale = 1.0f;
    };

  private:
    [[nodiscard]] size_t checkedIndex(int32_t i) const;
    // A place on a polyline: segment j and t in [0, 1] along it.
    struct CurvePlace {
        int32_t segment = 0;
        float t = 0.0f;
    };
    // The segments (original) or samples (smooth) of one reference curve binned into a uniform grid of
    // cells by their r-neighbourhood's bounding box: a point within r of an item finds it in its own cell.
    // Each cell lists items in ascending order, which keeps "smallest parameter on ties".
    struct CellGrid {
        glm::vec3 origin{0.0f}, end{0.0f};  // the reference's bounding box grown by r
        float inverseCell = 1.0f;
        glm::ivec3 dims{1, 1, 1};
        std::vector<int32_t> start, items;  // CSR over cells x + dims.x (y + dims.y z)
    };
    [[nodiscard]] Components transformAt(int32_t w, const CurvePlace& place) const;
    void updateWireTangents(int32_t w);
    void buildGrid(int32_t w);

    std::vector<Wire> wires_;
    WiresOptions options_;
    std::vector<std::vector<glm::vec3>> referenceTangents_, wireTangents_;  // unit vertex tangents
    // Smooth variant: per wire its K sample places and trapezoidal arc-length weights; the first
    // transformation index of each wire (prefix sums of K).
    std::vector<int32_t> sampleCount_, sampleBase_;
    std::vector<CurvePlace> samplePlace_;
    std::vector<float> sampleWeight_;
    // Bind cache: the fields, and for the original variant the nearest place of each entry.
    SparseFields fields_;
    std::vector<int32_t> entryWire_;
    std::vector<CurvePlace> entryPlace_;
    std::vector<CellGrid> grids_;
    std::vector<SampleTransform> scratch_;  // smooth variant: the K transformations of every wire
    bool bound_ = false;
};

}  // namespace deformkit::warp
