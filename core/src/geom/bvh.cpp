#include "deformkit/geom/bvh.h"
#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/triangulation.h"

namespace deformkit::geom {
namespace {

constexpr int32_t kMaxLeafSize = 4;
constexpr int32_t kBins = 16;
// Below this depth splits follow the SAH; beyond it they halve the triangle count (object median), which
// bounds the depth by kSahDepth + 31 and so the traversal stacks by kStackSize.
constexpr int32_t kSahDepth = 64;
constexpr int32_t kStackSize = 128;
// Float box tests are widened by this relative slack so rounding never prunes a box the exact test keeps.
constexpr float kBoxSlack = 1e-6f;
// A triangle whose |ab x ac|^2 is below this fraction of |ab|^2 |ac|^2 has (numerically) collinear corners.
constexpr double kCollinear = 1e-20;

void requireFinitePoints(std::span<const glm::vec3> points, const char* what) {
    for (size_t v = 0; v < points.size(); ++v) {
        if (!geom::isFinite(points[v])) {
            throw InvalidInput(formatError(what, "vertex " + std::to_string(v),
                                           "has a NaN or infinite coordinate", "finite coordinates"));
        }
    }
}

float halfArea(const Box3& b) {
    const glm::vec3 e = b.extent();
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

float boxDistance2(const Box3& b, const glm::vec3& p) {
    const glm::vec3 d = glm::max(glm::max(b.min - p, p - b.max), glm::vec3(0.0f));
    return glm::dot(d, d) * (1.0f - kBoxSlack);
}

// Entry parameter of the ray into the box within [tMin, tMax], or +infinity when it misses.
float rayBoxEntry(const Box3& b, const glm::vec3& origin, const glm::vec3& direction,
                  const glm::vec3& inverse, float tMin, float tMax) {
    float tNear = -std::numeric_limits<float>::infinity();
    float tFar = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (direction[a] == 0.0f) {
            if (origin[a] < b.min[a] || origin[a] > b.max[a]) return std::numeric_limits<float>::infinity();
            continue;
        }
        float t0 = (b.min[a] - origin[a]) * inverse[a];
        float t1 = (b.max[a] - origin[a]) * inverse[a];
        if (t0 > t1) std::swap(t0, t1);
        tNear = std::max(tNear, t0);
        tFar = std::min(tFar, t1);
    }
    tNear -= std::abs(tNear) * kBoxSlack;
    tFar += std::abs(tFar) * kBoxSlack;
    tNear = std::max(tNear, tMin);
    tFar = std::min(tFar, tMax);
    return tNear <= tFar ? tNear : std::numeric_limits<float>::infinity();
}

struct TrianglePoint {
    double distance2 = 0.0;
    glm::dvec3 point{0.0};
    glm::dvec3 barycentric{0.0};
};

TrianglePoint onSegment(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    const glm::dvec3 q = a + t * ab;
    return {glm::dot(p - q, p - q), q, glm::dvec3(1.0 - t, t, 0.0)};
}

// Corners collinear or coincident: the closest of the three edges.
TrianglePoint closestOnDegenerate(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                  const glm::dvec3& c) {
    TrianglePoint best = onSegment(p, a, b);
    TrianglePoint bc = onSegment(p, b, c);
    if (bc.distance2 < best.distance2)
        best = {bc.distance2, bc.point, {0.0, bc.barycentric.x, bc.barycentric.y}};
    TrianglePoint ca = onSegment(p, c, a);
    if (ca.distance2 < best.distance2)
        best = {ca.distance2, ca.point, {ca.barycentric.y, 0.0, ca.barycentric.x}};
    return best;
}

// Ericson, Real-Time Collision Detection, section 5.1.5: find which Voronoi region of the triangle (a
// vertex, an edge or the face) holds p from dot products alone, then project onto that feature.
TrianglePoint closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a;
    const glm::dvec3 n = glm::cross(ab, ac);
    if (glm::dot(n, n) <= kCollinear * glm::dot(ab, ab) * glm::dot(ac, ac))
        return closestOnDegenerate(p, a, b, c);

    auto result = [&p](const glm::dvec3& q, const glm::dvec3& bary) {
        return TrianglePoint{glm::dot(p - q, p - q), q, bary};
    };
    // The point t of the way along the edge from corner i (at `from`, direction `along`) to corner j.
    auto onEdge = [&](const glm::dvec3& from, const glm::dvec3& along, double t, int i, int j) {
        glm::dvec3 bary(0.0);
        bary[i] = 1.0 - t;
        bary[j] = t;
        return result(from + t * along, bary);
    };
    // Vertex regions, then the edge regions between them (Ericson's d1..d6 and va, vb, vc).
    const glm::dvec3 ap = p - a, bp = p - b, cp = p - c;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return result(a, {1.0, 0.0, 0.0});
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return result(b, {0.0, 1.0, 0.0});
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return onEdge(a, ab, d1 / (d1 - d3), 0, 1);
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return result(c, {0.0, 0.0, 1.0});
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return onEdge(a, ac, d2 / (d2 - d6), 0, 2);
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
        return onEdge(b, c - b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), 1, 2);

