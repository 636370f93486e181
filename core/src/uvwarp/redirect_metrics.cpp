#include "deformkit/uvwarp/redirect_metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/io/sampling.h"
#include "memory/large_buffers.h"
#include "redirect_cells.h"
#include "row_runs.h"
#include "tile_uvs.h"

namespace deformkit::uvwarp {
namespace {

// Rows per parallel work item: fixed, so the sums are taken in the same order for any thread count.
constexpr int32_t kMetricBandRows = 16;
// Texels per side of a point-location bucket.
constexpr int32_t kBucketTexels = 4;
// How far outside a UV triangle (in barycentric terms) a point still counts as inside it: float rounding of
// a redirect texel that sits on a chart border.
constexpr double kInsideTolerance = 1e-7;

// Barycentric coordinates of p in the UV triangle t (double; may be negative outside it).
glm::dvec3 barycentricIn(const std::array<glm::vec2, 3>& t, glm::dvec2 p) {
    const glm::dvec2 a(t[0]), b(t[1]), c(t[2]);
    const glm::dvec2 v0 = b - a, v1 = c - a, v2 = p - a;
    const double den = v0.x * v1.y - v1.x * v0.y;
    if (den == 0.0) return glm::dvec3(-1.0);  // a degenerate UV triangle contains nothing
    const double l1 = (v2.x * v1.y - v1.x * v2.y) / den;
    const double l2 = (v0.x * v2.y - v2.x * v0.y) / den;
    return {1.0 - l1 - l2, l1, l2};
}

// UV triangles sharing an edge, UVs welded by value: the charts (connected components), and per triangle the
// triangle across the edge opposite each corner (-1 none; where more than two share an edge, the last two).
struct Adjacency {
    std::vector<int32_t> chart;
    std::vector<std::array<int32_t, 3>> across;
};

Adjacency adjacencyOf(const detail::TileUVs& uvs) {
    const size_t n = uvs.uvs.size();
    std::vector<int32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](int32_t i) {
        while (parent[i] != i)
            i = parent[i] = parent[parent[i]];
        return i;
    };
    const auto key = [](glm::vec2 p) {
        uint32_t x = 0, y = 0;
        std::memcpy(&x, &p.x, 4);
        std::memcpy(&y, &p.y, 4);
        return (static_cast<uint64_t>(x) << 32) | y;
    };
    struct EdgeKey {
        uint64_t a, b;
        bool operator==(const EdgeKey&) const = default;
    };
    struct EdgeHash {
        size_t operator()(const EdgeKey& e) const {
            return std::hash<uint64_t>()(e.a * 0x9E3779B97F4A7C15ULL ^ e.b);
        }
    };
    struct Use {
        int32_t triangle, opposite;  // the triangle, and its corner opposite the edge
    };
    Adjacency out;
    out.across.assign(n, {-1, -1, -1});
    std::unordered_map<EdgeKey, Use, EdgeHash> lastUse;
    for (size_t t = 0; t < n; ++t) {
        for (int k = 0; k < 3; ++k) {
            uint64_t a = key(uvs.uvs[t][k]), b = key(uvs.uvs[t][(k + 1) % 3]);
            if (a > b) std::swap(a, b);
            const Use use{static_cast<int32_t>(t), (k + 2) % 3};
            const auto [it, inserted] = lastUse.emplace(EdgeKey{a, b}, use);
            if (inserted) continue;
            parent[find(use.triangle)] = find(it->second.triangle);
            out.across[t][use.opposite] = it->second.triangle;
            out.across[it->second.triangle][it->second.opposite] = use.triangle;
            it->second = use;
        }
    }
    out.chart.resize(n);
    for (size_t t = 0; t < n; ++t)
        out.chart[t] = find(static_cast<int32_t>(t));
    return out;
}

// What a texel shows: where it sits on the deformed surface, and its content's rest position and rigidity,
// through the map and for the identity.
struct TexelSample {
    int32_t chart = -1;  // -1: not a chart texel
    bool located = false;
    bool rigid = false;            // the content at r is rigid (located only)
    bool identityRigid = false;    // the content at q is
    glm::dvec3 deformed{0.0};      // f_D(q)
    glm::dvec3 rest{0.0};          // f_O(r)
    glm::dvec2 r{0.0};             // r = R(q), tile-local
    glm::dvec3 identityRest{0.0};  // f_O(q)
};

// Sums of one band of rows, added up in band order.
struct BandSums {
    double error = 0.0, identityError = 0.0;
    int64_t edges = 0, identityEdges = 0, offChart = 0, chart = 0, inverted = 0;
};

}  // namespace

