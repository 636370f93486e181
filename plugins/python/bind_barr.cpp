// Python bindings of Barr's taper, twist and bend (core/include/deformkit/warp/barr.h): one-off functions
// taper/twist/bend and Taper/Twist/Bend classes that bind once and evaluate many times, plus the host
// parameter conversions (barr_dcc.h). numpy float32 in and out.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_dcc.h"
#include "numpy_support.h"
#include "object_lock.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

using warp::AxialWarp;
using warp::AxisFrame;
using warp::ProfileCurve;

glm::vec3 vec3Of(const FloatArray& a, const char* source, const char* name) {
    requireFloats(a, source, name);
    if (a.ndim() != 1 || a.shape(0) != 3) {
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a), "3 numbers"));
    }
    return {a.data()[0], a.data()[1], a.data()[2]};
}

std::vector<float> floatsOf(const FloatArray& a, const char* source, const char* name) {
    requireFloats(a, source, name);
    if (a.ndim() != 1)
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a), "a 1-D array"));
    return std::vector<float>(a.data(), a.data() + a.shape(0));
}

ProfileCurve profileOf(const FloatArray& z, const FloatArray& v, const char* source) {
    return ProfileCurve(floatsOf(z, source, "z_samples"), floatsOf(v, source, "value_samples"), source);
}

// Deforms `points` with a bound warp into a new (n, 3) float32 array: the input is read in place and the
// warp writes the output directly (no other copy).
py::array_t<float> run(AxialWarp& warp, std::mutex* mutex, const FloatArray& points,
                       const std::optional<FloatArray>& weights, float envelope, const char* source,
                       const py::object& outArg = py::none()) {
    const std::span<const glm::vec3> in = pointsView(points, source, "points");
    std::span<const float> w;
    if (weights) {
        requireFloats(*weights, source, "weights");
        if (weights->ndim() != 1) {
            throw InvalidInput(
                formatError(source, "weights", "has shape " + shapeOf(*weights), "a 1-D array"));
        }
        w = {weights->data(), static_cast<size_t>(weights->shape(0))};
        if (w.size() != in.size()) {
            throw InvalidInput(formatError(source, "weights", "has " + std::to_string(w.size()) + " entries",
                                           std::to_string(in.size()) + " entries, one per point"));
        }
    }
    auto [out, pts] = outputArray(outArg, in.size(), source);
    {
        py::gil_scoped_release release;
        std::unique_lock<std::mutex> lock;
        if (mutex) lock = std::unique_lock<std::mutex>(*mutex);
        requireSameOrApart(in, pts, source);
        if (pts.data() == in.data()) {
            warp.deform(pts, w, envelope);  // out is the input: in place
        } else {
            warp.deform(in, pts, w, envelope);
        }
    }
    return out;
}

// The direct path's bind (no engine fields), reading the rest points in place (at construction: no other
// thread has the object yet).
template <class W>
void bindRest(W& warp, const FloatArray& rest, const char* source, const char* argument = "rest_points") {
    const std::span<const glm::vec3> pts = pointsView(rest, source, argument);
    py::gil_scoped_release release;
    warp.bind(pts);
}

py::dict frameDict(const AxisFrame& f) {
    py::dict d;
    d["axis_origin"] = std::vector<float>{f.origin.x, f.origin.y, f.origin.z};
    d["axis_dir"] = std::vector<float>{f.axis.x, f.axis.y, f.axis.z};
    d["up_dir"] = std::vector<float>{f.up.x, f.up.y, f.up.z};
    return d;
}

// Keyword arguments of bend() for a bend set up from a host's parameters.
py::dict bendDict(const warp::BendSetup& s) {
    py::dict d = frameDict(s.frame);
    d["rate"] = s.params.rate;
    d["centre"] = s.params.centre;
    d["lo"] = s.params.lo;
    d["hi"] = s.params.hi;
    return d;
}

}  // namespace

// The one-off function of a profile-driven axial warp (taper, twist): bind to `points`, deform a copy.
template <class W>
void defineProfileWarpFunction(py::module_& m, const char* name, const char* doc) {
    using namespace pybind11::literals;
    m.def(
        name,
        [name](const FloatArray& points, const FloatArray& origin, const FloatArray& axis,
               const FloatArray& z, const FloatArray& v, const std::optional<FloatArray>& weights,
               float envelope) {
            W w({vec3Of(origin, name, "axis_origin"), vec3Of(axis, name, "axis_dir")}, profileOf(z, v, name));
            bindRest(w, points, name, "points");  // the one-off's own argument
            return run(w, nullptr, points, weights, envelope, name);
        },
        "points"_a, "axis_origin"_a, "axis_dir"_a, "z_samples"_a, "value_samples"_a, "weights"_a = py::none(),
        "envelope"_a = 1.0f, doc);
}

