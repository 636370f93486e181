// Python bindings of the slide (core/include/deformkit/slide/slider.h, Pinskiy "Sliding deformation"): the
// one-off function slide and the Slider class that binds once to a rest mesh and its handles and
// evaluates for many displacements. numpy float32 points in and out; landings as int32 / float64 arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/slide/slider.h"
#include "numpy_support.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

using slide::Falloff;
using slide::RegionMetric;
using slide::SlideDrive;
using slide::SlideHandle;
using slide::Slider;
using slide::SlideResult;
using slide::SurfaceMode;

RegionMetric regionOf(const std::string& name, const std::string& source, const std::string& element) {
    if (name == "euclidean") return RegionMetric::Euclidean;
    if (name == "geodesic") return RegionMetric::Geodesic;
    throw InvalidInput(formatError(source, element, "is '" + name + "'", "'euclidean' or 'geodesic'"));
}

const char* regionName(RegionMetric metric) {
    return metric == RegionMetric::Geodesic ? "geodesic" : "euclidean";
}

slide::SlideOptions optionsOf(const std::string& surface, int64_t maxWalk, const std::string& paintedWeights,
                              bool foldLimit, double weldTolerance, const std::string& source) {
    slide::SlideOptions o;
    o.weldTolerance = weldTolerance;  // checked by the slider
    if (paintedWeights == "scale") {
        o.weights = slide::PaintedWeights::ScaleFalloff;
    } else if (paintedWeights == "falloff") {
        o.weights = slide::PaintedWeights::AreFalloff;
    } else {
        throw InvalidInput(
            formatError(source, "painted_weights", "is '" + paintedWeights + "'",
                        "'scale' (weight x falloff) or 'falloff' (the weight is the falloff)"));
    }
    o.foldLimit = foldLimit;
    if (surface == "cage") {
        o.surface = SurfaceMode::Cage;
    } else if (surface == "limit") {
        o.surface = SurfaceMode::Limit;
    } else {
        throw InvalidInput(formatError(source, "surface", "is '" + surface + "'", "'cage' or 'limit'"));
    }
    if (maxWalk < 1 || maxWalk > std::numeric_limits<int32_t>::max()) {
        throw InvalidInput(formatError(source, "max_walk_triangles", "is " + std::to_string(maxWalk),
                                       "an integer in [1, 2147483647]"));
    }
    o.maxWalkTriangles = static_cast<int32_t>(maxWalk);
    return o;
}

int32_t vertexOf(int64_t vertex, const std::string& source, const std::string& element) {
    // Larger values would wrap into range as int32; the core names everything else out of range.
    if (vertex < std::numeric_limits<int32_t>::min() || vertex > std::numeric_limits<int32_t>::max()) {
        throw InvalidInput(formatError(source, element,
                                       std::to_string(vertex) + ": vertex index out of range",
                                       "a vertex index of the mesh"));
    }
    return static_cast<int32_t>(vertex);
}

// "smooth", "linear", or a 1-D sequence of ramp samples at x = i / (n - 1).
Falloff falloffOf(py::handle value, const std::string& source, const std::string& name) {
    const char* expected = "'smooth', 'linear' or a 1-D sequence of ramp samples";
    if (py::isinstance<py::str>(value)) {
        const auto text = value.cast<std::string>();
        if (text == "smooth") return Falloff::smooth();
        if (text == "linear") return Falloff::linear();
        throw InvalidInput(formatError(source, name, "is '" + text + "'", expected));
    }
    const std::string type = py::str(py::type::of(value).attr("__name__"));
    if (!py::isinstance<py::sequence>(value) && !py::isinstance<py::array>(value)) {
        throw InvalidInput(formatError(source, name, "is a " + type, expected));
    }
    const std::optional<FloatArray> samples = floatArrayOf(value);
    if (!samples)
        throw InvalidInput(formatError(source, name, "is a " + type + " that is not numeric", expected));
    requireFloats(*samples, source, name);
    if (samples->ndim() != 1)
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(*samples), expected));
    return Falloff::ramp(std::span<const float>(samples->data(), static_cast<size_t>(samples->shape(0))),
                         source + ": " + name);
}