struct RedirectMetrics::Impl {
    std::string source;
    int32_t texels = 0;
    detail::TileUVs uvs;
    std::vector<int32_t> chart;                  // per UV triangle
    std::vector<std::array<int32_t, 3>> across;  // per UV triangle, Adjacency::across
    // Per UV triangle: corner a and the rows of the inverse of (b - a, c - a), for mayShow's quick test.
    std::vector<std::array<glm::dvec2, 3>> inverse;
    // Per texel, the UV triangle its centre lies in (-1 none), run-length coded per row: row y holds runs r
    // in [rowRunBegin[y], rowRunBegin[y + 1]), run r from column runStart[r] to the next run's start (or the
    // row's end) with triangle runTriangle[r]. A few bytes a row, not 4 a texel.
    std::vector<int64_t> rowRunBegin;
    std::vector<int32_t> runStart, runTriangle;
    std::vector<glm::vec3> restPoints;  // f_O's vertices
    int32_t buckets = 1;                // point-location buckets per side
    std::vector<int32_t> bucketStart, bucketTriangles;
    io::Image rigidity;      // T x T x 1
    double minLength = 0.0;  // rest lengths at or below are not measurable

    // The UV triangle holding tile-local r (the lowest index among overlapping ones), or -1.
    [[nodiscard]] int32_t locate(glm::dvec2 r, glm::dvec3& bary) const {
        const auto cell = [&](double c) {
            return std::clamp(static_cast<int32_t>(std::floor(c * buckets)), 0, buckets - 1);
        };
        const int32_t b = cell(r.y) * buckets + cell(r.x);
        for (int32_t k = bucketStart[b]; k < bucketStart[b + 1]; ++k) {
            const int32_t t = bucketTriangles[k];
            const glm::dvec3 l = barycentricIn(uvs.uvs[t], r);
            if (l.x >= -kInsideTolerance && l.y >= -kInsideTolerance && l.z >= -kInsideTolerance) {
                bary = l;
                return t;
            }
        }
        return -1;
    }

    // Barycentric coordinates of r in UV triangle t (those of corners 1 and 2), for the quick tests below.
    [[nodiscard]] glm::dvec2 quickBarycentric(int32_t t, glm::dvec2 r) const {
        const auto& [a, row0, row1] = inverse[static_cast<size_t>(t)];
        const glm::dvec2 p = r - a;
        return {row0.x * p.x + row0.y * p.y, row1.x * p.x + row1.y * p.y};
    }
    // Whether barycentric coordinates l (corners 1 and 2) lie inside their triangle with a margin far
    // beyond this test's rounding: a sure yes before locate().
    static bool insideWithMargin(glm::dvec2 l) {
        constexpr double kMargin = 1e-6;
        return l.x >= kMargin && l.y >= kMargin && l.x + l.y <= 1.0 - kMargin;
    }
    [[nodiscard]] bool insideWithMargin(int32_t t, glm::dvec2 r) const {
        return insideWithMargin(quickBarycentric(t, r));
    }

