// Python bindings of Wires (paper §4.4) and its smooth variant (§5.3): the one-off `wires` function and
// the bind-once `Wires` class. numpy float32 in and out; deformkit.InvalidInput for bad input.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/warp/curve.h"
#include "deformkit/warp/wires.h"
#include "numpy_support.h"
#include "object_lock.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

using PerWire = std::variant<float, std::vector<float>>;

warp::CurveType curveType(const std::string& name) {
    if (name == "polyline") return warp::CurveType::Polyline;
    if (name == "catmull_rom") return warp::CurveType::CatmullRom;
    if (name == "bezier") return warp::CurveType::Bezier;
    throw InvalidInput(
        formatError("wires", "curve_type", "is '" + name + "'", "'polyline', 'catmull_rom' or 'bezier'"));
}

warp::WiresVariant wiresVariantOf(const std::string& name) {
    if (name == "original") return warp::WiresVariant::Original;
    if (name == "smooth") return warp::WiresVariant::Smooth;
    throw InvalidInput(formatError("wires", "variant", "is '" + name + "'", "'original' or 'smooth'"));
}

std::vector<float> perWire(const PerWire& value, size_t count, const char* name) {
    if (const float* one = std::get_if<float>(&value)) return std::vector<float>(count, *one);
    const auto& list = std::get<std::vector<float>>(value);
    if (list.size() != count) {
        throw InvalidInput(formatError("wires", name, "has " + std::to_string(list.size()) + " values",
                                       "one value, or one per wire (" + std::to_string(count) + ")"));
    }
    return list;
}

// The curves as polylines: sampled when curve_type names a cubic type.
struct CurveSampling {
    warp::CurveType type = warp::CurveType::Polyline;
    int32_t samplesPerSpan = 8;

    std::vector<glm::vec3> operator()(const FloatArray& a, const std::string& name) const {
        const std::vector<glm::vec3> controls = pointsOf(a, "wires", name);
        if (type == warp::CurveType::Polyline) return controls;
        return warp::sampleCurve(controls, type, samplesPerSpan, name);
    }
};

std::vector<warp::Wire> makeWires(const std::vector<FloatArray>& references,
                                  const std::optional<std::vector<FloatArray>>& wireCurves,
                                  const PerWire& radius, const PerWire& scale,
                                  const std::optional<std::vector<float>>& falloff,
                                  const CurveSampling& sampling) {
    if (wireCurves && wireCurves->size() != references.size()) {
        throw InvalidInput(
            formatError("wires", "wire_curves", "has " + std::to_string(wireCurves->size()) + " curves",
                        std::to_string(references.size()) + " curves, one per reference curve"));
    }
    const std::vector<float> radii = perWire(radius, references.size(), "radius");
    const std::vector<float> scales = perWire(scale, references.size(), "scale");
    std::vector<warp::Wire> wires(references.size());
    for (size_t i = 0; i < references.size(); ++i) {
        warp::Wire& w = wires[i];
        w.reference = sampling(references[i], "reference_curves[" + std::to_string(i) + "]");
        w.wire =
            wireCurves ? sampling((*wireCurves)[i], "wire_curves[" + std::to_string(i) + "]") : w.reference;
        w.radius = radii[i];
        w.scale = scales[i];
        if (falloff) w.falloff = warp::Falloff::fromSamples(*falloff, "falloff");
    }
    return wires;
}

// Bind once to rest points, then evaluate for new wire curves. Calls are serialised (object_lock.h).
class PyWires {
  public:
    PyWires(const std::vector<FloatArray>& references, const PerWire& radius, const PerWire& scale, float m,
            const std::string& variant, const std::optional<std::vector<float>>& falloff, int32_t samples,
            const std::string& type, int32_t samplesPerSpan)
        : sampling_{curveType(type), samplesPerSpan},
          wires_(makeWires(references, std::nullopt, radius, scale, falloff, sampling_),
                 warp::WiresOptions{wiresVariantOf(variant), m, samples}) {}

