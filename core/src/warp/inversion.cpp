#include "deformkit/warp/inversion.h"

#include <string>

#include "deformkit/error.h"

namespace deformkit::warp {

Transformations invertedTransformations(const Transformations& transforms) {
    Transformations out;
    invertedTransformations(transforms, out);
    return out;
}

void invertedTransformations(const Transformations& transforms, Transformations& out) {
    out.method = transforms.method;
    const int32_t n = transforms.size();
    const bool affine = transforms.method == ScaleMethod::Displacement;
    out.affine.resize(affine ? static_cast<size_t>(n) : 0);
    out.components.resize(affine ? 0 : static_cast<size_t>(n));
    for (int32_t i = 0; i < n; ++i) {
        try {
            if (affine) {
                out.affine[i] = inverse(transforms.affine[i]);
            } else {
                const Components& c = transforms.components[i];
                out.components[i] = decompose(inverse(toAffine(c)), c.pivot + c.translation);
            }
        } catch (const InvalidInput& e) {
            throw InvalidInput(formatError("inverse warp", "transformation " + std::to_string(i), e.what(),
                                           "invertible transformations"));
        }
    }
}

void InvertedWarp::transformations(Transformations& out) const {
    forward_.transformations(forwardTransforms_);
    invertedTransformations(forwardTransforms_, out);
}

}  // namespace deformkit::warp