    // Whether r lies on a UV triangle: the same answer as locate() >= 0, quicker. Each test below is a sure
    // yes (r inside a triangle with a margin, where the bucket's loop would find it too); only a point near
    // an edge reaches locate(). First the texel's own triangle `own`, then a short walk from it across the
    // edge r lies furthest beyond (content moved a few texels mostly lies in a neighbour), then r's bucket.
    // `hint`, when given, is the entry of bucketTriangles that answered the last bucket search: neighbouring
    // texels' content mostly lies in the same triangle, so it is tried first when r falls in the same bucket.
    [[nodiscard]] bool onChart(int32_t own, glm::dvec2 r, int32_t* hint = nullptr) const {
        constexpr int32_t kWalkSteps = 3;
        for (int32_t t = own, step = 0; t >= 0 && step <= kWalkSteps; ++step) {
            const glm::dvec2 l = quickBarycentric(t, r);
            if (insideWithMargin(l)) return true;
            const double l0 = 1.0 - l.x - l.y;
            const int32_t beyond = l0 <= l.x ? (l0 <= l.y ? 0 : 2) : (l.x <= l.y ? 1 : 2);
            t = across[static_cast<size_t>(t)][beyond];
        }
        const auto cell = [&](double c) {
            return std::clamp(static_cast<int32_t>(std::floor(c * buckets)), 0, buckets - 1);
        };
        const int32_t b = cell(r.y) * buckets + cell(r.x);
        if (hint && *hint >= bucketStart[b] && *hint < bucketStart[b + 1] &&
            insideWithMargin(bucketTriangles[*hint], r))
            return true;
        for (int32_t k = bucketStart[b]; k < bucketStart[b + 1]; ++k) {
            if (!insideWithMargin(bucketTriangles[k], r)) continue;
            if (hint) *hint = k;
            return true;
        }
        glm::dvec3 bary;
        return locate(r, bary) >= 0;
    }

    [[nodiscard]] glm::dvec3 pointOn(std::span<const glm::vec3> points, int32_t t,
                                     const glm::dvec3& l) const {
        const auto& v = uvs.vertices[t];
        return l.x * glm::dvec3(points[v[0]]) + l.y * glm::dvec3(points[v[1]]) +
               l.z * glm::dvec3(points[v[2]]);
    }

    [[nodiscard]] bool rigidAt(glm::dvec2 r) const {
        float value = 0.0f;
        io::sampleImage(rigidity,
                        glm::vec2(static_cast<float>(r.x * texels), static_cast<float>((1.0 - r.y) * texels)),
                        io::SampleFilter::Bilinear, std::span<float>(&value, 1));
        return value >= 0.5f;
    }

    // The UV triangle texel (x, y)'s centre lies in, -1 none.
    [[nodiscard]] int32_t texelTriangle(int32_t x, int32_t y) const {
        const auto first = runStart.begin() + rowRunBegin[y], last = runStart.begin() + rowRunBegin[y + 1];
        return runTriangle[static_cast<size_t>(std::upper_bound(first, last, x) - runStart.begin() - 1)];
    }

    [[nodiscard]] TexelSample sample(std::span<const glm::vec3> deformed, const io::Image& redirect,
                                     int32_t x, int32_t y) const {
        TexelSample s;
        const int32_t t = texelTriangle(x, y);
        if (t < 0) return s;
        s.chart = chart[t];
        const glm::dvec2 q((x + 0.5) / texels, 1.0 - (y + 0.5) / texels);
        const glm::dvec3 lq = barycentricIn(uvs.uvs[t], q);
        s.deformed = pointOn(deformed, t, lq);
        s.identityRest = pointOn(restPoints, t, lq);
        s.identityRigid = rigidity.at(x, y, 0) >= 0.5f;
        const glm::dvec2 r = detail::redirectAt(redirect, x, y);
        s.r = r;
        glm::dvec3 lr;
        const int32_t tr = locate(r, lr);
        if (tr >= 0) {
            s.located = true;
            s.rest = pointOn(restPoints, tr, lr);
            s.rigid = rigidAt(r);
        }
        return s;
    }

    // Adds edge (a, b) to the sums and to a's texel sums (error, edges; identity error, edges).
    void addEdge(const TexelSample& a, const TexelSample& b, BandSums& sums, glm::dvec4& texel) const {
        if (a.chart < 0 || a.chart != b.chart) return;
        const double deformedLength = glm::length(b.deformed - a.deformed);
        if (a.identityRigid && b.identityRigid) {
            const double rest = glm::length(b.identityRest - a.identityRest);
            if (rest > minLength) {
                const double error = std::abs(deformedLength / rest - 1.0);
                sums.identityError += error;
                ++sums.identityEdges;
                texel.z += error;
                texel.w += 1.0;
            }
        }
        if (a.located && b.located && a.rigid && b.rigid) {
            // Both texels showing one point of the map counts as an error of 1 (DeliveredMetrics), so that a
            // map smearing rigid detail cannot score as if it removed its stretch; distinct points on a rest
            // surface degenerate there are left out, as at the identity.
            const double rest = glm::length(b.rest - a.rest);
            if (rest > minLength || a.r == b.r) {
                const double error = rest > minLength ? std::abs(deformedLength / rest - 1.0) : 1.0;
                sums.error += error;
                ++sums.edges;
                texel.x += error;
                texel.y += 1.0;
            }
        }
    }
};

