#include "deformkit/warp/barr.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/error.h"

namespace deformkit::warp {
namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string str(const glm::vec3& v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

void requireFinitePoints(std::span<const glm::vec3> points, const std::string& source, const char* what) {
    for (size_t i = 0; i < points.size(); ++i) {
        if (!finite(points[i])) {
            throw InvalidInput(formatError(source, std::string(what) + " " + std::to_string(i),
                                           "is " + str(points[i]), "finite coordinates"));
        }
    }
}

// sin(t)/t and (1 - cos t)/t, stable at and near t = 0.
double sinc(double t) {
    return std::abs(t) < 1e-4 ? 1.0 - t * t / 6.0 : std::sin(t) / t;
}
double versinc(double t) {
    if (std::abs(t) < 1e-4) return 0.5 * t;
    const double s = std::sin(0.5 * t);
    return 2.0 * s * s / t;
}
float sincf(float t) {
    return std::abs(t) < 1e-3f ? 1.0f - t * t * (1.0f / 6.0f) : std::sin(t) / t;
}
float versincf(float t) {
    if (std::abs(t) < 1e-3f) return 0.5f * t;
    const float s = std::sin(0.5f * t);
    return 2.0f * s * s / t;
}

// The world map x -> o + F M F^T (x - o) + F t, F = [side up axis]: a local-frame affine map in world space.
Affine fromLocal(const OrthoFrame& f, const glm::dmat3& m, const glm::dvec3& t) {
    const glm::dmat3 basis(glm::dvec3(f.side), glm::dvec3(f.up), glm::dvec3(f.axis));
    const glm::dmat3 linear = basis * m * glm::transpose(basis);
    const glm::dvec3 o(f.origin);
    return {glm::mat3(linear), glm::vec3(o + basis * t - linear * o)};
}

}  // namespace

glm::vec3 OrthoFrame::toLocal(const glm::vec3& p) const {
    const glm::vec3 d = p - origin;
    return {glm::dot(d, side), glm::dot(d, up), glm::dot(d, axis)};
}

glm::vec3 OrthoFrame::toWorld(const glm::vec3& l) const {
    return origin + l.x * side + l.y * up + l.z * axis;
}

OrthoFrame orthonormalFrame(const AxisFrame& frame, bool needUp, std::string_view sourceName) {
    const std::string source(sourceName);
    if (!finite(frame.origin)) {
        throw InvalidInput(
            formatError(source, "axis_origin", "is " + str(frame.origin), "finite coordinates"));
    }
    if (!finite(frame.axis)) {
        throw InvalidInput(formatError(source, "axis_dir", "is " + str(frame.axis), "finite coordinates"));
    }
    const double axisLength = glm::length(glm::dvec3(frame.axis));
    if (!(axisLength > 1e-12)) {
        throw InvalidInput(formatError(source, "axis_dir", "is the zero vector", "a non-zero direction"));
    }
    OrthoFrame out;
    out.origin = frame.origin;
    const glm::dvec3 axis = glm::dvec3(frame.axis) / axisLength;
    glm::dvec3 up(0.0);
    if (finite(frame.up)) {
        const glm::dvec3 u(frame.up);
        const double upLength = glm::length(u);
        // Perpendicular part; "parallel" means within about 0.06 degrees of the axis.
        const glm::dvec3 perpendicular = u - glm::dot(u, axis) * axis;
        if (upLength > 1e-12 && glm::length(perpendicular) > 1e-6 * upLength)
            up = glm::normalize(perpendicular);
    } else if (needUp) {
        throw InvalidInput(formatError(source, "up_dir", "is " + str(frame.up), "finite coordinates"));
    }
    if (up == glm::dvec3(0.0)) {
        if (needUp) {
            throw InvalidInput(formatError(
                source, "up_dir", str(frame.up) + " is zero or parallel to axis_dir " + str(frame.axis),
                "a direction not parallel to the axis"));
        }
        // Any perpendicular: the coordinate axis least aligned with the axis, made perpendicular.
        const glm::dvec3 a = glm::abs(axis);
        const glm::dvec3 e = a.x <= a.y && a.x <= a.z ? glm::dvec3(1, 0, 0)
                             : a.y <= a.z             ? glm::dvec3(0, 1, 0)
                                                      : glm::dvec3(0, 0, 1);
        up = glm::normalize(e - glm::dot(e, axis) * axis);
    }
    out.axis = glm::vec3(axis);
    out.up = glm::vec3(up);
    out.side = glm::vec3(glm::cross(up, axis));
    return out;
}

AxialWarp::AxialWarp(const AxisFrame& frame, bool needUp, std::string name)
    : name_(std::move(name)), needUp_(needUp), frame_(orthonormalFrame(frame, needUp, name_)) {}

void AxialWarp::setFrame(const AxisFrame& frame) {
    frame_ = orthonormalFrame(frame, needUp_, name_);
    bound_ = false;
}

void AxialWarp::bind(std::span<const glm::vec3> restPoints, SparseFields& fields) {
    requireFinitePoints(restPoints, name_, "rest point");
    const size_t n = restPoints.size();
    restZ_.resize(n);
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(n); ++u)
        restZ_[u] = frame_.toLocal(restPoints[u]).z;
    fields.offsets.resize(n + 1);
    fields.transform.resize(n);
    fields.strength.assign(n, 1.0f);
    fields.weight.assign(n, 1.0f);
    for (size_t u = 0; u <= n; ++u)
        fields.offsets[u] = static_cast<int32_t>(u);
    for (size_t u = 0; u < n; ++u)
        fields.transform[u] = static_cast<int32_t>(u);
    scratch_.resize(n);
    bound_ = true;
}

