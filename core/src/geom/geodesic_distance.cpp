#include "deformkit/geom/geodesic_distance.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/triangulation.h"

namespace deformkit::geom {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A finished vertex whose value later drops by more than this fraction is finished again, at most
// kMaxFinishes times in all. Smaller drops (rounding) are kept without re-propagating them.
constexpr double kRefinishDrop = 1e-9;
constexpr uint8_t kMaxFinishes = 8;

// Slack, as a fraction of |AB|, when testing whether the path from the unfolded source to C crosses
// the edge AB: a path through A or B exactly is also found by the edge update.
constexpr double kCrossingSlack = 1e-9;
constexpr double kTangentSlack = 1e-12;

// Distance to C from the point source placed at da from A and db from B, on the far side of AB from C,
// in the plane of triangle ABC (Novotni & Klein 2002, circular wavefront). +infinity when A and B
// coincide, the two distances cannot come from one point (|da - db| > |AB| or da + db < |AB|), or the
// straight path from that point to C misses the edge AB (it belongs to another triangle or bends
// around a vertex).
double circularUpdate(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double da, double db) {
    const glm::dvec3 ab = b - a, ac = c - a;
    const double ab2 = glm::dot(ab, ab);
    if (!(ab2 > 0.0)) return kInfinity;
    const double lab = std::sqrt(ab2);
    // Unfolded frame: A at the origin, B on +x, C above the x axis.
    const double xc = glm::dot(ac, ab) / lab;
    // yc = 0 is kept: C on the segment AB (a collinear corner of an n-gon, whose fan triangle has no
    // area) still gets the source's distance through the edge it lies on.
    const double yc2 = glm::dot(ac, ac) - xc * xc;
    if (std::isnan(yc2)) return kInfinity;
    const double yc = std::sqrt(std::max(yc2, 0.0));
    // Circle-circle intersection, factored to keep precision when da, db >> |AB|.
    const double xs = ((da - db) * (da + db) + ab2) / (2.0 * lab);
    double ys2 = (da - xs) * (da + xs);
    // Tangent circles (the source on the line AB, e.g. C straight across a collinear corner) come out
    // slightly negative from rounding.
    if (ys2 < 0.0 && ys2 >= -kTangentSlack * (da * da + db * db)) ys2 = 0.0;
    if (!(ys2 >= 0.0)) return kInfinity;
    const double ys = -std::sqrt(ys2);
    // Source and C both on the line AB: the edge updates cover that path.
    if (!(yc - ys > 0.0)) return kInfinity;
    // Where the segment from the source to C crosses the line AB.
    const double x = xs + (xc - xs) * (-ys / (yc - ys));
    if (x < -kCrossingSlack * lab || x > (1.0 + kCrossingSlack) * lab) return kInfinity;
    return std::hypot(xc - xs, yc - ys);
}

}  // namespace

GeodesicDistanceSolver::GeodesicDistanceSolver(const Mesh& mesh)
    : points_(mesh.points().begin(), mesh.points().end()),
      triangles_(triangleVertices(mesh, triangulate(mesh))) {
    const int32_t n = mesh.numVertices();
    vertexTriangleOffsets_.assign(static_cast<size_t>(n) + 1, 0);
    for (const auto& t : triangles_) {
        for (int32_t v : t)
            ++vertexTriangleOffsets_[v + 1];
    }
    for (int32_t v = 0; v < n; ++v)
        vertexTriangleOffsets_[v + 1] += vertexTriangleOffsets_[v];
    vertexTriangles_.resize(static_cast<size_t>(vertexTriangleOffsets_[n]));
    std::vector<int32_t> fill(vertexTriangleOffsets_.begin(), vertexTriangleOffsets_.end() - 1);
    for (int32_t t = 0; t < static_cast<int32_t>(triangles_.size()); ++t) {
        for (int32_t v : triangles_[t])
            vertexTriangles_[fill[v]++] = t;
    }
    updateReach();
}

void GeodesicDistanceSolver::updateReach() {
    reach_.assign(points_.size(), 0.0);
    for (const auto& t : triangles_) {
        for (int k = 0; k < 3; ++k) {
            const int32_t a = t[k], b = t[(k + 1) % 3];
            const double len = glm::length(points_[b] - points_[a]);
            for (int32_t v : t)
                reach_[v] = std::max(reach_[v], len);
        }
    }
}

