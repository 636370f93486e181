#include <cmath>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <glm/geometric.hpp>

#include "slider_impl.h"

namespace deformkit::slide {

glm::dvec3 Slider::Impl::toRestFrame(size_t h, std::span<const glm::vec3> in, const glm::dvec3& d) const {
    const int32_t p = handles[h].vertex;
    bool moved = in[p] != mesh.points()[p];
    for (int32_t q : surface.neighbors(p))
        moved = moved || in[q] != mesh.points()[q];
    if (!moved) return d;
    const glm::dvec3 p0 = surface.point(p), p1(in[p]);
    auto column = [](const glm::dvec3& v) { return Eigen::Vector3d(v.x, v.y, v.z); };
    Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();  // sum of incoming x rest^T
    Eigen::Matrix3d gram = Eigen::Matrix3d::Zero();   // sum of rest x rest^T
    double scale2 = 0.0;
    for (int32_t q : surface.neighbors(p)) {
        const glm::dvec3 e = surface.point(q) - p0, f = glm::dvec3(in[q]) - p1;
        cross += column(f) * column(e).transpose();
        gram += column(e) * column(e).transpose();
        scale2 += glm::dot(e, e);
    }
    glm::dvec3 normal(0.0);  // area-weighted incoming normal
    for (int32_t c : surface.vertexCorners(p)) {
        const glm::dvec3 a(in[surface.vertex(c)]), b(in[surface.vertex(SlideSurface::next(c))]),
            e(in[surface.vertex(SlideSurface::prev(c))]);
        normal += glm::cross(b - a, e - a);
    }
    const double length = glm::length(normal);
    const double ring = std::sqrt(scale2 / static_cast<double>(surface.neighbors(p).size()));
    if (length > 0.0) {
        const Eigen::Vector3d n0 = column(surface.normal(p)) * ring, n1 = column(normal / length) * ring;
        cross += n1 * n0.transpose();
        gram += n0 * n0.transpose();
    }
    const Eigen::Vector3d v = column(d);
    Eigen::Vector3d out;
    const Eigen::Matrix3d map = cross * gram.inverse();  // gram is positive definite: the ring spans
    const double det = map.determinant();
    if (std::isfinite(det) && det > 1e-6) {
        out = map.inverse() * v;
    } else {
        const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
        Eigen::Matrix3d U = svd.matrixU();
        if ((U * svd.matrixV().transpose()).determinant() < 0.0) U.col(2) = -U.col(2);
        out = (U * svd.matrixV().transpose()).transpose() * v;
    }
    return {out.x(), out.y(), out.z()};
}

}  // namespace deformkit::slide