    const double denom = 1.0 / (va + vb + vc);
    const double v = vb * denom, w = vc * denom;
    return result(a + v * ab + w * ac, {1.0 - v - w, v, w});
}

struct TriangleHit {
    double t = 0.0;
    double u = 0.0;
    double v = 0.0;
};

// Moller and Trumbore, "Fast, minimum storage ray/triangle intersection" (1997), without back-face culling.
bool intersectTriangle(const glm::dvec3& origin, const glm::dvec3& direction, const glm::dvec3& a,
                       const glm::dvec3& b, const glm::dvec3& c, TriangleHit& hit) {
    const glm::dvec3 e1 = b - a, e2 = c - a;
    const glm::dvec3 pvec = glm::cross(direction, e2);
    const double det = glm::dot(e1, pvec);
    // Rays in the triangle's plane and collinear triangles: det is rounding noise.
    if (det * det <= kCollinear * glm::dot(direction, direction) * glm::dot(e1, e1) * glm::dot(e2, e2))
        return false;
    const double inv = 1.0 / det;
    const glm::dvec3 tvec = origin - a;
    const double u = glm::dot(tvec, pvec) * inv;
    if (u < 0.0 || u > 1.0) return false;
    const glm::dvec3 qvec = glm::cross(tvec, e1);
    const double v = glm::dot(direction, qvec) * inv;
    if (v < 0.0 || u + v > 1.0) return false;
    hit = {glm::dot(e2, qvec) * inv, u, v};
    return true;
}

std::string rangeText(size_t n) {
    return "an index in [0, " + std::to_string(n) + ")";
}

}  // namespace

Bvh::Bvh(const Mesh& mesh) : points_(mesh.points().begin(), mesh.points().end()) {
    Triangulation tris = triangulate(mesh);
    triangles_ = triangleVertices(mesh, tris);
    faceOfTriangle_ = std::move(tris.face);
    build();
}

Bvh::Bvh(std::span<const glm::vec3> points, std::span<const std::array<int32_t, 3>> triangles)
    : points_(points.begin(), points.end()), triangles_(triangles.begin(), triangles.end()) {
    requireFinitePoints(points, "bvh");
    const auto numPoints = static_cast<int64_t>(points.size());
    for (size_t t = 0; t < triangles_.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            const int32_t v = triangles_[t][k];
            if (v < 0 || v >= numPoints) {
                throw InvalidInput(formatError(
                    "bvh", "triangle " + std::to_string(t) + " corner " + std::to_string(k),
                    "vertex index " + std::to_string(v) + " is out of range", rangeText(points.size())));
            }
        }
    }
    faceOfTriangle_.resize(triangles_.size());
    std::iota(faceOfTriangle_.begin(), faceOfTriangle_.end(), 0);
    build();
}

