#include "deformkit/warp/beier_neely.h"
#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"

namespace deformkit::warp {
namespace {

std::string str(glm::vec2 v) {
    std::ostringstream s;
    s << "(" << v.x << ", " << v.y << ")";
    return s.str();
}

void checkSegment(const std::string& source, const std::string& element, const char* which, glm::vec2 p,
                  glm::vec2 q) {
    if (!geom::isFinite(p) || !geom::isFinite(q)) {
        throw InvalidInput(
            formatError(source, element,
                        std::string(which) + " segment has a non-finite endpoint " + str(p) + " -> " + str(q),
                        "finite pixel coordinates"));
    }
    // Lengths and distances are squared in float: endpoints near float's largest gave an infinite length,
    // a map of inf and a weight of NaN.
    if (!geom::isWithinSquaredRange(p) || !geom::isWithinSquaredRange(q)) {
        throw InvalidInput(formatError(
            source, element,
            std::string(which) + " segment has an endpoint beyond +-1e15: " + str(p) + " -> " + str(q),
            "pixel coordinates within +-1e15 (lengths are squared in float)"));
    }
    if (const float length = glm::length(q - p); !(length > kMinSegmentLength)) {
        const std::string what = length == 0.0f ? " segment has zero length (P = Q = " + str(p) + ")"
                                                : " segment is " + numberText(length) +
                                                      " long (P = " + str(p) + ", Q = " + str(q) + ")";
        throw InvalidInput(formatError(source, element, std::string(which) + what,
                                       "a segment longer than " + numberText(kMinSegmentLength)));
    }
}

// The weighting field's per-feature constants, shared by bind() and the fast path so both compute the
// same float weight.
using WeightTerms = BeierNeelyWarp::WeightTerms;

WeightTerms weightTerms(const SegmentPair& s) {
    const glm::vec2 d = s.dstQ - s.dstP;
    const float lengthSq = glm::dot(d, d);
    WeightTerms t;
    t.p = s.dstP;
    t.d = d;
    t.invLengthSq = 1.0f / lengthSq;
    t.lengthPow = std::pow(std::sqrt(lengthSq), s.p);
    t.a = s.a;
    t.b = s.b;
    return t;
}

// length^p / (a + dist(x)), in float.
inline float baseOf(const WeightTerms& t, glm::vec2 x) {
    const glm::vec2 rel = x - t.p;
    const float u = std::clamp(glm::dot(rel, t.d) * t.invLengthSq, 0.0f, 1.0f);
    const glm::vec2 off = rel - u * t.d;
    const float dist = std::sqrt(off.x * off.x + off.y * off.y);
    return t.lengthPow / (t.a + dist);
}

inline float weightOf(const WeightTerms& t, glm::vec2 x) {
    const float base = baseOf(t, x);
    // b = 1 and 2 are the common choices; pow is the hot spot of the image warp otherwise.
    if (t.b == 2.0f) return base * base;
    if (t.b == 1.0f) return base;
    if (t.b == 0.0f) return 1.0f;
    return std::pow(base, t.b);
}

// A point whose float weights sum below this has every feature far away for its a and b: float keeps
// neither their ratios nor, further out, anything but 0 (a = 10, b = 30: every pixel past 52 from the
// features). Such a point takes relativeWeights instead.
constexpr double kSmallestWeightSum = 1e-30;

// Eq. (3)'s weights at x divided by the largest of them, which the normalised sum divides out: w_i =
// exp(b_i ln base_i - max_j b_j ln base_j) in double, base_i as weightOf rounds it. All 0 when every base is
// 0 (the identity, as for weights that sum to 0).
void relativeWeights(std::span<const WeightTerms> terms, glm::vec2 x, double* w) {
    double largest = -std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < terms.size(); ++i) {
        const WeightTerms& t = terms[i];
        w[i] = t.b == 0.0f ? 0.0 : static_cast<double>(t.b) * std::log(static_cast<double>(baseOf(t, x)));
        largest = std::max(largest, w[i]);
    }
    for (size_t i = 0; i < terms.size(); ++i)
        w[i] = std::isinf(largest) ? 0.0 : std::exp(w[i] - largest);
}

double pointSegmentDistance(glm::dvec2 x, glm::dvec2 p, glm::dvec2 q) {
    const glm::dvec2 d = q - p;
    const double u = std::clamp(glm::dot(x - p, d) / glm::dot(d, d), 0.0, 1.0);
    return glm::length(x - (p + u * d));
}

double cross(glm::dvec2 a, glm::dvec2 b) {
    return a.x * b.y - a.y * b.x;
}

// Minimum distance between segments (p1, q1) and (p2, q2): 0 if they cross, else the least of the four
// endpoint-to-segment distances.
double segmentDistance(glm::dvec2 p1, glm::dvec2 q1, glm::dvec2 p2, glm::dvec2 q2) {
    const glm::dvec2 d1 = q1 - p1, d2 = q2 - p2;
    const double den = cross(d1, d2);
    if (den != 0.0) {
        const double t = cross(p2 - p1, d2) / den, u = cross(p2 - p1, d1) / den;
        if (t >= 0.0 && t <= 1.0 && u >= 0.0 && u <= 1.0) return 0.0;
    }
    return std::min({pointSegmentDistance(p1, p2, q2), pointSegmentDistance(q1, p2, q2),
                     pointSegmentDistance(p2, p1, q1), pointSegmentDistance(q2, p1, q1)});
}

glm::dvec2 perpUnit(glm::dvec2 d) {
    return glm::dvec2(-d.y, d.x) / glm::length(d);
}

}  // namespace

