// The `deformkit` Python module: numpy float32 in and out, views instead of copies where the data
// lives in a C++ object, deformkit.Error (and subclasses) for every bad input.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstring>
#include <exception>
#include <new>
#include <utility>

#include "bindings.h"
#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/interrupter.h"
#include "deformkit/io/image.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/preview.h"
#include "deformkit/io/udim.h"
#include "deformkit/version.h"
#include "numpy_support.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

// A numpy view of `count` rows of `cols` values owned by `owner` (kept alive by the array).
template <class T>
py::array view(const T* data, size_t count, size_t cols, py::handle owner, bool writeable) {
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(count)},
        strides{static_cast<py::ssize_t>(sizeof(T) * cols)};
    if (cols > 1) {
        shape.push_back(static_cast<py::ssize_t>(cols));
        strides.push_back(sizeof(T));
    }
    py::array a(py::dtype::of<T>(), shape, strides, data, owner);
    if (!writeable) a.attr("setflags")(py::arg("write") = false);
    return a;
}

geom::Mesh makeMesh(const FloatArray& points, const IntArray& faceCounts, const IntArray& faceIndices,
                    const std::optional<FloatArray>& uvs, const std::optional<IntArray>& uvIndices) {
    return meshOf(points, faceCounts, faceIndices, uvs, uvIndices, "Mesh", "Mesh");
}

io::PixelType pixelType(const std::string& name) {
    if (name == "auto") return io::PixelType::Auto;
    if (name == "uint8") return io::PixelType::UInt8;
    if (name == "uint16") return io::PixelType::UInt16;
    if (name == "half") return io::PixelType::Half;
    if (name == "float") return io::PixelType::Float;
    throw InvalidInput(formatError("write_image", "type", "'" + name + "' is not a pixel type",
                                   "auto, uint8, uint16, half or float"));
}

// The Python errors of the library's, made once at import.
struct ErrorTypes {
    PyObject* error = nullptr;
    PyObject* io = nullptr;
    PyObject* parse = nullptr;
    PyObject* invalid = nullptr;
    PyObject* topology = nullptr;
    PyObject* cancelled = nullptr;
};
ErrorTypes& errorTypes() {
    static ErrorTypes types;
    return types;
}

// Raises `type` with `message` decoded from UTF-8, a byte that is not UTF-8 (a file name in another encoding,
// a Latin-1 key in a scene) shown as its \xNN escape: PyErr_SetString would leave the error without a
// message, and a surrogate escape would fail to print.
void raise(PyObject* type, const char* message) {
    PyObject* text =
        PyUnicode_DecodeUTF8(message, static_cast<Py_ssize_t>(std::strlen(message)), "backslashreplace");
    if (text == nullptr) {  // only when memory runs out
        PyErr_Clear();
        PyErr_SetNone(type);
        return;
    }
    PyErr_SetObject(type, text);
    Py_DECREF(text);
}

void translateErrors(std::exception_ptr thrown) {
    const ErrorTypes& types = errorTypes();
    try {
        std::rethrow_exception(thrown);
    } catch (const TopologyError& e) {
        raise(types.topology, e.what());
    } catch (const InvalidInput& e) {
        raise(types.invalid, e.what());
    } catch (const ParseError& e) {
        raise(types.parse, e.what());
    } catch (const IoError& e) {
        raise(types.io, e.what());
    } catch (const Cancelled& e) {
        raise(types.cancelled, e.what());
    } catch (const Error& e) {
        raise(types.error, e.what());
    } catch (const std::bad_alloc& e) {
        raise(PyExc_MemoryError, e.what());
    }
}

}  // namespace

py::str textOf(const std::string& bytes) {
    PyObject* text =
        PyUnicode_DecodeUTF8(bytes.data(), static_cast<Py_ssize_t>(bytes.size()), "surrogateescape");
    if (text == nullptr) throw py::error_already_set();
    return py::reinterpret_steal<py::str>(text);
}

}  // namespace deformkit::python

