#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "deformkit/warp/engine.h"

namespace deformkit::warp {

namespace detail {
struct LocalBlock;  // ffd_kernels.h
struct DisplacementBlock;
}  // namespace detail

// Free-form deformation (paper §4.1, Sederberg and Parry 1986): point features on a uniform lattice in a
// parallelepiped, strength 1, transformations T_ijk = P*_ijk - P_ijk, weighting fields the trivariate
// Bernstein polynomials of the point's local coordinates. Also the local B-spline variant (§4.1, after
// Greissmair and Purgathofer 1989), and Blender's Lattice interpolations with its end conditions (linear,
// cardinal, Catmull-Rom, B-spline; end controls repeated). Decisions: docs/decisions.md, "FFD and FFD with
// frames".

enum class FfdBasis {
    Bernstein,   // B^l_i(s) B^m_j(t) B^n_k(u): every control reaches every point inside the lattice
    BSpline,     // uniform cubic B-spline, approximating: a point pays for 4x4x4 (Blender's "B-Spline")
    Linear,      // piecewise linear: trilinear inside each cell, 2x2x2 (Blender's "Linear")
    Cardinal,    // cardinal spline of tension 0.71, interpolating, 4x4x4 (Blender's "Cardinal")
    CatmullRom,  // Catmull-Rom spline (cardinal of tension 0.5), interpolating, 4x4x4 (Blender's
                 // "Catmull-Rom")
};

// The basis along each lattice axis (X, Y, Z). One value sets all three; Blender's lattices choose each
// axis's interpolation on its own.
struct FfdBases {
    std::array<FfdBasis, 3> axis{FfdBasis::Bernstein, FfdBasis::Bernstein, FfdBasis::Bernstein};

    FfdBases() = default;
    FfdBases(FfdBasis all) : axis{all, all, all} {}  // NOLINT(google-explicit-constructor): one for all
    FfdBases(FfdBasis x, FfdBasis y, FfdBasis z) : axis{x, y, z} {}
    [[nodiscard]] FfdBasis operator[](int32_t a) const { return axis[static_cast<size_t>(a)]; }
    [[nodiscard]] bool all(FfdBasis b) const { return axis[0] == b && axis[1] == b && axis[2] == b; }
    bool operator==(const FfdBases&) const = default;
};

enum class FfdOutside {
    None,         // points outside the lattice are left where they are (Maya's default)
    Extrapolate,  // the deformation continues beyond [0, 1] from each face with its value and slope there
                  // (linear per axis); splines with FfdEnds::Repeat: the end controls, as Blender's
};

// How the spline bases (all but Bernstein) make up the controls a span needs beyond the end faces.
enum class FfdEnds {
    Extrapolate,  // linear extrapolations of the end controls (T_-1 = 2 T_0 - T_1): linear precision, and
                  // the B-spline reaches the end faces
    Repeat,       // the end controls repeated, as Blender's Lattice modifier does: with FfdOutside::
                  // Extrapolate a point beyond the lattice follows the nearest end controls
};

// The source lattice. Control point P_ijk = origin + i/l X + j/m Y + k/n Z for 0 <= i <= l, 0 <= j <= m,
// 0 <= k <= n, stored at index (i (m + 1) + j) (n + 1) + k: a C-order (l+1, m+1, n+1) array.
struct Lattice {
    glm::vec3 origin{0.0f};  // corner of the parallelepiped, scene units
    glm::mat3 axes{1.0f};    // columns X, Y, Z: the parallelepiped's edge vectors, need not be orthogonal
    glm::ivec3 divisions{1, 1, 1};  // l, m, n: cells along X, Y, Z, each in [1, kMaxFfdDivisions]

    [[nodiscard]] int32_t numControls() const {
        return (divisions.x + 1) * (divisions.y + 1) * (divisions.z + 1);
    }
    [[nodiscard]] int32_t index(int32_t i, int32_t j, int32_t k) const {
        return (i * (divisions.y + 1) + j) * (divisions.z + 1) + k;
    }
    [[nodiscard]] glm::vec3 controlPoint(int32_t i, int32_t j, int32_t k) const;
    // All P_ijk in index order.
    [[nodiscard]] std::vector<glm::vec3> controlPoints() const;
};

// Divisions per axis are limited so that a lattice stays a deformer, not a volume grid; the Bernstein
// basis (global support, degree = divisions) is limited further, beyond which the B-spline basis is the tool.
inline constexpr int32_t kMaxFfdDivisions = 1024;
inline constexpr int32_t kMaxBernsteinDegree = 64;

// Which kernel the fast path may use for the 4x4x4 lattice (divisions 3, 3, 3; translations), Bernstein or
// spline. Auto takes the AVX2 kernel when the CPU has it (checked at run time; the build sets no -march) and
// the environment variable DEFORMKIT_SIMD is not "baseline", else the portable one. Portable forces the
// portable kernel; PerPoint the per-point path of other lattices (for tests and benchmarks that compare
// them). None uses fused multiply-add: all give the same bytes, on any CPU and for any thread count.
enum class FfdKernel { Auto, Portable, PerPoint };

struct FfdOptions {
    FfdBases basis = FfdBasis::Bernstein;
    FfdOutside outside = FfdOutside::None;
    FfdKernel kernel = FfdKernel::Auto;
    FfdEnds ends = FfdEnds::Extrapolate;
};

// True when FfdKernel::Auto runs the AVX2 kernel in this process.
[[nodiscard]] bool ffdHasAvx2Kernel();

// The lattice geometry, its weighting fields and the bind cache (each point's local coordinates), shared
// by Ffd and FfdFrames. Throws InvalidInput naming the element on a bad lattice: divisions < 1 or too
// large, non-finite origin or axes, a zero-length axis or coplanar axes.
class FfdLattice {
  public:
    explicit FfdLattice(const Lattice& lattice, const FfdOptions& options = {});