void validateSegmentPairs(std::span<const SegmentPair> pairs, const std::string& source) {
    for (size_t i = 0; i < pairs.size(); ++i) {
        const SegmentPair& s = pairs[i];
        const std::string element = "segment pair " + std::to_string(i);
        checkSegment(source, element, "destination", s.dstP, s.dstQ);
        checkSegment(source, element, "source", s.srcP, s.srcQ);
        if (!std::isfinite(s.a) || s.a <= 0.0f) {
            throw InvalidInput(
                formatError(source, element, "has a = " + std::to_string(s.a), "a > 0 (pixels)"));
        }
        if (!std::isfinite(s.b) || s.b < 0.0f) {
            throw InvalidInput(
                formatError(source, element, "has b = " + std::to_string(s.b), "finite b >= 0"));
        }
        if (!std::isfinite(s.p) || s.p < 0.0f) {
            throw InvalidInput(
                formatError(source, element, "has p = " + std::to_string(s.p), "finite p >= 0"));
        }
        // The weight peaks on the segment itself (distance 0), in float as every path computes it (the sums
        // are in double): an infinite one gives a point on the segment inf / inf.
        const float peak = weightOf(weightTerms(s), s.dstP);
        if (!std::isfinite(peak)) {
            throw InvalidInput(formatError(source, element,
                                           "has a weight of " + numberText(peak) +
                                               " on its segment ((length^p / a)^b, p = " + numberText(s.p) +
                                               ", a = " + numberText(s.a) + ", b = " + numberText(s.b) + ")",
                                           "a weight within float range: a larger a, or a smaller p or b"));
        }
    }
}

float beierNeelyWeight(const SegmentPair& pair, glm::vec2 x) {
    return weightOf(weightTerms(pair), x);
}