PYBIND11_MODULE(deformkit, m) {
    using namespace deformkit;
    using namespace deformkit::python;
    m.doc() = "DeformKit: production deformers. Meshes and images as numpy float32 arrays.";
    m.attr("__version__") = kVersionString;

    ErrorTypes& types = errorTypes();
    const auto addError = [&](const char* name, PyObject* base) {
        py::exception<Error> type(m, name, base);
        return type.release().ptr();  // held for the life of the process, as the module's other types
    };
    types.error = addError("Error", PyExc_RuntimeError);
    types.io = addError("IoError", types.error);
    types.parse = addError("ParseError", types.error);
    types.invalid = addError("InvalidInput", types.error);
    types.topology = addError("TopologyError", types.invalid);
    types.cancelled = addError("Cancelled", types.error);
    py::register_exception_translator(translateErrors);

    py::class_<geom::Mesh>(
        m, "Mesh", "A polygon mesh: float32 points, faces as counts + indices, optional face-varying UVs.")
        .def(py::init(&makeMesh), py::arg("points"), py::arg("face_counts"), py::arg("face_indices"),
             py::arg("uvs") = py::none(), py::arg("uv_indices") = py::none(),
             "points (N, 3) float32; face_counts (F,) int32; face_indices (sum of counts,) int32;\n"
             "uvs (K, 2) float32 and uv_indices (sum of counts,) int32, both or neither.")
        .def_property_readonly(
            "points",
            [](py::object self) {
                auto& mesh = self.cast<geom::Mesh&>();
                return view(reinterpret_cast<const float*>(mesh.points().data()), mesh.points().size(), 3,
                            self, true);
            },
            "(N, 3) float32 view of the positions; writable, the mesh sees the changes")
        .def_property_readonly("face_counts",
                               [](py::object self) {
                                   const auto& mesh = self.cast<const geom::Mesh&>();
                                   return view(mesh.faceCounts().data(), mesh.faceCounts().size(), 1, self,
                                               false);
                               })
        .def_property_readonly("face_indices",
                               [](py::object self) {
                                   const auto& mesh = self.cast<const geom::Mesh&>();
                                   return view(mesh.faceIndices().data(), mesh.faceIndices().size(), 1, self,
                                               false);
                               })
        .def_property_readonly(
            "uvs",
            [](py::object self) -> py::object {
                auto& mesh = self.cast<geom::Mesh&>();
                if (!mesh.hasUVs()) return py::none();
                return view(reinterpret_cast<const float*>(mesh.uvs().data()), mesh.uvs().size(), 2, self,
                            true);
            },
            "(K, 2) float32 view of the UVs, or None")
        .def_property_readonly(
            "uv_indices",
            [](py::object self) -> py::object {
                const auto& mesh = self.cast<const geom::Mesh&>();
                if (!mesh.hasUVs()) return py::none();
                return view(mesh.uvIndices().data(), mesh.uvIndices().size(), 1, self, false);
            },
            "(corners,) int32 view of each face corner's UV index (-1 on every corner of "
            "a face without UVs), or None")
        .def_property_readonly("num_vertices", &geom::Mesh::numVertices)
        .def_property_readonly("num_faces", &geom::Mesh::numFaces)
        .def("udim_tiles", &geom::Mesh::udimTiles, "UDIM tiles the UV faces touch")
        .def("is_manifold",
             [](const geom::Mesh& mesh) {
                 const py::gil_scoped_release release;  // a large mesh's half-edges take seconds
                 return mesh.halfEdges().report().isManifold();
             })
        .def("__repr__", [](const geom::Mesh& mesh) {
            return "<deformkit.Mesh " + std::to_string(mesh.numVertices()) + " vertices, " +
                   std::to_string(mesh.numFaces()) + " faces" + (mesh.hasUVs() ? ", uvs>" : ">");
        });

    m.def(
        "read_mesh",
        [](const std::filesystem::path& path) {
            py::gil_scoped_release release;
            return io::readMesh(path).mesh;
        },
        py::arg("path"),
        "Read a mesh: OBJ, glTF (.gltf, .glb), FBX, PLY or Collada (.dae); docs/io.md says what each gives.");
    m.def(
        "write_mesh",
        [](const std::filesystem::path& path, const geom::Mesh& mesh) {
            py::gil_scoped_release release;
            io::writeObj(path, mesh);
        },
        py::arg("path"), py::arg("mesh"), "Write an OBJ file atomically.");

    m.def(
        "read_image",
        [](const std::filesystem::path& path, int32_t channels) {
            if (channels < 0) {
                throw InvalidInput(formatError("read_image", "channels", "is " + std::to_string(channels),
                                               "0 (every channel the file has) or a channel count > 0"));
            }
            io::Image img;
            {
                py::gil_scoped_release release;
                img = io::readImage(path, {channels, ""});
            }
            return imageArray(std::move(img));
        },
        py::arg("path"), py::arg("channels") = 0,
        "Read an image as a (H, W, C) float32 array; channels > 0 requires that count.");
    m.def(
        "read_image_info",
        [](const std::filesystem::path& path) {
            io::ImageInfo info;
            {
                py::gil_scoped_release release;
                info = io::readImageInfo(path);
            }
            py::dict attributes;
            for (const auto& [name, value] : info.attributes)
                attributes[textOf(name)] = textOf(value);
            py::list channelNames;
            for (const std::string& name : info.channelNames)
                channelNames.append(textOf(name));
            using namespace pybind11::literals;
            return py::dict("width"_a = info.width, "height"_a = info.height, "channels"_a = info.channels,
                            "format"_a = info.format, "pixel_type"_a = info.pixelType,
                            "channel_names"_a = channelNames, "attributes"_a = attributes);
        },
        py::arg("path"),
        "Read an image's header only: a dict of width, height, channels, format (\"openexr\", \"png\", "
        "...),\n"
        "pixel_type (\"half\", \"float\", \"uint8\", ...), channel_names and attributes ({name: value}, the\n"
        "header's string attributes, e.g. the provenance of a redirect map).");
    m.def(
        "write_image",
        [](const std::filesystem::path& path, const FloatArray& array, const std::string& type,
           const std::map<std::string, std::string>& attributes) {
            io::ImageWriteOptions options;
            options.type = pixelType(type);
            options.attributes.assign(attributes.begin(), attributes.end());
            io::Image img = imageOf(array, "write_image", "array");
            py::gil_scoped_release release;
            io::writeImage(path, img, options);
        },
        py::arg("path"), py::arg("array"), py::arg("type") = "auto",
        py::arg("attributes") = std::map<std::string, std::string>{},
        "Write a (H, W) or (H, W, C) float array atomically; type: auto, uint8, uint16, half, float (auto: "
        "half\n"
        "for EXR, float when a value would round to inf as a half; 8-bit for other formats).");
    m.def(
        "udim_tiles",
        [](const std::filesystem::path& pattern) {
            py::dict out;
            for (const auto& f : io::findUdimFiles(pattern))
                out[py::int_(f.tile)] = f.path.string();
            return out;
        },
        py::arg("pattern"), "Existing tiles of a UDIM pattern as {tile: path}, sorted by tile.");
    m.def("expand_udim", &io::expandUdim, py::arg("pattern"), py::arg("tile"));

    m.def(
        "render_preview",
        [](const geom::Mesh& mesh, std::optional<std::string> texture, int32_t width, int32_t height,
           bool edges) {
            io::PreviewOptions options;
            options.width = width;
            options.height = height;
            options.drawEdges = edges;
            io::Image img;
            {
                py::gil_scoped_release release;
                std::optional<io::PreviewTexture> tex;
                if (texture) tex = io::loadPreviewTexture(*texture);
                img = io::renderPreview(mesh, options, tex ? &*tex : nullptr);
            }
            return imageArray(std::move(img));
        },
        py::arg("mesh"), py::arg("texture") = py::none(), py::arg("width") = 960, py::arg("height") = 720,
        py::arg("edges") = false, "Render a shaded preview; returns (H, W, 3) float32.");

    m.def(
        "make_grid",
        [](int32_t cx, int32_t cy, float sx, float sy) {
            // Named by the keywords (the library names its own fields, "primitive: cellsX").
            for (const auto& [name, cells] : {std::pair{"cells_x", cx}, std::pair{"cells_y", cy}}) {
                if (cells < 1) {
                    throw InvalidInput(
                        formatError("make_grid", name, "is " + std::to_string(cells), "at least 1"));
                }
            }
            for (const auto& [name, size] : {std::pair{"size_x", sx}, std::pair{"size_y", sy}}) {
                if (!std::isfinite(size)) {
                    throw InvalidInput(
                        formatError("make_grid", name, "is " + numberText(size), "a finite size"));
                }
            }
            return geom::makeGrid({cx, cy, sx, sy});
        },
        py::arg("cells_x") = 16, py::arg("cells_y") = 16, py::arg("size_x") = 1.0f, py::arg("size_y") = 1.0f);
    python::bindWarpEngine(m);
    python::bindFfd(m);
    python::bindBarr(m);
    python::bindWires(m);
    python::bindMeshWarp(m);
    python::bindBeierNeely(m);
    python::bindSlide(m);
    python::bindUvWarp(m);
    python::bindHost(m);
    python::bindPtex(m);
    python::bindPointCache(m);
    python::bindShotReport(m);

    m.def(
        "make_capped_tube", [] { return geom::makeCappedTube(); },
        "The demo's capped tube (UDIM 1001-1002).");
}