// One falloff for every handle, or a list of one per handle: a list whose items are strings or
// sequences (or a 2-D array) is per handle; a flat list of numbers is one ramp.
std::vector<Falloff> falloffsOf(py::handle value, size_t handles, const std::string& source) {
    bool perHandle = false;
    if (py::isinstance<py::array>(value)) {
        perHandle = py::reinterpret_borrow<py::array>(value).ndim() == 2;
    } else if ((py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) && py::len(value) > 0) {
        const py::handle first = py::reinterpret_borrow<py::sequence>(value)[0];
        perHandle = py::isinstance<py::str>(first) || py::isinstance<py::sequence>(first) ||
                    py::isinstance<py::array>(first);
    }
    if (!perHandle) return std::vector<Falloff>(handles, falloffOf(value, source, "falloff"));
    const auto items = py::reinterpret_borrow<py::sequence>(value);
    if (items.size() != handles) {
        throw InvalidInput(formatError(source, "falloff", "has " + std::to_string(items.size()) + " items",
                                       "one falloff, or one per handle (" + std::to_string(handles) + ")"));
    }
    std::vector<Falloff> out;
    for (size_t h = 0; h < handles; ++h)
        out.push_back(falloffOf(items[h], source, "falloff[" + std::to_string(h) + "]"));
    return out;
}

// Displacements: (3,) for one handle, (H, 3) for H handles.
std::vector<glm::dvec3> displacementsOf(const DoubleArray& a, size_t handles, const std::string& source) {
    requireDoubles(a, source, "displacement");
    const bool single = a.ndim() == 1 && a.shape(0) == 3 && handles == 1;
    const bool rows = a.ndim() == 2 && a.shape(1) == 3 && static_cast<size_t>(a.shape(0)) == handles;
    if (!single && !rows) {
        throw InvalidInput(formatError(
            source, "displacement", "has shape " + shapeOf(a),
            handles == 1 ? "(3,) or (1, 3)" : "(" + std::to_string(handles) + ", 3), one row per handle"));
    }
    std::vector<glm::dvec3> out(handles);
    for (size_t h = 0; h < handles; ++h) {
        const double* d = a.data() + 3 * h;
        out[h] = glm::dvec3(d[0], d[1], d[2]);
    }
    return out;
}

// handles=[{"vertex": .., "radius": .., "region": ..}, ...]; "region" is optional.
std::vector<SlideHandle> handlesOf(const std::optional<int64_t>& handle, const std::optional<double>& radius,
                                   const std::string& region,
                                   const std::optional<std::vector<py::dict>>& handles,
                                   const std::string& source) {
    if (handles) {
        if (handle || radius) {
            throw InvalidInput(formatError(source, "handles", "given together with handle or radius",
                                           "either handle and radius, or handles"));
        }
        std::vector<SlideHandle> out;
        for (size_t h = 0; h < handles->size(); ++h) {
            const py::dict& item = (*handles)[h];
            const std::string at = "handles[" + std::to_string(h) + "]";
            for (const auto& [key, value] : item) {
                const std::string k = py::str(key);
                if (k != "vertex" && k != "radius" && k != "region") {
                    throw InvalidInput(
                        formatError(source, at, "has the key '" + k + "'", "'vertex', 'radius', 'region'"));
                }
            }
            for (const char* key : {"vertex", "radius"}) {
                if (!item.contains(key)) {
                    throw InvalidInput(formatError(source, at + "." + key, "is missing", "a value"));
                }
            }
            // Each value named by its own path ("handles[0].vertex: is a float"), bools refused as numbers.
            SlideHandle s;
            const py::handle vertex = item["vertex"], radius = item["radius"];
            const std::optional<int64_t> index = wholeNumber(vertex);
            if (!index)
                throw InvalidInput(formatError(source, at + ".vertex", "is " + aTypeName(vertex), "an int"));
            s.vertex = vertexOf(*index, source, at + ".vertex");
            if (!isRealNumber(radius)) {
                throw InvalidInput(
                    formatError(source, at + ".radius", "is " + aTypeName(radius), "a number"));
            }
            s.radius = radius.cast<double>();
            if (item.contains("region")) {
                const py::handle region = item["region"];
                if (!py::isinstance<py::str>(region)) {
                    throw InvalidInput(formatError(source, at + ".region", "is " + aTypeName(region),
                                                   "'euclidean' or 'geodesic'"));
                }
                s.region = regionOf(region.cast<std::string>(), source, at + ".region");
            }
            out.push_back(s);
        }
        return out;
    }
    if (!handle && !radius) {
        throw InvalidInput(
            formatError(source, "handle", "no handle given", "handle and radius, or handles=[...]"));
    }
    if (!radius) {
        throw InvalidInput(
            formatError(source, "radius", "is missing", "a radius with handle " + std::to_string(*handle)));
    }
    if (!handle) {
        throw InvalidInput(formatError(source, "handle", "is missing", "a handle vertex with the radius"));
    }
    return {{vertexOf(*handle, source, "handle"), *radius, regionOf(region, source, "region")}};
}