// The bind/evaluate class of a profile-driven axial warp (Taper, Twist): constructed bound to rest points.
template <class W>
void bindProfileWarpClass(py::module_& m, const char* name, const char* doc) {
    using namespace pybind11::literals;
    py::class_<Locked<W>>(m, name, doc)
        .def(py::init([name](const FloatArray& rest, const FloatArray& origin, const FloatArray& axis,
                             const FloatArray& z, const FloatArray& v) {
                 auto w = std::make_unique<Locked<W>>(
                     AxisFrame{vec3Of(origin, name, "axis_origin"), vec3Of(axis, name, "axis_dir")},
                     profileOf(z, v, name));
                 bindRest(w->object, rest, name);
                 return w;
             }),
             "rest_points"_a, "axis_origin"_a, "axis_dir"_a, "z_samples"_a, "value_samples"_a)
        .def(
            "set_profile",
            [name](Locked<W>& w, const FloatArray& z, const FloatArray& v) {
                ProfileCurve profile = profileOf(z, v, name);
                const Lock lock(w.mutex);
                w.object.setProfile(std::move(profile));
            },
            "z_samples"_a, "value_samples"_a)
        .def(
            "evaluate",
            [name](Locked<W>& w, const FloatArray& points, const std::optional<FloatArray>& weights,
                   float envelope, const py::object& out) {
                return run(w.object, &w.mutex, points, weights, envelope, name, out);
            },
            "points"_a, "weights"_a = py::none(), "envelope"_a = 1.0f, "out"_a = py::none(),
            "Deform points (N, 3) into a new array, or into out: a writable (N, 3) float32 array reused from "
            "call to call (no allocation; it may be points itself).");
}

