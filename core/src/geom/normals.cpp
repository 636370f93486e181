#include "deformkit/geom/normals.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "deformkit/error.h"

namespace deformkit::geom {
namespace {

// Faces whose Newell vector is this small relative to their squared edge lengths are float noise:
// collinear or coincident corners.
constexpr double kDegenerateRatio = 1e-7;

// Newell's vector of face f: the sum of cross products of consecutive corners taken from the first one.
// Its length is twice the area of a planar face. Returns zero for a degenerate face.
glm::dvec3 newellVector(std::span<const glm::vec3> points, std::span<const int32_t> corners) {
    const glm::dvec3 origin(points[corners[0]]);
    glm::dvec3 sum(0.0);
    double edgeLengths = 0.0;
    glm::dvec3 prev(0.0);
    const size_t n = corners.size();
    for (size_t k = 1; k <= n; ++k) {
        const glm::dvec3 cur = k < n ? glm::dvec3(points[corners[k]]) - origin : glm::dvec3(0.0);
        sum += glm::cross(prev, cur);
        const glm::dvec3 edge = cur - prev;
        edgeLengths += glm::dot(edge, edge);
        prev = cur;
    }
    if (!(glm::length(sum) > kDegenerateRatio * edgeLengths)) return glm::dvec3(0.0);
    return sum;
}

glm::vec3 unitOrZero(const glm::dvec3& v) {
    const double len = std::sqrt(glm::dot(v, v));
    return len > 0.0 ? glm::vec3(v / len) : glm::vec3(0.0f);
}

void requireSize(const char* what, size_t got, int32_t expected, const char* per) {
    if (got != static_cast<size_t>(expected)) {
        throw InvalidInput(formatError("normals", what, "output holds " + std::to_string(got) + " entries",
                                       std::to_string(expected) + ", one per " + per));
    }
}

}  // namespace

void computeFaceNormals(const Mesh& mesh, std::span<glm::vec3> out) {
    requireSize("face normals", out.size(), mesh.numFaces(), "face");
    const auto points = mesh.points();
    for (int32_t f = 0; f < mesh.numFaces(); ++f)
        out[f] = unitOrZero(newellVector(points, mesh.face(f)));
}

void computeVertexNormals(const Mesh& mesh, std::span<glm::vec3> out, const NormalOptions& options) {
    requireSize("vertex normals", out.size(), mesh.numVertices(), "vertex");
    std::fill(out.begin(), out.end(), glm::vec3(0.0f));
    const auto points = mesh.points();
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const auto corners = mesh.face(f);
        const glm::dvec3 newell = newellVector(points, corners);
        if (newell == glm::dvec3(0.0)) continue;
        if (options.weighting == NormalWeighting::Area) {
            for (const int32_t v : corners)
                out[v] += glm::vec3(newell);
            continue;
        }
        const glm::dvec3 unit = newell / glm::length(newell);
        const size_t n = corners.size();
        for (size_t k = 0; k < n; ++k) {
            const glm::dvec3 p(points[corners[k]]);
            const glm::dvec3 a = glm::dvec3(points[corners[(k + n - 1) % n]]) - p;
            const glm::dvec3 b = glm::dvec3(points[corners[(k + 1) % n]]) - p;
            const double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
            out[corners[k]] += glm::vec3(angle * unit);
        }
    }
    for (auto& n : out)
        n = unitOrZero(glm::dvec3(n));
}

std::vector<glm::vec3> vertexNormals(const Mesh& mesh, const NormalOptions& options) {
    std::vector<glm::vec3> out(mesh.numVertices());
    computeVertexNormals(mesh, out, options);
    return out;
}

}  // namespace deformkit::geom