void Bvh::build() {
    const auto count = static_cast<int32_t>(triangles_.size());
    order_.resize(count);
    std::iota(order_.begin(), order_.end(), 0);
    nodes_.clear();
    if (count == 0) return;

    std::vector<Box3> triangleBoxes(count);
    std::vector<glm::vec3> centroids(count);
    for (int32_t t = 0; t < count; ++t) {
        for (const int32_t v : triangles_[t])
            triangleBoxes[t].extend(points_[v]);
        centroids[t] = triangleBoxes[t].center();
    }

    struct Task {
        int32_t node, begin, end, depth;
    };
    nodes_.reserve(2 * static_cast<size_t>(count) - 1);
    nodes_.emplace_back();
    std::vector<Task> tasks{{0, 0, count, 0}};
    struct Bin {
        Box3 box;
        int32_t count = 0;
    };
    std::array<Bin, kBins> bins;
    std::array<float, kBins> rightCost{};

    while (!tasks.empty()) {
        const Task task = tasks.back();
        tasks.pop_back();
        Box3 box, centroidBox;
        for (int32_t i = task.begin; i < task.end; ++i) {
            box.extend(triangleBoxes[order_[i]]);
            centroidBox.extend(centroids[order_[i]]);
        }
        nodes_[task.node].box = box;
        const int32_t n = task.end - task.begin;
        if (n <= kMaxLeafSize) {
            nodes_[task.node].first = task.begin;
            nodes_[task.node].count = n;
            continue;
        }

        const glm::vec3 extent = centroidBox.extent();
        int32_t mid = task.begin;
        if (task.depth < kSahDepth) {
            // Binned SAH (Wald, "On fast construction of SAH-based bounding volume hierarchies", 2007).
            int bestAxis = -1, bestSplit = 0;
            float bestCost = std::numeric_limits<float>::infinity();
            for (int axis = 0; axis < 3; ++axis) {
                if (!(extent[axis] > 0.0f)) continue;
                const float scale = kBins / extent[axis];
                bins.fill({});
                for (int32_t i = task.begin; i < task.end; ++i) {
                    const int32_t t = order_[i];
                    const int b = std::min(
                        kBins - 1, static_cast<int>((centroids[t][axis] - centroidBox.min[axis]) * scale));
                    bins[b].box.extend(triangleBoxes[t]);
                    ++bins[b].count;
                }
                Box3 right;
                int32_t rightCount = 0;
                for (int b = kBins - 1; b > 0; --b) {
                    right.extend(bins[b].box);
                    rightCount += bins[b].count;
                    rightCost[b] = rightCount > 0 ? rightCount * halfArea(right) : 0.0f;
                }
                Box3 left;
                int32_t leftCount = 0;
                for (int b = 1; b < kBins; ++b) {
                    left.extend(bins[b - 1].box);
                    leftCount += bins[b - 1].count;
                    const float cost = (leftCount > 0 ? leftCount * halfArea(left) : 0.0f) + rightCost[b];
                    if (cost < bestCost) {
                        bestCost = cost;
                        bestAxis = axis;
                        bestSplit = b;
                    }
                }
            }
            if (bestAxis >= 0) {
                const float scale = kBins / extent[bestAxis];
                const float lo = centroidBox.min[bestAxis];
                auto* split =
                    std::partition(order_.data() + task.begin, order_.data() + task.end, [&](int32_t t) {
                        return std::min(kBins - 1, static_cast<int>((centroids[t][bestAxis] - lo) * scale)) <
                               bestSplit;
                    });
                mid = static_cast<int32_t>(split - order_.data());
            }
        }
        if (mid <= task.begin || mid >= task.end) {
            // Object median along the widest centroid extent (also when all centroids coincide).
            mid = task.begin + n / 2;
            const int axis =
                extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
            std::nth_element(order_.begin() + task.begin, order_.begin() + mid, order_.begin() + task.end,
                             [&](int32_t l, int32_t r) {
                                 return centroids[l][axis] < centroids[r][axis] ||
                                        (centroids[l][axis] == centroids[r][axis] && l < r);
                             });
        }

        const auto left = static_cast<int32_t>(nodes_.size());
        nodes_.emplace_back();
        nodes_.emplace_back();
        nodes_[task.node].first = left;
        nodes_[task.node].count = 0;
        tasks.push_back({left + 1, mid, task.end, task.depth + 1});
        tasks.push_back({left, task.begin, mid, task.depth + 1});
    }
}

void Bvh::refit(std::span<const glm::vec3> points) {
    if (points.size() != points_.size()) {
        throw InvalidInput(
            formatError("bvh", "refit", "got " + std::to_string(points.size()) + " positions",
                        std::to_string(points_.size()) + " positions, as when the hierarchy was built"));
    }
    requireFinitePoints(points, "bvh refit");
    std::copy(points.begin(), points.end(), points_.begin());
    // Children always come after their parent in nodes_, so a reverse sweep sees children first.
    for (auto node = static_cast<int64_t>(nodes_.size()) - 1; node >= 0; --node) {
        Node& n = nodes_[node];
        Box3 box;
        if (n.count > 0) {
            for (int32_t i = n.first; i < n.first + n.count; ++i) {
                for (const int32_t v : triangles_[order_[i]])
                    box.extend(points_[v]);
            }
        } else {
            box = nodes_[n.first].box;
            box.extend(nodes_[n.first + 1].box);
        }
        n.box = box;
    }
}

Box3 Bvh::bounds() const {
    return nodes_.empty() ? Box3{} : nodes_[0].box;
}

