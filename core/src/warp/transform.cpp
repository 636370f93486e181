#include "deformkit/warp/transform.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "deformkit/error.h"

namespace deformkit::warp {
namespace {

Eigen::Matrix3d toEigen(const glm::mat3& m) {
    Eigen::Matrix3d e;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
            e(r, c) = m[c][r];
    }
    return e;
}

glm::mat3 toGlm(const Eigen::Matrix3d& e) {
    glm::mat3 m;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
            m[c][r] = static_cast<float>(e(r, c));
    }
    return m;
}

Eigen::Matrix3d rotationMatrix(const glm::vec3& rotation) {
    const double angle = glm::length(glm::dvec3(rotation));
    if (angle == 0.0) return Eigen::Matrix3d::Identity();
    const Eigen::Vector3d axis = Eigen::Vector3d(rotation.x, rotation.y, rotation.z) / angle;
    return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

}  // namespace

Affine inverse(const Affine& t) {
    const Eigen::Matrix3d a = toEigen(t.linear);
    const double largest = std::max({a.col(0).norm(), a.col(1).norm(), a.col(2).norm()});
    const double det = a.determinant();
    if (!(std::abs(det) > 1e-12 * largest * largest * largest)) {
        throw InvalidInput(formatError("transformation", "linear part",
                                       "is singular (determinant " + std::to_string(det) + ")",
                                       "an invertible transformation"));
    }
    const Eigen::Matrix3d inv = a.inverse();
    const glm::mat3 linear = toGlm(inv);
    return {linear, -(linear * t.translation)};
}

Affine scaleByDisplacement(const Affine& t, float s) {
    Affine out;
    out.linear = s * t.linear + (1.0f - s) * glm::mat3(1.0f);
    out.translation = s * t.translation;
    return out;
}

Affine toAffine(const Components& c) {
    Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
    shear(0, 1) = c.shear.x;
    shear(0, 2) = c.shear.y;
    shear(1, 2) = c.shear.z;
    const Eigen::Matrix3d scale = Eigen::Vector3d(c.scale.x, c.scale.y, c.scale.z).asDiagonal();
    const glm::mat3 linear = toGlm(rotationMatrix(c.rotation) * scale * shear);
    // x -> translation + pivot + linear (x - pivot)
    return {linear, c.translation + c.pivot - linear * c.pivot};
}

Components scaleByComposition(const Components& c, float s) {
    Components out = c;
    out.translation = s * c.translation;
    out.rotation = s * c.rotation;
    out.scale = glm::vec3(1.0f) + s * (c.scale - glm::vec3(1.0f));
    out.shear = s * c.shear;
    return out;
}

Components decompose(const Affine& t, const glm::vec3& pivot) {
    const Eigen::Matrix3d a = toEigen(t.linear);
    Eigen::HouseholderQR<Eigen::Matrix3d> qr(a);
    Eigen::Matrix3d q = qr.householderQ();
    Eigen::Matrix3d u = qr.matrixQR().triangularView<Eigen::Upper>();
    // Make the diagonal of U non-negative, then make Q a rotation (a reflection moves into U's last row).
    for (int i = 0; i < 3; ++i) {
        if (u(i, i) < 0.0) {
            q.col(i) = -q.col(i);
            u.row(i) = -u.row(i);
        }
    }
    if (q.determinant() < 0.0) {
        q.col(2) = -q.col(2);
        u.row(2) = -u.row(2);
    }
    Components c;
    c.pivot = pivot;
    const Eigen::AngleAxisd aa(q);
    c.rotation = glm::vec3(static_cast<float>(aa.axis().x() * aa.angle()),
                           static_cast<float>(aa.axis().y() * aa.angle()),
                           static_cast<float>(aa.axis().z() * aa.angle()));
    c.scale =
        glm::vec3(static_cast<float>(u(0, 0)), static_cast<float>(u(1, 1)), static_cast<float>(u(2, 2)));
    auto ratio = [](double num, double den) {
        return std::abs(den) > 1e-300 ? static_cast<float>(num / den) : 0.0f;
    };
    c.shear = glm::vec3(ratio(u(0, 1), u(0, 0)), ratio(u(0, 2), u(0, 0)), ratio(u(1, 2), u(1, 1)));
    // t<x> = A x + b = translation + pivot + A (x - pivot)  =>  translation = b + A pivot - pivot
    c.translation = t.translation + t.linear * pivot - pivot;
    return c;
}

}  // namespace deformkit::warp