void bindBarr(py::module_& m) {
    using namespace pybind11::literals;

    defineProfileWarpFunction<warp::TaperWarp>(
        m, "taper",
        "Barr taper (paper §4.3.1): the two coordinates across the axis scaled by f(z), f given by samples\n"
        "(z ascending, monotone cubic, held outside). points (n, 3) float32; returns a new (n, 3) array.\n"
        "weights: (n,) painted weights or None for 1; envelope scales the whole effect.");
    defineProfileWarpFunction<warp::TwistWarp>(
        m, "twist",
        "Barr twist: rotation by theta(z) radians about the axis (right-handed), theta given by samples.\n"
        "weights: (n,) painted weights or None for 1; envelope scales the whole effect.");

    m.def(
        "bend",
        [](const FloatArray& points, const FloatArray& origin, const FloatArray& axis, const FloatArray& up,
           float rate, float centre, float lo, float hi, const std::optional<FloatArray>& weights,
           float envelope) {
            warp::BendWarp w({vec3Of(origin, "bend", "axis_origin"), vec3Of(axis, "bend", "axis_dir"),
                              vec3Of(up, "bend", "up_dir")},
                             {rate, centre, lo, hi});
            bindRest(w, points, "bend", "points");  // the one-off's own argument
            return run(w, nullptr, points, weights, envelope, "bend");
        },
        "points"_a, "axis_origin"_a, "axis_dir"_a, "up_dir"_a, "rate"_a, "centre"_a, "lo"_a, "hi"_a,
        "weights"_a = py::none(), "envelope"_a = 1.0f,
        "Barr's bend: rate k radians per unit towards up_dir, fixed at axis coordinate centre, bent on\n"
        "[lo, hi] onto an arc of radius 1/k and continued straight outside. "
        "weights: (n,) painted weights or None for 1; envelope scales the whole effect.");

    bindProfileWarpClass<warp::TaperWarp>(m, "Taper",
                                          "Barr taper bound to rest points; set_profile, then evaluate.");
    bindProfileWarpClass<warp::TwistWarp>(m, "Twist",
                                          "Barr twist bound to rest points; set_profile, then evaluate.");

    py::class_<Locked<warp::BendWarp>>(m, "Bend",
                                       "Barr bend bound to rest points; set_params, then evaluate.")
        .def(py::init([](const FloatArray& rest, const FloatArray& origin, const FloatArray& axis,
                         const FloatArray& up, float rate, float centre, float lo, float hi) {
                 auto w = std::make_unique<Locked<warp::BendWarp>>(
                     AxisFrame{vec3Of(origin, "Bend", "axis_origin"), vec3Of(axis, "Bend", "axis_dir"),
                               vec3Of(up, "Bend", "up_dir")},
                     warp::BendParams{rate, centre, lo, hi});
                 bindRest(w->object, rest, "Bend");
                 return w;
             }),
             "rest_points"_a, "axis_origin"_a, "axis_dir"_a, "up_dir"_a, "rate"_a, "centre"_a, "lo"_a, "hi"_a)
        .def(
            "set_params",
            [](Locked<warp::BendWarp>& w, float rate, float centre, float lo, float hi) {
                const Lock lock(w.mutex);
                w.object.setParams({rate, centre, lo, hi});
            },
            "rate"_a, "centre"_a, "lo"_a, "hi"_a)
        .def(
            "evaluate",
            [](Locked<warp::BendWarp>& w, const FloatArray& points, const std::optional<FloatArray>& weights,
               float envelope, const py::object& out) {
                return run(w.object, &w.mutex, points, weights, envelope, "Bend", out);
            },
            "points"_a, "weights"_a = py::none(), "envelope"_a = 1.0f, "out"_a = py::none(),
            "Deform points (N, 3) into a new array, or into out: a writable (N, 3) float32 array reused from "
            "call to call (no allocation; it may be points itself).");

    m.def(
        "maya_bend_params",
        [](const FloatArray& handleOrigin, const FloatArray& handleX, const FloatArray& handleY,
           double curvature, double lowBound, double highBound) {
            warp::MayaBend maya{vec3Of(handleOrigin, "Maya bend", "handle_origin"),
                                vec3Of(handleX, "Maya bend", "handle_x"),
                                vec3Of(handleY, "Maya bend", "handle_y"),
                                curvature,
                                lowBound,
                                highBound};
            return bendDict(warp::fromMayaBend(maya));
        },
        "handle_origin"_a, "handle_x"_a, "handle_y"_a, "curvature"_a, "low_bound"_a = -1.0,
        "high_bound"_a = 1.0,
        "Maya deformBend -> keyword arguments of bend() (curvature in radians; handle axes in world).");

    m.def(
        "blender_simple_deform_params",
        [](const std::string& mode, const FloatArray& points, double angle, double factor,
           const std::string& axis, std::pair<double, double> limits, const std::optional<FloatArray>& origin,
           const std::optional<FloatArray>& basis) {
            warp::BlenderSimpleDeform b;
            if (origin) b.origin = vec3Of(*origin, "Blender SimpleDeform", "origin");
            if (basis) {
                requireFloats(*basis, "Blender SimpleDeform", "basis");
                if (basis->ndim() != 2 || basis->shape(0) != 3 || basis->shape(1) != 3) {
                    throw InvalidInput(formatError("Blender SimpleDeform", "basis",
                                                   "has shape " + shapeOf(*basis),
                                                   "(3, 3), rows = the origin space's x, y, z axes"));
                }
                for (int r = 0; r < 3; ++r)
                    b.basis[r] = glm::vec3(basis->at(r, 0), basis->at(r, 1), basis->at(r, 2));
            }
            if (axis == "X")
                b.deformAxis = warp::BlenderAxis::X;
            else if (axis == "Y")
                b.deformAxis = warp::BlenderAxis::Y;
            else if (axis == "Z")
                b.deformAxis = warp::BlenderAxis::Z;
            else
                throw InvalidInput(
                    formatError("Blender SimpleDeform", "deform_axis", "is '" + axis + "'", "X, Y or Z"));
            b.angle = angle;
            b.factor = factor;
            b.lowerLimit = limits.first;
            b.upperLimit = limits.second;
            const std::vector<glm::vec3> pts = pointsOf(points, "Blender SimpleDeform", "points");
            if (mode == "BEND") {
                return bendDict(warp::fromBlenderBend(b, pts));
            }
            if (mode != "TWIST" && mode != "TAPER") {
                throw InvalidInput(
                    formatError("Blender SimpleDeform", "mode", "is '" + mode + "'", "TWIST, BEND or TAPER"));
            }
            const warp::AxialSetup s =
                mode == "TWIST" ? warp::fromBlenderTwist(b, pts) : warp::fromBlenderTaper(b, pts);
            py::dict d;
            d["axis_origin"] = std::vector<float>{s.frame.origin.x, s.frame.origin.y, s.frame.origin.z};
            d["axis_dir"] = std::vector<float>{s.frame.axis.x, s.frame.axis.y, s.frame.axis.z};
            d["z_samples"] = s.profile.z();
            d["value_samples"] = s.profile.values();
            return d;
        },
        "mode"_a, "points"_a, "angle"_a = 0.0, "factor"_a = 0.0, "deform_axis"_a = "Z",
        "limits"_a = std::pair<double, double>{0.0, 1.0}, "origin"_a = py::none(), "basis"_a = py::none(),
        "Blender SimpleDeform (mode TWIST, BEND or TAPER) -> keyword arguments of twist()/bend()/taper().\n"
        "points: the mesh's world points (limits are fractions of their extent); basis rows: the origin\n"
        "space's unit axes in world (identity when None).");
}

}  // namespace deformkit::python