template <class Key, class Limit, class Visit>
void Bvh::descend(float rootKey, const Key& key, const Limit& limit, const Visit& visit) const {
    struct Entry {
        int32_t node;
        float key;
    };
    std::array<Entry, kStackSize> stack;
    int top = 0;
    // An infinite key (a box the ray misses) is pruned even when the limit is infinite too.
    const auto reaches = [&](float k) { return k != std::numeric_limits<float>::infinity() && k <= limit(); };
    if (reaches(rootKey)) stack[top++] = {0, rootKey};
    while (top > 0) {
        const Entry entry = stack[--top];
        if (entry.key > limit()) continue;
        int32_t node = entry.node;
        while (true) {
            const Node& n = nodes_[node];
            if (n.count > 0) {
                for (int32_t i = n.first; i < n.first + n.count; ++i)
                    visit(order_[i]);
                break;
            }
            int32_t near = n.first, far = n.first + 1;
            float nearKey = key(nodes_[near].box), farKey = key(nodes_[far].box);
            if (farKey < nearKey) {
                std::swap(near, far);
                std::swap(nearKey, farKey);
            }
            if (!reaches(nearKey)) break;
            if (reaches(farKey)) stack[top++] = {far, farKey};
            node = near;
        }
    }
}

Bvh::ClosestPoint Bvh::closestPoint(const glm::vec3& query, float maxDistance) const {
    if (!geom::isFinite(query)) {
        throw InvalidInput(
            formatError("bvh", "closest point query", "has a NaN or infinite coordinate", "a finite point"));
    }
    if (!(maxDistance >= 0.0f)) {
        throw InvalidInput(formatError("bvh", "closest point query",
                                       "maxDistance is " + std::to_string(maxDistance), "a distance >= 0"));
    }
    ClosestPoint result;
    if (nodes_.empty()) return result;

    const glm::dvec3 p(query);
    double best2 = static_cast<double>(maxDistance) * maxDistance;
    TrianglePoint best;
    descend(
        boxDistance2(nodes_[0].box, query), [&](const Box3& box) { return boxDistance2(box, query); },
        [&] { return best2; },
        [&](int32_t t) {
            const auto& tri = triangles_[t];
            const TrianglePoint c = closestOnTriangle(
                p, glm::dvec3(points_[tri[0]]), glm::dvec3(points_[tri[1]]), glm::dvec3(points_[tri[2]]));
            if (c.distance2 < best2 || (result.triangle < 0 && c.distance2 <= best2)) {
                best2 = c.distance2;
                best = c;
                result.triangle = t;
            }
        });
    if (result.triangle >= 0) {
        result.point = glm::vec3(best.point);
        result.distance = static_cast<float>(std::sqrt(best.distance2));
        result.face = faceOfTriangle_[result.triangle];
        result.barycentric = glm::vec3(best.barycentric);
    }
    return result;
}

std::optional<Bvh::RayHit> Bvh::intersectRay(const glm::vec3& origin, const glm::vec3& direction, float tMin,
                                             float tMax) const {
    if (!geom::isFinite(origin) || !geom::isFinite(direction) || direction == glm::vec3(0.0f)) {
        throw InvalidInput(formatError("bvh", "ray",
                                       "has a NaN or infinite origin or a zero or non-finite direction",
                                       "a finite origin and a finite, non-zero direction"));
    }
    if (std::isnan(tMin) || std::isnan(tMax)) {
        throw InvalidInput(formatError("bvh", "ray", "tMin or tMax is NaN", "an interval [tMin, tMax]"));
    }
    if (nodes_.empty() || tMin > tMax) return std::nullopt;

    const glm::vec3 inverse = 1.0f / direction;
    const glm::dvec3 o(origin), d(direction);
    double bestT = tMax;
    int32_t bestTriangle = -1;
    TriangleHit best;
    auto limit = [&] { return static_cast<float>(bestT) * (1.0f + kBoxSlack) + kBoxSlack; };
    descend(
        rayBoxEntry(nodes_[0].box, origin, direction, inverse, tMin, tMax),
        [&](const Box3& box) { return rayBoxEntry(box, origin, direction, inverse, tMin, limit()); }, limit,
        [&](int32_t t) {
            const auto& tri = triangles_[t];
            TriangleHit hit;
            if (!intersectTriangle(o, d, glm::dvec3(points_[tri[0]]), glm::dvec3(points_[tri[1]]),
                                   glm::dvec3(points_[tri[2]]), hit)) {
                return;
            }
            if (hit.t >= tMin && (hit.t < bestT || (bestTriangle < 0 && hit.t <= bestT))) {
                bestT = hit.t;
                best = hit;
                bestTriangle = t;
            }
        });
    if (bestTriangle < 0) return std::nullopt;
    RayHit hit;
    hit.t = static_cast<float>(best.t);
    hit.point = glm::vec3(o + best.t * d);
    hit.triangle = bestTriangle;
    hit.face = faceOfTriangle_[bestTriangle];
    hit.barycentric = glm::vec3(1.0 - best.u - best.v, best.u, best.v);
    return hit;
}

}  // namespace deformkit::geom