// What an evaluation returns: the slid points and, per moved vertex, where it landed.
struct PySlideResult {
    py::array_t<float> points;
    py::array_t<int32_t> vertices, faces, triangles;
    py::array_t<double> barycentric;
    slide::SlideResult counts;  // the counts and fold scales; its landings are the arrays above
};

// SlideResult's counts as read-only attributes of deformkit.SlideResult: name, member, meaning.
struct SlideCount {
    const char* name;
    int32_t slide::SlideResult::*member;
    const char* doc;
};
constexpr SlideCount kSlideCounts[] = {
    {"moved", &slide::SlideResult::moved, "vertices moved"},
    {"boundary_stopped", &slide::SlideResult::boundaryStopped,
     "moved vertices that reached a mesh boundary and stopped on it"},
    {"walk_limit_stopped", &slide::SlideResult::walkLimitStopped,
     "moved vertices whose walk stopped after max_walk_triangles triangles, or whose line left\n"
     "the triangles it crossed"},
    {"limited", &slide::SlideResult::limited,
     "moved vertices that travelled less than asked (boundary_stopped + walk_limit_stopped)"},
    {"flipped_triangles", &slide::SlideResult::flippedTriangles,
     "triangles with a slid corner whose orientation reversed (a fold of the texture)"},
    {"unreachable", &slide::SlideResult::unreachable,
     "vertices within a radius that the region's propagation cannot reach: unmoved"},
    {"without_tangent_plane", &slide::SlideResult::withoutTangentPlane,
     "vertices within a radius with only degenerate triangles around: unmoved"},
    {"welded", &slide::SlideResult::welded,
     "split vertices welded onto a coincident vertex at bind (the counts are of welded vertices)"},
    {"degenerate_triangles", &slide::SlideResult::degenerateTriangles,
     "zero-area triangles touching the region: skipped"},
};

PySlideResult resultOf(const std::vector<glm::vec3>& points, const SlideResult& r) {
    PySlideResult out;
    out.points = toArray(points);
    const auto m = static_cast<py::ssize_t>(r.landings.size());
    out.vertices = py::array_t<int32_t>(m);
    out.faces = py::array_t<int32_t>(m);
    out.triangles = py::array_t<int32_t>({m, py::ssize_t{3}});
    out.barycentric = py::array_t<double>({m, py::ssize_t{3}});
    int32_t* vertices = out.vertices.mutable_data();
    int32_t* faces = out.faces.mutable_data();
    int32_t* triangles = out.triangles.mutable_data();
    double* barycentric = out.barycentric.mutable_data();
    for (py::ssize_t i = 0; i < m; ++i) {
        const slide::SlideLanding& l = r.landings[static_cast<size_t>(i)];
        vertices[i] = l.vertex;
        faces[i] = l.face;
        for (int k = 0; k < 3; ++k) {
            triangles[3 * i + k] = l.triangle[k];
            barycentric[3 * i + k] = l.barycentric[k];
        }
    }
    for (const SlideCount& c : kSlideCounts)
        out.counts.*c.member = r.*c.member;
    out.counts.foldScale = r.foldScale;
    return out;
}

template <class T>
py::array_t<T> arrayOf(std::span<const T> values) {
    py::array_t<T> out(static_cast<py::ssize_t>(values.size()));
    if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
    return out;
}

py::tuple tupleOf(const glm::dvec3& v) {
    return py::make_tuple(v.x, v.y, v.z);
}

// The Slider binding. The bound core object is shared so that bind() during another thread's evaluate
// (which runs without the GIL) cannot free the slider under it.
class PySlider {
  public:
    PySlider(const FloatArray& points, const IntArray& counts, const IntArray& indices,
             const std::optional<int64_t>& handle, const std::optional<double>& radius,
             const std::string& region, const std::optional<std::vector<py::dict>>& handles,
             const std::string& surface, int64_t maxWalk, const std::string& paintedWeights, bool foldLimit,
             double weldTolerance) {
        bind(points, counts, indices, handle, radius, region, handles, surface, maxWalk, paintedWeights,
             foldLimit, weldTolerance);
    }