void GeodesicDistanceSolver::setPoints(std::span<const glm::vec3> points) {
    if (points.size() != points_.size()) {
        throw InvalidInput(formatError("geodesic distance", "points",
                                       "got " + std::to_string(points.size()) + " positions",
                                       std::to_string(points_.size()) + ", one per vertex"));
    }
    std::copy(points.begin(), points.end(), points_.begin());
    updateReach();
}

void GeodesicDistanceSolver::compute(int32_t source, std::span<double> out,
                                     const GeodesicOptions& options) const {
    const int32_t n = numVertices();
    if (source < 0 || source >= n) {
        throw InvalidInput(formatError("geodesic distance", "source vertex " + std::to_string(source),
                                       "is out of range", "an index in [0, " + std::to_string(n) + ")"));
    }
    if (out.size() != static_cast<size_t>(n)) {
        throw InvalidInput(formatError("geodesic distance", "output",
                                       "holds " + std::to_string(out.size()) + " entries",
                                       std::to_string(n) + ", one per vertex"));
    }
    const double maxDistance = options.maxDistance;
    if (!(maxDistance >= 0.0)) {
        throw InvalidInput(formatError("geodesic distance", "maxDistance",
                                       "is " + std::to_string(maxDistance),
                                       "a distance >= 0 (or +infinity)"));
    }

    std::fill(out.begin(), out.end(), kInfinity);
    std::vector<uint8_t> finishes(static_cast<size_t>(n), 0);  // times a vertex was finished (0: not known)
    std::vector<uint8_t> exact(static_cast<size_t>(n), 0);     // source and its one-ring: never updated
    std::vector<uint8_t> queued(static_cast<size_t>(n), 0);    // the queue holds the vertex's current value
    // Min-heap on (distance, vertex): the vertex index breaks ties, so the order is fully determined.
    using Entry = std::pair<double, int32_t>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;

    const glm::dvec3 ps = points_[source];
    auto triangles = [&](int32_t v) {
        return std::span<const int32_t>(vertexTriangles_)
            .subspan(vertexTriangleOffsets_[v], vertexTriangleOffsets_[v + 1] - vertexTriangleOffsets_[v]);
    };

    out[source] = 0.0;
    exact[source] = 1;
    finishes[source] = 1;
    for (int32_t t : triangles(source)) {
        for (int32_t v : triangles_[t]) {
            if (exact[v]) continue;
            exact[v] = 1;
            out[v] = glm::length(points_[v] - ps);
            if (out[v] <= maxDistance + reach_[v]) {
                queue.emplace(out[v], v);
                queued[v] = 1;
            }
        }
    }

    // C's candidate from the finished vertex A through triangle ABC: the circular update when B is known
    // too, else A's edge; never below the straight-line distance from the source.
    auto relax = [&](int32_t a, int32_t b, int32_t c) {
        if (exact[c]) return;
        const glm::dvec3& pa = points_[a];
        const glm::dvec3& pc = points_[c];
        double d = out[a] + glm::length(pc - pa);
        if (finishes[b] > 0) d = std::min(d, circularUpdate(pa, points_[b], pc, out[a], out[b]));
        d = std::max(d, glm::length(pc - ps));
        if (!(d < out[c])) return;
        const bool propagate = queued[c] || finishes[c] == 0 ||
                               (finishes[c] < kMaxFinishes && d < out[c] * (1.0 - kRefinishDrop));
        out[c] = d;
        if (propagate && d <= maxDistance + reach_[c]) {
            queue.emplace(d, c);
            queued[c] = 1;
        }
    };

    while (!queue.empty()) {
        const auto [d, v] = queue.top();
        queue.pop();
        if (d != out[v]) continue;  // superseded by a later, smaller entry
        queued[v] = 0;
        ++finishes[v];
        for (int32_t t : triangles(v)) {
            const auto& tri = triangles_[t];
            // The two other corners, each updated with the other as the second known vertex.
            const int32_t k = tri[0] == v ? 0 : (tri[1] == v ? 1 : 2);
            const int32_t p = tri[(k + 1) % 3], q = tri[(k + 2) % 3];
            relax(v, q, p);
            relax(v, p, q);
        }
    }

    for (double& d : out) {
        if (d > maxDistance) d = kInfinity;
    }
}

std::vector<double> geodesicDistances(const Mesh& mesh, int32_t source, const GeodesicOptions& options) {
    const GeodesicDistanceSolver solver(mesh);
    std::vector<double> out(static_cast<size_t>(mesh.numVertices()));
    solver.compute(source, out, options);
    return out;
}

}  // namespace deformkit::geom