RedirectMetrics::RedirectMetrics(const geom::Mesh& rest, int tile, io::Image rigidity,
                                 const std::string& source)
    : RedirectMetrics(rest, detail::collectTileUVs(rest, tile, source), std::move(rigidity), source) {}

RedirectMetrics::RedirectMetrics(const geom::Mesh& rest, detail::TileUVs uvs, io::Image rigidity,
                                 const std::string& source)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.source = source;
    m.uvs = std::move(uvs);
    if (m.uvs.uvs.empty()) {
        throw InvalidInput(formatError(detail::tileSource(source, m.uvs.tile), "", "holds no UV face",
                                       "a tile of the mesh's UVs"));
    }
    m.texels = rigidity.width;
    setRigidity(std::move(rigidity));
    Adjacency adjacency = adjacencyOf(m.uvs);
    m.chart = std::move(adjacency.chart);
    m.across = std::move(adjacency.across);
    m.inverse.reserve(m.uvs.uvs.size());
    for (const auto& tri : m.uvs.uvs) {
        const glm::dvec2 a(tri[0]), e0 = glm::dvec2(tri[1]) - a, e1 = glm::dvec2(tri[2]) - a;
        const double den = e0.x * e1.y - e1.x * e0.y;
        // A degenerate triangle gets rows that accept nothing (l1 = l2 = 0).
        m.inverse.push_back(den == 0.0 ? std::array<glm::dvec2, 3>{a, glm::dvec2(0.0), glm::dvec2(0.0)}
                                       : std::array<glm::dvec2, 3>{a, glm::dvec2(e1.y, -e1.x) / den,
                                                                   glm::dvec2(-e0.y, e0.x) / den});
    }
    m.restPoints.assign(rest.points().begin(), rest.points().end());
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const glm::vec3& p : m.restPoints) {
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    m.minLength = m.restPoints.empty() ? 0.0 : 1e-9 * glm::length(hi - lo);

    // Each texel centre's UV triangle (the rasteriser's top-left rule: one triangle per covered centre).
    const int32_t t = m.texels;
    const size_t triangles = m.uvs.uvs.size();
    std::vector<glm::vec2> corners(triangles * 3);
    std::vector<std::array<int32_t, 3>> indices(triangles);
    for (size_t k = 0; k < triangles; ++k) {
        for (int c = 0; c < 3; ++c) {
            const glm::vec2 uv = m.uvs.uvs[k][c];
            corners[3 * k + c] = {uv.x * static_cast<float>(t), (1.0f - uv.y) * static_cast<float>(t)};
            indices[k][c] = static_cast<int32_t>(3 * k + c);
        }
    }
    geom::AttributeRaster raster;
    geom::rasterizeAttributes({t, t}, corners, indices, {}, 0, raster);
    std::vector<int32_t> texelTriangle = std::move(raster.triangle);

    // Point-location buckets over the tile, each listing the triangles whose UV box overlaps it, ascending:
    // counted, then filled in triangle order (one array, not a list per bucket: a 16384^2 tile has 16.8M).
    m.buckets = std::max(1, t / kBucketTexels);
    const int32_t g = m.buckets;
    const auto forBuckets = [&](const auto& fn) {
        for (size_t k = 0; k < triangles; ++k) {
            const auto& tri = m.uvs.uvs[k];
            const float u0 = std::min({tri[0].x, tri[1].x, tri[2].x}),
                        u1 = std::max({tri[0].x, tri[1].x, tri[2].x});
            const float v0 = std::min({tri[0].y, tri[1].y, tri[2].y}),
                        v1 = std::max({tri[0].y, tri[1].y, tri[2].y});
            const auto cell = [&](float c) {
                return std::clamp(static_cast<int32_t>(std::floor(c * static_cast<float>(g))), 0, g - 1);
            };
            for (int32_t by = cell(v0); by <= cell(v1); ++by)
                for (int32_t bx = cell(u0); bx <= cell(u1); ++bx)
                    fn(static_cast<size_t>(by) * g + bx, static_cast<int32_t>(k));
        }
    };
    m.bucketStart.assign(static_cast<size_t>(g) * g + 1, 0);
    forBuckets([&](size_t b, int32_t) { ++m.bucketStart[b + 1]; });
    for (size_t b = 0; b + 1 < m.bucketStart.size(); ++b)
        m.bucketStart[b + 1] += m.bucketStart[b];
    m.bucketTriangles.resize(static_cast<size_t>(m.bucketStart.back()));
    {
        std::vector<int32_t> next(m.bucketStart.begin(), m.bucketStart.end() - 1);
        forBuckets([&](size_t b, int32_t k) { m.bucketTriangles[static_cast<size_t>(next[b]++)] = k; });
    }

    // The rasteriser snaps corners to 1/256 texel: a centre it covers within that of an edge may lie just
    // outside its triangle. A chart texel is one whose centre the point location finds, so that the
    // identity (r = q) never counts as off-chart.
#pragma omp parallel for schedule(static)
    for (int32_t y = 0; y < t; ++y) {
        for (int32_t x = 0; x < t; ++x) {
            int32_t& tri = texelTriangle[static_cast<size_t>(y) * t + x];
            if (tri < 0) continue;
            const glm::dvec2 q((x + 0.5) / t, 1.0 - (y + 0.5) / t);
            const glm::dvec3 l = barycentricIn(m.uvs.uvs[tri], q);
            if (l.x >= -kInsideTolerance && l.y >= -kInsideTolerance && l.z >= -kInsideTolerance) continue;
            glm::dvec3 bary;
            tri = m.locate(q, bary);
        }
    }
    detail::encodeRowRuns(texelTriangle, t, t, m.rowRunBegin, m.runStart, m.runTriangle);
}