void AxialWarp::transformations(Transformations& out) const {
    out.method = ScaleMethod::Displacement;  // strength is 1, so the method makes no difference (footnote 12)
    out.components.clear();
    out.affine.resize(restZ_.size());
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(restZ_.size()); ++u)
        out.affine[u] = transformationAt(restZ_[u]);
}

void AxialWarp::requireBound(size_t count, const char* what) const {
    if (!bound_)
        throw InvalidInput(formatError(name_, "evaluate", "called before bind", "bind(restPoints) first"));
    if (count != restZ_.size()) {
        throw InvalidInput(formatError(name_, what, "has " + std::to_string(count) + " entries",
                                       std::to_string(restZ_.size()) + " entries, as many as bound"));
    }
}

void AxialWarp::deform(std::span<glm::vec3> points, std::span<const float> weights, float envelope) {
    requireBound(points.size(), "points");
    requireFinitePoints(points, name_, "point");
    if (!std::isfinite(envelope)) {
        throw InvalidInput(formatError(name_, "envelope", "is not finite", "a number, usually in [0, 1]"));
    }
    evaluate(points, scratch_);
    applyEnvelope(points, scratch_, weights, envelope, points);
}

// ---- taper ----

TaperWarp::TaperWarp(const AxisFrame& frame, ProfileCurve profile)
    : AxialWarp(frame, false, "taper"), profile_(std::move(profile)) {}

Affine TaperWarp::transformationAt(float z) const {
    const double f = profile_(z);
    return fromLocal(frame_, glm::dmat3(glm::dvec3(f, 0, 0), glm::dvec3(0, f, 0), glm::dvec3(0, 0, 1)),
                     glm::dvec3(0.0));
}

void TaperWarp::evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    requireBound(points.size(), "points");
    requireBound(out.size(), "output points");
    const glm::vec3 o = frame_.origin, a = frame_.axis;
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(points.size()); ++u) {
        const glm::vec3 p = points[u];
        const glm::vec3 d = p - o;
        const glm::vec3 radial = d - glm::dot(d, a) * a;
        out[u] = p + (profile_(restZ_[u]) - 1.0f) * radial;
    }
}

// ---- twist ----

TwistWarp::TwistWarp(const AxisFrame& frame, ProfileCurve angle)
    : AxialWarp(frame, false, "twist"), angle_(std::move(angle)) {}

Affine TwistWarp::transformationAt(float z) const {
    const double t = angle_(z), c = std::cos(t), s = std::sin(t);
    return fromLocal(frame_, glm::dmat3(glm::dvec3(c, s, 0), glm::dvec3(-s, c, 0), glm::dvec3(0, 0, 1)),
                     glm::dvec3(0.0));
}

void TwistWarp::evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    requireBound(points.size(), "points");
    requireBound(out.size(), "output points");
    const glm::vec3 o = frame_.origin, a = frame_.axis;
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(points.size()); ++u) {
        const glm::vec3 p = points[u];
        const glm::vec3 d = p - o;
        const glm::vec3 radial = d - glm::dot(d, a) * a;
        const float t = angle_(restZ_[u]);
        // Rodrigues on the radial part: R r = cos t r + sin t (a x r).
        out[u] = p + (std::cos(t) - 1.0f) * radial + std::sin(t) * glm::cross(a, radial);
    }
}

// ---- bend ----

BendWarp::BendWarp(const AxisFrame& frame, const BendParams& params) : AxialWarp(frame, true, "bend") {
    setParams(params);
}

void BendWarp::setParams(const BendParams& p) {
    const auto check = [](float v, const char* name) {
        if (!std::isfinite(v)) throw InvalidInput(formatError("bend", name, "is not finite", "a number"));
    };
    check(p.rate, "rate");
    check(p.centre, "centre");
    check(p.lo, "lo");
    check(p.hi, "hi");
    if (p.lo > p.hi) {
        throw InvalidInput(formatError(
            "bend", "lo", "is " + std::to_string(p.lo) + ", above hi " + std::to_string(p.hi), "lo <= hi"));
    }
    params_ = p;
}

Affine BendWarp::transformationAt(float z) const {
    const double k = params_.rate, z0 = params_.centre;
    const double zc = std::clamp(z, params_.lo, params_.hi);
    const double t = k * (zc - z0), c = std::cos(t), s = std::sin(t);
    const double sinOverK = (zc - z0) * sinc(t), versOverK = (zc - z0) * versinc(t);
    // Local linear part: columns x, y, z of (x, y, z) -> (x, c y + s z, -s y + c z).
    const glm::dmat3 m(glm::dvec3(1, 0, 0), glm::dvec3(0, c, -s), glm::dvec3(0, s, c));
    return fromLocal(frame_, m, glm::dvec3(0.0, versOverK - s * zc, z0 + sinOverK - c * zc));
}

void BendWarp::evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    requireBound(points.size(), "points");
    requireBound(out.size(), "output points");
    const float k = params_.rate, z0 = params_.centre, lo = params_.lo, hi = params_.hi;
    const OrthoFrame f = frame_;
    if (k == 0.0f) {  // Barr's bend with k = 0 is the identity
        if (out.data() != points.data()) std::copy(points.begin(), points.end(), out.begin());
        return;
    }
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(points.size()); ++u) {
        const glm::vec3 l = f.toLocal(points[u]);
        const float zc = std::clamp(restZ_[u], lo, hi);
        const float d = zc - z0, t = k * d;
        const float c = std::cos(t), s = std::sin(t);
        const float along = l.z - zc;  // 0 inside the range for the rest points themselves
        const float y = c * l.y + s * along + d * versincf(t);
        const float z = z0 + d * sincf(t) - s * l.y + c * along;
        out[u] = f.origin + l.x * f.side + y * f.up + z * f.axis;
    }
}

}  // namespace deformkit::warp
