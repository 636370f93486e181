// Ptex files from Python: read_ptex, write_ptex, ptex_vertex_values.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bindings.h"
#include "deformkit/error.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "numpy_support.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

using ptex::DataType;

const char* typeName(DataType type) {
    switch (type) {
        case DataType::UInt8:
            return "u8";
        case DataType::UInt16:
            return "u16";
        case DataType::Half:
            return "half";
        case DataType::Float:
            return "float";
    }
    return "?";
}

py::dtype dtypeOf(DataType type) {
    switch (type) {
        case DataType::UInt8:
            return py::dtype("uint8");
        case DataType::UInt16:
            return py::dtype("uint16");
        case DataType::Half:
            return py::dtype("float16");
        case DataType::Float:
            return py::dtype("float32");
    }
    return py::dtype("uint8");
}

DataType typeOfDtype(const py::dtype& dtype, const std::string& source) {
    if (dtype.is(py::dtype("uint8"))) return DataType::UInt8;
    if (dtype.is(py::dtype("uint16"))) return DataType::UInt16;
    if (dtype.is(py::dtype("float16"))) return DataType::Half;
    if (dtype.is(py::dtype("float32"))) return DataType::Float;
    throw InvalidInput(formatError(source, "data",
                                   "has dtype " + py::str(static_cast<py::handle>(dtype)).cast<std::string>(),
                                   "uint8, uint16, float16 or float32 texels"));
}

template <class T>
py::array arrayOf(const std::vector<T>& values) {
    py::array_t<T> out(static_cast<py::ssize_t>(values.size()));
    if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
    return out;
}

// Ptex metadata text is bytes, Python text is str: bytes that are not UTF-8 (a key or value written by a
// Latin-1 tool) become surrogate escapes (textOf), so a file reads whatever its encoding and writes back
// byte for byte.
// The bytes of `text` (a str: UTF-8, surrogate escapes back to their bytes); InvalidInput naming `element`
// for anything else.
std::string bytesOf(py::handle text, const std::string& source, const std::string& element) {
    if (!py::isinstance<py::str>(text)) {
        throw InvalidInput(formatError(source, element,
                                       "is of type " + std::string(py::str(text.get_type().attr("__name__"))),
                                       "a str"));
    }
    PyObject* bytes = PyUnicode_AsEncodedString(text.ptr(), "utf-8", "surrogateescape");
    if (bytes == nullptr) {
        PyErr_Clear();
        throw InvalidInput(
            formatError(source, element, "holds a lone surrogate that is no escaped byte",
                        "text that encodes as UTF-8 (or bytes escaped as read_ptex gives them)"));
    }
    std::string out(PyBytes_AS_STRING(bytes), static_cast<size_t>(PyBytes_GET_SIZE(bytes)));
    Py_DECREF(bytes);
    return out;
}

py::object metaValue(const ptex::MetaValue& m) {
    switch (m.type) {
        case ptex::MetaType::String:
            return textOf(m.string);
        case ptex::MetaType::Int8:
            return arrayOf(m.int8s);
        case ptex::MetaType::Int16:
            return arrayOf(m.int16s);
        case ptex::MetaType::Int32:
            return arrayOf(m.int32s);
        case ptex::MetaType::Float:
            return arrayOf(m.floats);
        case ptex::MetaType::Double:
            return arrayOf(m.doubles);
    }
    return py::none();
}

ptex::MetaValue metaFrom(const std::string& key, py::handle value, const std::string& source) {
    if (py::isinstance<py::str>(value))
        return ptex::MetaValue::ofString(key, bytesOf(value, source, "metadata '" + key + "'"));
    // numpy makes None (and any object) a 0-dimensional array of objects: said as what it is.
    if (value.is_none() || (!py::isinstance<py::array>(value) && !py::isinstance<py::sequence>(value))) {
        throw InvalidInput(
            formatError(source, "metadata '" + key + "'",
                        "is " + py::str(py::type::of(value).attr("__name__")).cast<std::string>(),
                        "a string or a 1-D int8/int16/int32/float32/float64 array"));
    }
    const py::array a = py::array::ensure(value);
    if (!a || a.ndim() != 1) {
        throw InvalidInput(formatError(
            source, "metadata '" + key + "'",
            a ? "is an array of " + std::to_string(a.ndim()) + " dimensions" : "is not a string or an array",
            "a string or a 1-D int8/int16/int32/float32/float64 array"));
    }
    const py::dtype dt = a.dtype();
    const auto values = [&](auto tag) {
        using T = decltype(tag);
        const auto typed = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
        return std::vector<T>(typed.data(), typed.data() + typed.size());
    };
    if (dt.is(py::dtype("int8"))) return ptex::MetaValue::ofInt8(key, values(int8_t{}));
    if (dt.is(py::dtype("int16"))) return ptex::MetaValue::ofInt16(key, values(int16_t{}));
    if (dt.is(py::dtype("int32"))) return ptex::MetaValue::ofInt32(key, values(int32_t{}));
    if (dt.is(py::dtype("float32"))) return ptex::MetaValue::ofFloat(key, values(float{}));
    if (dt.is(py::dtype("float64"))) return ptex::MetaValue::ofDouble(key, values(double{}));
    throw InvalidInput(formatError(source, "metadata '" + key + "'",
                                   "has dtype " + py::str(static_cast<py::handle>(dt)).cast<std::string>(),
                                   "int8, int16, int32, float32 or float64"));
}