    void bind(const FloatArray& points, const IntArray& counts, const IntArray& indices,
              const std::optional<int64_t>& handle, const std::optional<double>& radius,
              const std::string& region, const std::optional<std::vector<py::dict>>& handles,
              const std::string& surface, int64_t maxWalk, const std::string& paintedWeights, bool foldLimit,
              double weldTolerance) {
        const std::string source = "Slider";
        const geom::Mesh mesh =
            meshOf(points, counts, indices, std::nullopt, std::nullopt, source, source + " mesh");
        std::vector<SlideHandle> h = handlesOf(handle, radius, region, handles, source);
        const slide::SlideOptions options =
            optionsOf(surface, maxWalk, paintedWeights, foldLimit, weldTolerance, source);
        std::shared_ptr<Slider> bound;
        {
            py::gil_scoped_release release;
            bound = std::make_shared<Slider>(mesh, std::move(h), options, source);
        }
        slider_ = std::move(bound);
        rest_.assign(mesh.points().begin(), mesh.points().end());
    }

    PySlideResult evaluate(const DoubleArray& displacement, py::handle falloff,
                           const std::optional<FloatArray>& weights, double envelope,
                           const std::optional<FloatArray>& points) const {
        const std::string source = "Slider.evaluate";
        const std::shared_ptr<Slider> slider = slider_;
        const auto handles = static_cast<size_t>(slider->numHandles());
        const std::vector<glm::dvec3> d = displacementsOf(displacement, handles, source);
        const std::vector<Falloff> f = falloffsOf(falloff, handles, source);
        std::vector<SlideDrive> drives;
        for (size_t h = 0; h < handles; ++h)
            drives.push_back({d[h], f[h]});
        std::vector<glm::vec3> pts = points ? pointsOf(*points, source, "points") : rest_;
        if (pts.size() != static_cast<size_t>(slider->numVertices())) {
            throw InvalidInput(formatError(source, "points", "has " + std::to_string(pts.size()) + " rows",
                                           std::to_string(slider->numVertices()) + ", one per vertex"));
        }
        const std::vector<float> w = weightsOf(weights, static_cast<size_t>(slider->numVertices()), source);
        SlideResult result;
        {
            py::gil_scoped_release release;
            slider->evaluate(drives, pts, w, envelope, &result);
        }
        return resultOf(pts, result);
    }

    [[nodiscard]] const Slider& slider() const { return *slider_; }

  private:
    std::shared_ptr<Slider> slider_;
    std::vector<glm::vec3> rest_;
};

py::dict regionDict(const slide::SupportRegion& r) {
    py::dict out;
    out["vertex"] = r.handle;
    out["radius"] = r.radius;
    out["region"] = regionName(r.metric);
    out["vertices"] = arrayOf<int32_t>(r.vertices);
    out["normalized_distance"] = arrayOf<float>(r.normalizedDistance);
    out["a1"] = tupleOf(r.a1);
    out["a2"] = tupleOf(r.a2);
    out["unreachable"] = r.unreachable;
    out["without_tangent_plane"] = r.withoutTangentPlane;
    return out;
}

}  // namespace

