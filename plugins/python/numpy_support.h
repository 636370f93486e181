#pragma once

// numpy <-> DeformKit conversions shared by the bind_*.cpp files. Every bad shape raises
// deformkit::InvalidInput naming the function (`source`) and the argument.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/error.h"

namespace deformkit::python {

using FloatArray = pybind11::array_t<float, pybind11::array::c_style | pybind11::array::forcecast>;
using IntArray = pybind11::array_t<int32_t, pybind11::array::c_style | pybind11::array::forcecast>;

// "(4, 3)" or "(7,)".
inline std::string shapeOf(const pybind11::array& a) {
    std::string s = "(";
    for (pybind11::ssize_t i = 0; i < a.ndim(); ++i)
        s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

// An (n, 3) array as positions (a copy the C++ side owns).
inline std::vector<glm::vec3> pointsOf(const FloatArray& a, const std::string& source,
                                       const std::string& name) {
    if (a.ndim() != 2 || a.shape(1) != 3) {
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a), "(n, 3) float32"));
    }
    std::vector<glm::vec3> out(static_cast<size_t>(a.shape(0)));
    if (!out.empty()) std::memcpy(out.data(), a.data(), out.size() * sizeof(glm::vec3));
    return out;
}

// Painted weights: None (all 1, returned empty) or one value per point.
inline std::vector<float> weightsOf(const std::optional<FloatArray>& weights, size_t count,
                                    const std::string& source) {
    if (!weights) return {};
    if (weights->ndim() != 1 || static_cast<size_t>(weights->shape(0)) != count) {
        throw InvalidInput(formatError(source, "weights", "has shape " + shapeOf(*weights),
                                       "(" + std::to_string(count) + ",), one per point"));
    }
    return std::vector<float>(weights->data(), weights->data() + count);
}

// Positions as a new (n, 3) float32 array.
inline pybind11::array_t<float> toArray(std::span<const glm::vec3> points) {
    pybind11::array_t<float> out({static_cast<pybind11::ssize_t>(points.size()), pybind11::ssize_t{3}});
    if (!points.empty()) std::memcpy(out.mutable_data(), points.data(), points.size() * sizeof(glm::vec3));
    return out;
}

}  // namespace deformkit::python