const std::array<const char*, 3> kBorderModes{"clamp", "black", "periodic"};
const std::array<const char*, 2> kEdgeFilterModes{"none", "tangent_vectors"};

// The index of `d[key]` among `names`, `fallback` when the key is absent.
template <size_t N>
size_t nameIndex(const py::dict& d, const char* key, const std::array<const char*, N>& names, size_t fallback,
                 const std::string& source) {
    if (!d.contains(key)) return fallback;
    const std::string value = py::str(d[key]).cast<std::string>();
    std::string expected;
    for (size_t i = 0; i < N; ++i) {
        if (value == names[i]) return i;
        expected += (i == 0 ? "'" : i + 1 == N ? " or '" : ", '") + std::string(names[i]) + "'";
    }
    throw InvalidInput(formatError(source, key, "is '" + value + "'", expected));
}

py::dict toDict(const ptex::PtexFile& file) {
    py::dict out;
    out["mesh_type"] = file.meshType == ptex::MeshType::Quad ? "quad" : "triangle";
    out["data_type"] = typeName(file.dataType);
    out["channels"] = file.channels;
    out["alpha_channel"] = file.alphaChannel;
    out["u_border_mode"] = kBorderModes[static_cast<size_t>(file.uBorderMode)];
    out["v_border_mode"] = kBorderModes[static_cast<size_t>(file.vBorderMode)];
    out["edge_filter_mode"] = kEdgeFilterModes[static_cast<size_t>(file.edgeFilterMode)];
    py::list faces, data;
    for (size_t f = 0; f < file.faces.size(); ++f) {
        const ptex::FaceInfo& info = file.faces[f];
        py::dict face;
        face["res"] = py::make_tuple(info.ures(), info.vres());
        face["adj_faces"] =
            py::make_tuple(info.adjFaces[0], info.adjFaces[1], info.adjFaces[2], info.adjFaces[3]);
        face["adj_edges"] =
            py::make_tuple(info.adjEdges[0], info.adjEdges[1], info.adjEdges[2], info.adjEdges[3]);
        face["constant"] = info.constant;
        face["subface"] = info.subface;
        faces.append(face);
        const std::vector<py::ssize_t> shape{info.vres(), info.ures(), file.channels};
        const size_t pixel = file.pixelSize();
        if (file.texels[f].empty() && file.constData.size() >= (f + 1) * pixel) {
            // A constant face is its one pixel seen at every texel (numpy.broadcast_to, read-only): a face
            // declared 32768 x 32768 costs its pixel, not 16 GiB. write_ptex writes such a view back as a
            // constant face.
            py::array one(dtypeOf(file.dataType), std::vector<py::ssize_t>{1, 1, file.channels});
            std::memcpy(one.mutable_data(), file.constData.data() + f * pixel, pixel);
            data.append(py::module_::import("numpy").attr("broadcast_to")(one, py::tuple(py::cast(shape))));
            continue;
        }
        const std::vector<uint8_t> texels = ptex::expandedTexels(file, f);
        py::array a(dtypeOf(file.dataType), shape);
        std::memcpy(a.mutable_data(), texels.data(), texels.size());
        data.append(a);
    }
    out["faces"] = faces;
    out["data"] = data;
    py::dict metadata;
    for (const ptex::MetaValue& m : file.metadata)
        metadata[textOf(m.key)] = metaValue(m);
    out["metadata"] = metadata;
    return out;
}

int8_t log2Of(py::ssize_t n, const std::string& source, const std::string& element) {
    int8_t log2 = 0;
    while (log2 < 16 && (py::ssize_t{1} << log2) < n)
        ++log2;
    if (n < 1 || log2 > 15 || (py::ssize_t{1} << log2) != n) {
        throw InvalidInput(formatError(source, element, "is " + std::to_string(n) + " texels across",
                                       "a power of two from 1 to 32768"));
    }
    return log2;
}