RedirectMetrics::~RedirectMetrics() = default;
RedirectMetrics::RedirectMetrics(RedirectMetrics&&) noexcept = default;
RedirectMetrics& RedirectMetrics::operator=(RedirectMetrics&&) noexcept = default;

bool RedirectMetrics::mayShow(int32_t x, int32_t y, glm::dvec2 r) const {
    const Impl& m = *impl_;
    if (x < 0 || y < 0 || x >= m.texels || y >= m.texels) return true;
    const int32_t own = m.texelTriangle(x, y);
    return own < 0 || m.onChart(own, r);
}

void RedirectMetrics::refusedInRow(const io::Image& redirect, int32_t y,
                                   std::vector<int32_t>& refused) const {
    const Impl& m = *impl_;
    int32_t hint = -1;
    for (int64_t run = m.rowRunBegin[y]; run < m.rowRunBegin[y + 1]; ++run) {
        const int32_t own = m.runTriangle[run];
        if (own < 0) continue;
        const int32_t end = run + 1 < m.rowRunBegin[y + 1] ? m.runStart[run + 1] : m.texels;
        for (int32_t x = m.runStart[run]; x < end; ++x)
            if (!m.onChart(own, detail::redirectAt(redirect, x, y), &hint)) refused.push_back(x);
    }
}

int32_t RedirectMetrics::texels() const {
    return impl_->texels;
}

const io::Image& RedirectMetrics::rigidity() const {
    return impl_->rigidity;
}

