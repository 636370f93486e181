#pragma once

// Conversions between the host layer's parameter values (doubles, vectors flattened x, y, z) and the core's
// float32 types, for the built-in deformers.

#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace deformkit::host::detail {

inline glm::vec3 vec3At(std::span<const double> v, size_t first = 0) {
    return {static_cast<float>(v[first]), static_cast<float>(v[first + 1]), static_cast<float>(v[first + 2])};
}

inline glm::dvec3 dvec3At(std::span<const double> v, size_t first = 0) {
    return {v[first], v[first + 1], v[first + 2]};
}

inline std::vector<double> flatten(std::span<const glm::vec3> points) {
    std::vector<double> out;
    out.reserve(points.size() * 3);
    for (const glm::vec3& p : points)
        out.insert(out.end(), {p.x, p.y, p.z});
    return out;
}

// Points from 3k values into `out` (reused: no allocation once it has grown).
inline void unflatten(std::span<const double> v, std::vector<glm::vec3>& out) {
    out.resize(v.size() / 3);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = vec3At(v, 3 * i);
}

}  // namespace deformkit::host::detail
