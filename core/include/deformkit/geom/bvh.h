#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/box.h"
#include "deformkit/geom/mesh.h"

namespace deformkit::geom {

// A bounding-volume hierarchy over triangles for closest-point and ray queries. Queries are const and
// thread-safe. Built once per topology; refit() updates the boxes after the points move (a deformer's
// evaluation) without rebuilding the tree.
class Bvh {
  public:
    // Triangulates the mesh (fan per face); results report the source face.
    explicit Bvh(const Mesh& mesh);
    // points: #V positions; triangles: #T vertex index triples. Face ids are the triangle indices.
    Bvh(std::span<const glm::vec3> points, std::span<const std::array<int32_t, 3>> triangles);

    // Positions changed, topology did not: recompute boxes bottom-up. Throws InvalidInput on a count
    // mismatch.
    void refit(std::span<const glm::vec3> points);

    struct ClosestPoint {
        glm::vec3 point{0.0f};  // closest point on the surface
        float distance = std::numeric_limits<float>::infinity();
        int32_t triangle = -1;        // -1 when nothing lies within maxDistance
        int32_t face = -1;            // source face of the triangle
        glm::vec3 barycentric{0.0f};  // of `point` in the triangle's three vertices
    };
    [[nodiscard]] ClosestPoint closestPoint(const glm::vec3& query,
                                            float maxDistance = std::numeric_limits<float>::infinity()) const;

    struct RayHit {
        float t = 0.0f;  // origin + t * direction
        glm::vec3 point{0.0f};
        int32_t triangle = -1;
        int32_t face = -1;
        glm::vec3 barycentric{0.0f};
    };
    // Nearest hit with t in [tMin, tMax]; both sides of a triangle hit. `direction` need not be unit length.
    [[nodiscard]] std::optional<RayHit> intersectRay(
        const glm::vec3& origin, const glm::vec3& direction, float tMin = 0.0f,
        float tMax = std::numeric_limits<float>::infinity()) const;

    [[nodiscard]] int32_t numTriangles() const { return static_cast<int32_t>(triangles_.size()); }
    [[nodiscard]] Box3 bounds() const;

  private:
    struct Node {
        Box3 box;
        int32_t first =
            0;  // leaf: first index into order_; inner: index of the left child (right = left + 1)
        int32_t count = 0;  // leaf: triangle count; inner: 0
    };
    void build();
    // The descent both queries share (bvh.cpp): nodes in order of key(box), the nearer child first; a node
    // whose key is not <= limit() is pruned; visit(triangle) for each triangle of a reached leaf.
    template <class Key, class Limit, class Visit>
    void descend(float rootKey, const Key& key, const Limit& limit, const Visit& visit) const;

    std::vector<glm::vec3> points_;
    std::vector<std::array<int32_t, 3>> triangles_;
    std::vector<int32_t> faceOfTriangle_;
    std::vector<int32_t> order_;  // triangle indices, grouped by leaf
    std::vector<Node> nodes_;
};

}  // namespace deformkit::geom