void RedirectMetrics::setRigidity(io::Image rigidity) {
    Impl& m = *impl_;
    if (rigidity.width < 1 || rigidity.width != rigidity.height || rigidity.channels < 1 ||
        rigidity.pixels.size() != static_cast<size_t>(rigidity.width) * rigidity.height * rigidity.channels) {
        throw InvalidInput(
            formatError(m.source, "rigidity map",
                        "is " + std::to_string(rigidity.width) + " x " + std::to_string(rigidity.height),
                        "a square map of at least 1 texel"));
    }
    if (m.texels != 0 && rigidity.width != m.texels) {
        throw InvalidInput(formatError(m.source, "rigidity map",
                                       std::to_string(rigidity.width) + " texels per side",
                                       std::to_string(m.texels) + ", the bound map's size"));
    }
    // Channel 0, finite and in [0, 1], as the solver takes it: a NaN or a 5 would change the figures.
    for (int32_t y = 0; y < rigidity.height; ++y) {
        for (int32_t x = 0; x < rigidity.width; ++x) {
            const float r = rigidity.at(x, y, 0);
            if (!(r >= 0.0f && r <= 1.0f)) {
                throw InvalidInput(formatError(
                    m.source, "rigidity map texel (" + std::to_string(x) + ", " + std::to_string(y) + ")",
                    "is " + numberText(r), "a finite value in [0, 1]"));
            }
        }
    }
    if (rigidity.channels == 1) {  // channel 0 is the map: kept as it comes, without a copy
        m.rigidity = std::move(rigidity);
        return;
    }
    m.rigidity.width = rigidity.width;
    m.rigidity.height = rigidity.height;
    m.rigidity.channels = 1;
    const auto count = static_cast<int64_t>(rigidity.width) * rigidity.height;
    deformkit::detail::assignLarge(m.rigidity.pixels, static_cast<size_t>(count), 0.0f);
#pragma omp parallel for schedule(static)
    for (int64_t k = 0; k < count; ++k)
        m.rigidity.pixels[k] = rigidity.pixels[k * rigidity.channels];
}

