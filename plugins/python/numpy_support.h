#pragma once

// numpy <-> DeformKit conversions shared by the bind_*.cpp files. Every bad shape raises
// deformkit::InvalidInput naming the function (`source`) and the argument.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"

namespace deformkit::python {

// Numbers from Python (a list, a numpy array of any float or integer type) as a C-contiguous float32 array:
// a view of a float32 C-contiguous array, otherwise numpy's cast. The conversion never fails when the
// argument is taken; `problem` says why the values are not float32 numbers ("is an array of bool values",
// "holds 1e+39 at flat index 4, beyond float32's range": numpy's cast would give 1 for True and inf for
// 1e39), and the helpers below (requireFloats), which name the argument, refuse them.
struct FloatArray : pybind11::array_t<float, pybind11::array::c_style | pybind11::array::forcecast> {
    using Base = pybind11::array_t<float, pybind11::array::c_style | pybind11::array::forcecast>;
    FloatArray() = default;
    explicit FloatArray(Base values) : Base(std::move(values)) {}
    std::string problem;
};
// Values read in double (a few parameters: a float32 copy would turn 4e38 into inf before it is checked), as
// FloatArray: `problem` says why they are not numbers (numpy's cast would read "0.1" as 0.1, True as 1 and
// drop an imaginary part), and requireDoubles refuses them.
struct DoubleArray : pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast> {
    using Base = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;
    DoubleArray() = default;
    explicit DoubleArray(Base values) : Base(std::move(values)) {}
    std::string problem;
};

// Whole numbers from Python (a list, a numpy array of any integer or float type) as int32, converted
// exactly: numpy's own cast would truncate 1.9 to 1 and wrap 2^32 + 2 to 2. The conversion never fails
// when the argument is taken; `problem` says why the values are not int32 whole numbers ("holds 1.9 at
// index 1"), and intsOf, which names the argument, refuses them.
struct IntArray {
    pybind11::array_t<int32_t, pybind11::array::c_style> values;
    std::string problem;

    [[nodiscard]] pybind11::ssize_t ndim() const { return values.ndim(); }
    [[nodiscard]] pybind11::ssize_t shape(pybind11::ssize_t i) const { return values.shape(i); }
    [[nodiscard]] const int32_t* data() const { return values.data(); }
    [[nodiscard]] operator const pybind11::array&() const { return values; }  // NOLINT: for shapeOf
};

// "(4, 3)" or "(7,)".
inline std::string shapeOf(const pybind11::array& a) {
    std::string s = "(";
    for (pybind11::ssize_t i = 0; i < a.ndim(); ++i)
        s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

// InvalidInput naming the argument when its values are not numbers (DoubleArray::problem).
inline void requireDoubles(const DoubleArray& a, const std::string& source, const std::string& name) {
    if (!a.problem.empty()) throw InvalidInput(formatError(source, name, a.problem, "numbers"));
}

// InvalidInput naming the argument when its values are not float32 numbers (FloatArray::problem).
inline void requireFloats(const FloatArray& a, const std::string& source, const std::string& name) {
    if (!a.problem.empty()) {
        throw InvalidInput(formatError(source, name, a.problem, "numbers within float32's range"));
    }
}

// How an in-memory mesh is named in messages: "(16 vertices, 9 faces)".
inline std::string meshLabel(const geom::Mesh& mesh) {
    return "(" + std::to_string(mesh.numVertices()) + " vertices, " + std::to_string(mesh.numFaces()) +
           " faces)";
}

// An (n, 3) array as positions (a copy the C++ side owns).
inline std::vector<glm::vec3> pointsOf(const FloatArray& a, const std::string& source,
                                       const std::string& name) {
    requireFloats(a, source, name);
    if (a.ndim() != 2 || a.shape(1) != 3) {
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a), "(n, 3) float32"));
    }
    std::vector<glm::vec3> out(static_cast<size_t>(a.shape(0)));
    if (!out.empty()) std::memcpy(out.data(), a.data(), out.size() * sizeof(glm::vec3));
    return out;
}

// The same (n, 3) float32 array as a view, no copy (FloatArray is C-contiguous float32: pybind11 converts
// anything else when the argument is taken). Valid while `a` lives.
inline std::span<const glm::vec3> pointsView(const FloatArray& a, const std::string& source,
                                             const std::string& name) {
    requireFloats(a, source, name);
    if (a.ndim() != 2 || a.shape(1) != 3) {
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a), "(n, 3) float32"));
    }
    return {reinterpret_cast<const glm::vec3*>(a.data()), static_cast<size_t>(a.shape(0))};
}

