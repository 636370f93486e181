// deformkit.warp_engine: the framework's Eq. (3) on dense per-point fields, for studio prototypes.
#include <cmath>
#include <string>

#include <pybind11/numpy.h>

#include "bindings.h"
#include "deformkit/error.h"
#include "deformkit/warp/engine.h"
#include "numpy_support.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

void requireShape(const FloatArray& a, const char* name, std::initializer_list<py::ssize_t> shape) {
    bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
    size_t k = 0;
    std::string want = "(";
    for (py::ssize_t s : shape) {
        want += (k ? ", " : "") + std::to_string(s);
        if (ok && a.shape(k) != s) ok = false;
        ++k;
    }
    if (!ok) {
        std::string got = "(";
        for (py::ssize_t i = 0; i < a.ndim(); ++i)
            got += (i ? ", " : "") + std::to_string(a.shape(i));
        throw InvalidInput(formatError("warp_engine", name, "has shape " + got + ")", want + ")"));
    }
}

// Every entry of `a` finite, or InvalidInput naming the first by its index ("transforms[1, 2, 3]").
void requireFinite(const FloatArray& a, const char* name) {
    const float* data = a.data();
    const auto count = static_cast<size_t>(a.size());
    for (size_t e = 0; e < count; ++e) {
        if (std::isfinite(data[e])) continue;
        std::string index;
        size_t rest = e;
        for (py::ssize_t d = a.ndim() - 1; d >= 0; --d) {
            index =
                std::to_string(rest % static_cast<size_t>(a.shape(d))) + (index.empty() ? "" : ", ") + index;
            rest /= static_cast<size_t>(a.shape(d));
        }
        throw InvalidInput(formatError("warp_engine", std::string(name) + "[" + index + "]",
                                       "is " + numberText(data[e]), "finite numbers"));
    }
}

}  // namespace

void bindWarpEngine(py::module_& m) {
    m.def(
        "warp_engine",
        [](const FloatArray& points, const FloatArray& transforms, const FloatArray& strengths,
           const FloatArray& weights) {
            if (points.ndim() != 2 || transforms.ndim() != 3) {
                throw InvalidInput(formatError("warp_engine", "points/transforms", "have the wrong rank",
                                               "points (N, 3) and transforms (n, 3, 4)"));
            }
            const py::ssize_t n = points.shape(0), k = transforms.shape(0);
            requireShape(points, "points", {n, 3});
            requireShape(transforms, "transforms", {k, 3, 4});
            requireShape(strengths, "strengths", {n, k});
            requireShape(weights, "weights", {n, k});
            // Eq. (3) turns a non-finite entry into NaN output, or a NaN weight into no weight at all.
            requireFinite(points, "points");
            requireFinite(transforms, "transforms");
            requireFinite(strengths, "strengths");
            requireFinite(weights, "weights");
            warp::Transformations t;
            for (py::ssize_t i = 0; i < k; ++i) {
                warp::Affine a;
                for (int r = 0; r < 3; ++r) {
                    for (int c = 0; c < 3; ++c)
                        a.linear[c][r] = transforms.at(i, r, c);
                    a.translation[r] = transforms.at(i, r, 3);
                }
                t.affine.push_back(a);
            }
            // Dense (N, n) fields become sparse: only non-zero weights are kept.
            warp::SparseFields fields;
            for (py::ssize_t u = 0; u < n; ++u) {
                for (py::ssize_t i = 0; i < k; ++i) {
                    if (weights.at(u, i) != 0.0f) {
                        fields.add(static_cast<int32_t>(i), strengths.at(u, i), weights.at(u, i));
                    }
                }
                fields.endPoint();
            }
            py::array_t<float> out({n, py::ssize_t{3}});
            const std::span<const glm::vec3> in(reinterpret_cast<const glm::vec3*>(points.data()), n);
            const std::span<glm::vec3> result(reinterpret_cast<glm::vec3*>(out.mutable_data()), n);
            {
                py::gil_scoped_release release;
                warp::evaluateWarp(in, fields, t, result);
            }
            return out;
        },
        py::arg("points"), py::arg("transforms"), py::arg("strengths"), py::arg("weights"),
        "Eq. (3) of the warp framework: points (N, 3), transforms (n, 3, 4) affine maps, strengths and\n"
        "weights (N, n), all finite; displacement method, normalised weights, all-zero weights leave a\n"
        "point.");
}

}  // namespace deformkit::python
