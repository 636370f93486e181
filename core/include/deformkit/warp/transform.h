#pragma once

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace deformkit::warp {

// An affine transformation of 3-space (a 3x4 matrix): T<P> = linear * P + translation. 2-D warps use
// the upper-left 2x2 block and the x, y translation, with z untouched.
struct Affine {
    glm::mat3 linear{1.0f};  // column-major, as GLM
    glm::vec3 translation{0.0f};

    [[nodiscard]] glm::vec3 apply(const glm::vec3& p) const { return linear * p + translation; }
    // Composition: (a * b)<P> = a<b<P>>.
    [[nodiscard]] Affine operator*(const Affine& b) const {
        return {linear * b.linear, linear * b.translation + translation};
    }

    [[nodiscard]] static Affine identity() { return {}; }
    [[nodiscard]] static Affine translate(const glm::vec3& t) { return {glm::mat3(1.0f), t}; }
    // The map x -> linear (x - pivot) + pivot.
    [[nodiscard]] static Affine about(const glm::mat3& linear, const glm::vec3& pivot) {
        return {linear, pivot - linear * pivot};
    }
};

// The inverse transformation; throws InvalidInput if the linear part is singular (|det| < 1e-12 relative
// to the cube of its largest column).
[[nodiscard]] Affine inverse(const Affine& t);

// Scalar times transformation by the *displacement method* (paper §3.3): s . T = s T + (1 - s) I, so
// (s . T)<P> = P + s (T<P> - P).
[[nodiscard]] Affine scaleByDisplacement(const Affine& t, float s);

// A transformation given by components, applied right to left about `pivot`:
//   T = Translate(translation) . Rotate(rotation) . Scale(scale) . Shear(shear), the last three about pivot.
// rotation is an axis times an angle in radians; shear = (xy, xz, yz) are the upper off-diagonal entries
// of a unit upper-triangular matrix. This is the form the *composition method* scales.
struct Components {
    glm::vec3 pivot{0.0f};
    glm::vec3 translation{0.0f};
    glm::vec3 rotation{0.0f};
    glm::vec3 scale{1.0f};
    glm::vec3 shear{0.0f};
};

[[nodiscard]] Affine toAffine(const Components& c);

// Scalar times transformation by the *composition method* (paper §3.3): each component's parameter is
// multiplied by s and the transformation recomposed. Parameters are measured from the identity, so
// s = 0 gives the identity and s = 1 gives c: translation s t, rotation angle s theta, scale 1 + s (k - 1),
// shear s h (docs/decisions.md).
[[nodiscard]] Components scaleByComposition(const Components& c, float s);

// Components of an affine map about `pivot`: linear = R . K with R a rotation and K upper triangular
// (QR decomposition; a reflection shows as a negative z scale). toAffine(decompose(t, p)) == t.
[[nodiscard]] Components decompose(const Affine& t, const glm::vec3& pivot = glm::vec3(0.0f));

}  // namespace deformkit::warp