std::vector<Affine> beierNeelyTransformations(std::span<const SegmentPair> pairs,
                                              const BeierNeelyOptions& options) {
    validateSegmentPairs(pairs);
    const size_t n = pairs.size();
    std::vector<Affine> out(n);
    for (size_t i = 0; i < n; ++i) {
        const SegmentPair& s = pairs[i];
        const glm::dvec2 d = glm::dvec2(s.dstQ - s.dstP), e = glm::dvec2(s.srcQ - s.srcP);
        const glm::dvec2 normal = perpUnit(d);
        glm::dvec2 target = perpUnit(e);  // §4.2: N*_i, perpendicular to L*_i
        if (options.variant == BeierNeelyVariant::Global) {
            // §5.2: N*_i = normalised sum_j w^_ij R_j<N_i>, R_j the rotation taking L_j's direction to
            // L*_j's; w_ij = (len_j^p_j / ((a_j + dist_ij)(a_j + |d_i . d_j| / len_i)))^b_j
            // (reconstruction: docs/decisions.md, BN-3).
            // The weights divided by the largest (exp(ln w_j - max ln w)): the normalised sum is the same,
            // and features far apart for their a and b (w below double's range) keep their ratios.
            const double lengthI = glm::length(d);
            std::vector<double> logWeight(n);
            std::vector<glm::dvec2> rotations(n);
            double largest = -std::numeric_limits<double>::infinity();
            for (size_t j = 0; j < n; ++j) {
                const SegmentPair& t = pairs[j];
                const glm::dvec2 dj = glm::dvec2(t.dstQ - t.dstP), ej = glm::dvec2(t.srcQ - t.srcP);
                const double lengthJ = glm::length(dj);
                const glm::dvec2 uj = dj / lengthJ, vj = ej / glm::length(ej);
                const double c = glm::dot(uj, vj), sn = cross(uj, vj);
                const glm::dvec2 rotated(c * normal.x - sn * normal.y, sn * normal.x + c * normal.y);
                const double dist = segmentDistance(glm::dvec2(s.dstP), glm::dvec2(s.dstQ),
                                                    glm::dvec2(t.dstP), glm::dvec2(t.dstQ));
                const double parallel = std::abs(glm::dot(d, dj)) / lengthI;
                const double base =
                    std::pow(lengthJ, static_cast<double>(t.p)) / ((t.a + dist) * (t.a + parallel));
                logWeight[j] = t.b == 0.0f ? 0.0 : static_cast<double>(t.b) * std::log(base);
                rotations[j] = rotated;
                largest = std::max(largest, logWeight[j]);
            }
            glm::dvec2 sum(0.0);
            double weightSum = 0.0;
            for (size_t j = 0; j < n && !std::isinf(largest); ++j) {
                const double w = std::exp(logWeight[j] - largest);
                sum += w * rotations[j];
                weightSum += w;
            }
            const double len = glm::length(sum);
            // Opposed rotations can cancel; keep the original perpendicular then.
            if (weightSum > 0.0 && len > 1e-9 * weightSum) target = sum / len;
        }
        // Linear part A with A d = e and A N = target: A = e d^T / |d|^2 + target N^T, since the columns
        // of [d, N] are orthogonal with |N| = 1.
        const double invLenSq = 1.0 / glm::dot(d, d);
        Affine t;
        for (int c = 0; c < 2; ++c) {
            for (int r = 0; r < 2; ++r) {
                t.linear[c][r] = static_cast<float>(e[r] * d[c] * invLenSq + target[r] * normal[c]);
            }
        }
        const glm::vec3 p(s.dstP, 0.0f);
        t.translation = glm::vec3(s.srcP, 0.0f) - t.linear * p;
        t.translation.z = 0.0f;
        out[i] = t;
    }
    return out;
}

BeierNeelyWarp::BeierNeelyWarp(std::vector<SegmentPair> pairs, BeierNeelyOptions options)
    : pairs_(std::move(pairs)), options_(options) {
    transforms_ = beierNeelyTransformations(pairs_, options_);
    for (const SegmentPair& s : pairs_)
        terms_.push_back(weightTerms(s));
}

void BeierNeelyWarp::setSourceSegments(std::span<const glm::vec2> srcEndpoints) {
    if (srcEndpoints.size() != 2 * pairs_.size()) {
        throw InvalidInput(formatError("Beier-Neely warp", "source segments",
                                       "has " + std::to_string(srcEndpoints.size()) + " endpoints",
                                       std::to_string(2 * pairs_.size()) + " (two per segment pair)"));
    }
    std::vector<SegmentPair> next = pairs_;
    for (size_t i = 0; i < next.size(); ++i) {
        next[i].srcP = srcEndpoints[2 * i];
        next[i].srcQ = srcEndpoints[2 * i + 1];
    }
    transforms_ = beierNeelyTransformations(next, options_);  // validates before anything changes
    pairs_ = std::move(next);
}

void BeierNeelyWarp::bind(std::span<const glm::vec3> restPoints, SparseFields& fields) {
    fields.clear();
    const size_t n = pairs_.size();
    fields.offsets.reserve(restPoints.size() + 1);
    fields.transform.reserve(restPoints.size() * n);
    fields.strength.reserve(restPoints.size() * n);
    fields.weight.reserve(restPoints.size() * n);
    std::vector<double> relative;
    for (size_t u = 0; u < restPoints.size(); ++u) {
        const glm::vec2 x(restPoints[u]);
        if (!geom::isFinite(x)) {
            throw InvalidInput(formatError("Beier-Neely warp", "rest point " + std::to_string(u),
                                           "is not finite", "finite coordinates"));
        }
        const size_t first = fields.weight.size();
        double sum = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const float w = weightOf(terms_[i], x);
            fields.add(static_cast<int32_t>(i), 1.0f, w);
            sum += w;
        }
        if (sum < kSmallestWeightSum) {
            relative.resize(n);
            relativeWeights(terms_, x, relative.data());
            for (size_t i = 0; i < n; ++i)
                fields.weight[first + i] = static_cast<float>(relative[i]);
        }
        fields.endPoint();
    }
}