    void bind(const FloatArray& points) {
        const std::vector<glm::vec3> rest = pointsOf(points, "wires", "points");
        py::gil_scoped_release release;
        const Lock lock(mutex_);
        wires_.bind(rest);
    }

    void setWireCurves(const std::vector<FloatArray>& curves) {
        const std::vector<std::vector<glm::vec3>> sampled = sampledCurves(curves);
        py::gil_scoped_release release;
        const Lock lock(mutex_);
        setAll(sampled);
    }

    // With wire_curves, the curves are set for this call and kept; a rejected call (bad points, weights,
    // envelope or curves) leaves the wires as they were.
    py::array_t<float> evaluate(const FloatArray& points,
                                const std::optional<std::vector<FloatArray>>& wireCurves,
                                const std::optional<FloatArray>& weights, float envelope) {
        const std::vector<std::vector<glm::vec3>> sampled =
            wireCurves ? sampledCurves(*wireCurves) : std::vector<std::vector<glm::vec3>>{};
        std::vector<glm::vec3> p = pointsOf(points, "wires", "points");
        const std::vector<float> w = weightsOf(weights, p.size(), "wires");
        {
            py::gil_scoped_release release;
            const Lock lock(mutex_);
            const std::vector<std::vector<glm::vec3>> before = wireCurves ? current() : decltype(before){};
            if (wireCurves) setAll(sampled);
            try {
                wires_.evaluate(p, w, envelope);
            } catch (...) {
                if (wireCurves) setAll(before);
                throw;
            }
        }
        return toArray(p);
    }

    template <class F>
    auto read(F&& f) {
        const Lock lock(mutex_);
        return f(static_cast<const warp::Wires&>(wires_));
    }

  private:
    // The curves as the wires take them, checked against every wire before any is set.
    std::vector<std::vector<glm::vec3>> sampledCurves(const std::vector<FloatArray>& curves) {
        const Lock lock(mutex_);
        if (static_cast<int32_t>(curves.size()) != wires_.numWires()) {
            throw InvalidInput(formatError("wires", "wire_curves",
                                           "has " + std::to_string(curves.size()) + " curves",
                                           std::to_string(wires_.numWires()) + " curves, one per wire"));
        }
        std::vector<std::vector<glm::vec3>> sampled;
        for (size_t i = 0; i < curves.size(); ++i) {
            sampled.push_back(sampling_(curves[i], "wire_curves[" + std::to_string(i) + "]"));
            const size_t want = wires_.wire(static_cast<int32_t>(i)).reference.size();
            if (sampled.back().size() != want) {
                throw InvalidInput(
                    formatError("wires", "wire " + std::to_string(i) + " wire curve",
                                "has " + std::to_string(sampled.back().size()) + " points",
                                std::to_string(want) + " points, as many as its reference curve"));
            }
        }
        return sampled;
    }

    [[nodiscard]] std::vector<std::vector<glm::vec3>> current() const {
        std::vector<std::vector<glm::vec3>> curves;
        for (int32_t i = 0; i < wires_.numWires(); ++i)
            curves.push_back(wires_.wire(i).wire);
        return curves;
    }

    // Sets every wire curve or none: a curve the wires refuse (a non-finite point) puts back those before it.
    void setAll(const std::vector<std::vector<glm::vec3>>& curves) {
        const std::vector<std::vector<glm::vec3>> before = current();
        size_t i = 0;
        try {
            for (; i < curves.size(); ++i)
                wires_.setWire(static_cast<int32_t>(i), curves[i]);
        } catch (...) {
            for (size_t j = 0; j < i; ++j)
                wires_.setWire(static_cast<int32_t>(j), before[j]);
            throw;
        }
    }

    CurveSampling sampling_;
    warp::Wires wires_;
    std::mutex mutex_;
};

}  // namespace