// A PtexFile from read_ptex's dict (data required; faces, metadata, alpha_channel optional). With a mesh,
// the faces' adjacency and sub-face flags are the mesh's and its standard metadata is written.
// A key of `d` that is none of `known`: refused naming it (a typo such as 'adjfaces' must not be ignored).
void requireKnownKeys(const py::dict& d, std::initializer_list<std::string_view> known,
                      const std::string& source, const std::string& where) {
    for (const auto& [key, value] : d) {
        const std::string k = py::isinstance<py::str>(key) ? key.cast<std::string>() : std::string();
        if (std::find(known.begin(), known.end(), k) != known.end()) continue;
        std::string list;
        for (const std::string_view name : known)
            list += (list.empty() ? "" : ", ") + std::string(name);
        throw InvalidInput(formatError(source, where + std::string(py::repr(key)), "is not a key it takes",
                                       "one of " + list));
    }
}

ptex::PtexFile fromDict(const py::dict& d, const std::optional<geom::Mesh>& mesh, const std::string& source) {
    // What read_ptex returns, so that its dict writes back; data_type and channels follow from data.
    requireKnownKeys(d,
                     {"data", "alpha_channel", "mesh_type", "u_border_mode", "v_border_mode",
                      "edge_filter_mode", "faces", "metadata", "data_type", "channels"},
                     source, "ptex key ");
    if (!d.contains("data")) {
        throw InvalidInput(formatError(source, "ptex", "has no 'data'", "a list of (vres, ures, C) arrays"));
    }
    const auto data = castArgument<py::list>(d["data"], source, "data", "a list of (vres, ures[, C]) arrays");
    ptex::PtexFile file;
    file.faces.resize(data.size());
    file.texels.resize(data.size());
    std::map<size_t, std::vector<uint8_t>> constantPixels;  // per constant face, its pixel
    for (size_t f = 0; f < data.size(); ++f) {
        const py::array a = py::array::ensure(data[f]);
        const std::string element = "data[" + std::to_string(f) + "]";
        if (!a || (a.ndim() != 2 && a.ndim() != 3)) {
            throw InvalidInput(
                formatError(source, element, "is not a 2-D or 3-D array", "(vres, ures[, C])"));
        }
        const DataType type = typeOfDtype(a.dtype(), source);
        const auto channels = static_cast<int32_t>(a.ndim() == 3 ? a.shape(2) : 1);
        if (f == 0) {
            file.dataType = type;
            file.channels = channels;
        } else if (type != file.dataType || channels != file.channels) {
            throw InvalidInput(formatError(source, element, "differs from data[0] in dtype or channels",
                                           "every face with data[0]'s dtype and channel count"));
        }
        file.faces[f].vlog2 = log2Of(a.shape(0), source, element + " rows");
        file.faces[f].ulog2 = log2Of(a.shape(1), source, element + " columns");
        if (a.strides(0) == 0 && a.strides(1) == 0) {
            // One pixel broadcast over the face (read_ptex's constant faces): written as a constant face,
            // without making the texels.
            std::vector<uint8_t> pixel(static_cast<size_t>(channels) * static_cast<size_t>(a.itemsize()));
            for (int32_t k = 0; k < channels; ++k) {
                const auto* from =
                    static_cast<const uint8_t*>(a.data()) + (a.ndim() == 3 ? k * a.strides(2) : 0);
                std::memcpy(pixel.data() + static_cast<size_t>(k) * a.itemsize(), from, a.itemsize());
            }
            constantPixels.emplace(f, std::move(pixel));
            continue;
        }
        const py::array c = py::array::ensure(a, py::array::c_style);
        file.texels[f].assign(static_cast<const uint8_t*>(c.data()),
                              static_cast<const uint8_t*>(c.data()) + c.nbytes());
    }
    file.constData.assign(file.faces.size() * file.pixelSize(), 0);
    for (const auto& [f, pixel] : constantPixels) {
        std::copy(pixel.begin(), pixel.end(),
                  file.constData.begin() + static_cast<std::ptrdiff_t>(f * pixel.size()));
        file.faces[f].constant = true;
    }
    if (d.contains("alpha_channel"))
        file.alphaChannel =
            castArgument<int32_t>(d["alpha_channel"], source, "alpha_channel", "an int (-1: none)");
    const std::array<const char*, 2> meshTypes{"triangle", "quad"};
    file.meshType = static_cast<ptex::MeshType>(nameIndex(d, "mesh_type", meshTypes, 1, source));
    file.uBorderMode = static_cast<ptex::BorderMode>(nameIndex(d, "u_border_mode", kBorderModes, 0, source));
    file.vBorderMode = static_cast<ptex::BorderMode>(nameIndex(d, "v_border_mode", kBorderModes, 0, source));
    file.edgeFilterMode =
        static_cast<ptex::EdgeFilterMode>(nameIndex(d, "edge_filter_mode", kEdgeFilterModes, 0, source));
    if (mesh) {
        // A mesh's Ptex faces are Catmull-Clark's (quads, N sub-faces per N-gon): a triangle-type file
        // cannot be laid out on it.
        if (file.meshType == ptex::MeshType::Triangle) {
            throw InvalidInput(
                formatError(source, "mesh_type", "is 'triangle' with a mesh",
                            "'quad' (a mesh's Ptex faces are quads and N-gons' sub-faces), or no "
                            "mesh and the faces' adjacency given"));
        }
        const ptex::PtexMesh pm(*mesh, source);
        const std::vector<ptex::FaceInfo> infos = pm.faceInfos(0, 0);
        if (infos.size() != file.faces.size()) {
            throw InvalidInput(formatError(source, "data",
                                           "has " + std::to_string(file.faces.size()) + " faces",
                                           std::to_string(infos.size()) + " Ptex faces of the mesh"));
        }
        for (size_t f = 0; f < infos.size(); ++f) {
            file.faces[f].adjFaces = infos[f].adjFaces;
            file.faces[f].adjEdges = infos[f].adjEdges;
            file.faces[f].subface = infos[f].subface;
        }
    } else if (d.contains("faces")) {
        const auto faces = castArgument<py::list>(d["faces"], source, "faces", "a list of dicts");
        if (faces.size() != file.faces.size()) {
            throw InvalidInput(formatError(source, "faces",
                                           "has " + std::to_string(faces.size()) + " entries",
                                           std::to_string(file.faces.size()) + ", one per face of data"));
        }
        for (size_t f = 0; f < faces.size(); ++f) {
            const std::string element = "faces[" + std::to_string(f) + "]";
            const auto face = castArgument<py::dict>(faces[f], source, element, "a dict");
            requireKnownKeys(face, {"adj_faces", "adj_edges", "subface", "res", "constant"}, source,
                             element + " key ");
            if (face.contains("adj_faces")) {
                const auto adj = castArgument<std::vector<int32_t>>(face["adj_faces"], source,
                                                                    element + "['adj_faces']", "4 ints");
                if (!face.contains("adj_edges")) {
                    throw InvalidInput(
                        formatError(source, element, "has adj_faces but no adj_edges", "both or neither"));
                }
                const auto edges = castArgument<std::vector<int32_t>>(face["adj_edges"], source,
                                                                      element + "['adj_edges']", "4 ints");
                for (const auto& [values, name] :
                     {std::pair{&adj, "adj_faces"}, std::pair{&edges, "adj_edges"}}) {
                    if (values->size() != 4) {
                        throw InvalidInput(formatError(source, element + "['" + name + "']",
                                                       "has " + std::to_string(values->size()) + " entries",
                                                       "4, one per edge"));
                    }
                }
                for (size_t e = 0; e < 4; ++e) {
                    if (edges[e] < 0 || edges[e] > 3) {
                        throw InvalidInput(formatError(source,
                                                       element + "['adj_edges'][" + std::to_string(e) + "]",
                                                       "is " + std::to_string(edges[e]), "an edge 0 to 3"));
                    }
                    file.faces[f].adjFaces[e] = adj[e];
                    file.faces[f].adjEdges[e] = static_cast<uint8_t>(edges[e]);
                }
            }
            if (face.contains("subface"))
                file.faces[f].subface =
                    castArgument<bool>(face["subface"], source, element + "['subface']", "a bool");
        }
    }
    if (d.contains("metadata")) {
        const auto metadata =
            castArgument<py::dict>(d["metadata"], source, "metadata", "a dict of str -> str or array");
        for (const auto& [key, value] : metadata) {
            const std::string k = bytesOf(key, source, "metadata key " + std::string(py::repr(key)));
            if (mesh && (k == "PtexFaceVertCounts" || k == "PtexFaceVertIndices" || k == "PtexVertPositions"))
                continue;  // written from the mesh
            file.metadata.push_back(metaFrom(k, value, source));
        }
    }
    return file;
}

