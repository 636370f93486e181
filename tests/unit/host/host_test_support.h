#pragma once

// Helpers shared by the host layer's tests: a mesh's rest positions, one adapter run on its own, and
// comparisons of point lists.

#include <algorithm>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/host/deformers.h"

namespace deformkit::test {

inline std::vector<glm::vec3> restOf(const geom::Mesh& mesh) {
    return {mesh.points().begin(), mesh.points().end()};
}

// The adapter alone: bind when it needs it, evaluate from the rest positions.
inline std::vector<glm::vec3> runAlone(host::Deformer& d, const geom::Mesh& rest) {
    if (d.needsBind()) d.bind(rest);
    const std::vector<glm::vec3> in = restOf(rest);
    std::vector<glm::vec3> out(in.size());
    d.evaluate(in, out);
    return out;
}

inline float maxDistance(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    float e = 0.0f;
    for (size_t i = 0; i < a.size(); ++i)
        e = std::max(e, glm::length(a[i] - b[i]));
    return e;
}

// x, y, z of every point in turn: the form of a deformer's point-list parameters.
inline std::vector<double> flatten(const std::vector<glm::vec3>& points) {
    std::vector<double> out;
    for (const glm::vec3& p : points)
        out.insert(out.end(), {p.x, p.y, p.z});
    return out;
}

}  // namespace deformkit::test