void bindWires(py::module_& m) {
    m.def(
        "wires",
        [](const FloatArray& points, const std::vector<FloatArray>& referenceCurves,
           const std::vector<FloatArray>& wireCurves, const PerWire& radius, const PerWire& scale,
           float exponent, const std::string& variant, const std::optional<FloatArray>& weights,
           float envelope, const std::optional<std::vector<float>>& falloff, int32_t samples,
           const std::string& type, int32_t samplesPerSpan) {
            const CurveSampling sampling{curveType(type), samplesPerSpan};
            warp::Wires wires(makeWires(referenceCurves, wireCurves, radius, scale, falloff, sampling),
                              warp::WiresOptions{wiresVariantOf(variant), exponent, samples});
            std::vector<glm::vec3> p = pointsOf(points, "wires", "points");
            const std::vector<float> w = weightsOf(weights, p.size(), "wires");
            {
                py::gil_scoped_release release;
                wires.bind(p);
                wires.evaluate(p, w, envelope);
            }
            return toArray(p);
        },
        py::arg("points"), py::arg("reference_curves"), py::arg("wire_curves"), py::arg("radius") = 1.0f,
        py::arg("scale") = 1.0f, py::arg("m") = 1.0f, py::arg("variant") = "original",
        py::arg("weights") = py::none(), py::arg("envelope") = 1.0f, py::arg("falloff") = py::none(),
        py::arg("samples") = 0, py::arg("curve_type") = "polyline", py::arg("samples_per_span") = 8,
        "Wires (Singh and Fiume 1998; Milliron et al. 2002 §4.4, smooth variant §5.3). points: (n, 3) rest "
        "positions; reference_curves, wire_curves: lists of (k_i, 3) curves, the same k_i per pair; radius, "
        "scale: one value or one per wire; m: displacement weighting exponent; falloff: ramp values at "
        "uniform "
        "t in [0, 1] from 1 to 0 (default 1 - 3t^2 + 2t^3); samples: smooth-variant samples per wire (0 = "
        "automatic); curve_type: 'polyline', 'catmull_rom' or 'bezier' (controls sampled samples_per_span "
        "per "
        "span). Returns the deformed (n, 3) float32 points.");

    py::class_<PyWires>(m, "Wires", "Wires bound once to rest points, evaluated for new wire curves.")
        .def(py::init<const std::vector<FloatArray>&, const PerWire&, const PerWire&, float,
                      const std::string&, const std::optional<std::vector<float>>&, int32_t,
                      const std::string&, int32_t>(),
             py::arg("reference_curves"), py::arg("radius") = 1.0f, py::arg("scale") = 1.0f,
             py::arg("m") = 1.0f, py::arg("variant") = "original", py::arg("falloff") = py::none(),
             py::arg("samples") = 0, py::arg("curve_type") = "polyline", py::arg("samples_per_span") = 8,
             "Wire curves start equal to the reference curves (the identity).")
        .def("bind", &PyWires::bind, py::arg("points"), "Caches nearest-point parameters / sample strengths.")
        .def("set_wire_curves", &PyWires::setWireCurves, py::arg("wire_curves"))
        .def("evaluate", &PyWires::evaluate, py::arg("points"), py::arg("wire_curves") = py::none(),
             py::arg("weights") = py::none(), py::arg("envelope") = 1.0f,
             "Deformed copy of points (the bound rest points or upstream points of the same count).")
        .def_property_readonly(
            "num_wires", [](PyWires& w) { return w.read([](const warp::Wires& x) { return x.numWires(); }); })
        .def_property_readonly(
            "is_bound", [](PyWires& w) { return w.read([](const warp::Wires& x) { return x.isBound(); }); })
        .def_property_readonly("num_field_entries",
                               [](PyWires& w) {
                                   return w.read([](const warp::Wires& x) {
                                       return x.isBound() ? x.fields().offsets.back() : 0;
                                   });
                               })
        .def(
            "smooth_samples",
            [](PyWires& w, int32_t i) {
                return w.read([i](const warp::Wires& x) { return x.smoothSamples(i); });
            },
            py::arg("wire"));
}

}  // namespace deformkit::python
