#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/warp/engine.h"
#include "deformkit/warp/transform.h"

namespace deformkit::warp {

// Beier and Neely's (1992) feature-based image warp cast in the framework (paper §4.2), and its global
// variant (§5.2). 2-D, inverse mapping: the warp takes a point of the *destination* image to the point
// of the *source* image whose colour it receives. Positions are in pixel units with the origin at the
// top-left image corner, so pixel (x, y) has its centre at (x + 0.5, y + 0.5). As a Warp over 3-D
// points it acts on x and y and leaves z untouched.

// One feature specification F_i = (L_i, L*_i, a_i, b_i, p_i). Segments are directed.
struct SegmentPair {
    glm::vec2 dstP{0.0f}, dstQ{1.0f, 0.0f};  // L_i = (P_i, Q_i), destination image, pixels
    glm::vec2 srcP{0.0f}, srcQ{1.0f, 0.0f};  // L*_i = (P*_i, Q*_i), source image, pixels
    float a = 1.0f;  // > 0, pixels: the larger, the smoother and the less exact near the segment
    float b = 2.0f;  // >= 0: how fast influence falls off with distance (Beier-Neely use [0.5, 2])
    float p = 0.5f;  // >= 0: how much longer segments dominate (Beier-Neely use [0, 1])
};

enum class BeierNeelyVariant {
    Original,  // §4.2: the y-basis of each target frame is perpendicular to L*_i (rigid per feature)
    Global,    // §5.2: the y-basis of each target frame is a weighted average of all features' rotations
};

struct BeierNeelyOptions {
    BeierNeelyVariant variant = BeierNeelyVariant::Original;
};

// Segments this long or shorter (pixels, or scene units) have no direction: refused.
inline constexpr float kMinSegmentLength = 1e-6f;

// Throws InvalidInput naming `source` and "segment pair i" for a segment up to kMinSegmentLength long or
// non-finite, a <= 0, b < 0, p < 0 or a non-finite parameter.
void validateSegmentPairs(std::span<const SegmentPair> pairs, const std::string& source = "Beier-Neely warp");

// Weighting field of feature i at point x (§4.2): (length_i^p_i / (a_i + dist_i(x)))^b_i with length_i
// = |Q_i - P_i| and dist_i the distance from x to the destination segment L_i. Strength is always 1.
[[nodiscard]] float beierNeelyWeight(const SegmentPair& pair, glm::vec2 x);

// The construction function's transformations T_i: the affine map of the frame (P_i, Q_i - P_i, N_i)
// onto (P*_i, Q*_i - P*_i, N*_i), N = unit perpendicular (-d.y, d.x) / |d|. With Global, N*_i is the
// §5.2 weighted average (docs/decisions.md). z untouched. Validates the pairs.
[[nodiscard]] std::vector<Affine> beierNeelyTransformations(std::span<const SegmentPair> pairs,
                                                            const BeierNeelyOptions& options = {});

// The warp. Construction validates; bind() evaluates the (dense: Beier-Neely weights never vanish)
// weighting fields on the rest points from the destination segments; setSourceSegments() moves the
// source segments L*_i (the controls an artist drags) and only recomputes the transformations, so a
// bound deformer need not rebind.
class BeierNeelyWarp : public Warp {
  public:
    explicit BeierNeelyWarp(std::vector<SegmentPair> pairs, BeierNeelyOptions options = {});

    // srcEndpoints: 2 * #pairs points (P*_0, Q*_0, P*_1, ...), source-image pixels. Throws InvalidInput
    // on a count mismatch, a zero-length or non-finite segment; the warp is unchanged then.
    void setSourceSegments(std::span<const glm::vec2> srcEndpoints);

    void bind(std::span<const glm::vec3> restPoints, SparseFields& fields) override;
    void transformations(Transformations& out) const override;

    [[nodiscard]] const std::vector<SegmentPair>& pairs() const { return pairs_; }
    [[nodiscard]] const BeierNeelyOptions& options() const { return options_; }

    // Fast 2-D path, equal to evaluateWarp over bind()'s fields and transformations() (to float
    // rounding; tests/unit/warp/beier_neely_test.cpp). points and out: #points positions, may alias.
    void mapPoints(std::span<const glm::vec2> points, std::span<glm::vec2> out) const;
    // The source position of every destination pixel centre (x + 0.5, y + 0.5), row-major (H, W):
    // out has width * height entries. OpenMP over rows; bit-identical for any thread count.
    void mapPixelCentres(int32_t width, int32_t height, std::span<glm::vec2> out) const;

    // Per-feature constants of the weighting field, from the destination segment and a, b, p.
    struct WeightTerms {
        glm::vec2 p{0.0f}, d{0.0f};  // P_i and Q_i - P_i
        float invLengthSq = 0.0f;    // 1 / |Q_i - P_i|^2
        float lengthPow = 0.0f;      // |Q_i - P_i|^p_i
        float a = 1.0f, b = 0.0f;
    };

  private:
    std::vector<WeightTerms> terms_;  // cached from pairs_ (destination segments do not change)
    std::vector<SegmentPair> pairs_;
    BeierNeelyOptions options_;
    std::vector<Affine> transforms_;  // cached T_i for the current pairs
};

// One-off: the (H, W) map of source positions for every destination pixel centre.
[[nodiscard]] std::vector<glm::vec2> beierNeelyMap(int32_t width, int32_t height,
                                                   std::span<const SegmentPair> pairs,
                                                   const BeierNeelyOptions& options = {});

}  // namespace deformkit::warp