DeliveredMetrics RedirectMetrics::measure(std::span<const glm::vec3> deformed, const io::Image& redirect,
                                          DeliveredTexels* texels) const {
    const Impl& m = *impl_;
    const int32_t t = m.texels;
    if (deformed.size() != m.restPoints.size()) {
        throw InvalidInput(
            formatError(m.source, "deformed positions", std::to_string(deformed.size()) + " points",
                        std::to_string(m.restPoints.size()) + ", the rest mesh's vertex count"));
    }
    if (redirect.width != t || redirect.height != t || redirect.channels < 2) {
        throw InvalidInput(formatError(m.source, "redirect map",
                                       "is " + std::to_string(redirect.width) + " x " +
                                           std::to_string(redirect.height) + " with " +
                                           std::to_string(redirect.channels) + " channels",
                                       std::to_string(t) + " x " + std::to_string(t) + " with 2 channels"));
    }
    for (size_t v = 0; v < deformed.size(); ++v) {
        const glm::vec3& p = deformed[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            throw InvalidInput(formatError(m.source, "deformed position of vertex " + std::to_string(v),
                                           "is not finite", "finite x, y, z"));
        }
    }
    for (int32_t y = 0; y < t; ++y) {
        for (int32_t x = 0; x < t; ++x) {
            if (!std::isfinite(redirect.at(x, y, 0)) || !std::isfinite(redirect.at(x, y, 1))) {
                throw InvalidInput(formatError(
                    m.source, "redirect map texel (" + std::to_string(x) + ", " + std::to_string(y) + ")",
                    "is not finite", "finite tile-local uv"));
            }
        }
    }
    if (texels) {
        const float none = std::numeric_limits<float>::quiet_NaN();
        texels->stretch = io::Image(t, t, 1);
        texels->identityStretch = io::Image(t, t, 1);
        std::fill(texels->stretch.pixels.begin(), texels->stretch.pixels.end(), none);
        std::fill(texels->identityStretch.pixels.begin(), texels->identityStretch.pixels.end(), none);
        texels->folds = io::Image(t, t, 1);
        texels->offChart = io::Image(t, t, 1);
        texels->chart = io::Image(t, t, 1);
    }
    const int32_t bands = (t + kMetricBandRows - 1) / kMetricBandRows;
    std::vector<BandSums> sums(static_cast<size_t>(bands));
#pragma omp parallel for schedule(dynamic, 1)
    for (int32_t b = 0; b < bands; ++b) {
        const int32_t y0 = b * kMetricBandRows, y1 = std::min(t, y0 + kMetricBandRows);
        const int32_t rows = std::min(t, y1 + 1) - y0;  // one more row for the band's last vertical edges
        std::vector<TexelSample> samples(static_cast<size_t>(rows) * t);
        for (int32_t r = 0; r < rows; ++r)
            for (int32_t x = 0; x < t; ++x)
                samples[static_cast<size_t>(r) * t + x] = m.sample(deformed, redirect, x, y0 + r);
        BandSums& s = sums[static_cast<size_t>(b)];
        for (int32_t y = y0; y < y1; ++y) {
            const TexelSample* row = &samples[static_cast<size_t>(y - y0) * t];
            const TexelSample* below = y + 1 < t ? row + t : nullptr;
            for (int32_t x = 0; x < t; ++x) {
                const bool offChart = row[x].chart >= 0 && !row[x].located;
                if (row[x].chart >= 0) ++s.chart;
                if (offChart) ++s.offChart;
                glm::dvec4 texel(0.0);  // this texel's edges: error, count; identity error, count
                if (x + 1 < t) m.addEdge(row[x], row[x + 1], s, texel);
                if (below) m.addEdge(row[x], below[x], s, texel);
                if (texels) {
                    if (texel.y > 0.0) texels->stretch.at(x, y, 0) = static_cast<float>(texel.x / texel.y);
                    if (texel.w > 0.0) {
                        texels->identityStretch.at(x, y, 0) = static_cast<float>(texel.z / texel.w);
                    }
                    texels->offChart.at(x, y, 0) = offChart ? 1.0f : 0.0f;
                    texels->chart.at(x, y, 0) = row[x].chart >= 0 ? 1.0f : 0.0f;
                    if (below && x + 1 < t && detail::invertedInCell(redirect, x, y) > 0) {
                        texels->folds.at(x, y, 0) = 1.0f;
                    }
                }
            }
        }
        s.inverted = detail::invertedInRows(redirect, y0, y1);
    }
    BandSums total;
    for (const BandSums& s : sums) {
        total.error += s.error;
        total.identityError += s.identityError;
        total.edges += s.edges;
        total.identityEdges += s.identityEdges;
        total.offChart += s.offChart;
        total.chart += s.chart;
        total.inverted += s.inverted;
    }
    DeliveredMetrics out;
    out.rigidEdges = total.edges;
    out.identityRigidEdges = total.identityEdges;
    out.rigidStretchError = total.edges > 0 ? total.error / static_cast<double>(total.edges) : 0.0;
    out.identityStretchError =
        total.identityEdges > 0 ? total.identityError / static_cast<double>(total.identityEdges) : 0.0;
    out.removed = out.identityStretchError > 0.0 && total.edges > 0
                      ? 1.0 - out.rigidStretchError / out.identityStretchError
                      : 0.0;
    out.invertedTriangles = total.inverted;
    out.offChartTexels = total.offChart;
    out.chartTexels = total.chart;
    return out;
}

std::vector<ReportedFigure> reportedFigures(const DeliveredMetrics& m) {
    using Kind = ReportedFigure::Kind;
    return {{"rigid_stretch_error", Kind::Number, m.rigidStretchError},
            {"identity_stretch_error", Kind::Number, m.identityStretchError},
            {"rigid_stretch_removed", Kind::Number, m.removed},
            {"rigid_edges", Kind::Count, static_cast<double>(m.rigidEdges)},
            {"identity_rigid_edges", Kind::Count, static_cast<double>(m.identityRigidEdges)},
            {"inverted_triangles", Kind::Count, static_cast<double>(m.invertedTriangles)},
            {"off_chart_texels", Kind::Count, static_cast<double>(m.offChartTexels)},
            {"chart_texels", Kind::Count, static_cast<double>(m.chartTexels)}};
}

int64_t countInvertedTriangles(const io::Image& redirect) {
    if (redirect.width < 1 || redirect.height < 1 || redirect.channels < 2) {
        throw InvalidInput(
            formatError("redirect map", "", "is empty or has fewer than 2 channels", "a T x T x 2 map"));
    }
    return detail::invertedInRows(redirect, 0, redirect.height);
}

}  // namespace deformkit::uvwarp