// How a mesh argument is named in messages: its OBJ path, or its size when it is a Mesh or arrays.
std::string meshName(py::handle mesh, const geom::Mesh& m) {
    if (!py::isinstance<geom::Mesh>(mesh))
        return mesh.cast<std::filesystem::path>().string();  // meshFrom read it
    return meshLabel(m);
}

geom::Mesh meshFrom(py::handle mesh, const std::string& source) {
    if (py::isinstance<geom::Mesh>(mesh)) return mesh.cast<geom::Mesh>();
    return io::readMesh(castArgument<std::filesystem::path>(mesh, source, "mesh",
                                                            "a deformkit.Mesh or a mesh file path"))
        .mesh;
}

}  // namespace

void bindPtex(py::module_& m) {
    m.def(
        "read_ptex",
        [](const std::filesystem::path& path) {
            ptex::PtexFile file;
            {
                py::gil_scoped_release release;
                file = ptex::readPtex(path);
            }
            return toDict(file);
        },
        py::arg("path"),
        "Read a Ptex file as a dict: mesh_type ('quad'/'triangle'), data_type ('u8', 'u16', 'half', "
        "'float'),\n"
        "channels, alpha_channel (-1: none), u_border_mode and v_border_mode ('clamp', 'black', "
        "'periodic'),\n"
        "edge_filter_mode ('none', 'tangent_vectors'), faces (per face a dict: res (ures, vres), adj_faces "
        "and\n"
        "adj_edges (4 each, edges bottom, right, top, left; -1: none), constant, subface), data (per face a\n"
        "(vres, ures, channels) array in the file's dtype: uint8, uint16, float16, float32; row 0 at v = 0;\n"
        "constant faces expanded) and metadata (key -> str or 1-D array).");
    m.def(
        "write_ptex",
        [](const std::filesystem::path& path, const py::dict& ptex, py::object mesh, int compression,
           bool reductions) {
            std::optional<geom::Mesh> m;
            if (!mesh.is_none()) m = meshFrom(mesh, "write_ptex");
            const ptex::PtexFile file = fromDict(ptex, m, "write_ptex");
            ptex::WriteOptions options;
            options.compressionLevel = compression;
            options.reductions = reductions;
            if (m) options.mesh = ptex::meshData(*m, "write_ptex: mesh");
            py::gil_scoped_release release;
            ptex::writePtex(path, file, options);
        },
        py::arg("path"), py::arg("ptex"), py::arg("mesh") = py::none(), py::arg("compression") = 6,
        py::arg("reductions") = true,
        "Write a Ptex file atomically from a dict as read_ptex returns (only 'data' is required: per face a\n"
        "(vres, ures[, C]) uint8 / uint16 / float16 / float32 array, power-of-two sizes; optional 'faces'\n"
        "with adjacency and sub-face flags, 'metadata', 'alpha_channel', 'mesh_type' (default 'quad';\n"
        "'triangle' takes square faces), the border and edge filter modes). With mesh (a deformkit.Mesh or "
        "an\n"
        "OBJ path) the faces' adjacency and sub-face flags are the mesh's (OpenSubdiv's Ptex faces) and its\n"
        "face and vertex data are written as the standard mesh metadata.");
    m.def(
        "ptex_vertex_values",
        [](py::object mesh, py::object ptex) {
            constexpr const char* kFunction = "ptex_vertex_values";
            const geom::Mesh m = meshFrom(mesh, kFunction);
            const bool dict = py::isinstance<py::dict>(ptex);
            const std::filesystem::path path =
                dict ? std::filesystem::path()
                     : castArgument<std::filesystem::path>(ptex, kFunction, "ptex",
                                                           "a Ptex file path or read_ptex's dict");
            const ptex::PtexFile file =
                dict ? fromDict(ptex.cast<py::dict>(), std::nullopt, kFunction) : ptex::readPtex(path);
            const std::string source = dict ? std::string("ptex") : path.string();
            const std::string name = meshName(mesh, m);
            std::vector<float> values;
            {
                py::gil_scoped_release release;
                values = ptex::vertexValues(ptex::PtexMesh(m, name), file, source);
            }
            py::array_t<float> out(std::vector<py::ssize_t>{m.numVertices(), file.channels});
            std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(float));
            return out;
        },
        py::arg("mesh"), py::arg("ptex"),
        "Per-vertex values (V, C) float32 of a Ptex map painted on mesh (a deformkit.Mesh or an OBJ path;\n"
        "ptex a path or read_ptex's dict): each vertex the mean, over the Ptex faces meeting at it, of the\n"
        "texel in that corner; u8 and u16 read as [0, 1]. Painted weights for the slide and every warp.");
}

}  // namespace deformkit::python