// InvalidInput naming the argument when its values are not int32 whole numbers.
inline void requireInts(const IntArray& a, const std::string& source, const std::string& name) {
    if (!a.problem.empty()) {
        throw InvalidInput(formatError(source, name, a.problem, "whole numbers from -2^31 to 2^31 - 1"));
    }
}

// A 1-D int array as indices or counts.
inline std::vector<int32_t> intsOf(const IntArray& a, const std::string& source, const std::string& name) {
    requireInts(a, source, name);
    if (a.ndim() != 1)
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a), "a 1-D int array"));
    return std::vector<int32_t>(a.data(), a.data() + a.shape(0));
}

// A mesh from arrays, as deformkit.Mesh takes them: points, face counts and face indices, and uvs with
// uv_indices both or neither (None). `prefix` names the arguments in messages ("cage_" gives
// cage_points, ...); `meshName` is the mesh's name in the core's own messages.
inline geom::Mesh meshOf(const FloatArray& points, const IntArray& counts, const IntArray& indices,
                         const std::optional<FloatArray>& uvs, const std::optional<IntArray>& uvIndices,
                         const std::string& source, const std::string& meshName,
                         const std::string& prefix = "") {
    geom::Mesh::Data d;
    d.points = pointsOf(points, source, prefix + "points");
    d.faceCounts = intsOf(counts, source, prefix + "face_counts");
    d.faceIndices = intsOf(indices, source, prefix + "face_indices");
    if (uvs.has_value() != uvIndices.has_value()) {
        throw InvalidInput(formatError(source, prefix + "uvs",
                                       "given without uv_indices or the other way round",
                                       "both uvs and uv_indices, or neither"));
    }
    if (uvs) {
        requireFloats(*uvs, source, prefix + "uvs");
        if (uvs->ndim() != 2 || uvs->shape(1) != 2)
            throw InvalidInput(
                formatError(source, prefix + "uvs", "has shape " + shapeOf(*uvs), "(k, 2) float32"));
        d.uvs.resize(static_cast<size_t>(uvs->shape(0)));
        if (!d.uvs.empty()) std::memcpy(d.uvs.data(), uvs->data(), d.uvs.size() * sizeof(glm::vec2));
        d.uvIndices = intsOf(*uvIndices, source, prefix + "uv_indices");
    }
    return geom::Mesh(std::move(d), meshName);
}

// Python's bool or numpy's (np.bool_, what comparisons of arrays give).
inline bool isBool(pybind11::handle value) {
    if (pybind11::isinstance<pybind11::bool_>(value)) return true;
    const pybind11::handle type = pybind11::type::of(value);
    return pybind11::str(type.attr("__module__")).cast<std::string>() == "numpy" &&
           pybind11::str(type.attr("__name__")).cast<std::string>() == "bool_";
}

// A real number from Python: an int or a float (not a bool), or a numpy integer or floating scalar.
inline bool isRealNumber(pybind11::handle value) {
    if (isBool(value)) return false;
    if (pybind11::isinstance<pybind11::float_>(value) || PyLong_Check(value.ptr())) return true;
    if (pybind11::isinstance<pybind11::str>(value) || !pybind11::hasattr(value, "dtype")) return false;
    const std::string kind = pybind11::str(value.attr("dtype").attr("kind"));
    return kind == "f" || kind == "i" || kind == "u";
}

// A whole number from Python: an int or numpy's integer scalars (not a bool); nullopt otherwise.
inline std::optional<int64_t> wholeNumber(pybind11::handle value) {
    if (isBool(value) || !PyIndex_Check(value.ptr())) return std::nullopt;
    try {
        return pybind11::int_(pybind11::reinterpret_borrow<pybind11::object>(value)).cast<int64_t>();
    } catch (const pybind11::error_already_set&) {
        return std::nullopt;
    } catch (const pybind11::cast_error&) {
        return std::nullopt;
    }
}

// The Python type of a value with its article ("a list", "an int"), for messages.
inline std::string aTypeName(pybind11::handle value) {
    const std::string name = pybind11::str(pybind11::type::of(value).attr("__name__"));
    const bool vowel =
        !name.empty() && std::string_view("aeiouAEIOU").find(name[0]) != std::string_view::npos;
    return (vowel ? "an " : "a ") + name;
}

// `value` as T, or InvalidInput naming the function (`source`) and the element when it is not one
// ("write_ptex: faces: is an int (expected a list of dicts)"), instead of pybind11's "Unable to cast".
template <class T>
T castArgument(pybind11::handle value, const std::string& source, const std::string& element,
               const std::string& expected) {
    try {
        return value.cast<T>();
    } catch (const pybind11::cast_error&) {
    } catch (const pybind11::error_already_set& e) {  // a Python type's constructor refused it
        if (!e.matches(PyExc_TypeError)) throw;
    }
    throw InvalidInput(formatError(source, element, "is " + aTypeName(value), expected));
}

