#pragma once

// Helpers shared by the host layer's tests: a mesh's rest positions, one adapter run on its own, and point
// lists as parameters (maxError of warp_test_support.h compares point lists).

#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/host/deformers.h"
#include "warp/warp_test_support.h"

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

// x, y, z of every point in turn: the form of a deformer's point-list parameters.
inline std::vector<double> flatten(const std::vector<glm::vec3>& points) {
    std::vector<double> out;
    for (const glm::vec3& p : points)
        out.insert(out.end(), {p.x, p.y, p.z});
    return out;
}

}  // namespace deformkit::test