    [[nodiscard]] const Lattice& lattice() const { return lattice_; }
    [[nodiscard]] const FfdOptions& options() const { return options_; }
    [[nodiscard]] int32_t numControls() const { return lattice_.numControls(); }

    // (s, t, u): the point's coordinates in the frame (origin; X, Y, Z), found by solving the 3x3 system
    // axes (s, t, u) = p - origin; the lattice is [0, 1]^3.
    [[nodiscard]] glm::vec3 localCoordinates(const glm::vec3& p) const;

    // Caches each rest point's local coordinates (the only per-point bind data). Throws on a non-finite
    // point.
    void bind(std::span<const glm::vec3> restPoints);
    [[nodiscard]] bool isBound() const { return bound_; }
    // A one-off without the bind cache: bind(restPoints) then deform(points, translations, 3, ...), the same
    // bytes, each point's coordinates computed where it is deformed (no per-point memory). Done for the
    // Bernstein 4x4x4 lattice only; returns false (doing nothing) otherwise. Throws as bind() does, and as
    // deform() does on an output point that is not finite.
    // `in` and `out` as deform()'s.
    bool deformUnbound(std::span<const glm::vec3> restPoints, std::span<const glm::vec3> in,
                       std::span<glm::vec3> out, const float* translations, std::span<const float> weights,
                       float envelope) const;
    [[nodiscard]] int32_t numBoundPoints() const { return static_cast<int32_t>(local_.size()); }

    // Weighting fields from the cache, non-zero weights only, strength 1. With FfdOutside::None a point
    // outside the lattice gets no entries (the engine's identity); with Extrapolate weights may be negative
    // but still sum to 1, so Eq. (3)'s normalisation leaves them as they are.
    void fields(SparseFields& out) const;

    // Separable weights of one point along one axis: writes count weights for controls first..first+count-1
    // into w (room for kMaxBernsteinDegree + 1) and returns count. x is the local coordinate times divisions.
    int32_t axisWeights(int32_t axis, float x, int32_t& first, float* w) const;

    // Fast path of Eq. (3) for the bind cache: points[u] += envelope * weight[u] * D_u(points[u]) with
    // D_u(p) = sum_c w_c(rest_u) (T_c<p> - p). deltas holds one record per control: 3 floats (a translation)
    // when stride is 3, or 12 floats (the 3x4 matrix T_c - I, column-major: three linear columns, then the
    // translation) when stride is 12. OpenMP over points; allocates nothing; bit-identical for any thread
    // count.
    void deform(std::span<glm::vec3> points, std::span<const float> deltas, int32_t stride,
                std::span<const float> weights, float envelope) const {
        deform(points, points, deltas, stride, weights, envelope);
    }
    // The same from `in` into `out` (as many points; the same span, or not overlapping): out[u] = in[u] +
    // envelope * weight[u] * D_u(in[u]), one pass over the input instead of a copy and a pass. Throws
    // InvalidInput naming the first point whose output is not finite (an input point that is not, or one
    // taken beyond float range); `out` then holds partial results.
    void deform(std::span<const glm::vec3> in, std::span<glm::vec3> out, std::span<const float> deltas,
                int32_t stride, std::span<const float> weights, float envelope) const;