// Painted weights: None (all 1, returned empty) or one value per point.
inline std::vector<float> weightsOf(const std::optional<FloatArray>& weights, size_t count,
                                    const std::string& source) {
    if (!weights) return {};
    requireFloats(*weights, source, "weights");
    if (weights->ndim() != 1 || static_cast<size_t>(weights->shape(0)) != count) {
        throw InvalidInput(formatError(source, "weights", "has shape " + shapeOf(*weights),
                                       "(" + std::to_string(count) + ",), one per point"));
    }
    return std::vector<float>(weights->data(), weights->data() + count);
}

// The same check, as a view of the array's data (valid while it lives); empty for None.
inline std::span<const float> weightsView(const std::optional<FloatArray>& weights, size_t count,
                                          const std::string& source) {
    if (!weights) return {};
    requireFloats(*weights, source, "weights");
    if (weights->ndim() != 1 || static_cast<size_t>(weights->shape(0)) != count) {
        throw InvalidInput(formatError(source, "weights", "has shape " + shapeOf(*weights),
                                       "(" + std::to_string(count) + ",), one per point"));
    }
    return {weights->data(), count};
}

// Where a deformer writes `count` points: a new (count, 3) float32 array when `out` is None, else the
// caller's array, which must be a writable C-contiguous (count, 3) float32 array (InvalidInput naming
// `source` and "out" otherwise): reusing it spares the allocation. Returns the array and its points.
inline std::pair<pybind11::array_t<float>, std::span<glm::vec3>> outputArray(const pybind11::object& out,
                                                                             size_t count,
                                                                             const std::string& source) {
    namespace py = pybind11;
    if (out.is_none()) {
        py::array_t<float> fresh({static_cast<py::ssize_t>(count), py::ssize_t{3}});
        return {fresh, {reinterpret_cast<glm::vec3*>(fresh.mutable_data()), count}};
    }
    const std::string expected =
        "None or a writable C-contiguous (" + std::to_string(count) + ", 3) float32 array";
    if (!py::isinstance<py::array_t<float, py::array::c_style>>(out)) {
        throw InvalidInput(formatError(source, "out", "is not a C-contiguous float32 array", expected));
    }
    auto a = py::reinterpret_borrow<py::array_t<float, py::array::c_style>>(out);
    if (a.ndim() != 2 || a.shape(1) != 3 || static_cast<size_t>(a.shape(0)) != count || !a.writeable()) {
        throw InvalidInput(formatError(
            source, "out", "has shape " + shapeOf(a) + (a.writeable() ? "" : ", read-only"), expected));
    }
    return {a, {reinterpret_cast<glm::vec3*>(a.mutable_data()), count}};
}

// A deformer's output `out` must be its input `in` (in place) or lie apart from it: an output that overlaps
// its input elsewhere would be read after it is written.
inline void requireSameOrApart(std::span<const glm::vec3> in, std::span<const glm::vec3> out,
                               const std::string& source) {
    if (in.empty() || out.empty() || in.data() == out.data()) return;
    const auto* inBegin = reinterpret_cast<const char*>(in.data());
    const auto* outBegin = reinterpret_cast<const char*>(out.data());
    const bool apart = outBegin >= inBegin + in.size_bytes() || inBegin >= outBegin + out.size_bytes();
    if (!apart) {
        throw InvalidInput(formatError(source, "out", "overlaps points without being the same array",
                                       "points itself (in place) or an array apart from it"));
    }
}

// An (H, W) or (H, W, C) array as an image (a copy); `expected` says which shapes the caller takes.
// InvalidInput naming the argument when a side (or the channel count) of an image array is beyond what an
// image holds (2^31 - 1): it would be cut to its low 32 bits, and the image cropped without a word.
inline void requireImageSides(const pybind11::array& a, const std::string& source, const std::string& name) {
    for (pybind11::ssize_t i = 0; i < a.ndim(); ++i) {
        if (a.shape(i) > std::numeric_limits<int32_t>::max()) {
            throw InvalidInput(
                formatError(source, name, "has shape " + shapeOf(a), "at most 2147483647 along each axis"));
        }
    }
}

