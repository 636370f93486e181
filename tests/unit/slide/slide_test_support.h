#pragma once

// Analytic test surfaces for the slide tests, built here rather than taken from geom/primitives so the
// closed forms the tests use (plane, cylinder, sphere) are visible beside the meshes.

#include <array>
#include <cmath>
#include <map>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/geom/bvh.h"
#include "deformkit/geom/mesh.h"

namespace deformkit::test {

// nx x ny quads spanning [0, (nx) h] x [0, (ny) h] at z = 0, vertex (i, j) = j (nx + 1) + i.
inline geom::Mesh planeGrid(int nx, int ny, float h, const glm::mat3& rotation = glm::mat3(1.0f),
                            const glm::vec3& offset = glm::vec3(0.0f)) {
    geom::Mesh::Data d;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
            d.points.push_back(rotation * glm::vec3(i * h, j * h, 0.0f) + offset);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const int a = j * (nx + 1) + i;
            d.faceCounts.push_back(4);
            d.faceIndices.insert(d.faceIndices.end(), {a, a + 1, a + nx + 2, a + nx + 1});
        }
    return geom::Mesh(std::move(d), "plane");
}

// Open cylinder about the z axis: `around` vertices per ring (vertex k at angle 2 pi k / around),
// rings at z = j * height / rows, quads facing outwards. Vertex (k, j) = j * around + k.
inline geom::Mesh cylinder(int around, int rows, float radius, float height) {
    geom::Mesh::Data d;
    for (int j = 0; j <= rows; ++j)
        for (int k = 0; k < around; ++k) {
            const double a = 2.0 * M_PI * k / around;
            d.points.emplace_back(radius * std::cos(a), radius * std::sin(a), height * j / rows);
        }
    for (int j = 0; j < rows; ++j)
        for (int k = 0; k < around; ++k) {
            const int k1 = (k + 1) % around;
            d.faceCounts.push_back(4);
            d.faceIndices.insert(d.faceIndices.end(), {j * around + k, j * around + k1, (j + 1) * around + k1,
                                                       (j + 1) * around + k});
        }
    return geom::Mesh(std::move(d), "cylinder");
}

// Icosphere of radius `radius`: an icosahedron subdivided `levels` times, vertices on the sphere.
inline geom::Mesh icosphere(int levels, float radius) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<glm::dvec3> p = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (auto& q : p)
        q = glm::normalize(q);
    std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                         {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                         {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                         {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<int, int>, int> mid;
        auto midpoint = [&](int a, int b) {
            const auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            p.push_back(glm::normalize(p[a] + p[b]));
            return mid[key] = static_cast<int>(p.size()) - 1;
        };
        std::vector<std::array<int, 3>> g;
        for (const auto& tri : f) {
            const int ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]),
                      ca = midpoint(tri[2], tri[0]);
            g.push_back({tri[0], ab, ca});
            g.push_back({tri[1], bc, ab});
            g.push_back({tri[2], ca, bc});
            g.push_back({ab, bc, ca});
        }
        f = std::move(g);
    }
    geom::Mesh::Data d;
    for (const auto& q : p)
        d.points.push_back(glm::vec3(q * static_cast<double>(radius)));
    for (const auto& tri : f) {
        d.faceCounts.push_back(3);
        d.faceIndices.insert(d.faceIndices.end(), tri.begin(), tri.end());
    }
    return geom::Mesh(std::move(d), "icosphere");
}

// Largest distance from `points` to the rest mesh's surface (one-sided Hausdorff distance), through the
// BVH's closest-point query: a structure independent of the slide's walk.
inline double distanceToSurface(const geom::Mesh& rest, const std::vector<glm::vec3>& points) {
    const geom::Bvh bvh(rest);
    double worst = 0.0;
    for (const glm::vec3& p : points)
        worst = std::max(worst, static_cast<double>(bvh.closestPoint(p).distance));
    return worst;
}

inline double smoothFalloff(double x) {
    return x >= 1.0 ? 0.0 : 1.0 - x * x * (3.0 - 2.0 * x);
}

}  // namespace deformkit::test
