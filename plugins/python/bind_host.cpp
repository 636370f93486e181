// Python bindings of the host layer every host shares (core/include/deformkit/host/): the deformer types,
// DeformerStack (rest mesh, entries with named parameters, painted weights and envelopes, bind on demand),
// scenes (readScene) and SceneEvaluator. A plugin host (the Blender add-on) drives the same code as the
// standalone host through these. Positions are numpy float32 (n, 3); parameter values are doubles.
//
// The stack and the evaluator run without the GIL during bind and evaluation: each carries its Python
// object's mutex (object_lock.h).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "deformkit/uvwarp/options.h"
#include "numpy_support.h"
#include "object_lock.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

// Scenes read from Python take every weight source, Ptex files included (as the CLI does).
scene::Scene readSceneFile(const std::filesystem::path& path) {
    scene::SceneReadOptions options;
    options.ptexWeights = ptex::weightsFromPtex;
    return scene::readScene(path, options);
}

using host::DeformerStack;
using scene::Scene;
using scene::SceneEvaluator;

struct PyStack {
    DeformerStack stack;
    std::mutex mutex;
};

struct PyEvaluator {
    explicit PyEvaluator(Scene scene) : evaluator(std::move(scene)) {}
    SceneEvaluator evaluator;
    std::mutex mutex;
};

// A parameter value from Python: a number, or any sequence or array of numbers (flattened in C order, so
// an (n, 3) array of points gives x, y, z of each point in turn). nullopt for anything else, `problem` then
// saying what it is ("is a bool", "is an array of complex128 values", "is a list that is not numeric").
std::optional<std::vector<double>> valuesOf(py::handle value, std::string& problem) {
    problem = "is " + aTypeName(value);
    if (isBool(value)) return std::nullopt;  // True is an int to Python, not a parameter value
    if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) {
        return std::vector<double>{value.cast<double>()};
    }
    // numpy would read "1.5" as 1.5, None as NaN, True as 1 and drop an imaginary part: none is a value.
    py::array a;
    if (!numericArray(value, a, problem)) return std::nullopt;
    if (!problem.empty()) return std::nullopt;
    auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
    if (!values) return std::nullopt;
    return std::vector<double>(values.data(), values.data() + values.size());
}

// Painted weights from Python: None or an empty sequence for none (empty), else a 1-D array-like of
// numbers. On failure `problem` says what was found and nullopt is returned.
std::optional<std::vector<float>> weightValuesOf(py::handle weights, std::string& problem) {
    if (weights.is_none()) return std::vector<float>{};
    if (!py::isinstance<py::str>(weights) && !py::isinstance<py::bytes>(weights)) {
        if (const std::optional<FloatArray> a = floatArrayOf(weights)) {
            if (!a->problem.empty()) {
                problem = a->problem;
                return std::nullopt;
            }
            if (a->size() == 0) return std::vector<float>{};
            if (a->ndim() == 1) return std::vector<float>(a->data(), a->data() + a->size());
            problem = "has shape " + shapeOf(*a);
            return std::nullopt;
        }
    }
    problem = "is " + aTypeName(weights);
    return std::nullopt;
}

py::array_t<float> floatArray(std::span<const float> values) {
    py::array_t<float> out(static_cast<py::ssize_t>(values.size()));
    if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(float));
    return out;
}

void checkPointsShape(const py::array& a, const char* source) {
    if (a.ndim() != 2 || a.shape(1) != 3) {
        throw InvalidInput(formatError(source, "points", "has shape " + shapeOf(a), "(n, 3)"));
    }
}

