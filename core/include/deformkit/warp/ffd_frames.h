#pragma once

#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "deformkit/warp/engine.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/transform.h"

namespace deformkit::warp {

// A coordinate frame: an origin and three basis vectors (columns of `basis`), scene units. Need not be
// orthonormal; a source frame's basis must be invertible.
struct Frame {
    glm::vec3 origin{0.0f};
    glm::mat3 basis{1.0f};
};

// The affine map taking frame `from` to frame `to` (paper §3.3): T<p> = B_to B_from^-1 (p - o_from) + o_to.
// Throws InvalidInput naming `element` if from's basis is singular or either frame is not finite.
[[nodiscard]] Affine frameToFrame(const Frame& from, const Frame& to, const std::string& element = "frame");

// FFD with coordinate-frame features (paper §5.1): the lattice and weighting fields of FFD (§4.1), but each
// control point carries a source and a target frame and T_ijk is the affine map between them, strength 1,
// displacement method. Rotating a control's frame rotates the model locally about that control, which
// plain FFD cannot do (Fig. 13, 14); with translation-only frames (target basis = source basis, source
// origins = P_ijk) it is FFD exactly. The weights are the bind data: changing any frame redoes no bind work.
class FfdFrames : public LatticeWarp {
  public:
    // Source frames start at (P_ijk, identity basis), targets equal to them (the identity warp).
    explicit FfdFrames(const Lattice& lattice, const FfdOptions& options = {});

    [[nodiscard]] std::span<const Frame> sourceFrames() const { return source_; }
    [[nodiscard]] std::span<const Frame> targetFrames() const { return target_; }
    // The current T_ijk, index order as Lattice::index.
    [[nodiscard]] std::span<const Affine> controlTransformations() const { return transform_; }

    // (l+1)(m+1)(n+1) frames each, index order as Lattice::index. Throw on a wrong count, a non-finite
    // frame or a singular source basis (naming the control).
    void setSourceFrames(std::span<const Frame> frames);
    void setTargetFrames(std::span<const Frame> frames);

    void transformations(Transformations& out) const override;
    // Fast path, as Ffd::evaluate.
    void evaluate(std::span<glm::vec3> points, std::span<const float> weights = {},
                  float envelope = 1.0f) const {
        evaluate(points, points, weights, envelope);
    }
    // The same from `in` into `out` (FfdLattice::deform's in and out).
    void evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out, std::span<const float> weights,
                  float envelope) const;

  private:
    void update();
    void checkCount(std::span<const Frame> frames, const char* what) const;

    std::vector<Frame> source_, target_;
    std::vector<Affine> transform_;
    std::vector<float> delta_;  // per control: T_ijk - I as 12 floats (FfdLattice::deform)
};

}  // namespace deformkit::warp