  private:
    // A point's local coordinates times the divisions, and whether it lies in the lattice (bind's formula).
    [[nodiscard]] glm::vec3 boundCoordinates(const glm::vec3& p, const glm::dvec3& scale, bool& inside) const;
    // A kernel of eight points' 4x4x4 sums with their weights (ffd_kernels.h): Bernstein or B-spline.
    using LaneKernel = void (*)(const detail::LocalBlock&, const float*, detail::DisplacementBlock&);
    // deform() for divisions (3, 3, 3) with translations in the Bernstein cubic or a cubic B-spline: SoA
    // blocks of 8 points, the weights computed from the bound coordinates in registers (ffd.cpp).
    // Both return the first point whose output is not finite, or #points.
    [[nodiscard]] int64_t deformLanes444(LaneKernel kernel, std::span<const glm::vec3> in,
                                         std::span<glm::vec3> out, const float* translations,
                                         std::span<const float> weights, float envelope) const;
    // The same lattice in the other bases whose weights fit the 4x4x4 window (Catmull-Rom, cardinal, linear),
    // and any basis with affine maps (stride 12, FFD with frames): each point's weights as the per-point path
    // computes them (at bind for splines), the sum in eight-lane blocks; the per-point path's bytes.
    [[nodiscard]] int64_t deformWindow444(std::span<const glm::vec3> in, std::span<glm::vec3> out,
                                          const float* data, int32_t stride, std::span<const float> weights,
                                          float envelope) const;
    // The window weights of points begin .. begin + count - 1 into a block ([axis][control][lane], 8 lanes;
    // zero for inactive points and lanes past count).
    void windowWeightsOf(int64_t begin, int count, float* block) const;

    Lattice lattice_;
    FfdOptions options_;
    glm::dmat3 toLocal_{1.0};         // inverse of the axes
    std::vector<float> binomial_[3];  // Bernstein coefficients C(d, i) per axis
    std::vector<glm::vec3> local_;    // per bound point: (s l, t m, u n), lattice units
    std::vector<uint8_t> active_;     // per bound point: 1 if the warp reaches it
    // For deformWindow444 in a spline basis: each point's weights of the 4 controls per axis in blocks of 8
    // points ([block][axis][control][lane]; inactive points' weights are never used). The first evaluation
    // after a bind computes them on the fly (a one-off pays no 48 bytes a point); the second keeps them, so
    // an animation only sums. Copies of the lattice start without them.
    struct WeightCache {
        std::vector<float> weights;
        int evaluations = 0;  // since the bind
        std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
        WeightCache() = default;
        WeightCache(const WeightCache&) : WeightCache() {}
        WeightCache& operator=(const WeightCache&) {
            weights.clear();
            evaluations = 0;
            return *this;
        }
        WeightCache(WeightCache&&) noexcept = default;
        WeightCache& operator=(WeightCache&&) noexcept = default;
    };
    mutable WeightCache windowCache_;
    bool windowSpline_ = false;  // bound to a 4x4x4 lattice in a spline basis
    bool bound_ = false;
};

// What FFD and FFD with frames share: the lattice's weighting fields bound once, as a Warp for the generic
// engine (bind() with fields builds the sparse fields) and as a fast path (bind() without caches local
// coordinates only; each warp's evaluate() then deforms points, the bound rest points or the upstream points
// of the same count, in place).
class LatticeWarp : public Warp {
  public:
    [[nodiscard]] const FfdLattice& lattice() const { return lattice_; }
    void bind(std::span<const glm::vec3> restPoints, SparseFields& fields) override;
    void bind(std::span<const glm::vec3> restPoints) { lattice_.bind(restPoints); }

  protected:
    LatticeWarp(const Lattice& lattice, const FfdOptions& options) : lattice_(lattice, options) {}

    FfdLattice lattice_;
};

// Plain FFD as a Warp for the generic engine (transformations() gives the translations), plus a fast path
// that skips the fields and equals the engine to 1e-5. Moving controls (setTargets) never redoes bind work.
class Ffd : public LatticeWarp {
  public:
    // Targets start equal to the source lattice (the identity).
    explicit Ffd(const Lattice& lattice, const FfdOptions& options = {});

    [[nodiscard]] std::span<const glm::vec3> sourcePoints() const { return source_; }
    [[nodiscard]] std::span<const glm::vec3> targets() const { return target_; }
    // P*_ijk in index order, (l+1)(m+1)(n+1) of them. Throws on a wrong count or a non-finite target.
    void setTargets(std::span<const glm::vec3> targets);

    void transformations(Transformations& out) const override;
    // Fast path: painted weights (#points, or empty for 1) and the envelope scale the displacement as in
    // WarpDeformer.
    // A one-off: bind(restPoints) then evaluate(points, ...), the same bytes; on the Bernstein 4x4x4
    // lattice without keeping the bind cache (the warp is then left unbound).
    void bindAndEvaluate(std::span<const glm::vec3> restPoints, std::span<glm::vec3> points,
                         std::span<const float> weights = {}, float envelope = 1.0f) {
        bindAndEvaluate(restPoints, points, points, weights, envelope);
    }
    // The same from `in` into `out` (FfdLattice::deform's in and out).
    void bindAndEvaluate(std::span<const glm::vec3> restPoints, std::span<const glm::vec3> in,
                         std::span<glm::vec3> out, std::span<const float> weights, float envelope);
    void evaluate(std::span<glm::vec3> points, std::span<const float> weights = {},
                  float envelope = 1.0f) const {
        evaluate(points, points, weights, envelope);
    }
    void evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out, std::span<const float> weights,
                  float envelope) const;

  private:
    std::vector<glm::vec3> source_, target_, translation_;
};

}  // namespace deformkit::warp