inline io::Image imageOf(const FloatArray& a, const std::string& source, const std::string& name,
                         const std::string& expected = "(H, W) or (H, W, C) float32") {
    requireFloats(a, source, name);
    if (a.ndim() != 2 && a.ndim() != 3)
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a), expected));
    if (a.size() == 0)
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a) + " with 0 pixels", expected));
    requireImageSides(a, source, name);
    const int32_t channels = a.ndim() == 3 ? static_cast<int32_t>(a.shape(2)) : 1;
    io::Image image(static_cast<int32_t>(a.shape(1)), static_cast<int32_t>(a.shape(0)), channels);
    std::memcpy(image.pixels.data(), a.data(), image.pixels.size() * sizeof(float));
    return image;
}

// An image's pixels moved into a numpy array without a copy: (H, W, C), or (H, W) when `flat`.
inline pybind11::array imageArray(io::Image&& image, bool flat = false) {
    auto* pixels = new std::vector<float>(std::move(image.pixels));
    pybind11::capsule owner(pixels, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    if (flat) return pybind11::array_t<float>({image.height, image.width}, pixels->data(), owner);
    return pybind11::array_t<float>({image.height, image.width, image.channels}, pixels->data(), owner);
}

// Positions as a new (n, 3) float32 array.
inline pybind11::array_t<float> toArray(std::span<const glm::vec3> points) {
    pybind11::array_t<float> out({static_cast<pybind11::ssize_t>(points.size()), pybind11::ssize_t{3}});
    if (!points.empty()) std::memcpy(out.mutable_data(), points.data(), points.size() * sizeof(glm::vec3));
    return out;
}

// For the array casters below: the numpy array of `src` in `a`, and in `problem` why its values are not
// numbers (an array of bool, strings, objects or complex numbers, or a list of such); empty when they are.
// False when numpy reads no array from it (None, a str or bytes: another overload may take them).
inline bool numericArray(pybind11::handle src, pybind11::array& a, std::string& problem) {
    namespace py = pybind11;
    if (src.is_none() || py::isinstance<py::str>(src) || py::isinstance<py::bytes>(src)) return false;
    a = py::isinstance<py::array>(src) ? py::reinterpret_borrow<py::array>(src) : py::array::ensure(src);
    if (!a) return false;
    const char kind = a.dtype().kind();
    problem.clear();
    if (kind != 'f' && kind != 'i' && kind != 'u') {
        problem = py::isinstance<py::array>(src)
                      ? "is an array of " + std::string(py::str(a.dtype())) + " values"
                      : "is " + aTypeName(src) + " that is not numeric";
    }
    return true;
}

}  // namespace deformkit::python

namespace pybind11::detail {

// Takes what numpy reads as an array of numbers; None is no FloatArray (an optional one is then absent), nor
// is a str or bytes (another overload may take a path). Arrays of bool, strings, objects or complex numbers,
// and float64 values beyond float32's range, are taken with FloatArray::problem set.
template <>
struct type_caster<deformkit::python::FloatArray> {
    PYBIND11_TYPE_CASTER(deformkit::python::FloatArray, const_name("numpy.ndarray[float32]"));

    bool load(handle src, bool convert) {
        using Base = deformkit::python::FloatArray::Base;
        if (!convert && !Base::check_(src)) return false;
        value = deformkit::python::FloatArray();
        array a;
        std::string problem;
        if (!deformkit::python::numericArray(src, a, problem)) return false;
        const char kind = a.dtype().kind();
        if (!problem.empty()) {
            // numpy's cast of bools and strings, for a caller that reads the values without requireFloats
            // (not of complex numbers, whose cast warns).
            if (kind == 'b' || kind == 'U' || kind == 'S') {
                if (Base cast = Base::ensure(a)) value = deformkit::python::FloatArray(std::move(cast));
                PyErr_Clear();
            }
            value.problem = problem;
            return true;
        }
        Base values = Base::ensure(a);
        if (!values) return false;
        if (kind == 'f' && a.itemsize() > 4) {
            // numpy's cast gives inf for a finite value beyond float32's range: find the first such one.
            const ssize_t n = values.size();
            const float* v = values.data();
            std::optional<array_t<double, array::c_style | array::forcecast>> wide;  // once an inf is found
            for (ssize_t i = 0; i < n; ++i) {
                if (!std::isinf(v[i])) continue;
                if (!wide) wide = array_t<double, array::c_style | array::forcecast>::ensure(a);
                if (!*wide || !std::isfinite(wide->data()[i])) continue;
                value = deformkit::python::FloatArray(std::move(values));
                value.problem = "holds " + deformkit::numberText(wide->data()[i]) +
                                (a.ndim() == 1 ? " at index " : " at flat index ") + std::to_string(i) +
                                ", beyond float32's range";
                return true;
            }
        }
        value = deformkit::python::FloatArray(std::move(values));
        return true;
    }

