#pragma once

// The real models of the slide tests (tests/data/README.md: sources and licences), read once per test
// binary, and the length scale their tolerances are relative to.

#include <span>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/obj.h"

namespace deformkit::test {

// Keenan Crane's "Spot": quads, with creases, concave dimples and thin parts (ears, horns, legs).
inline const geom::Mesh& spot() {
    static const geom::Mesh mesh = io::readObj(DEFORMKIT_TEST_DATA "/spot/spot_quadrangulated.obj").mesh;
    return mesh;
}

// Keenan Crane's "Bob": a triangle mesh with thin parts (the beak, the tail) and slivers.
inline const geom::Mesh& bob() {
    static const geom::Mesh mesh = io::readObj(DEFORMKIT_TEST_DATA "/bob/bob_tri.obj").mesh;
    return mesh;
}

// Length of the bounding-box diagonal of `points`.
inline double diagonal(std::span<const glm::vec3> points) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::vec3& p : points) {
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    return glm::length(hi - lo);
}

}  // namespace deformkit::test
