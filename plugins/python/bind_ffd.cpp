// Python bindings of free-form deformation (core/include/deformkit/warp/ffd.h) and FFD with coordinate
// frames (ffd_frames.h): one-off functions ffd / ffd_frames and Ffd / FfdFrames classes that bind once and
// evaluate many times. numpy float32 in and out. Lattice axes and frame bases are given as rows:
// axes[0] = X, axes[1] = Y, axes[2] = Z; bases[..., a, :] = basis vector a.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/warp/ffd.h"
#include "deformkit/warp/ffd_frames.h"
#include "numpy_support.h"
#include "object_lock.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

using warp::Ffd;
using warp::FfdFrames;
using warp::Frame;
using warp::Lattice;

Lattice latticeOf(const FloatArray& origin, const FloatArray& axes, const IntArray& divisions,
                  const char* source) {
    requireFloats(origin, source, "origin");
    if (origin.ndim() != 1 || origin.shape(0) != 3) {
        throw InvalidInput(formatError(source, "origin", "has shape " + shapeOf(origin), "(3,)"));
    }
    requireFloats(axes, source, "axes");
    if (axes.ndim() != 2 || axes.shape(0) != 3 || axes.shape(1) != 3) {
        throw InvalidInput(
            formatError(source, "axes", "has shape " + shapeOf(axes), "(3, 3), one axis X, Y, Z per row"));
    }
    requireInts(divisions, source, "divisions");
    if (divisions.ndim() != 1 || divisions.shape(0) != 3) {
        throw InvalidInput(
            formatError(source, "divisions", "has shape " + shapeOf(divisions), "(3,) integers l, m, n"));
    }
    Lattice l;
    l.origin = {origin.data()[0], origin.data()[1], origin.data()[2]};
    for (int a = 0; a < 3; ++a) {
        l.axes[a] = {axes.data()[3 * a], axes.data()[3 * a + 1], axes.data()[3 * a + 2]};
        l.divisions[a] = divisions.data()[a];
    }
    return l;
}

warp::FfdBasis basisNamed(const std::string& name, const std::string& given, const char* source) {
    if (name == "bernstein") return warp::FfdBasis::Bernstein;
    if (name == "bspline") return warp::FfdBasis::BSpline;
    if (name == "linear") return warp::FfdBasis::Linear;
    if (name == "cardinal") return warp::FfdBasis::Cardinal;
    if (name == "catmull_rom") return warp::FfdBasis::CatmullRom;
    throw InvalidInput(formatError(source, "basis", "'" + given + "' is not a basis",
                                   "bernstein, bspline, linear, cardinal or catmull_rom, or three of them "
                                   "separated by commas (X, Y, Z)"));
}