void BeierNeelyWarp::transformations(Transformations& out) const {
    out.method = ScaleMethod::Displacement;
    out.affine = transforms_;
    out.components.clear();
}

namespace {

// Eq. (3)'s weighted mean at x with the arithmetic of evaluateWarp (float displacement per feature, double
// accumulation), feature i weighing weight(i); sets the weights' sum.
template <class Weight>
glm::vec2 weightedMean(glm::vec2 x, std::span<const Affine> transforms, const Weight& weight,
                       double& weightSum) {
    double dx = 0.0, dy = 0.0;
    weightSum = 0.0;
    for (size_t i = 0; i < transforms.size(); ++i) {
        const Affine& t = transforms[i];
        const float mx = t.linear[0][0] * x.x + t.linear[1][0] * x.y + t.translation.x;
        const float my = t.linear[0][1] * x.x + t.linear[1][1] * x.y + t.translation.y;
        const double w = weight(i);
        // (P + 1 * (T<P> - P)) - P, rounded as the engine's displacement-method product is.
        dx += w * static_cast<double>((x.x + (mx - x.x)) - x.x);
        dy += w * static_cast<double>((x.y + (my - x.y)) - x.y);
        weightSum += w;
    }
    if (!(weightSum > 0.0)) return x;
    return {x.x + static_cast<float>(dx / weightSum), x.y + static_cast<float>(dy / weightSum)};
}

// Eq. (3) for a point whose float weights sum below kSmallestWeightSum, with relativeWeights (the engine's
// sum over the fields bind writes for it, up to their float rounding).
glm::vec2 mapFar(glm::vec2 x, std::span<const WeightTerms> terms, std::span<const Affine> transforms) {
    thread_local std::vector<double> w;  // one per thread: no allocation per point in the parallel loops
    w.resize(terms.size());
    relativeWeights(terms, x, w.data());
    double weightSum = 0.0;
    return weightedMean(
        x, transforms, [&](size_t i) { return w[i]; }, weightSum);
}

// Eq. (3) for one point: the float weights (weightOf); a point every feature is far from, mapFar; all-zero
// weights give the identity.
inline glm::vec2 mapOne(glm::vec2 x, std::span<const WeightTerms> terms, std::span<const Affine> transforms) {
    double weightSum = 0.0;
    const glm::vec2 mean = weightedMean(
        x, transforms, [&](size_t i) { return static_cast<double>(weightOf(terms[i], x)); }, weightSum);
    return weightSum < kSmallestWeightSum ? mapFar(x, terms, transforms) : mean;
}

enum class Falloff { Square, Linear, Constant, Power };

// One segment's contribution to a row of pixel centres (x + 0.5, cy): weightOf and mapOne written out
// per component, same operations in the same order, so results are bit-identical to mapOne.
template <Falloff F>
void accumulateRow(const WeightTerms& t, const Affine& T, float cy, int32_t width, double* __restrict dx,
                   double* __restrict dy, double* __restrict ws) {
    const float l00 = T.linear[0][0], l10 = T.linear[1][0], l01 = T.linear[0][1], l11 = T.linear[1][1];
    const float tx = T.translation.x, ty = T.translation.y;
    const float ry = cy - t.p.y;
    for (int32_t x = 0; x < width; ++x) {
        const float px = static_cast<float>(x) + 0.5f;
        const float rx = px - t.p.x;
        float u = (rx * t.d.x + ry * t.d.y) * t.invLengthSq;
        u = u < 0.0f ? 0.0f : (1.0f < u ? 1.0f : u);  // std::clamp(u, 0, 1)
        const float ox = rx - u * t.d.x, oy = ry - u * t.d.y;
        const float sq = ox * ox + oy * oy;
        const float dist = std::sqrt(sq);
        const float base = t.lengthPow / (t.a + dist);
        float w;
        if constexpr (F == Falloff::Square) {
            w = base * base;
        } else if constexpr (F == Falloff::Linear) {
            w = base;
        } else if constexpr (F == Falloff::Constant) {
            w = 1.0f;
        } else {
            w = std::pow(base, t.b);
        }
        const float mx = l00 * px + l10 * cy + tx;
        const float my = l01 * px + l11 * cy + ty;
        const double wd = w;
        dx[x] += wd * static_cast<double>((px + (mx - px)) - px);
        dy[x] += wd * static_cast<double>((cy + (my - cy)) - cy);
        ws[x] += wd;
    }
}

}  // namespace