void bindSlide(py::module_& m) {
    m.def(
        "slide",
        [](const FloatArray& points, const IntArray& counts, const IntArray& indices, int64_t handle,
           const DoubleArray& displacement, double radius, py::object falloff,
           const std::optional<FloatArray>& weights, double envelope, const std::string& region,
           const std::string& surface, const std::optional<std::filesystem::path>& weightsPtex,
           int32_t weightsChannel, const std::string& paintedWeights, bool foldLimit, double weldTolerance) {
            const std::string source = "slide";
            const geom::Mesh mesh =
                meshOf(points, counts, indices, std::nullopt, std::nullopt, source, source + " mesh");
            if (weights && weightsPtex) {
                throw InvalidInput(formatError(source, "weights_ptex", "is given with weights",
                                               "one source of painted weights"));
            }
            const std::vector<SlideHandle> handles = {
                {vertexOf(handle, source, "handle"), radius, regionOf(region, source, "region")}};
            const slide::SlideOptions options =
                optionsOf(surface, 4096, paintedWeights, foldLimit, weldTolerance, source);
            const std::vector<SlideDrive> drives = {
                {displacementsOf(displacement, 1, source)[0], falloffOf(falloff, source, "falloff")}};
            const std::vector<float> w =
                weightsPtex ? ptex::weightsFromPtex(mesh, meshLabel(mesh), *weightsPtex, weightsChannel,
                                                    "slide: weights_ptex")
                            : weightsOf(weights, static_cast<size_t>(mesh.numVertices()), source);
            std::vector<glm::vec3> out(mesh.points().begin(), mesh.points().end());
            {
                py::gil_scoped_release release;
                Slider slider(mesh, handles, options, source);
                slider.evaluate(drives, out, w, envelope);
            }
            return toArray(out);
        },
        py::arg("points"), py::arg("face_counts"), py::arg("face_indices"), py::arg("handle"),
        py::arg("displacement"), py::arg("radius"), py::arg("falloff") = "smooth",
        py::arg("weights") = py::none(), py::arg("envelope") = 1.0, py::arg("region") = "euclidean",
        py::arg("surface") = "cage", py::arg("weights_ptex") = py::none(), py::arg("weights_channel") = 0,
        py::arg("painted_weights") = "scale", py::arg("fold_limit") = false, py::arg("weld_tolerance") = 0.0,
        "Slide vertices over the surface (Pinskiy, 'Sliding deformation'): the region within `radius` of "
        "the\n"
        "`handle` vertex moves by `displacement` (3,) times the falloff, along the surface, so the shape "
        "stays\n"
        "and the texture travels. points (N, 3) float32; face_counts (F,) int32; face_indices (sum of "
        "counts,)\n"
        "int32; radius in scene units; falloff 'smooth' (1 - 3x^2 + 2x^3), 'linear' or ramp samples at\n"
        "x = i / (n - 1) of distance / radius; weights (N,) painted, or weights_ptex: a Ptex file painted on "
        "the\n"
        "mesh (its per-vertex values of weights_channel); envelope scalar; region 'euclidean' or\n"
        "'geodesic'; surface 'cage' or 'limit' (Catmull-Clark); painted_weights 'scale' (weight x falloff) "
        "or\n"
        "'falloff' (the paper's: the weight is the falloff, the radius only bounds the region); fold_limit\n"
        "scales the drag down so no triangle of the region flips. Returns the slid points (N, 3) float32.");

    py::class_<PySlideResult> result(m, "SlideResult",
                                     "The slid points and, per moved vertex, where it landed.");
    result.def_readonly("points", &PySlideResult::points, "(N, 3) float32 slid points")
        .def_readonly("vertices", &PySlideResult::vertices, "(M,) int32 moved vertices, ascending")
        .def_readonly("faces", &PySlideResult::faces, "(M,) int32 polygon each landed on")
        .def_readonly("triangles", &PySlideResult::triangles,
                      "(M, 3) int32 vertices of the rest-mesh triangle (fan of the polygon) each landed on")
        .def_readonly(
            "barycentric", &PySlideResult::barycentric,
            "(M, 3) float64 barycentric coordinates on `triangles`: on the cage surface the slid point is\n"
            "their combination of the rest positions")
        .def_property_readonly(
            "fold_scale", [](const PySlideResult& r) { return arrayOf<double>(r.counts.foldScale); },
            "(H,) float64 per handle: the share of its displacement applied (below 1 under the fold limit)")
        .def("__repr__", [](const PySlideResult& r) {
            std::string text;
            for (const SlideCount& c : kSlideCounts) {
                if (c.member == &slide::SlideResult::limited ||
                    c.member == &slide::SlideResult::withoutTangentPlane)
                    continue;  // limited is a sum of two shown; without_tangent_plane is rare
                text += (text.empty() ? "" : ", ") + std::string(c.name) + " " +
                        std::to_string(r.counts.*c.member);
            }
            return "<deformkit.SlideResult " + text + ">";
        });
    for (const SlideCount& c : kSlideCounts) {
        result.def_property_readonly(
            c.name, [member = c.member](const PySlideResult& r) { return r.counts.*member; }, c.doc);
    }

    py::class_<PySlider>(
        m, "Slider",
        "The slide bound once to a rest mesh and its handles (support regions, region bases),\n"
        "evaluated for many displacements.")
        .def(py::init<const FloatArray&, const IntArray&, const IntArray&, const std::optional<int64_t>&,
                      const std::optional<double>&, const std::string&,
                      const std::optional<std::vector<py::dict>>&, const std::string&, int64_t,
                      const std::string&, bool, double>(),
             py::arg("points"), py::arg("face_counts"), py::arg("face_indices"),
             py::arg("handle") = py::none(), py::arg("radius") = py::none(), py::arg("region") = "euclidean",
             py::arg("handles") = py::none(), py::arg("surface") = "cage",
             py::arg("max_walk_triangles") = 4096, py::arg("painted_weights") = "scale",
             py::arg("fold_limit") = false, py::arg("weld_tolerance") = 0.0,
             "Bind to the rest mesh (points (N, 3), face_counts, face_indices) and one handle (handle, "
             "radius,\n"
             "region) or several: handles=[{'vertex': i, 'radius': r, 'region': 'geodesic'}, ...] ('region'\n"
             "optional, default 'euclidean'). surface 'cage' or 'limit'; max_walk_triangles bounds one "
             "vertex's\n"
             "walk in one evaluation. painted_weights 'scale' or 'falloff' (the paper's rule); fold_limit\n"
             "scales each drag down so no triangle of its region flips. Split vertices (coincident, or "
             "within\n"
             "weld_tolerance) are welded: the slide walks across seams and every copy moves as the others.")
        .def("bind", &PySlider::bind, py::arg("points"), py::arg("face_counts"), py::arg("face_indices"),
             py::arg("handle") = py::none(), py::arg("radius") = py::none(), py::arg("region") = "euclidean",
             py::arg("handles") = py::none(), py::arg("surface") = "cage",
             py::arg("max_walk_triangles") = 4096, py::arg("painted_weights") = "scale",
             py::arg("fold_limit") = false, py::arg("weld_tolerance") = 0.0,
             "Bind again, to a new rest mesh or handle set; arguments as the constructor.")
        .def(
            "evaluate", &PySlider::evaluate, py::arg("displacement"), py::arg("falloff") = "smooth",
            py::arg("weights") = py::none(), py::arg("envelope") = 1.0, py::arg("points") = py::none(),
            "Slide for displacement (3,) (one handle) or (H, 3) (one row per handle); falloff one value for\n"
            "every handle or a list of one per handle; weights (N,), envelope scalar; points (N, 3): the\n"
            "surface to slide over, a deformed copy of the rest mesh (default: the rest points), with\n"
            "displacement in its space. Returns a SlideResult.")
        .def_property_readonly("num_vertices", [](const PySlider& s) { return s.slider().numVertices(); })
        .def_property_readonly("num_handles", [](const PySlider& s) { return s.slider().numHandles(); })
        .def_property_readonly(
            "handles",
            [](const PySlider& s) {
                py::list out;
                for (const SlideHandle& h : s.slider().handles()) {
                    py::dict d;
                    d["vertex"] = h.vertex;
                    d["radius"] = h.radius;
                    d["region"] = regionName(h.region);
                    out.append(d);
                }
                return out;
            },
            "The bound handles as [{'vertex', 'radius', 'region'}, ...]")
        .def_property_readonly(
            "active_vertices",
            [](const PySlider& s) { return arrayOf<int32_t>(s.slider().activeVertices()); },
            "(A,) int32 vertices in at least one handle's region, ascending")
        .def(
            "region",
            [](const PySlider& s, int32_t handle) {
                if (handle < 0 || handle >= s.slider().numHandles()) {
                    throw InvalidInput(formatError("Slider.region", "handle",
                                                   std::to_string(handle) + " is out of range",
                                                   "[0, " + std::to_string(s.slider().numHandles()) + ")"));
                }
                return regionDict(s.slider().region(handle));
            },
            py::arg("handle") = 0,
            "Handle `handle`'s support region: {'vertex', 'radius', 'region', 'vertices' (K,) int32 in\n"
            "breadth-first order, 'normalized_distance' (K,) float32 = distance / radius, 'a1', 'a2' (the "
            "region\n"
            "basis at the handle), 'unreachable', 'without_tangent_plane'}.")
        .def("__repr__", [](const PySlider& s) {
            return "<deformkit.Slider " + std::to_string(s.slider().numVertices()) + " vertices, " +
                   std::to_string(s.slider().numHandles()) + " handles, " +
                   std::to_string(s.slider().activeVertices().size()) + " active>";
        });
}

}  // namespace deformkit::python