warp::FfdOptions optionsOf(const std::string& basis, const std::string& outside, const std::string& ends,
                           const char* source) {
    warp::FfdOptions o;
    std::vector<std::string> names;
    for (size_t start = 0;;) {
        const size_t comma = basis.find(',', start);
        names.push_back(basis.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (names.size() == 1) {
        o.basis = basisNamed(names[0], basis, source);
    } else if (names.size() == 3) {
        o.basis = {basisNamed(names[0], basis, source), basisNamed(names[1], basis, source),
                   basisNamed(names[2], basis, source)};
    } else {
        basisNamed("", basis, source);  // throws: neither one basis nor three
    }
    if (outside == "none") {
        o.outside = warp::FfdOutside::None;
    } else if (outside == "extrapolate") {
        o.outside = warp::FfdOutside::Extrapolate;
    } else {
        throw InvalidInput(
            formatError(source, "outside", "'" + outside + "' is not an option", "none or extrapolate"));
    }
    if (ends == "extrapolate") {
        o.ends = warp::FfdEnds::Extrapolate;
    } else if (ends == "repeat") {
        o.ends = warp::FfdEnds::Repeat;
    } else {
        throw InvalidInput(
            formatError(source, "ends", "'" + ends + "' is not an option", "extrapolate or repeat"));
    }
    return o;
}

// A (l+1, m+1, n+1, trailing...) array in the lattice's index order, checked against the divisions.
void checkLatticeShape(const FloatArray& a, const Lattice& l, std::vector<py::ssize_t> trailing,
                       const char* source, const char* name) {
    requireFloats(a, source, name);
    std::vector<py::ssize_t> expected{l.divisions.x + 1, l.divisions.y + 1, l.divisions.z + 1};
    expected.insert(expected.end(), trailing.begin(), trailing.end());
    bool ok = a.ndim() == static_cast<py::ssize_t>(expected.size());
    for (size_t i = 0; ok && i < expected.size(); ++i)
        ok = a.shape(static_cast<py::ssize_t>(i)) == expected[i];
    if (!ok) {
        std::string e = "(";
        for (size_t i = 0; i < expected.size(); ++i)
            e += (i ? ", " : "") + std::to_string(expected[i]);
        throw InvalidInput(formatError(source, name, "has shape " + shapeOf(a),
                                       e + ") for divisions (" + std::to_string(l.divisions.x) + ", " +
                                           std::to_string(l.divisions.y) + ", " +
                                           std::to_string(l.divisions.z) + ")"));
    }
}

std::vector<glm::vec3> latticePointsOf(const FloatArray& a, const Lattice& l, const char* source,
                                       const char* name) {
    checkLatticeShape(a, l, {3}, source, name);
    std::vector<glm::vec3> out(static_cast<size_t>(l.numControls()));
    std::memcpy(out.data(), a.data(), out.size() * sizeof(glm::vec3));
    return out;
}

// Bases (l+1, m+1, n+1, 3, 3), basis vectors as rows.
std::vector<glm::mat3> basesOf(const FloatArray& bases, const Lattice& l, const char* source,
                               const char* name) {
    checkLatticeShape(bases, l, {3, 3}, source, name);
    std::vector<glm::mat3> out(static_cast<size_t>(l.numControls()));
    const float* b = bases.data();
    for (size_t c = 0; c < out.size(); ++c) {
        for (int a = 0; a < 3; ++a)
            out[c][a] = {b[9 * c + 3 * a], b[9 * c + 3 * a + 1], b[9 * c + 3 * a + 2]};
    }
    return out;
}

std::vector<Frame> framesOf(const FloatArray& origins, const FloatArray& bases, const Lattice& l,
                            const char* source, const char* originName, const char* basisName) {
    const std::vector<glm::vec3> o = latticePointsOf(origins, l, source, originName);
    const std::vector<glm::mat3> b = basesOf(bases, l, source, basisName);
    std::vector<Frame> frames(o.size());
    for (size_t c = 0; c < o.size(); ++c)
        frames[c] = {o[c], b[c]};
    return frames;
}

py::array_t<float> latticeArray(std::span<const glm::vec3> pts, const Lattice& l) {
    py::array_t<float> out({static_cast<py::ssize_t>(l.divisions.x + 1),
                            static_cast<py::ssize_t>(l.divisions.y + 1),
                            static_cast<py::ssize_t>(l.divisions.z + 1), static_cast<py::ssize_t>(3)});
    std::memcpy(out.mutable_data(), pts.data(), pts.size() * sizeof(glm::vec3));
    return out;
}

// Binds `warp` to `points` (read in place) and deforms the copy it returns, without the GIL.
template <class W>
py::array_t<float> bindAndRun(W& warp, const FloatArray& points, const std::optional<FloatArray>& weights,
                              float envelope, const char* source) {
    const std::span<const glm::vec3> in = pointsView(points, source, "points");
    const std::span<const float> w = weightsView(weights, in.size(), source);
    auto [out, pts] = outputArray(py::none(), in.size(), source);
    {
        py::gil_scoped_release release;
        if constexpr (std::is_same_v<W, Ffd>) {
            warp.bindAndEvaluate(in, in, pts, w, envelope);  // no bind cache where it can do without
        } else {
            warp.bind(in);
            warp.evaluate(in, pts, w, envelope);
        }
    }
    return out;
}

// Evaluates a bound warp on a copy of `points` (the rest points when None) under the object's mutex.
template <class W>
py::array_t<float> evaluateBound(const W& warp, const std::vector<glm::vec3>& rest, std::mutex& mutex,
                                 const std::optional<FloatArray>& points,
                                 const std::optional<FloatArray>& weights, float envelope, const char* source,
                                 const py::object& outArg) {
    const std::optional<std::span<const glm::vec3>> given =
        points ? std::optional(pointsView(*points, source, "points")) : std::nullopt;
    size_t count = 0;
    if (given) {
        count = given->size();
    } else {
        const Lock lock(mutex);
        count = rest.size();
    }
    const std::span<const float> w = weightsView(weights, count, source);
    auto [out, pts] = outputArray(outArg, count, source);
    {
        py::gil_scoped_release release;
        const Lock lock(mutex);
        const std::span<const glm::vec3> in = given ? *given : std::span<const glm::vec3>(rest);
        if (in.size() != count) {
            throw InvalidInput(formatError(source, "points",
                                           "were bound again by another thread during the call",
                                           "bind and evaluate of one object in the same thread"));
        }
        requireSameOrApart(in, pts, source);
        warp.evaluate(in, pts, w, envelope);  // into out, or in place when out is the input
    }
    return out;
}

// The bound classes keep their rest points so evaluate() without points deforms the rest shape. Calls are
// serialised (object_lock.h).
struct PyFfd {
    explicit PyFfd(Ffd f) : ffd(std::move(f)) {}
    Ffd ffd;
    std::vector<glm::vec3> rest;
    std::mutex mutex;
};

struct PyFfdFrames {
    explicit PyFfdFrames(FfdFrames f) : frames(std::move(f)) {}
    FfdFrames frames;
    std::vector<glm::vec3> rest;
    std::mutex mutex;
};

// A copy of lattice points taken under the object's mutex, as an array.
py::array_t<float> latticeCopy(std::mutex& mutex, const Lattice& lattice,
                               const std::function<std::vector<glm::vec3>()>& copy) {
    std::vector<glm::vec3> points;
    {
        const Lock lock(mutex);
        points = copy();
    }
    return latticeArray(points, lattice);
}

}  // namespace

void bindFfd(py::module_& m) {
    m.def(
        "ffd",
        [](const FloatArray& points, const FloatArray& origin, const FloatArray& axes,
           const IntArray& divisions, const FloatArray& target, const std::string& basis,
           const std::string& outside, const std::string& ends, const std::optional<FloatArray>& weights,
           float envelope) {
            const char* source = "ffd";
            const Lattice l = latticeOf(origin, axes, divisions, source);
            Ffd ffd(l, optionsOf(basis, outside, ends, source));
            ffd.setTargets(latticePointsOf(target, l, source, "target"));
            return bindAndRun(ffd, points, weights, envelope, source);
        },
        py::arg("points"), py::arg("origin"), py::arg("axes"), py::arg("divisions"), py::arg("target"),
        py::arg("basis") = "bernstein", py::arg("outside") = "none", py::arg("ends") = "extrapolate",
        py::arg("weights") = py::none(), py::arg("envelope") = 1.0f,
        "Free-form deformation (Sederberg-Parry; Milliron et al. 4.1). points (N, 3); origin (3,); axes (3, "
        "3) with\n"
        "rows X, Y, Z (edge vectors of the parallelepiped); divisions (3,) = l, m, n; target (l+1, m+1, n+1, "
        "3)\n"
        "moved control points; basis 'bernstein', 'bspline', 'linear', 'cardinal', 'catmull_rom' or three of "
        "them\n"
        "separated by commas (X, Y, Z); outside 'none' (unchanged) or 'extrapolate'; ends 'extrapolate' or\n"
        "'repeat' (Blender's lattice);\n"
        "weights (N,) painted, envelope scalar. Returns (N, 3) float32.");

    m.def(
        "ffd_frames",
        [](const FloatArray& points, const FloatArray& origin, const FloatArray& axes,
           const IntArray& divisions, const FloatArray& targetOrigins, const FloatArray& targetBases,
           const std::optional<FloatArray>& sourceOrigins, const std::optional<FloatArray>& sourceBases,
           const std::string& basis, const std::string& outside, const std::string& ends,
           const std::optional<FloatArray>& weights, float envelope) {
            const char* source = "ffd_frames";
            const Lattice l = latticeOf(origin, axes, divisions, source);
            FfdFrames frames(l, optionsOf(basis, outside, ends, source));
            if (sourceOrigins || sourceBases) {
                std::vector<Frame> src(frames.sourceFrames().begin(), frames.sourceFrames().end());
                if (sourceOrigins) {
                    const auto o = latticePointsOf(*sourceOrigins, l, source, "source_origins");
                    for (size_t c = 0; c < src.size(); ++c)
                        src[c].origin = o[c];
                }
                if (sourceBases) {
                    const auto b = basesOf(*sourceBases, l, source, "source_bases");
                    for (size_t c = 0; c < src.size(); ++c)
                        src[c].basis = b[c];
                }
                frames.setSourceFrames(src);
            }
            frames.setTargetFrames(
                framesOf(targetOrigins, targetBases, l, source, "target_origins", "target_bases"));
            return bindAndRun(frames, points, weights, envelope, source);
        },
        py::arg("points"), py::arg("origin"), py::arg("axes"), py::arg("divisions"),
        py::arg("target_origins"), py::arg("target_bases"), py::arg("source_origins") = py::none(),
        py::arg("source_bases") = py::none(), py::arg("basis") = "bernstein", py::arg("outside") = "none",
        py::arg("ends") = "extrapolate", py::arg("weights") = py::none(), py::arg("envelope") = 1.0f,
        "FFD with coordinate-frame features (Milliron et al. 5.1): each control carries a frame; the source "
        "frame\n"
        "(origin, basis) is mapped to the target frame. target_origins (l+1, m+1, n+1, 3); target_bases\n"
        "(l+1, m+1, n+1, 3, 3) with basis vectors as rows; source_origins default to the lattice points, "
        "source_bases\n"
        "to the identity. Other arguments as ffd. Returns (N, 3) float32.");

    py::class_<PyFfd>(m, "Ffd",
                      "Free-form deformation bound once to rest points, evaluated for many target lattices.")
        .def(py::init([](const FloatArray& origin, const FloatArray& axes, const IntArray& divisions,
                         const std::string& basis, const std::string& outside, const std::string& ends) {
                 const Lattice l = latticeOf(origin, axes, divisions, "Ffd");
                 return std::make_unique<PyFfd>(Ffd(l, optionsOf(basis, outside, ends, "Ffd")));
             }),
             py::arg("origin"), py::arg("axes"), py::arg("divisions"), py::arg("basis") = "bernstein",
             py::arg("outside") = "none", py::arg("ends") = "extrapolate")
        .def(
            "bind",
            [](PyFfd& self, const FloatArray& points) {
                std::vector<glm::vec3> rest = pointsOf(points, "Ffd.bind", "points");
                py::gil_scoped_release release;
                const Lock lock(self.mutex);
                self.ffd.bind(rest);
                self.rest = std::move(rest);
            },
            py::arg("points"), "Cache each rest point's lattice coordinates (N, 3).")
        .def(
            "set_target",
            [](PyFfd& self, const FloatArray& target) {
                const std::vector<glm::vec3> targets =
                    latticePointsOf(target, self.ffd.lattice().lattice(), "Ffd.set_target", "target");
                const Lock lock(self.mutex);
                self.ffd.setTargets(targets);
            },
            py::arg("target"), "Move the controls: target (l+1, m+1, n+1, 3). Does no bind work.")
        .def_property_readonly(
            "source_points",
            [](PyFfd& self) {
                return latticeCopy(self.mutex, self.ffd.lattice().lattice(), [&] {
                    return std::vector<glm::vec3>(self.ffd.sourcePoints().begin(),
                                                  self.ffd.sourcePoints().end());
                });
            },
            "(l+1, m+1, n+1, 3) undeformed control points P_ijk")
        .def_property_readonly("target",
                               [](PyFfd& self) {
                                   return latticeCopy(self.mutex, self.ffd.lattice().lattice(), [&] {
                                       return std::vector<glm::vec3>(self.ffd.targets().begin(),
                                                                     self.ffd.targets().end());
                                   });
                               })
        .def(
            "evaluate",
            [](PyFfd& self, const std::optional<FloatArray>& points, const std::optional<FloatArray>& weights,
               float envelope, const py::object& out) {
                return evaluateBound(self.ffd, self.rest, self.mutex, points, weights, envelope,
                                     "Ffd.evaluate", out);
            },
            py::arg("points") = py::none(), py::arg("weights") = py::none(), py::arg("envelope") = 1.0f,
            py::arg("out") = py::none(),
            "Deform points (N, 3), the bound rest points when None; returns (N, 3) float32: a new array, or\n"
            "out, a writable (N, 3) float32 array reused from call to call (no allocation; it may be "
            "points).");

    py::class_<PyFfdFrames>(m, "FfdFrames",
                            "FFD with coordinate-frame features, bound once, evaluated many times.")
        .def(py::init([](const FloatArray& origin, const FloatArray& axes, const IntArray& divisions,
                         const std::string& basis, const std::string& outside, const std::string& ends) {
                 const Lattice l = latticeOf(origin, axes, divisions, "FfdFrames");
                 return std::make_unique<PyFfdFrames>(
                     FfdFrames(l, optionsOf(basis, outside, ends, "FfdFrames")));
             }),
             py::arg("origin"), py::arg("axes"), py::arg("divisions"), py::arg("basis") = "bernstein",
             py::arg("outside") = "none", py::arg("ends") = "extrapolate")
        .def(
            "bind",
            [](PyFfdFrames& self, const FloatArray& points) {
                std::vector<glm::vec3> rest = pointsOf(points, "FfdFrames.bind", "points");
                py::gil_scoped_release release;
                const Lock lock(self.mutex);
                self.frames.bind(rest);
                self.rest = std::move(rest);
            },
            py::arg("points"))
        .def(
            "set_source_frames",
            [](PyFfdFrames& self, const FloatArray& origins, const FloatArray& bases) {
                const auto frames = framesOf(origins, bases, self.frames.lattice().lattice(),
                                             "FfdFrames.set_source_frames", "origins", "bases");
                const Lock lock(self.mutex);
                self.frames.setSourceFrames(frames);
            },
            py::arg("origins"), py::arg("bases"))
        .def(
            "set_target_frames",
            [](PyFfdFrames& self, const FloatArray& origins, const FloatArray& bases) {
                const auto frames = framesOf(origins, bases, self.frames.lattice().lattice(),
                                             "FfdFrames.set_target_frames", "origins", "bases");
                const Lock lock(self.mutex);
                self.frames.setTargetFrames(frames);
            },
            py::arg("origins"), py::arg("bases"),
            "origins (l+1, m+1, n+1, 3), bases (l+1, m+1, n+1, 3, 3) rows.")
        .def(
            "evaluate",
            [](PyFfdFrames& self, const std::optional<FloatArray>& points,
               const std::optional<FloatArray>& weights, float envelope, const py::object& out) {
                return evaluateBound(self.frames, self.rest, self.mutex, points, weights, envelope,
                                     "FfdFrames.evaluate", out);
            },
            py::arg("points") = py::none(), py::arg("weights") = py::none(), py::arg("envelope") = 1.0f,
            py::arg("out") = py::none(), "As Ffd.evaluate.");
}

}  // namespace deformkit::python
