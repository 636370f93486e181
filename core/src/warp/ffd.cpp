#include "deformkit/warp/ffd.h"
#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/envelope.h"
#include "ffd_kernels.h"
#include "simd/cpu.h"
#include "warp/checks.h"
#include "warp/point_text.h"

namespace deformkit::warp {
namespace {

constexpr const char* kAxisNames[3] = {"X", "Y", "Z"};
constexpr const char* kDivisionNames[3] = {"divisions[0] (l)", "divisions[1] (m)", "divisions[2] (n)"};
// Points this far outside [0, 1] in local coordinates (round-off on the lattice faces) still count as
// inside; they are evaluated with their unclamped coordinates, so nothing is clamped.
constexpr double kInsideTolerance = 1e-5;
constexpr int64_t kMaxControls = int64_t{1} << 24;
// The tension of Blender's "Cardinal" spline.
constexpr float kCardinalTension = 0.71f;

void validate(const Lattice& lattice, const FfdOptions& options) {
    const char* source = "FFD lattice";
    for (int a = 0; a < 3; ++a) {
        const bool bernstein = options.basis[a] == FfdBasis::Bernstein;
        const int32_t maxDiv = bernstein ? kMaxBernsteinDegree : kMaxFfdDivisions;
        const int32_t d = lattice.divisions[a];
        if (d < 1 || d > maxDiv) {
            throw InvalidInput(
                formatError(source, kDivisionNames[a], "is " + std::to_string(d),
                            "an integer in [1, " + std::to_string(maxDiv) + "]" +
                                (bernstein && d > maxDiv ? "; use the B-spline basis for more" : "")));
        }
    }
    int64_t controls = 1;
    for (int a = 0; a < 3; ++a)
        controls *= lattice.divisions[a] + 1;
    if (controls > kMaxControls) {
        throw InvalidInput(formatError(source, "divisions",
                                       "give " + std::to_string(controls) + " control points",
                                       "at most " + std::to_string(kMaxControls)));
    }
    if (!geom::isFinite(lattice.origin)) {
        throw InvalidInput(
            formatError(source, "origin", "is not finite: " + detail::pointText(lattice.origin), "finite"));
    }
    double lengths = 1.0;
    for (int a = 0; a < 3; ++a) {
        const glm::vec3 axis = lattice.axes[a];
        const std::string element = std::string("axis ") + kAxisNames[a];
        if (!geom::isFinite(axis))
            throw InvalidInput(
                formatError(source, element, "is not finite: " + detail::pointText(axis), "finite"));
        const double len = glm::length(glm::dvec3(axis));
        if (len == 0.0) {
            throw InvalidInput(formatError(source, element, "has zero length", "a non-zero edge vector"));
        }
        lengths *= len;
    }
    const double det = glm::determinant(glm::dmat3(lattice.axes));
    if (std::abs(det) <= 1e-6 * lengths) {
        throw InvalidInput(formatError(source, "axes X, Y, Z", "are coplanar (zero volume)",
                                       "three linearly independent edge vectors"));
    }
}

// The four weights of controls span - 1 .. span + 2 of a spline basis at u in [0, 1] along the span (beyond
// it when extrapolating). Linear touches only the middle two.
void splineWeights(FfdBasis basis, float u, float* b) {
    const float u2 = u * u, u3 = u2 * u;
    switch (basis) {
        case FfdBasis::Linear:
            b[0] = 0.0f;
            b[1] = 1.0f - u;
            b[2] = u;
            b[3] = 0.0f;
            return;
        case FfdBasis::Cardinal:
        case FfdBasis::CatmullRom: {
            // The cardinal spline of tension a: the Hermite curve through controls 1 and 2 with tangents
            // a (P_2 - P_0) and a (P_3 - P_1); Blender's "Cardinal" takes a = 0.71, Catmull-Rom a = 1/2.
            const float a = basis == FfdBasis::Cardinal ? kCardinalTension : 0.5f;
            b[0] = -a * u3 + 2.0f * a * u2 - a * u;
            b[1] = (2.0f - a) * u3 + (a - 3.0f) * u2 + 1.0f;
            b[2] = (a - 2.0f) * u3 + (3.0f - 2.0f * a) * u2 + a * u;
            b[3] = a * u3 - a * u2;
            return;
        }
        default: {  // uniform cubic B-spline
            const float v = 1.0f - u;
            b[0] = v * v * v / 6.0f;
            b[1] = (3.0f * u3 - 6.0f * u2 + 4.0f) / 6.0f;
            b[2] = (-3.0f * u3 + 3.0f * u2 + 3.0f * u + 1.0f) / 6.0f;
            b[3] = u3 / 6.0f;
            return;
        }
    }
}

// The hot loop for a 4x4x4 window of controls (B-spline, or Bernstein of degree 3): for each (i, j) the
// window's run of 4 controls is contiguous (4 Stride floats), so the sum over (i, j) is a fixed-width
// vector accumulation and the k weights are applied once at the end. Fixed order: deterministic.
// GCC/Clang vector extension: four floats in one SSE register; loads and stores through memcpy (unaligned).
typedef float Float4 __attribute__((vector_size(16)));

inline Float4 load4(const float* p) {
    Float4 v;
    std::memcpy(&v, p, sizeof(v));
    return v;
}

template <int Stride>
void windowSum(const float* data, int32_t ny, int32_t nz, const int32_t* first, const float (*w)[4],
               float* out) {
    constexpr int kVectors = Stride;  // 4 controls x Stride floats = Stride vectors of 4
    Float4 acc[kVectors] = {};
    for (int32_t a = 0; a < 4; ++a) {
        for (int32_t b = 0; b < 4; ++b) {
            const float wab = w[0][a] * w[1][b];
            const float* row =
                data + static_cast<size_t>(((first[0] + a) * ny + first[1] + b) * nz + first[2]) * Stride;
            for (int v = 0; v < kVectors; ++v)
                acc[v] += wab * load4(row + 4 * v);
        }
    }
    float sum[4 * Stride];
    std::memcpy(sum, acc, sizeof(sum));
    for (int e = 0; e < Stride; ++e) {
        out[e] = w[2][0] * sum[e] + w[2][1] * sum[Stride + e] + w[2][2] * sum[2 * Stride + e] +
                 w[2][3] * sum[3 * Stride + e];
    }
}

// The 4x4x4 kernels (ffd_kernels.h) for this CPU; Portable forces the baseline build.
const detail::FfdKernels& ffdKernels(FfdKernel choice) {
#ifdef DEFORMKIT_SIMD_X86
    if (choice == FfdKernel::Auto && simd::activeIsa() == simd::Isa::Avx2) return detail::kAvx2FfdKernels;
#endif
    (void)choice;
    return detail::kBaselineFfdKernels;
}

// The kernel giving the 4x4x4 window weights of eight points at once for these options: the Bernstein cubic
// or a cubic B-spline (either end rule) on every axis; nullptr for the other bases (their per-point path).
decltype(detail::FfdKernels::bernsteinWeights444) laneWeights444(const detail::FfdKernels& kernels,
                                                                 const FfdOptions& options) {
    if (options.basis.all(FfdBasis::Bernstein)) return kernels.bernsteinWeights444;
    if (!options.basis.all(FfdBasis::BSpline)) return nullptr;
    return options.ends == FfdEnds::Repeat ? kernels.bsplineRepeatWeights444 : kernels.bsplineWeights444;
}

// The kernel giving the 4x4x4 sums of eight points with their weights computed in registers, for these
// options: the Bernstein cubic or a cubic B-spline (either end rule) on every axis; nullptr for the others.
decltype(detail::FfdKernels::bernstein444) laneKernel444(const detail::FfdKernels& kernels,
                                                         const FfdOptions& options) {
    if (options.basis.all(FfdBasis::Bernstein)) return kernels.bernstein444;
    if (!options.basis.all(FfdBasis::BSpline)) return nullptr;
    return options.ends == FfdEnds::Repeat ? kernels.bsplineRepeat444 : kernels.bspline444;
}

// The blocked loops below go over runs of kRunBlocks blocks (512 points) and check each run's outputs once
// written, while they are in cache, in one vectorised pass: a check per point costs the 4x4x4 kernels, whose
// per-point work is small, about a tenth of their time.
constexpr int64_t kRunBlocks = 64;

// The first point of `run` whose output is not finite, or n: the check of a run once written (in cache).
int64_t firstNonFiniteOfRun(std::span<const glm::vec3> out, int64_t run, int64_t n) {
    const int64_t begin = run * kRunBlocks * detail::kBlock;
    return detail::firstNonFiniteOfRun(out, begin, std::min(n - begin, kRunBlocks * detail::kBlock), n);
}

// The 4x4x4 lattice in blocks of eight points: local(u, active) gives point u's bound coordinates and
// whether the warp reaches it, kernel(local block, displacements) their displacements D; out[u] = points[u] +
// envelope * weight * D(u) for those it reaches, points[u] for the others (out may be points). Each block
// reads and writes its own points only: the output does not depend on the schedule. Returns the first point
// whose output is not finite, or n.
template <class Local, class Kernel>
int64_t blocks444(int64_t n, const Kernel& kernel, std::span<const glm::vec3> points,
                  std::span<glm::vec3> out, std::span<const float> weights, float envelope,
                  const Local& local) {
    constexpr int kBlock = detail::kBlock;
    const int64_t blocks = (n + kBlock - 1) / kBlock;
    const int64_t runs = (blocks + kRunBlocks - 1) / kRunBlocks;
    int64_t bad = n;
    // The loop over runs is written out here and in deformWindow444: through a shared lambda the Bernstein
    // evaluate took 1.14-1.17x the unchecked loop's time, written out 1.05-1.07x.
#pragma omp parallel for schedule(dynamic, 8) reduction(min : bad)
    for (int64_t run = 0; run < runs; ++run) {
        const int64_t lastBlock = std::min(blocks, (run + 1) * kRunBlocks);
        for (int64_t b = run * kRunBlocks; b < lastBlock; ++b) {
            const int64_t begin = b * kBlock;
            const int count = static_cast<int>(std::min<int64_t>(kBlock, n - begin));
            detail::LocalBlock in{};
            bool active[kBlock] = {};
            for (int lane = 0; lane < count; ++lane) {
                const glm::vec3 l = local(begin + lane, active[lane]);
                in.x[lane] = l.x;
                in.y[lane] = l.y;
                in.z[lane] = l.z;
            }
            detail::DisplacementBlock d;
            kernel(in, d);
            for (int lane = 0; lane < count; ++lane) {
                const int64_t u = begin + lane;
                if (!active[lane]) {
                    out[u] = points[u];
                    continue;
                }
                const float k = envelope * (weights.empty() ? 1.0f : weights[u]);
                out[u] = points[u] + k * glm::vec3(d.x[lane], d.y[lane], d.z[lane]);
            }
        }
        bad = std::min(bad, firstNonFiniteOfRun(out, run, n));
    }
    return bad;
}

// Weights of controls first .. first + count - 1 along one axis of d divisions at x = local coordinate * d.
// Beyond the lattice (x < 0 or x > d: FfdOutside::Extrapolate, or round-off within kInsideTolerance) every
// basis but a spline with repeated ends continues from its end face with the value and slope it has there,
// T_0 + x k (T_1 - T_0) or T_d + (x - d) k (T_d - T_(d-1)): k = 1 for the Bernstein polynomial, the linear
// basis, the B-spline and Catmull-Rom with extrapolated ends, 2 a for the cardinal spline of tension a (its
// end tangent over the extrapolated control). Linear in x, so an affine lattice stays affine at any degree
// (float rounding growing with the weights' size, the distance), where the polynomials amplify it by (2 |s| +
// 1)^degree (docs/decisions.md, "FFD points outside the lattice"). The SoA kernels (ffd_kernels.h) compute
// the same weights with the same operations.
inline int32_t basisWeights(FfdBasis basis, FfdEnds ends, int32_t d, const float* binomial, float x,
                            int32_t& first, float* w) {
    if ((x < 0.0f || x > static_cast<float>(d)) &&
        (basis == FfdBasis::Bernstein || ends != FfdEnds::Repeat)) {
        const float slope = basis == FfdBasis::Cardinal ? 2.0f * kCardinalTension : 1.0f;
        if (x < 0.0f) {
            first = 0;
            w[0] = 1.0f - slope * x;
            w[1] = slope * x;
            return 2;
        }
        const float e = x - static_cast<float>(d);
        first = d - 1;
        w[0] = -(slope * e);
        w[1] = 1.0f + slope * e;
        return 2;
    }
    if (basis == FfdBasis::Bernstein && d == 3) {
        // The common cubic in closed form.
        const float s = x / 3.0f, r = 1.0f - s;
        w[0] = r * r * r;
        w[1] = 3.0f * s * r * r;
        w[2] = 3.0f * s * s * r;
        w[3] = s * s * s;
        first = 0;
        return 4;
    }
    if (basis == FfdBasis::Bernstein) {
        // B^d_i(s) = C(d, i) s^i (1 - s)^(d - i), s = x / d (Sederberg and Parry's convention: i = 0 at s =
        // 0).
        const float s = x / static_cast<float>(d), r = 1.0f - s;
        float power = 1.0f;
        for (int32_t i = 0; i <= d; ++i) {
            w[i] = binomial[i] * power;
            power *= s;
        }
        power = 1.0f;
        for (int32_t i = d; i >= 0; --i) {
            w[i] *= power;
            power *= r;
        }
        first = 0;
        return d + 1;
    }
    float b[4];
    if (ends == FfdEnds::Repeat) {
        // Blender's Lattice: the span holding x, controls span - 1 .. span + 2 with indices clamped to the
        // lattice, so a missing control is the end control again; beyond the lattice every tap lands on the
        // end control (the span is kept within two of the ends, which changes no index, not u).
        const float cell = std::floor(x);
        const float u = x - cell;
        const auto span = static_cast<int32_t>(std::clamp(cell, -2.0f, static_cast<float>(d) + 1.0f));
        splineWeights(basis, u, b);
        first = std::clamp(span - 1, 0, d);
        const int32_t last = std::clamp(span + 2, 0, d);
        for (int32_t i = 0; i <= last - first; ++i)
            w[i] = 0.0f;
        for (int32_t c = 0; c < 4; ++c)
            w[std::clamp(span - 1 + c, 0, d) - first] += b[c];
        return last - first + 1;
    }
    // The span holding x, the end spans beyond the lattice, touching controls span - 1 .. span + 2. The
    // missing controls -1 and d + 1 beyond the ends are linear extrapolations (T_-1 = 2 T_0 - T_1), folded
    // into the weights here: partition of unity, linear precision and, for the B-spline, interpolation of
    // the end faces.
    const int32_t span = std::clamp(static_cast<int32_t>(std::floor(x)), 0, d - 1);
    splineWeights(basis, x - static_cast<float>(span), b);
    if (span == 0) {
        b[1] += 2.0f * b[0];
        b[2] -= b[0];
        b[0] = 0.0f;
    }
    if (span + 2 > d) {
        b[2] += 2.0f * b[3];
        b[1] -= b[3];
        b[3] = 0.0f;
    }
    const int32_t lo = span - 1;
    first = std::max(lo, 0);
    const int32_t last = std::min(span + 2, d);
    for (int32_t i = first; i <= last; ++i)
        w[i - first] = b[i - lo];
    return last - first + 1;
}

}  // namespace

bool ffdHasAvx2Kernel() {
    return simd::activeIsa() == simd::Isa::Avx2;
}

glm::vec3 Lattice::controlPoint(int32_t i, int32_t j, int32_t k) const {
    // In double so that the corner P_lmn lands on origin + X + Y + Z up to one rounding.
    const glm::dvec3 st(static_cast<double>(i) / divisions.x, static_cast<double>(j) / divisions.y,
                        static_cast<double>(k) / divisions.z);
    return glm::vec3(glm::dvec3(origin) + glm::dmat3(axes) * st);
}

std::vector<glm::vec3> Lattice::controlPoints() const {
    std::vector<glm::vec3> out(static_cast<size_t>(numControls()));
    for (int32_t i = 0; i <= divisions.x; ++i)
        for (int32_t j = 0; j <= divisions.y; ++j)
            for (int32_t k = 0; k <= divisions.z; ++k)
                out[index(i, j, k)] = controlPoint(i, j, k);
    return out;
}

FfdLattice::FfdLattice(const Lattice& lattice, const FfdOptions& options)
    : lattice_(lattice), options_(options) {
    validate(lattice, options);
    toLocal_ = glm::inverse(glm::dmat3(lattice.axes));
    for (int a = 0; a < 3; ++a) {
        const int32_t d = lattice.divisions[a];
        binomial_[a].assign(static_cast<size_t>(d) + 1, 1.0f);
        if (options.basis[a] != FfdBasis::Bernstein) continue;
        double c = 1.0;
        for (int32_t i = 1; i <= d; ++i) {
            c = c * (d - i + 1) / i;
            binomial_[a][i] = static_cast<float>(c);
        }
    }
}

glm::vec3 FfdLattice::localCoordinates(const glm::vec3& p) const {
    return glm::vec3(toLocal_ * (glm::dvec3(p) - glm::dvec3(lattice_.origin)));
}

glm::vec3 FfdLattice::boundCoordinates(const glm::vec3& p, const glm::dvec3& scale, bool& inside) const {
    const glm::dvec3 s = toLocal_ * (glm::dvec3(p) - glm::dvec3(lattice_.origin));
    inside = true;
    for (int a = 0; a < 3; ++a)
        inside = inside && s[a] >= -kInsideTolerance && s[a] <= 1.0 + kInsideTolerance;
    return glm::vec3(s * scale);
}

bool FfdLattice::deformUnbound(std::span<const glm::vec3> restPoints, std::span<const glm::vec3> points,
                               std::span<glm::vec3> out, const float* translations,
                               std::span<const float> weights, float envelope) const {
    const bool bernstein = options_.basis.all(FfdBasis::Bernstein);
    const bool bspline = options_.basis.all(FfdBasis::BSpline);
    if (options_.kernel == FfdKernel::PerPoint || !(bernstein || bspline) ||
        lattice_.divisions != glm::ivec3(3) || restPoints.size() != points.size() ||
        out.size() != points.size()) {
        return false;  // evaluate() checks the envelope and weights
    }
    requireFiniteEnvelope("FFD evaluate", weights, envelope);
    const auto n = static_cast<int64_t>(restPoints.size());
    int64_t bad = n;  // bind's check, naming the first non-finite point whatever the schedule
#pragma omp parallel for schedule(static) reduction(min : bad) if (n >= 65536)
    for (int64_t u = 0; u < n; ++u) {
        if (!geom::isFinite(restPoints[u])) bad = std::min(bad, u);
    }
    if (bad < n) {
        throw InvalidInput(formatError("FFD bind", "point " + std::to_string(bad),
                                       "is not finite: " + detail::pointText(restPoints[bad]),
                                       "finite positions"));
    }
    if (!weights.empty() && weights.size() != points.size()) return false;  // evaluate() names the mismatch
    const glm::dvec3 scale(lattice_.divisions);
    const bool extrapolate = options_.outside == FfdOutside::Extrapolate;
    const auto local = [&](int64_t u, bool& active) {
        bool inside = true;
        const glm::vec3 l = boundCoordinates(restPoints[u], scale, inside);
        active = inside || extrapolate;
        return l;
    };
    const auto kernel = laneKernel444(ffdKernels(options_.kernel), options_);
    const int64_t notFinite = blocks444(
        n, [&](const detail::LocalBlock& in, detail::DisplacementBlock& d) { kernel(in, translations, d); },
        points, out, weights, envelope, local);
    requireFiniteResult("FFD evaluate", points, out, notFinite);
    return true;
}

void FfdLattice::bind(std::span<const glm::vec3> restPoints) {
    // Validate first: a rejected bind leaves the previous one in place.
    const int64_t n = static_cast<int64_t>(restPoints.size());
    for (int64_t u = 0; u < n; ++u) {
        if (!geom::isFinite(restPoints[u])) {
            throw InvalidInput(formatError("FFD bind", "point " + std::to_string(u),
                                           "is not finite: " + detail::pointText(restPoints[u]),
                                           "finite positions"));
        }
    }
    local_.resize(static_cast<size_t>(n));
    active_.resize(static_cast<size_t>(n));
    const glm::dvec3 scale(lattice_.divisions);
    const bool extrapolate = options_.outside == FfdOutside::Extrapolate;
    // Dynamic chunks: a thread the host deschedules does not hold up the others. Each point is written
    // by one thread from its own inputs only, so the output does not depend on the schedule.
#pragma omp parallel for schedule(dynamic, 4096)
    for (int64_t u = 0; u < n; ++u) {
        bool inside = true;
        local_[u] = boundCoordinates(restPoints[u], scale, inside);
        active_[u] = (inside || extrapolate) ? 1 : 0;
    }
    // The 4x4x4 lattice in a spline basis: its weights are kept from the second evaluation on
    // (deformWindow444).
    windowSpline_ = lattice_.divisions == glm::ivec3(3) && !options_.basis.all(FfdBasis::Bernstein);
    {
        const std::lock_guard<std::mutex> lock(*windowCache_.mutex);
        windowCache_.weights.clear();
        windowCache_.evaluations = 0;
    }
    bound_ = true;
}

int32_t FfdLattice::axisWeights(int32_t axis, float x, int32_t& first, float* w) const {
    return basisWeights(options_.basis[axis], options_.ends, lattice_.divisions[axis], binomial_[axis].data(),
                        x, first, w);
}

void FfdLattice::fields(SparseFields& out) const {
    out.clear();
    const int32_t n = numBoundPoints();
    const int32_t ny = lattice_.divisions.y + 1, nz = lattice_.divisions.z + 1;
    float w[3][kMaxBernsteinDegree + 1];
    int32_t first[3], count[3];
    for (int32_t u = 0; u < n; ++u) {
        if (active_[u]) {
            for (int a = 0; a < 3; ++a)
                count[a] = axisWeights(a, local_[u][a], first[a], w[a]);
            for (int32_t a = 0; a < count[0]; ++a) {
                for (int32_t b = 0; b < count[1]; ++b) {
                    const float wab = w[0][a] * w[1][b];
                    const int32_t row = ((first[0] + a) * ny + first[1] + b) * nz + first[2];
                    for (int32_t c = 0; c < count[2]; ++c) {
                        const float wabc = wab * w[2][c];
                        if (wabc != 0.0f) out.add(row + c, 1.0f, wabc);
                    }
                }
            }
        }
        out.endPoint();
    }
}

void FfdLattice::deform(std::span<const glm::vec3> points, std::span<glm::vec3> out,
                        std::span<const float> deltas, int32_t stride, std::span<const float> weights,
                        float envelope) const {
    if (!bound_) {
        throw InvalidInput(formatError("FFD", "evaluate", "called before bind", "bind(restPoints) first"));
    }
    const int64_t n = numBoundPoints();
    for (const auto& [name, size] :
         {std::pair<const char*, size_t>{"points", points.size()}, {"output", out.size()}}) {
        if (static_cast<int64_t>(size) != n) {
            throw InvalidInput(formatError("FFD evaluate", name, "has " + std::to_string(size) + " points",
                                           std::to_string(n) + " points, as bound"));
        }
    }
    if (!weights.empty() && static_cast<int64_t>(weights.size()) != n) {
        throw InvalidInput(formatError("FFD evaluate", "painted weights",
                                       "has " + std::to_string(weights.size()) + " entries",
                                       std::to_string(n) + " entries, one per point, or none"));
    }
    requireFiniteEnvelope("FFD evaluate", weights, envelope);
    if ((stride != 3 && stride != 12) || deltas.size() != static_cast<size_t>(numControls()) * stride) {
        throw InvalidInput(formatError("FFD evaluate", "control transformations",
                                       "has " + std::to_string(deltas.size()) + " floats",
                                       "3 or 12 per control point"));
    }
    const glm::ivec3 div = lattice_.divisions;
    const int32_t ny = div.y + 1, nz = div.z + 1;
    const float* data = deltas.data();
    const bool blocks = options_.kernel != FfdKernel::PerPoint;
    const auto laneKernel = laneKernel444(ffdKernels(options_.kernel), options_);
    if (blocks && laneKernel != nullptr && div == glm::ivec3(3) && stride == 3) {
        requireFiniteResult("FFD evaluate", points, out,
                            deformLanes444(laneKernel, points, out, data, weights, envelope));
        return;
    }
    // Every point's weights fit a 4x4x4 window of controls: along each axis a spline with >= 3 divisions,
    // or the Bernstein cubic (the benchmark's 4x4x4 lattice).
    bool window = true;
    for (int a = 0; a < 3; ++a)
        window = window && (options_.basis[a] == FfdBasis::Bernstein ? div[a] == 3 : div[a] >= 3);
    // The 4x4x4 lattice: a spline basis with translations (weights from bind), or any basis with affine maps.
    if (blocks && window && div == glm::ivec3(3) && (stride == 12 || windowSpline_)) {
        requireFiniteResult("FFD evaluate", points, out,
                            deformWindow444(points, out, data, stride, weights, envelope));
        return;
    }

    int finite = 1;
#pragma omp parallel for schedule(dynamic, 4096) reduction(& : finite)
    for (int64_t u = 0; u < n; ++u) {
        if (!active_[u]) {
            out[u] = points[u];
            finite &= detail::finiteBits(points[u]);
            continue;
        }
        const float k = envelope * (weights.empty() ? 1.0f : weights[u]);
        float w[3][kMaxBernsteinDegree + 1];
        int32_t first[3], count[3];
        for (int a = 0; a < 3; ++a) {
            count[a] = axisWeights(a, local_[u][a], first[a], w[a]);
        }
        float acc[12] = {};
        if (window) {
            float w4[3][4];
            int32_t start[3];
            for (int a = 0; a < 3; ++a) {
                start[a] = std::min(first[a], div[a] - 3);
                for (int c = 0; c < 4; ++c) {
                    const int32_t i = start[a] + c - first[a];
                    w4[a][c] = (i >= 0 && i < count[a]) ? w[a][i] : 0.0f;
                }
            }
            if (stride == 3) {
                windowSum<3>(data, ny, nz, start, w4, acc);
            } else {
                windowSum<12>(data, ny, nz, start, w4, acc);
            }
        } else {
            // Separable: sum_i w_i sum_j w_j sum_k w_k delta_ijk, the innermost run contiguous in memory.
            for (int32_t a = 0; a < count[0]; ++a) {
                for (int32_t b = 0; b < count[1]; ++b) {
                    const float wab = w[0][a] * w[1][b];
                    const float* row =
                        data +
                        static_cast<size_t>(((first[0] + a) * ny + first[1] + b) * nz + first[2]) * stride;
                    float s[12] = {};
                    for (int32_t c = 0; c < count[2]; ++c) {
                        for (int e = 0; e < stride; ++e)
                            s[e] += w[2][c] * row[stride * c + e];
                    }
                    for (int e = 0; e < stride; ++e)
                        acc[e] += wab * s[e];
                }
            }
        }
        const glm::vec3 p = points[u];
        glm::vec3 d;
        if (stride == 3) {
            d = {acc[0], acc[1], acc[2]};
        } else {
            d = glm::vec3(acc[0], acc[1], acc[2]) * p.x + glm::vec3(acc[3], acc[4], acc[5]) * p.y +
                glm::vec3(acc[6], acc[7], acc[8]) * p.z + glm::vec3(acc[9], acc[10], acc[11]);
        }
        const glm::vec3 r = p + k * d;
        out[u] = r;
        finite &= detail::finiteBits(r);
    }
    if (finite == 0) requireFiniteResult("FFD evaluate", points, out, detail::firstNonFinite(out));
}

int64_t FfdLattice::deformLanes444(LaneKernel kernel, std::span<const glm::vec3> points,
                                   std::span<glm::vec3> out, const float* translations,
                                   std::span<const float> weights, float envelope) const {
    return blocks444(
        numBoundPoints(),
        [&](const detail::LocalBlock& in, detail::DisplacementBlock& d) { kernel(in, translations, d); },
        points, out, weights, envelope,
        [&](int64_t u, bool& active) {
            active = active_[u] != 0;
            return local_[u];
        });
}

int64_t FfdLattice::deformWindow444(std::span<const glm::vec3> points, std::span<glm::vec3> out,
                                    const float* data, int32_t stride, std::span<const float> weights,
                                    float envelope) const {
    const detail::FfdKernels& kernels = ffdKernels(options_.kernel);
    // Weights in eight lanes (Bernstein, cubic B-splines), or point by point for the other bases.
    const auto laneWeights = laneWeights444(kernels, options_);
    const int64_t n = numBoundPoints();
    constexpr int kBlock = detail::kBlock;
    constexpr size_t kBlockFloats = sizeof(detail::WeightBlock::w) / sizeof(float);
    const int64_t blocks = (n + kBlock - 1) / kBlock;
    // Spline weights: read from the cache, or computed, and kept on the second evaluation since the bind. An
    // evaluation that finds another one filling the cache computes its own.
    const float* cached = nullptr;
    float* keep = nullptr;
    std::unique_lock<std::mutex> filling;
    if (windowSpline_) {
        std::unique_lock<std::mutex> lock(*windowCache_.mutex, std::try_to_lock);
        if (lock.owns_lock()) {
            if (!windowCache_.weights.empty()) {
                cached = windowCache_.weights.data();
            } else if (++windowCache_.evaluations >= 2) {
                windowCache_.weights.resize(static_cast<size_t>(blocks) * kBlockFloats);
                keep = windowCache_.weights.data();
            }
            filling = std::move(lock);  // held while this evaluation reads or fills the cache
        }
    }
    // Each block reads and writes its own points only: the output does not depend on the schedule.
    const int64_t runs = (blocks + kRunBlocks - 1) / kRunBlocks;
    int64_t bad = n;
#pragma omp parallel for schedule(dynamic, 8) reduction(min : bad)
    for (int64_t run = 0; run < runs; ++run) {
        const int64_t lastBlock = std::min(blocks, (run + 1) * kRunBlocks);
        for (int64_t b = run * kRunBlocks; b < lastBlock; ++b) {
            const int64_t begin = b * kBlock;
            const int count = static_cast<int>(std::min<int64_t>(kBlock, n - begin));
            detail::WeightBlock in;
            if (cached != nullptr) {
                std::memcpy(in.w, cached + static_cast<size_t>(b) * kBlockFloats, sizeof(in.w));
            } else {
                if (laneWeights != nullptr) {
                    // Inactive lanes get weights too: their sums are computed and not used.
                    detail::LocalBlock local{};
                    for (int lane = 0; lane < count; ++lane) {
                        const glm::vec3& l = local_[begin + lane];
                        local.x[lane] = l.x;
                        local.y[lane] = l.y;
                        local.z[lane] = l.z;
                    }
                    laneWeights(local, in);
                } else {
                    windowWeightsOf(begin, count, &in.w[0][0][0]);
                }
                if (keep != nullptr)
                    std::memcpy(keep + static_cast<size_t>(b) * kBlockFloats, in.w, sizeof(in.w));
            }
            // Translations (stride 3) or affine maps (stride 12): each active point's displacement.
            detail::DisplacementBlock d;
            detail::AffineBlock m;
            if (stride == 3) {
                kernels.window444(in, data, d);
            } else {
                kernels.frames444(in, data, m);
            }
            for (int lane = 0; lane < count; ++lane) {
                const int64_t u = begin + lane;
                const glm::vec3 p = points[u];
                if (!active_[u]) {
                    out[u] = p;
                    continue;
                }
                const float k = envelope * (weights.empty() ? 1.0f : weights[u]);
                const glm::vec3 shift = stride == 3
                                            ? glm::vec3(d.x[lane], d.y[lane], d.z[lane])
                                            : glm::vec3(m.a[0][lane], m.a[1][lane], m.a[2][lane]) * p.x +
                                                  glm::vec3(m.a[3][lane], m.a[4][lane], m.a[5][lane]) * p.y +
                                                  glm::vec3(m.a[6][lane], m.a[7][lane], m.a[8][lane]) * p.z +
                                                  glm::vec3(m.a[9][lane], m.a[10][lane], m.a[11][lane]);
                out[u] = p + k * shift;
            }
        }
        bad = std::min(bad, firstNonFiniteOfRun(out, run, n));
    }
    return bad;
}

void FfdLattice::windowWeightsOf(int64_t begin, int count, float* block) const {
    constexpr int kBlock = detail::kBlock;
    std::fill(block, block + 3 * 4 * kBlock, 0.0f);
    for (int lane = 0; lane < count; ++lane) {
        const int64_t u = begin + lane;
        if (!active_[u]) continue;
        float w[kMaxBernsteinDegree + 1];
        for (int a = 0; a < 3; ++a) {
            int32_t first = 0;
            const int32_t taps = axisWeights(a, local_[u][a], first, w);
            // Divisions 3: every point's window starts at control 0 (first is never below 0).
            for (int32_t i = 0; i < taps; ++i)
                block[(a * 4 + first + i) * kBlock + lane] = w[i];
        }
    }
}

void LatticeWarp::bind(std::span<const glm::vec3> restPoints, SparseFields& fields) {
    lattice_.bind(restPoints);
    lattice_.fields(fields);
}

Ffd::Ffd(const Lattice& lattice, const FfdOptions& options)
    : LatticeWarp(lattice, options),
      source_(lattice.controlPoints()),
      target_(source_),
      translation_(source_.size(), glm::vec3(0.0f)) {}

void Ffd::setTargets(std::span<const glm::vec3> targets) {
    const Lattice& l = lattice_.lattice();
    if (targets.size() != source_.size()) {
        throw InvalidInput(formatError("FFD", "targets", "has " + std::to_string(targets.size()) + " points",
                                       "(l+1)(m+1)(n+1) = " + std::to_string(source_.size()) +
                                           " points for divisions (" + std::to_string(l.divisions.x) + ", " +
                                           std::to_string(l.divisions.y) + ", " +
                                           std::to_string(l.divisions.z) + ")"));
    }
    const int32_t ny = l.divisions.y + 1, nz = l.divisions.z + 1;
    for (size_t c = 0; c < targets.size(); ++c) {
        if (!geom::isFinite(targets[c])) {
            const int32_t ci = static_cast<int32_t>(c);
            throw InvalidInput(formatError(
                "FFD",
                "target " + std::to_string(c) + " (i=" + std::to_string(ci / (ny * nz)) +
                    ", j=" + std::to_string(ci / nz % ny) + ", k=" + std::to_string(ci % nz) + ")",
                "is not finite: " + detail::pointText(targets[c]), "finite positions"));
        }
    }
    std::copy(targets.begin(), targets.end(), target_.begin());
    // T_ijk = P*_ijk - P_ijk (§4.1).
    for (size_t c = 0; c < targets.size(); ++c)
        translation_[c] = target_[c] - source_[c];
}

void Ffd::transformations(Transformations& out) const {
    out.method = ScaleMethod::Displacement;  // translations: both methods agree (§4.1)
    out.components.clear();
    out.affine.resize(translation_.size());
    for (size_t c = 0; c < translation_.size(); ++c)
        out.affine[c] = Affine::translate(translation_[c]);
}

void Ffd::bindAndEvaluate(std::span<const glm::vec3> restPoints, std::span<const glm::vec3> in,
                          std::span<glm::vec3> out, std::span<const float> weights, float envelope) {
    if (lattice_.deformUnbound(restPoints, in, out, reinterpret_cast<const float*>(translation_.data()),
                               weights, envelope)) {
        return;
    }
    bind(restPoints);
    evaluate(in, out, weights, envelope);
}

void Ffd::evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out, std::span<const float> weights,
                   float envelope) const {
    lattice_.deform(in, out, {reinterpret_cast<const float*>(translation_.data()), translation_.size() * 3},
                    3, weights, envelope);
}

}  // namespace deformkit::warp