// The buffer of an array evaluate_inplace may write into: float32, (n, 3), C-contiguous, writeable, aligned.
std::span<glm::vec3> inplacePoints(py::handle points) {
    const char* source = "DeformerStack.evaluate_inplace";
    const char* expected = "a writeable C-contiguous (n, 3) float32 numpy array (evaluate() takes any other)";
    if (!py::isinstance<py::array>(points)) {
        throw InvalidInput(formatError(source, "points", "is " + aTypeName(points), expected));
    }
    auto a = py::reinterpret_borrow<py::array>(points);
    if (!py::isinstance<py::array_t<float>>(a)) {
        throw InvalidInput(
            formatError(source, "points", "has dtype " + std::string(py::str(a.dtype())), expected));
    }
    checkPointsShape(a, source);
    if (!(a.flags() & py::array::c_style)) {
        throw InvalidInput(formatError(source, "points", "is not C-contiguous", expected));
    }
    if (!a.writeable()) throw InvalidInput(formatError(source, "points", "is read-only", expected));
    auto* data = static_cast<float*>(a.mutable_data());
    if (reinterpret_cast<std::uintptr_t>(data) % alignof(glm::vec3) != 0) {
        throw InvalidInput(formatError(source, "points", "is not aligned", expected));
    }
    return {reinterpret_cast<glm::vec3*>(data), static_cast<size_t>(a.shape(0))};
}

py::list parameterList(const std::vector<host::ParamInfo>& infos) {
    py::list out;
    using namespace pybind11::literals;
    for (const host::ParamInfo& p : infos) {
        out.append(py::dict("name"_a = p.name, "components"_a = p.components, "rebinds"_a = p.rebinds,
                            "doc"_a = p.doc, "stride"_a = p.stride));
    }
    return out;
}

const scene::SceneObject& sceneObject(const Scene& scene, size_t object) {
    if (object >= scene.objects.size()) {
        throw InvalidInput(formatError(scene.source, "object " + std::to_string(object), "does not exist",
                                       "an index below " + std::to_string(scene.objects.size())));
    }
    return scene.objects[object];
}

std::vector<std::string> objectNames(const Scene& scene) {
    std::vector<std::string> names;
    for (const scene::SceneObject& o : scene.objects)
        names.push_back(o.name);
    return names;
}

py::list entryList(const scene::SceneObject& object) {
    py::list out;
    for (const scene::SceneDeformer& d : object.stack) {
        py::dict e;
        e["type"] = d.type;
        e["label"] = d.label;
        e["path"] = d.path;
        out.append(std::move(e));
    }
    if (object.uvwarp) {
        py::dict e;
        e["type"] = "uvwarp";
        e["label"] = object.uvwarp->label;
        e["path"] = object.uvwarp->path;
        e["options"] = uvwarpOptionsDict(object.uvwarp->options, false);
        e["preset"] = object.uvwarp->preset
                          ? py::object(py::str(std::string(uvwarp::presetName(*object.uvwarp->preset))))
                          : py::object(py::none());
        out.append(std::move(e));
    }
    return out;
}

// A stack entry's index from Python: a negative one (Python's from-the-end) is named as the stack names one
// past its end, not left to the int conversion's TypeError.
size_t entryIndex(int64_t entry) {
    if (entry < 0) {
        throw InvalidInput(formatError("stack", "entry " + std::to_string(entry), "does not exist",
                                       "an index from 0, in stack order"));
    }
    return static_cast<size_t>(entry);
}

}  // namespace

