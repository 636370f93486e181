// deformkit.shot_report: a UV-warp shot's logs as one HTML page (uvwarp/html_report.h), for scripts and the
// Blender add-on's bake, whose inputs are not files (an evaluated Blender object, painted images): those
// come through arguments instead of the maps' headers.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.h"
#include "deformkit/error.h"
#include "deformkit/uvwarp/html_report.h"
#include "deformkit/uvwarp/shot_log.h"
#include "numpy_support.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

constexpr const char* kReport = "shot_report";

// {tile: (T, T) or (T, T, C) float32} as images by tile; None gives none.
std::map<int, io::Image> tileImages(const py::object& value, const std::string& name) {
    std::map<int, io::Image> out;
    if (value.is_none()) return out;
    if (!py::isinstance<py::dict>(value)) {
        throw InvalidInput(
            formatError(kReport, name, "is " + aTypeName(value), "None or {tile: float32 array}"));
    }
    for (const auto& [key, array] : py::reinterpret_borrow<py::dict>(value)) {
        const std::string element = name + "[" + std::string(py::repr(key)) + "]";
        const std::optional<int64_t> tile = wholeNumber(key);
        if (!tile || *tile < 1001 || *tile > 9999) {
            throw InvalidInput(formatError(kReport, element, "is not a UDIM tile", "1001..9999"));
        }
        const std::optional<FloatArray> image = floatArrayOf(array);
        if (!image) {
            throw InvalidInput(
                formatError(kReport, element, "is " + aTypeName(array), "(T, T) or (T, T, C) float32"));
        }
        out.emplace(static_cast<int>(*tile),
                    imageOf(*image, kReport, element, "(T, T) or (T, T, C) float32"));
    }
    return out;
}

py::dict shotReport(const py::object& logs, const std::filesystem::path& page, const std::string& title,
                    const std::vector<std::string>& rerun, const std::optional<geom::Mesh>& rest,
                    const py::object& deformed, const py::object& rigidity, const py::object& texture) {
    std::vector<std::filesystem::path> files;
    if (py::isinstance<py::str>(logs) || py::hasattr(logs, "__fspath__")) {
        files.push_back(logs.cast<std::filesystem::path>());
    } else {
        files = castArgument<std::vector<std::filesystem::path>>(logs, kReport, "logs",
                                                                 "a JSON-lines log path or a list of them");
    }
    if (rest.has_value() != !deformed.is_none()) {
        throw InvalidInput(formatError(kReport, rest ? "deformed" : "rest",
                                       "is None while the other is given",
                                       "rest and deformed together, or neither"));
    }
    if (!deformed.is_none() && !PyCallable_Check(deformed.ptr())) {
        throw InvalidInput(formatError(kReport, "deformed", "is " + aTypeName(deformed),
                                       "a callable frame -> (N, 3) float32 (or (positions, name))"));
    }
    uvwarp::HtmlReportOptions options;
    if (!title.empty()) options.title = title;
    options.rerun = rerun;
    if (rest) {
        // Called from the report, which runs without the GIL (other Python threads, a DCC's interface, go
        // on): the callable runs with it, on this thread.
        options.geometry = [&](const std::string&, int frame) -> std::optional<uvwarp::ReportGeometry> {
            const py::gil_scoped_acquire gil;
            py::object result = deformed(frame);
            if (py::isinstance<py::tuple>(result)) {
                const auto pair = py::reinterpret_borrow<py::tuple>(result);
                result = pair.empty() ? py::none() : py::object(pair[0]);
            }
            const std::optional<FloatArray> array = floatArrayOf(result);
            const std::string element = "deformed(" + std::to_string(frame) + ")";
            if (array) requireFloats(*array, kReport, element);
            if (!array || array->ndim() != 2 || array->shape(1) != 3 ||
                static_cast<size_t>(array->shape(0)) != rest->points().size()) {
                throw InvalidInput(formatError(kReport, element, "is not the rest mesh's positions",
                                               "(" + std::to_string(rest->points().size()) + ", 3) float32"));
            }
            const auto* p = reinterpret_cast<const glm::vec3*>(array->data());
            return uvwarp::ReportGeometry{*rest, std::vector<glm::vec3>(p, p + array->shape(0))};
        };
    }
    const std::map<int, io::Image> rigidityMaps = tileImages(rigidity, "rigidity");
    const std::map<int, io::Image> textures = tileImages(texture, "texture");
    const auto lookup = [](const std::map<int, io::Image>& maps) {
        return [&maps](const std::string&, int tile) -> std::optional<io::Image> {
            const auto it = maps.find(tile);
            return it == maps.end() ? std::nullopt : std::optional<io::Image>(it->second);
        };
    };
    if (!rigidityMaps.empty()) options.rigidity = lookup(rigidityMaps);
    if (!textures.empty()) options.texture = lookup(textures);

    uvwarp::ShotLog log;
    uvwarp::HtmlReportResult result;
    {
        const py::gil_scoped_release release;
        for (const std::filesystem::path& file : files)
            uvwarp::readShotLogFile(file, log);
        result = uvwarp::writeHtmlReport(log, page, options);
    }
    py::list written;
    for (const std::filesystem::path& f : result.files)
        written.append(f.string());
    py::dict out;
    out["page"] = page.string();
    out["files"] = written;
    out["problems"] = result.problems;
    out["notes"] = result.notes;
    out["log_lines"] = log.lines.size();
    return out;
}

}  // namespace

void bindShotReport(py::module_& m) {
    m.def(
        "shot_report", &shotReport, py::arg("logs"), py::arg("page"), py::arg("title") = "",
        py::arg("rerun") = std::vector<std::string>{}, py::arg("rest") = py::none(),
        py::arg("deformed") = py::none(), py::arg("rigidity") = py::none(), py::arg("texture") = py::none(),
        "shot_report(logs, page, title='', rerun=[], rest=None, deformed=None, rigidity=None, texture=None)\n"
        "Writes a UV-warp shot's JSON-lines logs (uvwarp_shot's log=, `deformkit uvwarp --log`, farm tasks'\n"
        "output; a path or a list, merged in any order) as one HTML page readable offline, its pictures in\n"
        "<page stem>_files/ beside it (`deformkit report`, docs/report.md): per tile, plots over frames of "
        "the\n"
        "rigid stretch removed, inverted triangles, off-chart texels and seconds, and at the worst frame\n"
        "heatmaps of the rigid stretch left and the texture plain and warped. The pictures are made again\n"
        "from the files the worst frame's redirect map names; inputs that are not files come from the\n"
        "arguments: rest (a Mesh with UVs) with deformed (frame -> (N, 3) float32, or (positions, name)),\n"
        "rigidity and texture ({tile: (T, T) or (T, T, C) float32}, row 0 at v = 1). A broken log line is\n"
        "reported in the page (file and line), not raised. Returns {'page', 'files', 'problems', 'notes',\n"
        "'log_lines'}.");
}

}  // namespace deformkit::python
