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
    double scale2 = 0.0, incoming2 = 0.0;
    for (int32_t q : surface.neighbors(p)) {
        const glm::dvec3 e = surface.point(q) - p0, f = glm::dvec3(in[q]) - p1;
        cross += column(f) * column(e).transpose();
        gram += column(e) * column(e).transpose();
        scale2 += glm::dot(e, e);
        incoming2 += glm::dot(f, f);
    }
    glm::dvec3 normal(0.0);  // area-weighted incoming normal
    for (int32_t c : surface.vertexCorners(p)) {
        const glm::dvec3 a(in[surface.vertex(c)]), b(in[surface.vertex(SlideSurface::next(c))]),
            e(in[surface.vertex(SlideSurface::prev(c))]);
        normal += glm::cross(b - a, e - a);
    }
    const double length = glm::length(normal);
    const auto count = static_cast<double>(surface.neighbors(p).size());
    // The normals as a third pair of edges, each as long as its own ring (RMS edge length): the normal
    // scales as the surface does, so a uniformly scaled input is s I, however small s (a mesh in mm driven
    // by a rig in m), not a map whose determinant s^2 looks collapsed.
    const double ring = std::sqrt(scale2 / count), incomingRing = std::sqrt(incoming2 / count);
    if (length > 0.0) {
        const Eigen::Vector3d n0 = column(surface.normal(p)) * ring,
                              n1 = column(normal / length) * incomingRing;
        cross += n1 * n0.transpose();
        gram += n0 * n0.transpose();
    }
    const Eigen::Vector3d v = column(d);
    Eigen::Vector3d out;
    const Eigen::Matrix3d map = cross * gram.inverse();  // gram is positive definite: the ring spans
    // Invertible and not folded, relative to its own size (det of s I is s^3): else the nearest rotation.
    const double det = map.determinant(), size = map.norm() / std::sqrt(3.0);
    if (std::isfinite(det) && size > 0.0 && det > 1e-6 * size * size * size) {
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
