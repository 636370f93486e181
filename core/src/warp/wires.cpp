#include "deformkit/warp/wires.h"
#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/warp/envelope.h"
#include "warp/checks.h"
#include "warp/point_text.h"
#include "warp/weighted_mean.h"

namespace deformkit::warp {
namespace {

constexpr int32_t kMaxSmoothSamples = 4096;

std::string wireLabel(size_t i) {
    return "wire " + std::to_string(i);
}

void requireCurve(std::span<const glm::vec3> curve, const std::string& label) {
    for (size_t j = 0; j < curve.size(); ++j) {
        if (!geom::isWithinSquaredRange(curve[j])) {
            throw InvalidInput(formatError(
                "wires", label + " point " + std::to_string(j), "is " + detail::pointText(curve[j]),
                "finite coordinates within +-1e15 (wires square lengths in float)"));
        }
    }
}

glm::vec3 unitOrZero(const glm::vec3& v) {
    const float len = glm::length(v);
    return len > 0.0f ? v / len : glm::vec3(0.0f);
}

// Unit tangents at the polyline's points: the mean of the adjacent unit segment directions (one-sided at the
// ends), so that tangents interpolated along a segment vary continuously from one segment to the next.
std::vector<glm::vec3> vertexTangents(const std::vector<glm::vec3>& p) {
    const size_t n = p.size();
    std::vector<glm::vec3> out(n);
    for (size_t j = 0; j < n; ++j) {
        const glm::vec3 before = j > 0 ? unitOrZero(p[j] - p[j - 1]) : glm::vec3(0.0f);
        const glm::vec3 after = j + 1 < n ? unitOrZero(p[j + 1] - p[j]) : glm::vec3(0.0f);
        out[j] = unitOrZero(before + after);
    }
    return out;
}

// dC/dv direction at (segment j, t): vertex tangents interpolated and normalised; the segment direction
// where they cancel (a hairpin); zero on a collapsed segment with no usable tangent.
glm::vec3 tangentAt(const std::vector<glm::vec3>& p, const std::vector<glm::vec3>& tangents, int32_t j,
                    float t) {
    const glm::vec3 a = (1.0f - t) * tangents[j] + t * tangents[j + 1];
    const float len = glm::length(a);
    if (len > 1e-6f) return a / len;
    return unitOrZero(p[j + 1] - p[j]);
}

// The rotation vector (axis times angle) of the smallest rotation taking unit a to unit b; zero when either
// is zero. Antiparallel tangents have no unique smallest rotation: the half turn about the axis
// perpendicular to a that is closest to a coordinate axis is used (deterministic).
glm::vec3 minimalRotation(const glm::vec3& a, const glm::vec3& b) {
    if (a == glm::vec3(0.0f) || b == glm::vec3(0.0f)) return glm::vec3(0.0f);
    const glm::dvec3 da(a), db(b);
    const glm::dvec3 c = glm::cross(da, db);
    const double sinA = glm::length(c), cosA = glm::dot(da, db);
    if (sinA > 1e-9) return glm::vec3(c * (std::atan2(sinA, cosA) / sinA));
    if (cosA > 0.0) return glm::vec3(0.0f);
    const glm::dvec3 absA = glm::abs(da);
    const glm::dvec3 helper = absA.x <= absA.y && absA.x <= absA.z ? glm::dvec3(1, 0, 0)
                              : absA.y <= absA.z                   ? glm::dvec3(0, 1, 0)
                                                                   : glm::dvec3(0, 0, 1);
    return glm::vec3(glm::normalize(glm::cross(da, helper)) * 3.14159265358979323846);
}

double powAbs(double x, double m) {
    // x^m as std::pow gives it (the engine's weighting); x^1 and x^2 are exact either way, so the common
    // exponents skip the call without changing a bit.
    if (m == 1.0) return x;
    if (m == 2.0) return x * x;
    return std::pow(x, m);
}

}  // namespace

// ---------------------------------------------------------------------------------------------- Falloff

Falloff Falloff::fromSamples(std::vector<float> values, std::string_view name) {
    const size_t n = values.size();
    if (n < 2) {
        throw InvalidInput(
            formatError("wires", name, "has " + std::to_string(n) + " samples", "at least 2 samples"));
    }
    for (size_t j = 0; j < n; ++j) {
        if (!(values[j] >= 0.0f && values[j] <= 1.0f)) {
            throw InvalidInput(formatError("wires", std::string(name) + " sample " + std::to_string(j),
                                           "is " + std::to_string(values[j]), "a value in [0, 1]"));
        }
    }
    if (values.front() != 1.0f || values.back() != 0.0f) {
        throw InvalidInput(formatError(
            "wires", name,
            "starts at " + std::to_string(values.front()) + " and ends at " + std::to_string(values.back()),
            "f(0) = 1 and f(1) = 0"));
    }
    Falloff f;
    const float h = 1.0f / static_cast<float>(n - 1);
    f.slopes_.assign(n, 0.0f);
    for (size_t j = 1; j + 1 < n; ++j) {
        const float before = (values[j] - values[j - 1]) / h, after = (values[j + 1] - values[j]) / h;
        // Harmonic mean of the secants (Fritsch and Butland): zero at an extremum, no overshoot.
        if (before * after > 0.0f) f.slopes_[j] = 2.0f / (1.0f / before + 1.0f / after);
    }
    f.values_ = std::move(values);
    return f;
}

float Falloff::operator()(float t) const {
    if (!(t < 1.0f)) return 0.0f;
    if (t <= 0.0f) return 1.0f;
    if (values_.empty()) return 1.0f - t * t * (3.0f - 2.0f * t);
    const int32_t spans = static_cast<int32_t>(values_.size()) - 1;
    const float x = t * static_cast<float>(spans);
    const int32_t j = std::min(static_cast<int32_t>(x), spans - 1);
    const float u = x - static_cast<float>(j), h = 1.0f / static_cast<float>(spans);
    const float u2 = u * u, u3 = u2 * u;
    const float v = (2 * u3 - 3 * u2 + 1) * values_[j] + (u3 - 2 * u2 + u) * h * slopes_[j] +
                    (-2 * u3 + 3 * u2) * values_[j + 1] + (u3 - u2) * h * slopes_[j + 1];
    return std::clamp(v, 0.0f, 1.0f);  // rounding only: the Hermite pieces stay within their samples
}

// ------------------------------------------------------------------------------------------------ Wires

Wires::Wires(std::vector<Wire> wires, const WiresOptions& options)
    : wires_(std::move(wires)), options_(options) {
    if (!(std::isfinite(options_.exponent) && options_.exponent >= 0.0f)) {
        throw InvalidInput(formatError("wires", "exponent m", "is " + std::to_string(options_.exponent),
                                       "a finite value >= 0"));
    }
    if (options_.smoothSamples < 0 || options_.smoothSamples == 1 ||
        options_.smoothSamples > kMaxSmoothSamples) {
        throw InvalidInput(
            formatError("wires", "smooth samples", "is " + std::to_string(options_.smoothSamples),
                        "0 (automatic) or an integer in [2, " + std::to_string(kMaxSmoothSamples) + "]"));
    }
    const size_t numWires = wires_.size();
    referenceTangents_.resize(numWires);
    wireTangents_.resize(numWires);
    sampleCount_.resize(numWires);
    sampleBase_.assign(numWires + 1, 0);
    for (size_t i = 0; i < numWires; ++i) {
        const Wire& w = wires_[i];
        const std::string label = wireLabel(i);
        if (w.reference.size() < 2) {
            throw InvalidInput(formatError("wires", label + " reference curve",
                                           "has " + std::to_string(w.reference.size()) + " points",
                                           "at least 2 points"));
        }
        if (w.wire.size() != w.reference.size()) {
            throw InvalidInput(formatError(
                "wires", label + " wire curve", "has " + std::to_string(w.wire.size()) + " points",
                std::to_string(w.reference.size()) + " points, as many as its reference curve"));
        }
        requireCurve(w.reference, label + " reference curve");
        requireCurve(w.wire, label + " wire curve");
        if (!(std::isfinite(w.radius) && w.radius > 0.0f)) {
            throw InvalidInput(formatError("wires", label + " radius", "is " + std::to_string(w.radius),
                                           "a finite distance > 0"));
        }
        if (!(std::isfinite(w.scale) && w.scale > 0.0f)) {
            throw InvalidInput(formatError("wires", label + " scale", "is " + std::to_string(w.scale),
                                           "a finite value > 0"));
        }
        double length = 0.0;
        for (size_t j = 0; j + 1 < w.reference.size(); ++j)
            length += glm::length(glm::dvec3(w.reference[j + 1] - w.reference[j]));
        if (!(length > 0.0)) {
            throw InvalidInput(formatError("wires", label + " reference curve", "has length 0",
                                           "at least two distinct points"));
        }
        referenceTangents_[i] = vertexTangents(w.reference);
        updateWireTangents(static_cast<int32_t>(i));
        int32_t k = options_.smoothSamples;
        if (k == 0) {
            const double automatic = std::ceil(8.0 * length / w.radius) + 1.0;
            k = static_cast<int32_t>(std::clamp(automatic, 16.0, static_cast<double>(kMaxSmoothSamples)));
        }
        sampleCount_[i] = k;
        sampleBase_[i + 1] = sampleBase_[i] + k;

        // K places uniform in arc length, v_k = k / (K - 1) of the length, and their trapezoidal weights.
        std::vector<double> cumulative(w.reference.size(), 0.0);
        for (size_t j = 1; j < w.reference.size(); ++j) {
            cumulative[j] = cumulative[j - 1] + glm::length(glm::dvec3(w.reference[j] - w.reference[j - 1]));
        }
        const int32_t lastSegment = static_cast<int32_t>(w.reference.size()) - 2;
        int32_t j = 0;
        for (int32_t s = 0; s < k; ++s) {
            const double target = length * s / (k - 1);
            while (j < lastSegment && cumulative[j + 1] < target)
                ++j;
            const double segment = cumulative[j + 1] - cumulative[j];
            float t = segment > 0.0
                          ? static_cast<float>(std::clamp((target - cumulative[j]) / segment, 0.0, 1.0))
                          : 0.0f;
            if (s == k - 1) {
                j = lastSegment;
                t = 1.0f;
            }
            samplePlace_.push_back({j, t});
            const double weight = length / (k - 1) * (s == 0 || s == k - 1 ? 0.5 : 1.0);
            sampleWeight_.push_back(static_cast<float>(weight));
        }
    }
    scratch_.resize(static_cast<size_t>(sampleBase_.back()));
    grids_.resize(numWires);
    for (size_t i = 0; i < numWires; ++i)
        buildGrid(static_cast<int32_t>(i));
}

namespace {

glm::ivec3 cellOf(const glm::vec3& p, const glm::vec3& origin, float inverseCell, const glm::ivec3& dims) {
    const glm::ivec3 c(glm::floor((p - origin) * inverseCell));
    return glm::clamp(c, glm::ivec3(0), dims - 1);
}

}  // namespace

void Wires::buildGrid(int32_t w) {
    const Wire& wire = wires_[w];
    const bool smooth = options_.variant == WiresVariant::Smooth;
    CellGrid& g = grids_[w];
    g.origin = g.end = wire.reference[0];
    float largest = 0.0f;
    for (const glm::vec3& p : wire.reference) {
        g.origin = glm::min(g.origin, p);
        g.end = glm::max(g.end, p);
        largest = std::max({largest, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    }
    // Grown by r plus a margin for float rounding against the double distances of bind.
    const glm::vec3 r(wire.radius * 1.001f + 1e-5f * (largest + wire.radius));
    g.origin -= r;
    g.end += r;
    // Cells of size r, at most 64 along an axis (the lists grow but stay short where it matters).
    const glm::vec3 extent = g.end - g.origin;
    const float cell = std::max(wire.radius, std::max({extent.x, extent.y, extent.z}) / 64.0f);
    g.inverseCell = 1.0f / cell;
    g.dims = glm::max(glm::ivec3(glm::ceil(extent * g.inverseCell)), glm::ivec3(1));
    const int32_t numItems = smooth ? sampleCount_[w] : static_cast<int32_t>(wire.reference.size()) - 1;
    auto itemBox = [&](int32_t i, glm::vec3& lo, glm::vec3& hi) {
        if (smooth) {
            const CurvePlace& place = samplePlace_[sampleBase_[w] + i];
            lo = hi = (1.0f - place.t) * wire.reference[place.segment] +
                      place.t * wire.reference[place.segment + 1];
        } else {
            lo = glm::min(wire.reference[i], wire.reference[i + 1]);
            hi = glm::max(wire.reference[i], wire.reference[i + 1]);
        }
        // Grown by r (with the margin above): a point within r of the item lies in this box.
        lo -= r;
        hi += r;
    };
    const size_t numCells = static_cast<size_t>(g.dims.x) * g.dims.y * g.dims.z;
    g.start.assign(numCells + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<int32_t> fill;
        if (pass == 1) {
            for (size_t c = 0; c < numCells; ++c)
                g.start[c + 1] += g.start[c];
            g.items.resize(static_cast<size_t>(g.start.back()));
            fill.assign(g.start.begin(), g.start.end() - 1);
        }
        for (int32_t i = 0; i < numItems; ++i) {
            glm::vec3 lo, hi;
            itemBox(i, lo, hi);
            const glm::ivec3 a = cellOf(lo, g.origin, g.inverseCell, g.dims),
                             b = cellOf(hi, g.origin, g.inverseCell, g.dims);
            for (int32_t z = a.z; z <= b.z; ++z) {
                for (int32_t y = a.y; y <= b.y; ++y) {
                    for (int32_t x = a.x; x <= b.x; ++x) {
                        const size_t c =
                            static_cast<size_t>(x) +
                            g.dims.x * (static_cast<size_t>(y) + static_cast<size_t>(g.dims.y) * z);
                        if (pass == 0) {
                            ++g.start[c + 1];
                        } else {
                            g.items[fill[c]++] = i;
                        }
                    }
                }
            }
        }
    }
}

void Wires::updateWireTangents(int32_t w) {
    wireTangents_[w] = vertexTangents(wires_[w].wire);
}

size_t Wires::checkedIndex(int32_t i) const {
    if (i < 0 || i >= numWires()) {
        throw InvalidInput(formatError("wires", "wire index " + std::to_string(i), "does not exist",
                                       "an index in [0, " + std::to_string(numWires()) + ")"));
    }
    return static_cast<size_t>(i);
}

void Wires::setWire(int32_t i, std::span<const glm::vec3> wireCurve) {
    (void)checkedIndex(i);
    const std::string label = wireLabel(static_cast<size_t>(i)) + " wire curve";
    if (wireCurve.size() != wires_[i].reference.size()) {
        throw InvalidInput(formatError(
            "wires", label, "has " + std::to_string(wireCurve.size()) + " points",
            std::to_string(wires_[i].reference.size()) + " points, as many as its reference curve"));
    }
    requireCurve(wireCurve, label);
    std::copy(wireCurve.begin(), wireCurve.end(), wires_[i].wire.begin());
    updateWireTangents(i);
}

namespace {

Wires::SampleTransform toSample(const Components& c) {
    Wires::SampleTransform out;
    out.pivot = c.pivot;
    out.translation = c.translation;
    out.angle = glm::length(c.rotation);
    out.axis = out.angle > 0.0f ? c.rotation / out.angle : glm::vec3(0.0f);
    out.scale = c.scale.x;
    return out;
}

// (s . T)<p> by the composition method (transform.h: translation s t, rotation angle s theta, scale
// 1 + s (x - 1), all about the pivot), written out with Rodrigues' formula instead of building the matrix.
glm::vec3 applyComposition(const Wires::SampleTransform& c, float s, const glm::vec3& p) {
    glm::vec3 q = (p - c.pivot) * (1.0f + s * (c.scale - 1.0f));
    if (c.angle > 0.0f) {
        const float cs = std::cos(s * c.angle), sn = std::sin(s * c.angle);
        q = q * cs + glm::cross(c.axis, q) * sn + c.axis * (glm::dot(c.axis, q) * (1.0f - cs));
    }
    return q + c.pivot + s * c.translation;
}

}  // namespace

Components Wires::transformAt(int32_t w, const CurvePlace& place) const {
    const Wire& wire = wires_[w];
    const int32_t j = place.segment;
    const float t = place.t;
    const glm::vec3 c = (1.0f - t) * wire.reference[j] + t * wire.reference[j + 1];
    const glm::vec3 cStar = (1.0f - t) * wire.wire[j] + t * wire.wire[j + 1];
    Components out;
    // T(v) = X . R . S: S and R about C(v), then X = C*(v) - C(v), so C(v) maps to C*(v) (§4.4).
    out.pivot = c;
    out.translation = cStar - c;
    out.rotation = minimalRotation(tangentAt(wire.reference, referenceTangents_[w], j, t),
                                   tangentAt(wire.wire, wireTangents_[w], j, t));
    out.scale = glm::vec3(wire.scale);
    return out;
}

void Wires::bind(std::span<const glm::vec3> restPoints) {
    bound_ = false;
    const int64_t n = static_cast<int64_t>(restPoints.size());
    for (int64_t u = 0; u < n; ++u) {
        if (!geom::isWithinSquaredRange(restPoints[u])) {
            throw InvalidInput(formatError(
                "wires", "rest point " + std::to_string(u), "is " + detail::pointText(restPoints[u]),
                "finite coordinates within +-1e15 (wires square lengths in float)"));
        }
    }
    const int32_t numWires = this->numWires();
    const bool smooth = options_.variant == WiresVariant::Smooth;

    // Calls emit(wire, place or transformation index, strength, weight) for every field entry of point p,
    // in wire order then curve order: the same entries in the counting and the filling pass.
    auto visit = [&](const glm::vec3& p, auto&& emit) {
        for (int32_t w = 0; w < numWires; ++w) {
            const CellGrid& g = grids_[w];
            if (glm::any(glm::lessThan(p, g.origin)) || glm::any(glm::greaterThan(p, g.end))) continue;
            const glm::ivec3 c = cellOf(p, g.origin, g.inverseCell, g.dims);
            const size_t cell = static_cast<size_t>(c.x) +
                                g.dims.x * (static_cast<size_t>(c.y) + static_cast<size_t>(g.dims.y) * c.z);
            const Wire& wire = wires_[w];
            const double r = wire.radius;
            if (smooth) {
                for (int32_t item = g.start[cell]; item < g.start[cell + 1]; ++item) {
                    const int32_t index = sampleBase_[w] + g.items[item];
                    const CurvePlace& place = samplePlace_[index];
                    const glm::dvec3 q =
                        (1.0 - place.t) * glm::dvec3(wire.reference[place.segment]) +
                        static_cast<double>(place.t) * glm::dvec3(wire.reference[place.segment + 1]);
                    const double d = glm::length(glm::dvec3(p) - q);
                    if (d >= r) continue;
                    const float f = wire.falloff(static_cast<float>(d / r));
                    if (f > 0.0f) emit(w, CurvePlace{index, 0.0f}, f, f * sampleWeight_[index]);
                }
                continue;
            }
            // Nearest point on the reference curve among the segments that can be within r (any nearer
            // segment is in the cell); ascending order and a strict '<' keep the smallest parameter on ties.
            double best = INFINITY;
            CurvePlace nearest;
            for (int32_t item = g.start[cell]; item < g.start[cell + 1]; ++item) {
                const int32_t j = g.items[item];
                const glm::dvec3 a(wire.reference[j]), ab = glm::dvec3(wire.reference[j + 1]) - a;
                const double len2 = glm::dot(ab, ab);
                const double t =
                    len2 > 0.0 ? std::clamp(glm::dot(glm::dvec3(p) - a, ab) / len2, 0.0, 1.0) : 0.0;
                const glm::dvec3 q = a + t * ab - glm::dvec3(p);
                const double d2 = glm::dot(q, q);
                if (d2 < best) {
                    best = d2;
                    nearest = {j, static_cast<float>(t)};
                }
            }
            const double d = std::sqrt(best);
            if (!(d < r)) continue;
            const float f = wire.falloff(static_cast<float>(d / r));
            if (f > 0.0f) emit(w, nearest, f, 1.0f);
        }
    };

    // Two passes: count each point's entries, then fill them at its offset. The original variant keeps
    // pass 1's nearest points (at most one per wire) so the search runs once, in one list per block of
    // points (each point's entries depend on the point alone, so the lists are the same for any thread
    // count; their size is the entries', not points x wires); the smooth variant's test is a distance to
    // a sample, cheaper to repeat than to store.
    struct Found {
        CurvePlace place;
        float strength = 0.0f;
        int32_t wire = 0;
    };
    constexpr int64_t kBlock = 4096;
    const int64_t numBlocks = (n + kBlock - 1) / kBlock;
    std::vector<int32_t> counts(static_cast<size_t>(n) + 1, 0);
    std::vector<std::vector<Found>> found(smooth ? 0 : static_cast<size_t>(numBlocks));
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t b = 0; b < numBlocks; ++b) {
        for (int64_t u = b * kBlock; u < std::min(n, (b + 1) * kBlock); ++u) {
            int32_t c = 0;
            visit(restPoints[u], [&](int32_t w, const CurvePlace& place, float s, float) {
                if (!smooth) found[static_cast<size_t>(b)].push_back({place, s, w});
                ++c;
            });
            counts[u + 1] = c;
        }
    }
    fields_.offsets.resize(static_cast<size_t>(n) + 1);
    fields_.offsets[0] = 0;
    for (int64_t u = 0; u < n; ++u) {
        const int64_t next = static_cast<int64_t>(fields_.offsets[u]) + counts[u + 1];
        if (next > INT32_MAX) {
            throw InvalidInput(formatError("wires", "bind", "needs more than 2^31 field entries",
                                           "fewer points, smaller radii or fewer smooth samples"));
        }
        fields_.offsets[u + 1] = static_cast<int32_t>(next);
    }
    const size_t entries = static_cast<size_t>(fields_.offsets.back());
    fields_.transform.resize(entries);
    fields_.strength.resize(entries);
    fields_.weight.resize(entries);
    entryWire_.resize(smooth ? 0 : entries);
    entryPlace_.resize(smooth ? 0 : entries);
    if (!smooth) {
#pragma omp parallel for schedule(static)
        for (int64_t b = 0; b < numBlocks; ++b) {
            // The block's entries lie at its first point's offset, in the order they were found.
            const std::vector<Found>& list = found[static_cast<size_t>(b)];
            const int32_t first = fields_.offsets[b * kBlock];
            for (size_t k = 0; k < list.size(); ++k) {
                const auto e = static_cast<size_t>(first) + k;
                // T_i is sampled once per entry (W9), so transformation e belongs to entry e.
                fields_.transform[e] = static_cast<int32_t>(e);
                fields_.strength[e] = list[k].strength;
                fields_.weight[e] = 1.0f;
                entryWire_[e] = list[k].wire;
                entryPlace_[e] = list[k].place;
            }
        }
    } else {
#pragma omp parallel for schedule(dynamic, 4096)
        for (int64_t u = 0; u < n; ++u) {
            int32_t e = fields_.offsets[u];
            visit(restPoints[u], [&](int32_t, const CurvePlace& sample, float s, float weight) {
                fields_.transform[e] = sample.segment;  // the sample's transformation index (visit)
                fields_.strength[e] = s;
                fields_.weight[e] = weight;
                ++e;
            });
        }
    }
    bound_ = true;
}

void Wires::bind(std::span<const glm::vec3> restPoints, SparseFields& fields) {
    bind(restPoints);
    fields = fields_;
}

void Wires::transformations(Transformations& out) const {
    out.method = ScaleMethod::Composition;
    out.affine.clear();
    if (options_.variant == WiresVariant::Smooth) {
        out.components.resize(samplePlace_.size());
        for (int32_t w = 0; w < numWires(); ++w) {
            for (int32_t i = sampleBase_[w]; i < sampleBase_[w + 1]; ++i)
                out.components[i] = transformAt(w, samplePlace_[i]);
        }
        return;
    }
    if (!bound_) {
        throw InvalidInput(
            formatError("wires", "transformations", "requested before bind",
                        "bind(restPoints) first: the original variant samples T(v) per point"));
    }
    out.components.resize(entryPlace_.size());
#pragma omp parallel for schedule(static)
    for (int64_t e = 0; e < static_cast<int64_t>(entryPlace_.size()); ++e) {
        out.components[e] = transformAt(entryWire_[e], entryPlace_[e]);
    }
}

void Wires::evaluate(std::span<glm::vec3> points, std::span<const float> weights, float envelope) {
    if (!bound_) {
        throw InvalidInput(formatError("wires", "evaluate", "called before bind", "bind(restPoints) first"));
    }
    const int64_t n = fields_.numPoints();
    if (static_cast<int64_t>(points.size()) != n) {
        throw InvalidInput(formatError("wires", "points", "has " + std::to_string(points.size()) + " entries",
                                       std::to_string(n) + " entries, as many as the bound rest points"));
    }
    if (!weights.empty() && static_cast<int64_t>(weights.size()) != n) {
        throw InvalidInput(formatError("wires", "painted weights",
                                       "has " + std::to_string(weights.size()) + " entries",
                                       std::to_string(n) + " entries, or none"));
    }
    requireFiniteEnvelope("wires", weights, envelope);
    const bool smooth = options_.variant == WiresVariant::Smooth;
    if (smooth) {
        for (int32_t w = 0; w < numWires(); ++w) {
            for (int32_t i = sampleBase_[w]; i < sampleBase_[w + 1]; ++i) {
                scratch_[i] = toSample(transformAt(w, samplePlace_[i]));
            }
        }
    }
    const double m = options_.exponent;
    int finite = 1;  // 0 once a point's output is not finite
#pragma omp parallel for schedule(dynamic, 4096) reduction(& : finite)
    for (int64_t u = 0; u < n; ++u) {
        const int32_t begin = fields_.offsets[u], end = fields_.offsets[u + 1];
        const glm::vec3 p = points[u];
        finite &= detail::finiteBits(p);
        if (begin == end) continue;
        // Eq. (3) as in evaluateWarp: displacements accumulated in double, weights times |d|^m.
        glm::dvec3 mean;
        const bool any = detail::weightedMeanDisplacement(
            begin, end, m,
            [&](int32_t e) {
                const float s = fields_.strength[e];
                return (smooth
                            ? applyComposition(scratch_[fields_.transform[e]], s, p)
                            : applyComposition(toSample(transformAt(entryWire_[e], entryPlace_[e])), s, p)) -
                       p;
            },
            [&](int32_t e) { return static_cast<double>(fields_.weight[e]); }, powAbs, mean);
        if (!any) continue;
        const glm::vec3 moved = p + glm::vec3(mean);
        const float k = envelope * (weights.empty() ? 1.0f : weights[u]);
        const glm::vec3 r = p + k * (moved - p);
        points[u] = r;
        finite &= detail::finiteBits(r);
    }
    if (finite == 0) requireFiniteResult("wires", {}, points, detail::firstNonFinite(points));
}

}  // namespace deformkit::warp