    static handle cast(const deformkit::python::FloatArray& src, return_value_policy, handle) {
        return src.inc_ref();
    }
};

// As FloatArray's caster, in double: arrays of bool, strings, objects or complex numbers are taken with
// DoubleArray::problem set.
template <>
struct type_caster<deformkit::python::DoubleArray> {
    PYBIND11_TYPE_CASTER(deformkit::python::DoubleArray, const_name("numpy.ndarray[float64]"));

    bool load(handle src, bool convert) {
        using Base = deformkit::python::DoubleArray::Base;
        if (!convert && !Base::check_(src)) return false;
        value = deformkit::python::DoubleArray();
        array a;
        if (!deformkit::python::numericArray(src, a, value.problem)) return false;
        if (!value.problem.empty()) return true;
        Base values = Base::ensure(a);
        if (!values) return false;
        value = deformkit::python::DoubleArray(std::move(values));
        return true;
    }

    static handle cast(const deformkit::python::DoubleArray& src, return_value_policy, handle) {
        return src.inc_ref();
    }
};

// Takes anything numpy reads as an array (None is no IntArray: an optional one is then absent).
template <>
struct type_caster<deformkit::python::IntArray> {
    PYBIND11_TYPE_CASTER(deformkit::python::IntArray, const_name("numpy.ndarray[int32]"));

    bool load(handle src, bool) {
        if (src.is_none()) return false;
        array a = array::ensure(src);
        if (!a) return false;
        value.problem.clear();
        const char kind = a.dtype().kind();
        if (kind == 'i' && a.itemsize() == 4) {  // int32 already: a view, or one contiguous copy
            value.values = array_t<int32_t, array::c_style | array::forcecast>::ensure(a);
            return static_cast<bool>(value.values);
        }
        std::vector<ssize_t> shape(a.shape(), a.shape() + a.ndim());
        value.values = array_t<int32_t, array::c_style>(shape);
        int32_t* out = value.values.mutable_data();
        const ssize_t n = a.size();
        const auto fail = [&](const std::string& what, ssize_t i) {
            value.problem = what + (a.ndim() == 1 ? " at index " + std::to_string(i)
                                                  : " at flat index " + std::to_string(i));
        };
        if (kind == 'i' || kind == 'u') {
            if (kind == 'u' && a.itemsize() == 8) {
                const auto u = array_t<uint64_t, array::c_style | array::forcecast>::ensure(a);
                for (ssize_t i = 0; i < n; ++i) {
                    if (u.data()[i] > static_cast<uint64_t>(INT32_MAX)) {
                        fail("holds " + std::to_string(u.data()[i]), i);
                        return true;
                    }
                    out[i] = static_cast<int32_t>(u.data()[i]);
                }
                return true;
            }
            const auto v = array_t<int64_t, array::c_style | array::forcecast>::ensure(a);
            for (ssize_t i = 0; i < n; ++i) {
                const int64_t x = v.data()[i];
                if (x < INT32_MIN || x > INT32_MAX) {
                    fail("holds " + std::to_string(x), i);
                    return true;
                }
                out[i] = static_cast<int32_t>(x);
            }
            return true;
        }
        if (kind == 'f') {
            const auto v = array_t<double, array::c_style | array::forcecast>::ensure(a);
            for (ssize_t i = 0; i < n; ++i) {
                const double x = v.data()[i];
                if (!(x >= INT32_MIN && x <= INT32_MAX) || x != std::floor(x)) {
                    fail("holds " + deformkit::numberText(x), i);
                    return true;
                }
                out[i] = static_cast<int32_t>(x);
            }
            return true;
        }
        value.problem = "is an array of " + std::string(str(a.dtype())) + " values";
        return true;
    }

    static handle cast(const deformkit::python::IntArray& src, return_value_policy, handle) {
        return src.values.inc_ref();
    }
};

}  // namespace pybind11::detail

namespace deformkit::python {

// The argument conversion (FloatArray's caster) for a value taken from a container or a callback (a dict's
// map, a function's result): nullopt, the Python error cleared, when numpy cannot read it as an array of
// numbers; otherwise the array, with `problem` set as for an argument (requireFloats).
inline std::optional<FloatArray> floatArrayOf(pybind11::handle value) {
    pybind11::detail::make_caster<FloatArray> caster;
    if (!caster.load(value, true)) {
        PyErr_Clear();
        return std::nullopt;
    }
    return pybind11::detail::cast_op<FloatArray&&>(std::move(caster));
}

}  // namespace deformkit::python