void BeierNeelyWarp::mapPoints(std::span<const glm::vec2> points, std::span<glm::vec2> out) const {
    if (out.size() != points.size()) {
        throw InvalidInput(formatError("Beier-Neely warp", "output points",
                                       "has " + std::to_string(out.size()) + " entries",
                                       std::to_string(points.size()) + " entries"));
    }
#pragma omp parallel for schedule(static)
    for (int64_t u = 0; u < static_cast<int64_t>(points.size()); ++u) {
        out[u] = mapOne(points[u], terms_, transforms_);
    }
}

void BeierNeelyWarp::mapPixelCentres(int32_t width, int32_t height, std::span<glm::vec2> out) const {
    if (width <= 0 || height <= 0) {
        throw InvalidInput(formatError("Beier-Neely warp", "image size",
                                       "is " + std::to_string(width) + " x " + std::to_string(height),
                                       "at least 1 x 1 pixels"));
    }
    const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
    if (out.size() != count) {
        throw InvalidInput(formatError("Beier-Neely warp", "output map",
                                       "has " + std::to_string(out.size()) + " entries",
                                       std::to_string(count) + " (width * height)"));
    }
#pragma omp parallel
    {
        // Row accumulators, one set per thread: segments outer, pixels inner, so the inner loop is
        // branch-free and vectorises. Per pixel the operations and their order are those of mapOne.
        std::vector<double> dx(width), dy(width), ws(width);
#pragma omp for schedule(static)
        for (int32_t y = 0; y < height; ++y) {
            const float cy = static_cast<float>(y) + 0.5f;
            std::fill(dx.begin(), dx.end(), 0.0);
            std::fill(dy.begin(), dy.end(), 0.0);
            std::fill(ws.begin(), ws.end(), 0.0);
            for (size_t i = 0; i < terms_.size(); ++i) {
                const WeightTerms& t = terms_[i];
                if (t.b == 2.0f) {
                    accumulateRow<Falloff::Square>(t, transforms_[i], cy, width, dx.data(), dy.data(),
                                                   ws.data());
                } else if (t.b == 1.0f) {
                    accumulateRow<Falloff::Linear>(t, transforms_[i], cy, width, dx.data(), dy.data(),
                                                   ws.data());
                } else if (t.b == 0.0f) {
                    accumulateRow<Falloff::Constant>(t, transforms_[i], cy, width, dx.data(), dy.data(),
                                                     ws.data());
                } else {
                    accumulateRow<Falloff::Power>(t, transforms_[i], cy, width, dx.data(), dy.data(),
                                                  ws.data());
                }
            }
            glm::vec2* row = out.data() + static_cast<size_t>(y) * width;
            for (int32_t x = 0; x < width; ++x) {
                const float px = static_cast<float>(x) + 0.5f;
                row[x] = ws[x] >= kSmallestWeightSum ? glm::vec2(px + static_cast<float>(dx[x] / ws[x]),
                                                                 cy + static_cast<float>(dy[x] / ws[x]))
                                                     : mapFar(glm::vec2(px, cy), terms_, transforms_);
            }
        }
    }
}

std::vector<glm::vec2> beierNeelyMap(int32_t width, int32_t height, std::span<const SegmentPair> pairs,
                                     const BeierNeelyOptions& options) {
    const BeierNeelyWarp warp(std::vector<SegmentPair>(pairs.begin(), pairs.end()), options);
    if (width <= 0 || height <= 0) {
        throw InvalidInput(formatError("Beier-Neely warp", "image size",
                                       "is " + std::to_string(width) + " x " + std::to_string(height),
                                       "at least 1 x 1 pixels"));
    }
    std::vector<glm::vec2> out(static_cast<size_t>(width) * static_cast<size_t>(height));
    warp.mapPixelCentres(width, height, out);
    return out;
}

}  // namespace deformkit::warp