void bindHost(py::module_& m) {
    using namespace pybind11::literals;

    m.def(
        "deformer_types",
        [] {
            std::vector<std::string> out;
            for (const host::DeformerType& t : host::deformerTypes())
                out.emplace_back(t.name);
            return out;
        },
        "The deformer type names DeformerStack.add takes, in alphabetical order.");

    py::class_<PyStack>(
        m, "DeformerStack",
        "Deformers over one rest mesh, each entry with painted weights and an envelope (Maya's\n"
        "rule out = in + envelope * w * (deformed - in)); entries bind to the rest mesh only when\n"
        "the rest mesh or one of their [bind] parameters changes. The host layer every host\n"
        "shares (deformkit/host/stack.h); parameters by name as in host/deformers.h.")
        .def(py::init<>())
        .def(
            "set_rest",
            [](PyStack& s, const geom::Mesh& rest) {
                Lock lock(s.mutex);
                s.stack.setRest(rest);
            },
            "mesh"_a, "The rest mesh every entry binds to (copied). Marks every entry for a new bind.")
        .def_property_readonly("has_rest",
                               [](PyStack& s) {
                                   Lock lock(s.mutex);
                                   return s.stack.hasRest();
                               })
        .def(
            "add",
            [](PyStack& s, const std::string& type, std::optional<std::string> label) {
                Lock lock(s.mutex);
                const std::string entry = "stack entry " + std::to_string(s.stack.size());
                std::unique_ptr<host::Deformer> d;
                try {
                    d = host::makeDeformer(type, label ? *label : type + std::to_string(s.stack.size() + 1));
                } catch (const InvalidInput& e) {
                    throw InvalidInput(entry + ": " + e.what());
                }
                return s.stack.add(std::move(d));
            },
            "type"_a, "label"_a = py::none(),
            "Appends a deformer of `type` (deformer_types()) with default parameters, envelope 1 and no\n"
            "weights; returns its index. label: unique in the stack; default the type followed by the\n"
            "entry number from 1 ('twist1'), as in scenes.")
        .def_property_readonly("size",
                               [](PyStack& s) {
                                   Lock lock(s.mutex);
                                   return s.stack.size();
                               })
        .def("__len__",
             [](PyStack& s) {
                 Lock lock(s.mutex);
                 return s.stack.size();
             })
        .def(
            "labels",
            [](PyStack& s) {
                Lock lock(s.mutex);
                std::vector<std::string> out;
                for (size_t i = 0; i < s.stack.size(); ++i)
                    out.push_back(s.stack.deformer(i).label());
                return out;
            },
            "The entries' labels in stack order.")
        .def(
            "type",
            [](PyStack& s, int64_t entry) {
                const size_t index = entryIndex(entry);
                Lock lock(s.mutex);
                return s.stack.deformer(index).type();
            },
            "index"_a, "The deformer type of entry `index`.")
        .def(
            "find",
            [](PyStack& s, const std::string& label) {
                Lock lock(s.mutex);
                return s.stack.find(label);
            },
            "label"_a, "The index of the entry labelled `label`.")
        .def(
            "parameters",
            [](PyStack& s, int64_t entry) {
                const size_t index = entryIndex(entry);
                std::vector<host::ParamInfo> infos;
                {
                    Lock lock(s.mutex);
                    infos = s.stack.parameters(index);
                }
                return parameterList(infos);
            },
            "index"_a,
            "Entry `index`'s parameters as dicts {name, components, rebinds, doc, stride}: 'envelope' "
            "first,\n"
            "then the deformer's in a good setting order (bind-time inputs first). rebinds: a change needs\n"
            "a new bind; stride > 0: resizable, any positive multiple of stride values.")
        .def(
            "set",
            [](PyStack& s, int64_t entry, const std::string& name, py::handle value) {
                const size_t index = entryIndex(entry);
                std::string found;
                const std::optional<std::vector<double>> values = valuesOf(value, found);
                Lock lock(s.mutex);
                if (!values) {
                    throw InvalidInput(formatError(s.stack.entryName(index), "parameter '" + name + "'",
                                                   found, "a number or a sequence of numbers"));
                }
                s.stack.set(index, name, *values);
            },
            "index"_a, "name"_a, "value"_a,
            "Sets a parameter ('envelope' or the deformer's): a number or a sequence / array of numbers\n"
            "(flattened in C order). Setting an animatable parameter never rebinds.")
        .def(
            "get",
            [](PyStack& s, int64_t entry, const std::string& name) {
                const size_t index = entryIndex(entry);
                Lock lock(s.mutex);
                return s.stack.get(index, name);
            },
            "index"_a, "name"_a, "A parameter's value as a list of floats.")
        .def(
            "set_weights",
            [](PyStack& s, int64_t entry, py::handle weights) {
                const size_t index = entryIndex(entry);
                std::string problem;
                std::optional<std::vector<float>> values = weightValuesOf(weights, problem);
                Lock lock(s.mutex);
                if (!values) {
                    throw InvalidInput(
                        formatError(s.stack.entryName(index), "weights", problem,
                                    "a 1-D float array, one per rest vertex, or None for none"));
                }
                s.stack.setWeights(index, std::move(*values));
            },
            "index"_a, "weights"_a,
            "Painted weights of entry `index`: one finite value per rest vertex (not clamped), or None / an\n"
            "empty sequence for all 1.")
        .def(
            "weights",
            [](PyStack& s, int64_t entry) {
                const size_t index = entryIndex(entry);
                std::vector<float> weights;
                {
                    Lock lock(s.mutex);
                    const std::span<const float> w = s.stack.weights(index);
                    weights.assign(w.begin(), w.end());
                }
                return floatArray(weights);
            },
            "index"_a, "A copy of entry `index`'s painted weights, (n,) float32; empty when none.")
        .def(
            "set_envelope",
            [](PyStack& s, int64_t entry, double envelope) {
                const size_t index = entryIndex(entry);
                Lock lock(s.mutex);
                s.stack.setEnvelope(index, envelope);
            },
            "index"_a, "envelope"_a, "Animatable, any finite value; 0 skips the entry.")
        .def(
            "envelope",
            [](PyStack& s, int64_t entry) {
                const size_t index = entryIndex(entry);
                Lock lock(s.mutex);
                return s.stack.envelope(index);
            },
            "index"_a)
        .def(
            "is_active",
            [](PyStack& s, int64_t entry) {
                const size_t index = entryIndex(entry);
                Lock lock(s.mutex);
                return s.stack.isActive(index);
            },
            "index"_a, "False when the entry is skipped: envelope 0 or all painted weights 0.")
        .def(
            "bind",
            [](PyStack& s) {
                py::gil_scoped_release release;
                Lock lock(s.mutex);
                s.stack.bind();
            },
            "Binds every entry that needs it (evaluate does this on its own).")
        .def(
            "evaluate",
            [](PyStack& s, const FloatArray& points) {
                requireFloats(points, "DeformerStack.evaluate", "points");
                checkPointsShape(points, "DeformerStack.evaluate");
                py::array_t<float> out({points.shape(0), py::ssize_t{3}});
                const auto n = static_cast<size_t>(points.shape(0));
                const std::span<const glm::vec3> in(reinterpret_cast<const glm::vec3*>(points.data()), n);
                const std::span<glm::vec3> to(reinterpret_cast<glm::vec3*>(out.mutable_data()), n);
                {
                    py::gil_scoped_release release;
                    Lock lock(s.mutex);
                    s.stack.evaluate(in, to);
                }
                return out;
            },
            "points"_a,
            "Deforms points (n, 3), one per rest vertex (the rest positions or an upstream stage's output),\n"
            "through every active entry; returns a new (n, 3) float32 array, the input unchanged.")
        .def(
            "evaluate_inplace",
            [](PyStack& s, py::handle points) {
                const std::span<glm::vec3> p = inplacePoints(points);
                py::gil_scoped_release release;
                Lock lock(s.mutex);
                s.stack.evaluate(p);
            },
            "points"_a,
            "Deforms a writeable C-contiguous (n, 3) float32 array in place (a DCC's foreach_get /\n"
            "foreach_set buffer). Unchanged when an error is raised.")
        .def_property_readonly(
            "bind_count",
            [](PyStack& s) {
                Lock lock(s.mutex);
                return s.stack.bindCount();
            },
            "Binds done by this stack in total.")
        .def(
            "bind_count_of",
            [](PyStack& s, int64_t entry) {
                const size_t index = entryIndex(entry);
                Lock lock(s.mutex);
                return s.stack.bindCount(index);
            },
            "index"_a, "Binds done by entry `index`.")
        .def("__repr__", [](PyStack& s) {
            Lock lock(s.mutex);
            std::string r = "<deformkit.DeformerStack " + std::to_string(s.stack.size()) + " entries";
            for (size_t i = 0; i < s.stack.size(); ++i) {
                const host::Deformer& d = s.stack.deformer(i);
                r += (i ? ", " : ": ") + d.type() + " '" + d.label() + "'";
            }
            return r + ">";
        });

    py::class_<Scene>(m, "Scene",
                      "A parsed DeformKit scene (docs/scene.md): objects, each a rest mesh under a deformer "
                      "stack.")
        .def_property_readonly("source", [](const Scene& s) { return s.source; })
        .def_property_readonly("first_frame", [](const Scene& s) { return s.firstFrame; })
        .def_property_readonly("last_frame", [](const Scene& s) { return s.lastFrame; })
        .def_property_readonly("num_objects", [](const Scene& s) { return s.objects.size(); })
        .def("object_names", &objectNames)
        .def(
            "rest_mesh", [](const Scene& s, size_t object) { return sceneObject(s, object).rest; },
            "object_index"_a,
            "A copy of the object's rest mesh (connectivity and UVs for the evaluated points).")
        .def(
            "entries", [](const Scene& s, size_t object) { return entryList(sceneObject(s, object)); },
            "object_index"_a,
            "The object's stack entries as dicts {type, label, path}; a UV-warp stage, last, also has\n"
            "options (every UV-warp option as the scene sets it, {camelCase name: value}) and preset (the\n"
            "library's preset it starts from, 'shot' or 'live', or None).");

    m.def(
        "read_scene",
        [](const std::filesystem::path& path) {
            py::gil_scoped_release release;
            return readSceneFile(path);
        },
        "path"_a, "Reads and checks a scene file (meshes and weights files load relative to it).");

    py::class_<PyEvaluator>(
        m, "SceneEvaluator",
        "Evaluates a scene frame after frame as a DCC does: one DeformerStack per object, "
        "built\n"
        "once; each frame sets the animated parameters and envelopes and evaluates.")
        .def(py::init([](const Scene& scene) {
                 py::gil_scoped_release release;
                 return std::make_unique<PyEvaluator>(scene);
             }),
             "scene"_a)
        .def(py::init([](const std::filesystem::path& path) {
                 py::gil_scoped_release release;
                 return std::make_unique<PyEvaluator>(readSceneFile(path));
             }),
             "path"_a, "Reads the scene file, then builds the stacks.")
        .def_property_readonly("num_objects",
                               [](PyEvaluator& e) {
                                   Lock lock(e.mutex);
                                   return e.evaluator.numObjects();
                               })
        .def_property_readonly("first_frame",
                               [](PyEvaluator& e) {
                                   Lock lock(e.mutex);
                                   return e.evaluator.scene().firstFrame;
                               })
        .def_property_readonly("last_frame",
                               [](PyEvaluator& e) {
                                   Lock lock(e.mutex);
                                   return e.evaluator.scene().lastFrame;
                               })
        .def("object_names",
             [](PyEvaluator& e) {
                 Lock lock(e.mutex);
                 return objectNames(e.evaluator.scene());
             })
        .def(
            "rest_mesh",
            [](PyEvaluator& e, size_t object) {
                Lock lock(e.mutex);
                return sceneObject(e.evaluator.scene(), object).rest;
            },
            "object_index"_a,
            "A copy of the object's rest mesh (connectivity and UVs for the evaluated points).")
        .def(
            "evaluate",
            [](PyEvaluator& e, size_t object, double frame) {
                // The output is allocated first: the vertex count is the scene's rest mesh's, which a
                // Python host cannot change.
                size_t n = 0;
                {
                    Lock lock(e.mutex);
                    n = static_cast<size_t>(sceneObject(e.evaluator.scene(), object).rest.numVertices());
                }
                py::array_t<float> out({static_cast<py::ssize_t>(n), py::ssize_t{3}});
                auto* to = out.mutable_data();
                {
                    py::gil_scoped_release release;
                    Lock lock(e.mutex);
                    const std::span<const glm::vec3> points = e.evaluator.evaluate(object, frame).points();
                    if (points.size() != n) {
                        throw InvalidInput(formatError("SceneEvaluator.evaluate",
                                                       "object " + std::to_string(object),
                                                       "has " + std::to_string(points.size()) + " points",
                                                       std::to_string(n) + ", as its rest mesh"));
                    }
                    if (n > 0) std::memcpy(to, points.data(), n * sizeof(glm::vec3));
                }
                return out;
            },
            "object_index"_a, "frame"_a,
            "The object's deformed points at `frame` (fractional frames allowed), a new (n, 3) float32 "
            "array.")
        .def(
            "bind_count",
            [](PyEvaluator& e, size_t object) {
                Lock lock(e.mutex);
                return e.evaluator.stack(object).bindCount();
            },
            "object_index"_a, "Binds done by the object's stack so far.");
}

}  // namespace deformkit::python
