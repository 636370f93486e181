#include "deformkit/warp/barr.h"
#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/envelope.h"
#include "warp/checks.h"
#include "warp/point_text.h"

namespace deformkit::warp {
namespace {

void requireFinitePoints(std::span<const glm::vec3> points, const std::string& source, const char* what) {
    // In parallel, naming the first bad point whatever the schedule.
    const auto n = static_cast<int64_t>(points.size());
    int64_t first = n;
#pragma omp parallel for schedule(static) reduction(min : first) if (n >= 65536)
    for (int64_t i = 0; i < n; ++i) {
        if (!geom::isFinite(points[i])) first = std::min(first, i);
    }
    if (first < n) {
        throw InvalidInput(formatError(source, std::string(what) + " " + std::to_string(first),
                                       "is " + detail::pointText(points[first]), "finite coordinates"));
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
float versincf(float t) {
    if (std::abs(t) < 1e-3f) return 0.5f * t;
    const float s = std::sin(0.5f * t);
    return 2.0f * s * s / t;
}

}  // namespace

namespace detail {

// The profile curve for the direct paths (outside the anonymous namespace: Taper and Twist's run<Check>
// member templates capture it): the same Fritsch-Carlson Hermite segments as
// ProfileCurve::operator(), evaluated inline in float. ProfileCurve works in double behind a call into
// another translation unit, which was most of the per-point cost of taper and twist; the two agree to float
// rounding (the engine path, which uses ProfileCurve, is checked against this one to 1e-5).
class InlineProfile {
  public:
    explicit InlineProfile(const ProfileCurve& curve)
        : z_(curve.z().data()),
          y_(curve.values().data()),
          m_(curve.tangents().data()),
          n_(curve.z().size()) {}

    float operator()(float z) const {
        if (!(z > z_[0])) return y_[0];
        if (z >= z_[n_ - 1]) return y_[n_ - 1];
        const size_t k = static_cast<size_t>(std::upper_bound(z_, z_ + n_, z) - z_) - 1;
        const float h = z_[k + 1] - z_[k], t = (z - z_[k]) / h;
        const float t2 = t * t, t3 = t2 * t;
        const float h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
        return h00 * y_[k] + h10 * h * m_[k] + h01 * y_[k + 1] + h11 * h * m_[k + 1];
    }

  private:
    const float *z_, *y_, *m_;
    size_t n_;
};

}  // namespace detail

namespace {

// sinc and versinc from an already computed s = sin t, c = cos t, sparing the bend's direct path two more
// trigonometric calls per point: (1 - cos t) / t = sin^2 t / ((1 + cos t) t), exact algebra, well
// conditioned while cos t > -1/2; near t = 0 and beyond |t| = 2 pi / 3 the direct forms above.
float sincFrom(float t, float s) {
    return std::abs(t) < 1e-3f ? 1.0f - t * t * (1.0f / 6.0f) : s / t;
}
float versincFrom(float t, float s, float c) {
    if (std::abs(t) < 1e-3f) return 0.5f * t;
    if (c > -0.5f) return s * s / ((1.0f + c) * t);
    return versincf(t);
}

// sin and cos of a block of angles without calls or branches, so that the compiler vectorises the loop
// (4 angles an SSE2 instruction; a glibc sincosf call per point was a third of the twist's time). The angle
// is reduced by the nearest multiple q of pi/2, with pi/2 split in three parts (Cody-Waite) so that q * part
// stays exact or nearly, to r in [-pi/4, pi/4]; then the Taylor series to degree 9 (sin) and 10 (cos), whose
// truncation error there is below 2e-9, far under float rounding. The quadrant q mod 4 swaps and negates.
// Valid for |t| <= kBlockTrigLimit; the callers fall back to std::sin/std::cos beyond it.
constexpr float kBlockTrigLimit = 8192.0f;
constexpr int kTrigBlock = 256;  // points per block: the scratch arrays live on the stack

void sinCosBlock(const float* t, float* sinOut, float* cosOut, int count) {
    constexpr float kTwoOverPi = 0.636619772367581343f;
    constexpr float kHalfPi1 = 1.5703125f;                // 8 significant bits: q * kHalfPi1 exact
    constexpr float kHalfPi2 = 4.837512969970703125e-4f;  // 13 bits
    constexpr float kHalfPi3 = 7.54978995489188216e-8f;   // the rest of pi/2
    constexpr float kRound = 12582912.0f;                 // 1.5 * 2^23: adding it rounds to an integer
    for (int i = 0; i < count; ++i) {
        const float x = t[i];
        const float q = (x * kTwoOverPi + kRound) - kRound;
        const float r = ((x - q * kHalfPi1) - q * kHalfPi2) - q * kHalfPi3;
        const float r2 = r * r;
        const float sr =
            r * (1.0f + r2 * (-1.0f / 6 + r2 * (1.0f / 120 + r2 * (-1.0f / 5040 + r2 * (1.0f / 362880)))));
        const float cr =
            1.0f + r2 * (-0.5f + r2 * (1.0f / 24 +
                                       r2 * (-1.0f / 720 + r2 * (1.0f / 40320 + r2 * (-1.0f / 3628800)))));
        const int quadrant = static_cast<int>(q) & 3;
        const float sq = (quadrant & 1) ? cr : sr, cq = (quadrant & 1) ? sr : cr;
        sinOut[i] = (quadrant & 2) ? -sq : sq;
        cosOut[i] = ((quadrant + 1) & 2) ? -cq : cq;
    }
}

// sinCosBlock, or std::sin/std::cos for the whole block when an angle is beyond its range (or not finite).
// The choice depends on the block's own angles only, so the output does not depend on the thread count.
void sinCos(const float* t, float* sinOut, float* cosOut, int count) {
    bool small = true;
    for (int i = 0; i < count; ++i)
        small = small && std::abs(t[i]) <= kBlockTrigLimit;
    if (small) {
        sinCosBlock(t, sinOut, cosOut, count);
        return;
    }
    for (int i = 0; i < count; ++i) {
        sinOut[i] = std::sin(t[i]);
        cosOut[i] = std::cos(t[i]);
    }
}

// Points in blocks of kTrigBlock over all threads (chunks of 16 blocks, 4096 points): each point's angle
// (angleOf(u)), then the block's sines and cosines in one vectorised pass, then the block's own work
// (apply(begin, count, t, sin t, cos t)). A point depends on its own inputs only: any schedule gives the
// same output. The callables are taken by value: what they capture stays in registers, not behind a
// reference that a store to the output could alias.
// apply returns the first point of its block that is not finite, or n: forEachAngleBlock returns the
// first of the whole run.
template <class AngleOf, class Apply>
int64_t forEachAngleBlock(int64_t n, const AngleOf angleOf, const Apply apply) {
    int64_t bad = n;
#pragma omp parallel for schedule(dynamic, 16) reduction(min : bad)
    for (int64_t begin = 0; begin < n; begin += kTrigBlock) {
        const int count = static_cast<int>(std::min<int64_t>(kTrigBlock, n - begin));
        float t[kTrigBlock], sinT[kTrigBlock], cosT[kTrigBlock];
        for (int i = 0; i < count; ++i)
            t[i] = angleOf(begin + i);
        sinCos(t, sinT, cosT, count);
        bad = std::min(bad, apply(begin, count, t, sinT, cosT));
    }
    return bad;
}

// Points a taper's parallel loop takes at a time, checking their outputs after (Check) while they are in
// cache: a vectorised pass over a run costs less than a test of each point.
constexpr int64_t kRun = 512;

// For a block of outputs just written (Check): the first point of out[begin, begin + count) that is not
// finite, or n; n without looking when not checking.
template <bool Check>
int64_t firstNonFiniteOf(std::span<const glm::vec3> out, int64_t begin, int count, int64_t n) {
    if constexpr (!Check) return n;
    return detail::firstNonFiniteOfRun(out, begin, count, n);
}

// The world map x -> o + F M F^T (x - o) + F t, F = [side up axis]: a local-frame affine map in world space.
Affine fromLocal(const OrthoFrame& f, const glm::dmat3& m, const glm::dvec3& t = glm::dvec3(0.0)) {
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
    if (!geom::isFinite(frame.origin)) {
        throw InvalidInput(formatError(source, "axis_origin", "is " + detail::pointText(frame.origin),
                                       "finite coordinates"));
    }
    if (!geom::isFinite(frame.axis)) {
        throw InvalidInput(
            formatError(source, "axis_dir", "is " + detail::pointText(frame.axis), "finite coordinates"));
    }
    const double axisLength = glm::length(glm::dvec3(frame.axis));
    if (!(axisLength > 1e-12)) {
        throw InvalidInput(formatError(source, "axis_dir",
                                       axisLength == 0.0 ? std::string("is the zero vector")
                                                         : "is " + detail::pointText(frame.axis) +
                                                               ", of length " + numberText(axisLength),
                                       "a direction longer than 1e-12"));
    }
    OrthoFrame out;
    out.origin = frame.origin;
    const glm::dvec3 axis = glm::dvec3(frame.axis) / axisLength;
    glm::dvec3 up(0.0);
    if (geom::isFinite(frame.up)) {
        const glm::dvec3 u(frame.up);
        const double upLength = glm::length(u);
        // Perpendicular part; "parallel" means within about 0.06 degrees of the axis.
        const glm::dvec3 perpendicular = u - glm::dot(u, axis) * axis;
        if (upLength > 1e-12 && glm::length(perpendicular) > 1e-6 * upLength)
            up = glm::normalize(perpendicular);
    } else if (needUp) {
        throw InvalidInput(
            formatError(source, "up_dir", "is " + detail::pointText(frame.up), "finite coordinates"));
    }
    if (up == glm::dvec3(0.0)) {
        if (needUp) {
            throw InvalidInput(formatError(source, "up_dir",
                                           detail::pointText(frame.up) + " is zero or parallel to axis_dir " +
                                               detail::pointText(frame.axis),
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

void AxialWarp::bind(std::span<const glm::vec3> restPoints) {
    requireFinitePoints(restPoints, name_, "rest point");
    const size_t n = restPoints.size();
    restZ_.resize(n);
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(n); ++u)
        restZ_[u] = frame_.toLocal(restPoints[u]).z;
    bound_ = true;
}

void AxialWarp::bind(std::span<const glm::vec3> restPoints, SparseFields& fields) {
    bind(restPoints);
    const size_t n = restPoints.size();
    fields.offsets.resize(n + 1);
    fields.transform.resize(n);
    fields.strength.assign(n, 1.0f);
    fields.weight.assign(n, 1.0f);
    for (size_t u = 0; u <= n; ++u)
        fields.offsets[u] = static_cast<int32_t>(u);
    for (size_t u = 0; u < n; ++u)
        fields.transform[u] = static_cast<int32_t>(u);
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

void AxialWarp::requireBound(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    requireBound(points.size(), "points");
    requireBound(out.size(), "output points");
}

void AxialWarp::deform(std::span<glm::vec3> points, std::span<const float> weights, float envelope) {
    requireBound(points.size(), "points");
    requireFinitePoints(points, name_, "point");
    requireFiniteEnvelope(name_, weights, envelope);
    if (envelope == 1.0f && weights.empty()) {
        // What the envelope gives for k = 1, without the copy; the input is finite (above), so a point that
        // is not is one the warp took beyond float range.
        requireFiniteResult(name_, {}, points, evaluateFinite(points, points));
        return;
    }
    // Where k = 0 the input stands whatever the warp gave there: only the blend is checked.
    scratch_.resize(points.size());
    evaluate(points, scratch_);
    requireFiniteResult(name_, {}, points, applyEnvelope(points, scratch_, weights, envelope, points));
}

void AxialWarp::deform(std::span<const glm::vec3> points, std::span<glm::vec3> out,
                       std::span<const float> weights, float envelope) {
    requireBound(points.size(), "points");
    requireFiniteEnvelope(name_, weights, envelope);
    // The output's first point that is not finite: the input's (named as such), or one the warp or the
    // envelope took beyond float range. With an envelope or weights only the blend is checked: where k = 0
    // the input stands whatever the warp gave there.
    if (envelope == 1.0f && weights.empty()) {
        requireFiniteResult(name_, points, out, evaluateFinite(points, out));
        return;
    }
    evaluate(points, out);
    requireFiniteResult(name_, points, out, applyEnvelope(points, out, weights, envelope, out));
}

// ---- taper ----

TaperWarp::TaperWarp(const AxisFrame& frame, ProfileCurve profile)
    : ProfiledAxialWarp(frame, "taper", std::move(profile)) {}

Affine TaperWarp::transformationAt(float z) const {
    const double f = profile_(z);
    return fromLocal(frame_, glm::dmat3(glm::dvec3(f, 0, 0), glm::dvec3(0, f, 0), glm::dvec3(0, 0, 1)));
}

void TaperWarp::evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    (void)run<false>(points, out);
}

int64_t TaperWarp::evaluateFinite(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    return run<true>(points, out);
}

template <bool Check>
int64_t TaperWarp::run(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    requireBound(points, out);
    const glm::vec3 o = frame_.origin, a = frame_.axis;
    const detail::InlineProfile profile(profile_);
    const auto n = static_cast<int64_t>(points.size());
    const int64_t runs = (n + kRun - 1) / kRun;
    int finite = 1;
    // Dynamic chunks of 4096 points (here and in twist and bend): a thread the host deschedules does not
    // hold up the others. Each point depends on its own inputs only: any schedule gives the same output.
#pragma omp parallel for schedule(dynamic, 8) reduction(& : finite)
    for (int64_t run = 0; run < runs; ++run) {
        const int64_t begin = run * kRun, end = std::min(n, begin + kRun);
        for (int64_t u = begin; u < end; ++u) {
            const glm::vec3 p = points[u];
            const glm::vec3 d = p - o;
            const glm::vec3 radial = d - glm::dot(d, a) * a;
            out[u] = p + (profile(restZ_[u]) - 1.0f) * radial;
        }
        if constexpr (Check) finite &= static_cast<int>(geom::allFinite(out.subspan(begin, end - begin)));
    }
    return Check && finite == 0 ? detail::firstNonFinite(out) : n;
}

// ---- twist ----

TwistWarp::TwistWarp(const AxisFrame& frame, ProfileCurve angle)
    : ProfiledAxialWarp(frame, "twist", std::move(angle)) {}

Affine TwistWarp::transformationAt(float z) const {
    const double t = profile_(z), c = std::cos(t), s = std::sin(t);
    return fromLocal(frame_, glm::dmat3(glm::dvec3(c, s, 0), glm::dvec3(-s, c, 0), glm::dvec3(0, 0, 1)));
}

void TwistWarp::evaluate(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    (void)run<false>(points, out);
}

int64_t TwistWarp::evaluateFinite(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    return run<true>(points, out);
}

template <bool Check>
int64_t TwistWarp::run(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    requireBound(points, out);
    const glm::vec3 o = frame_.origin, a = frame_.axis;
    const detail::InlineProfile angle(profile_);
    const float* z = restZ_.data();
    const auto n = static_cast<int64_t>(points.size());
    return forEachAngleBlock(
        n, [angle, z](int64_t u) { return angle(z[u]); },
        [o, a, points, out, n](int64_t begin, int count, const float*, const float* sinT, const float* cosT) {
            for (int i = 0; i < count; ++i) {
                const int64_t u = begin + i;
                const glm::vec3 p = points[u];
                const glm::vec3 d = p - o;
                const glm::vec3 radial = d - glm::dot(d, a) * a;
                // Rodrigues on the radial part: R r = cos t r + sin t (a x r).
                out[u] = p + (cosT[i] - 1.0f) * radial + sinT[i] * glm::cross(a, radial);
            }
            return firstNonFiniteOf<Check>(out, begin, count, n);
        });
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
    (void)run<false>(points, out);
}

int64_t BendWarp::evaluateFinite(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    return run<true>(points, out);
}

template <bool Check>
int64_t BendWarp::run(std::span<const glm::vec3> points, std::span<glm::vec3> out) const {
    requireBound(points, out);
    const float k = params_.rate, z0 = params_.centre, lo = params_.lo, hi = params_.hi;
    const OrthoFrame f = frame_;
    const auto n = static_cast<int64_t>(points.size());
    if (k == 0.0f) {  // Barr's bend with k = 0 is the identity
        if (out.data() != points.data()) std::copy(points.begin(), points.end(), out.begin());
        return Check ? detail::firstNonFinite(out) : n;
    }
    const float* z = restZ_.data();
    return forEachAngleBlock(
        n, [k, z0, lo, hi, z](int64_t u) { return k * (std::clamp(z[u], lo, hi) - z0); },
        [f, z0, lo, hi, z, points, out, n](int64_t begin, int count, const float* t, const float* sinT,
                                           const float* cosT) {
            for (int i = 0; i < count; ++i) {
                const int64_t u = begin + i;
                const glm::vec3 l = f.toLocal(points[u]);
                const float zc = std::clamp(z[u], lo, hi);
                const float d = zc - z0;
                const float c = cosT[i], s = sinT[i];
                const float along = l.z - zc;  // 0 inside the range for the rest points themselves
                const float y = c * l.y + s * along + d * versincFrom(t[i], s, c);
                const float zz = z0 + d * sincFrom(t[i], s) - s * l.y + c * along;
                out[u] = f.origin + l.x * f.side + y * f.up + zz * f.axis;
            }
            return firstNonFiniteOf<Check>(out, begin, count, n);
        });
}

}  // namespace deformkit::warp
