// Python bindings of the content-aware UV warp (core/include/deformkit/uvwarp/, Koniaris et al.): the
// UvWarpSolver class that binds one UDIM tile's maps and rest mesh once and solves frame after frame
// (warm start), the one-off uv_warp, apply_redirect (texture bake through a redirect map) and uvwarp_shot
// (the shot job of uvwarp/shot_job.h: every tile and frame written as files, resumable, cancellable). Maps
// are numpy float32 images in (H, W, C) layout, row 0 at v = 1 (grid.h).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/geom/mesh.h"
#include "deformkit/interrupter.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/udim.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/shot_log.h"
#include "deformkit/uvwarp/tile_warp.h"
#include "numpy_support.h"

namespace py = pybind11;

namespace deformkit::python {
namespace {

using uvwarp::TileWarp;
using uvwarp::TileWarpOptions;

// A one-channel map: (T, T) or (T, T, 1) float32. Squareness and values are checked by the core, which
// names the texel.
io::Image mapOf(const FloatArray& a, const std::string& source, const char* name) {
    requireFloats(a, source, name);
    if (!(a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 1)) || a.shape(0) < 1 || a.shape(1) < 1) {
        throw InvalidInput(
            formatError(source, name, "has shape " + shapeOf(a), "(T, T) or (T, T, 1) float32"));
    }
    requireImageSides(a, source, name);
    io::Image image(static_cast<int32_t>(a.shape(1)), static_cast<int32_t>(a.shape(0)), 1);
    std::memcpy(image.pixels.data(), a.data(), image.pixels.size() * sizeof(float));
    return image;
}

io::Image optionalMapOf(const std::optional<FloatArray>& a, const std::string& source, const char* name) {
    return a ? mapOf(*a, source, name) : io::Image{};
}

int32_t intOption(py::handle value, const std::string& source, const std::string& name, int64_t lo,
                  const char* expected) {
    int64_t v = 0;
    try {
        if (py::isinstance<py::float_>(value)) throw py::cast_error();
        v = value.cast<int64_t>();
    } catch (const py::cast_error&) {
        throw InvalidInput(formatError(
            source, name, "is a " + std::string(py::str(py::type::of(value).attr("__name__"))), expected));
    }
    if (v < lo || v > std::numeric_limits<int32_t>::max())
        throw InvalidInput(formatError(source, name, "is " + std::to_string(v), expected));
    return static_cast<int32_t>(v);
}

// A Python value as the library's options take it (uvwarp/options.h checks it): a bool, a number, a
// sequence of numbers, or anything else, described.
uvwarp::OptionValue optionValueOf(py::handle value) {
    using Kind = uvwarp::OptionValue::Kind;
    const auto number = [](py::handle x, double& out) {
        if (isBool(x) || py::isinstance<py::str>(x) || py::isinstance<py::bytes>(x) ||
            py::isinstance<py::sequence>(x))
            return false;
        try {
            out = x.cast<double>();
            return true;
        } catch (const py::cast_error&) {
            return false;
        }
    };
    uvwarp::OptionValue v;
    double x = 0.0;
    if (isBool(value)) {
        v.kind = Kind::Boolean;
        v.numbers = {py::bool_(value.cast<py::object>()) ? 1.0 : 0.0};
    } else if (number(value, x)) {
        v.numbers = {x};
    } else if (py::isinstance<py::sequence>(value) && !py::isinstance<py::str>(value)) {
        v.kind = Kind::List;
        for (py::handle item : py::reinterpret_borrow<py::sequence>(value)) {
            if (!number(item, x)) {
                v.kind = Kind::Other;
                v.shown = aTypeName(value) + " holding " + aTypeName(item);
                break;
            }
            v.numbers.push_back(x);
        }
    } else {
        v.kind = Kind::Other;
        v.shown = aTypeName(value);
    }
    if (v.kind != Kind::Other) v.shown = py::repr(value);  // as the caller wrote it: 2.0, [0, 0], True
    return v;
}

// The option whose snake_case name is `name`, or nullptr.
const uvwarp::OptionSpec* pythonOption(std::string_view name) {
    for (const uvwarp::OptionSpec& spec : uvwarp::optionSpecs()) {
        if (uvwarp::pythonName(spec) == name) return &spec;
    }
    return nullptr;
}

// The options a call asked for: resolution (grid cells per side, None = the rigidity map's size), the keyword
// options by their snake_case names (uvwarp/options.h, each checked by the library and named as the caller
// wrote it) and the keyword `preset` ('shot' or 'live'), the library's options but for those given.
struct CallOptions {
    TileWarpOptions options;  // starting from the call's base, with the options given
    std::optional<uvwarp::Preset> preset;
    std::vector<std::string> own;  // camelCase names of the options given

    // The options of one tile whose maps have `texels` per side.
    [[nodiscard]] TileWarpOptions forTile(int32_t texels) const {
        if (!preset) return options;
        return uvwarp::withPreset(*preset, options.cells != 0 ? options.cells : texels, options, own);
    }
};

// `base`: a solver's defaults (warm start) or a shot's (every frame from the identity, uvwarp::shotOptions).
CallOptions optionsOf(const std::optional<int64_t>& resolution, const py::kwargs& kwargs,
                      const std::string& source, const TileWarpOptions& base = {}) {
    CallOptions o{base, std::nullopt, {}};
    if (resolution) {
        uvwarp::OptionValue value;
        value.numbers = {static_cast<double>(*resolution)};
        uvwarp::setOption(o.options, *uvwarp::findOption("resolution"), value, source, "resolution");
        o.own.emplace_back("resolution");
    }
    for (const auto& [key, value] : kwargs) {
        const std::string k = py::str(key);
        if (k == "preset") {
            if (!py::isinstance<py::str>(value))
                throw InvalidInput(formatError(source, k, "is " + aTypeName(value), "'shot' or 'live'"));
            o.preset = uvwarp::presetNamed(value.cast<std::string>(), source, k);
            continue;
        }
        const uvwarp::OptionSpec* spec = pythonOption(k);
        if (spec == nullptr || k == "resolution") {
            std::string known = "preset";
            for (const uvwarp::OptionSpec& s : uvwarp::optionSpecs()) {
                if (s.name != "resolution") known += ", " + uvwarp::pythonName(s);
            }
            throw InvalidInput(formatError(source, k, "is not an option", known));
        }
        uvwarp::setOption(o.options, *spec, optionValueOf(value), source, k);
        o.own.emplace_back(spec->name);
    }
    return o;
}

// An option's value as Python sees it: bool, int, float or a list of ints.
py::object optionObject(const uvwarp::OptionSpec& spec, const TileWarpOptions& options) {
    const std::vector<double> v = spec.get(options);
    switch (spec.type) {
        case uvwarp::OptionType::Flag:
            return py::bool_(v.front() != 0);
        case uvwarp::OptionType::IntegerList: {
            py::list list;
            for (double x : v)
                list.append(py::int_(static_cast<int64_t>(x)));
            return std::move(list);
        }
        case uvwarp::OptionType::Integer:
            return py::int_(static_cast<int64_t>(v.front()));
        case uvwarp::OptionType::Number:
            break;
    }
    return py::float_(static_cast<double>(static_cast<float>(v.front())));
}

// The keyword options' part of the docstrings, made from the declaration.
std::string optionsDoc() {
    std::string doc =
        "preset: 'shot' (the default schedule, each frame from the identity) or 'live' (one warm-started\n"
        "iteration a frame, its schedule by the grid's size): the library's options for that use, but for\n"
        "the options given beside it.\n"
        "options (keywords; the same option is camelCase in scenes and `deformkit uvwarp "
        "--list-options`):\n";
    const TileWarpOptions defaults;
    for (const uvwarp::OptionSpec& spec : uvwarp::optionSpecs()) {
        if (spec.name == "resolution") continue;
        doc += "  " + uvwarp::pythonName(spec) + " (" + uvwarp::valueText(spec, spec.get(defaults)) + "; " +
               uvwarp::expectedValue(spec) + "): " + std::string(spec.meaning) + "\n";
    }
    return doc;
}

uvwarp::BakeOptions bakeOptionsOf(const std::string& filter, const std::string& source) {
    uvwarp::BakeOptions o;
    if (filter == "bilinear") {
        o.filter = io::SampleFilter::Bilinear;
    } else if (filter == "bicubic") {
        o.filter = io::SampleFilter::Bicubic;
    } else {
        throw InvalidInput(formatError(source, "filter", "is '" + filter + "'", "'bilinear' or 'bicubic'"));
    }
    return o;
}

// The warp grid as (n + 1, n + 1, 2) float32: [j, i] = (u, v) of grid point (i, j), j = 0 on v = 0.
py::array_t<float> gridArray(const uvwarp::WarpGrid& w) {
    const auto side = static_cast<py::ssize_t>(w.side());
    py::array_t<float> out({side, side, py::ssize_t{2}});
    float* p = out.mutable_data();
    for (size_t k = 0; k < w.numPoints(); ++k) {
        p[2 * k] = w.u[k];
        p[2 * k + 1] = w.v[k];
    }
    return out;
}

// Figures as a dict, by the names the library reports them under (uvwarp/metrics.h).
void addFigures(py::dict& d, const std::vector<uvwarp::ReportedFigure>& figures) {
    for (const uvwarp::ReportedFigure& f : figures) {
        const py::str name(f.name.data(), f.name.size());
        if (f.kind == uvwarp::ReportedFigure::Kind::Count) {
            d[name] = py::int_(static_cast<int64_t>(f.value));
        } else if (f.kind == uvwarp::ReportedFigure::Kind::Flag) {
            d[name] = py::bool_(f.value != 0);
        } else {
            d[name] = py::float_(f.value);
        }
    }
}

// The figures of a frame: its redirect map's, then the grid's (grid_*), and the solver's when given.
py::dict metricsDict(const uvwarp::DeliveredMetrics& delivered, const uvwarp::WarpMetrics& m,
                     const uvwarp::SolveStats* s = nullptr, const uvwarp::FoldRepair* repair = nullptr) {
    py::dict d;
    addFigures(d, uvwarp::reportedFigures(delivered));
    if (repair) addFigures(d, uvwarp::reportedFigures(*repair));
    addFigures(d, uvwarp::reportedFigures(m));
    if (s) addFigures(d, uvwarp::reportedFigures(*s));
    return d;
}

// A redirect map argument: (T, T, 2) float32, the tile-local (u', v'), as redirect_map returns it. A third
// channel is more likely a texture passed in its place (the arguments swapped) than a map: refused.
io::Image redirectOf(const FloatArray& a, const std::string& source, const char* expected) {
    requireFloats(a, source, "redirect");
    if (a.ndim() != 3 || a.shape(2) != 2)
        throw InvalidInput(formatError(source, "redirect", "has shape " + shapeOf(a), expected));
    return imageOf(a, source, "redirect", expected);
}

std::vector<glm::vec3> deformedOf(const FloatArray& a, int32_t vertices, const std::string& source) {
    requireFloats(a, source, "deformed_points");
    if (a.ndim() != 2 || a.shape(1) != 3 || a.shape(0) != vertices) {
        throw InvalidInput(formatError(source, "deformed_points", "has shape " + shapeOf(a),
                                       "(" + std::to_string(vertices) + ", 3), one row per rest vertex"));
    }
    return pointsOf(a, source, "deformed_points");
}

std::unique_ptr<TileWarp> bindTile(const geom::Mesh& mesh, int tile, const io::Image& rigidity,
                                   const io::Image& mask, const TileWarpOptions& options,
                                   const io::Image& orientation, const std::string& source) {
    py::gil_scoped_release release;
    return std::make_unique<TileWarp>(mesh, tile, rigidity, mask, options, orientation, source);
}

// The UvWarpSolver binding. A mutex serialises calls on one solver: solve runs without the GIL, so two
// Python threads could otherwise enter the same warm-started state at once.
class PyUvWarpSolver {
  public:
    PyUvWarpSolver(const geom::Mesh& mesh, int tile, const FloatArray& rigidity,
                   const std::optional<FloatArray>& mask, const std::optional<int64_t>& resolution,
                   const std::optional<FloatArray>& orientation, const py::kwargs& kwargs) {
        const std::string source = "UvWarpSolver";
        const io::Image rigidityMap = mapOf(rigidity, source, "rigidity");
        options_ = optionsOf(resolution, kwargs, source).forTile(rigidityMap.width);
        warp_ = bindTile(mesh, tile, rigidityMap, optionalMapOf(mask, source, "mask"), options_,
                         optionalMapOf(orientation, source, "orientation"), source);
        vertices_ = mesh.numVertices();
    }

    py::array_t<float> solve(const FloatArray& deformed) {
        const std::vector<glm::vec3> points = deformedOf(deformed, vertices_, "UvWarpSolver.solve");
        uvwarp::WarpGrid w;
        {
            py::gil_scoped_release release;
            const std::lock_guard<std::mutex> lock(mutex_);
            w = warp_->solve(points);
        }
        return gridArray(w);
    }

    py::array redirectMap() const {
        io::Image out;
        {
            py::gil_scoped_release release;
            const std::lock_guard<std::mutex> lock(mutex_);
            warp_->redirect(out);
        }
        return imageArray(std::move(out));
    }

    py::dict metrics() const {
        uvwarp::DeliveredMetrics delivered;
        uvwarp::WarpMetrics m;
        uvwarp::SolveStats s;
        uvwarp::FoldRepair repair;
        {
            py::gil_scoped_release release;
            const std::lock_guard<std::mutex> lock(mutex_);
            delivered = warp_->deliveredMetrics(&repair);
            m = warp_->metrics();
            s = warp_->stats();
        }
        return metricsDict(delivered, m, &s, &repair);
    }

    void reset() {
        py::gil_scoped_release release;
        const std::lock_guard<std::mutex> lock(mutex_);
        warp_->reset();
    }

    py::array_t<float> warp() const {
        uvwarp::WarpGrid w;
        {
            py::gil_scoped_release release;
            const std::lock_guard<std::mutex> lock(mutex_);
            w = warp_->warp();
        }
        return gridArray(w);
    }

    [[nodiscard]] const TileWarp& tileWarp() const { return *warp_; }
    [[nodiscard]] int32_t vertices() const { return vertices_; }
    [[nodiscard]] const TileWarpOptions& options() const { return options_; }

  private:
    TileWarpOptions options_;
    std::unique_ptr<TileWarp> warp_;
    int32_t vertices_ = 0;
    mutable std::mutex mutex_;
};

py::array uvWarp(const geom::Mesh& mesh, int tile, const FloatArray& rigidity, const FloatArray& deformed,
                 const std::optional<FloatArray>& mask, const std::optional<int64_t>& resolution,
                 const std::optional<FloatArray>& orientation, const py::kwargs& kwargs) {
    const std::string source = "uv_warp";
    const io::Image rigidityMap = mapOf(rigidity, source, "rigidity");
    const TileWarpOptions options = optionsOf(resolution, kwargs, source).forTile(rigidityMap.width);
    const std::vector<glm::vec3> points = deformedOf(deformed, mesh.numVertices(), source);
    const io::Image maskMap = optionalMapOf(mask, source, "mask");
    const io::Image orientationMap = optionalMapOf(orientation, source, "orientation");
    io::Image out;
    {
        py::gil_scoped_release release;
        TileWarp warp(mesh, tile, rigidityMap, maskMap, options, orientationMap, source);
        warp.solve(points);
        warp.redirect(out);
    }
    return imageArray(std::move(out));
}

// ---- The shot job (uvwarp/shot_job.h) ----

constexpr const char* kShot = "uvwarp_shot";
constexpr const char* kUdimTokens = "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_";

bool isPath(py::handle value) {
    return py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__");
}

// A per-tile map argument: a UDIM pattern of files, {tile: image} in memory (named `name` in messages and
// headers), or (label, {tile: image}) to name it otherwise. Images are (T, T) or (T, T, C) float32, row 0
// at v = 1; sizes and values are checked by the job, which names the tile.
uvwarp::TileMapSource mapSourceOf(const py::object& value, const std::string& name) {
    constexpr const char* expected =
        "a UDIM pattern such as 'rig.<UDIM>.exr', {tile: (T, T) or (T, T, C) float32 array} or "
        "(label, {tile: array})";
    uvwarp::TileMapSource map;
    if (value.is_none()) return map;
    if (isPath(value)) {
        map.pattern = value.cast<std::filesystem::path>();
        map.name = std::string(kShot) + ": " + name;  // the job checks its UDIM token
        return map;
    }
    py::handle images = value;
    map.name = name;
    if (py::isinstance<py::tuple>(value)) {
        const auto pair = py::reinterpret_borrow<py::tuple>(value);
        if (pair.size() != 2 || !py::isinstance<py::str>(pair[0]) || !py::isinstance<py::dict>(pair[1])) {
            throw InvalidInput(
                formatError(kShot, name, "is a tuple but not (label, {tile: array})", expected));
        }
        map.name = pair[0].cast<std::string>();
        images = pair[1];
    }
    if (!py::isinstance<py::dict>(images))
        throw InvalidInput(formatError(kShot, name, "is " + aTypeName(value), expected));
    for (const auto& [key, array] : py::reinterpret_borrow<py::dict>(images)) {
        const std::string keyText = py::repr(key);
        const int32_t tile = intOption(key, kShot, name + " key " + keyText, 1001, "a UDIM tile, 1001..9999");
        if (tile > 9999) {
            throw InvalidInput(
                formatError(kShot, name + " key " + keyText, "is not a UDIM tile", "1001..9999"));
        }
        const std::string element = name + "[" + std::to_string(tile) + "]";
        const std::optional<FloatArray> image = floatArrayOf(array);
        if (!image) {
            throw InvalidInput(
                formatError(kShot, element, "is " + aTypeName(array), "(T, T) or (T, T, C) float32"));
        }
        map.images.emplace(tile, imageOf(*image, kShot, element, "(T, T) or (T, T, C) float32"));
    }
    if (map.images.empty()) throw InvalidInput(formatError(kShot, name, "has no tile", expected));
    return map;
}

// Progress and cancellation from progress(done, total, unit), called with the GIL held from the job's
// thread after every tile and frame; a true result cancels (deformkit.Cancelled). An exception it raises
// ends the job and reaches the caller unchanged.
class PyProgress final : public Interrupter {
  public:
    explicit PyProgress(const py::object& progress) : progress_(progress) {}

    bool wasInterrupted(int64_t done, int64_t total, std::string_view unit) override {
        const py::gil_scoped_acquire gil;
        return py::bool_(progress_(done, total, py::str(unit.data(), unit.size())));
    }

  private:
    const py::object& progress_;  // the caller's argument, alive for the call
};

py::dict tileReportDict(const uvwarp::ShotTileReport& t) {
    using namespace pybind11::literals;
    py::dict d("warped"_a = t.warped, "written"_a = t.written, "baked"_a = t.baked, "replayed"_a = t.replayed,
               "skipped"_a = t.skipped, "map_changes"_a = t.mapChanges);
    const bool solved = t.written + t.replayed > 0;
    d["last_frame"] = solved ? py::object(py::int_(t.lastFrame)) : py::none();
    // Of the last frame written: its redirect map's figures, and its grid's.
    d["last_written_frame"] = t.written > 0 ? py::object(py::int_(t.lastWrittenFrame)) : py::none();
    d["metrics"] = t.written > 0
                       ? py::object(metricsDict(t.lastDelivered, t.lastMetrics, nullptr, &t.lastRepair))
                       : py::none();
    py::list files;
    for (const std::filesystem::path& f : t.files)
        files.append(f.string());
    d["files"] = files;
    d["notes"] = t.notes;
    d["summary"] = uvwarp::shotSummary(uvwarp::ShotReport{{t}});
    return d;
}

py::dict uvwarpShot(const geom::Mesh& rest, const std::vector<int>& frames, const py::object& deformed,
                    const py::object& rigidity, const py::object& out, const py::object& mask,
                    const py::object& orientation, const py::object& texture, const py::object& bake,
                    const std::optional<std::vector<int>>& tiles, const std::optional<int64_t>& resolution,
                    const std::string& filter, bool skipExisting, const py::object& log,
                    const py::object& progress, const std::string& restName,
                    const std::optional<double>& cacheStart, const py::kwargs& kwargs) {
    uvwarp::ShotJob job;
    const CallOptions options = optionsOf(resolution, kwargs, kShot, uvwarp::shotOptions());
    job.options = options.options;
    job.preset = options.preset;
    job.presetOwn = options.own;
    job.filter = bakeOptionsOf(filter, kShot).filter;
    if (frames.empty()) throw InvalidInput(formatError(kShot, "frames", "is empty", "at least one frame"));
    job.rest = &rest;
    job.restName = restName;
    job.frames = frames;
    if (tiles) {  // None is every tile; a list names each tile once, as --tiles and a scene's "tiles" do
        if (tiles->empty()) {
            throw InvalidInput(
                formatError(kShot, "tiles", "is an empty list", "None for every tile, or tiles"));
        }
        job.tiles = *tiles;
        std::sort(job.tiles.begin(), job.tiles.end());
        if (const auto twice = std::adjacent_find(job.tiles.begin(), job.tiles.end());
            twice != job.tiles.end()) {
            throw InvalidInput(formatError(kShot, "tiles", "lists tile " + std::to_string(*twice) + " twice",
                                           "each tile once"));
        }
    }
    if (rigidity.is_none())
        throw InvalidInput(formatError(kShot, "rigidity", "is None", "the rigidity maps"));
    job.rigidity = mapSourceOf(rigidity, "rigidity");
    job.mask = mapSourceOf(mask, "mask");
    job.orientation = mapSourceOf(orientation, "orientation");
    job.texture = mapSourceOf(texture, "texture");
    if (texture.is_none() != bake.is_none()) {
        throw InvalidInput(formatError(kShot, texture.is_none() ? "bake" : "texture",
                                       texture.is_none() ? "given without texture" : "given without bake",
                                       "texture and bake together"));
    }
    if (out.is_none()) {
        throw InvalidInput(
            formatError(kShot, "out", "is None", "a path pattern such as 'out/redirect.<UDIM>.####.exr'"));
    }
    for (const auto& [value, name] : {std::pair{&out, "out"}, std::pair{&bake, "bake"}}) {
        if (!value->is_none() && !isPath(*value)) {
            throw InvalidInput(formatError(kShot, name, "is " + aTypeName(*value),
                                           "a path pattern such as 'out/redirect.<UDIM>.####.exr'"));
        }
    }
    uvwarp::setOutputPatterns(job, out.cast<std::filesystem::path>(),
                              bake.is_none() ? std::filesystem::path() : bake.cast<std::filesystem::path>(),
                              std::string(kShot) + ": out", std::string(kShot) + ": bake");
    job.skipExisting = skipExisting;

    // The deformed positions: an OBJ sequence or a point cache, or a callable (frame) -> (N, 3) or ((N, 3),
    // name) called with the GIL held. The callable's array is copied: the job keeps it while Python code runs
    // in progress().
    uvwarp::DeformedFrames sequence;
    if (isPath(deformed)) {
        const auto path = deformed.cast<std::filesystem::path>();
        sequence = uvwarp::animatedFrames(path, frames, std::string(kShot) + ": deformed", rest, restName,
                                          cacheStart);
        for (uvwarp::ShotJob::CallerFile& file :
             uvwarp::deformedShotFiles(path, frames))  // inputs, never outputs
            job.callerFiles.push_back(std::move(file));
    } else if (!PyCallable_Check(deformed.ptr())) {
        throw InvalidInput(
            formatError(kShot, "deformed", "is " + aTypeName(deformed),
                        "a callable frame -> (N, 3) float32, an OBJ sequence pattern or a point "
                        "cache (.pc2, .mdd)"));
    } else if (cacheStart) {
        throw InvalidInput(formatError(kShot, "cache_start", "is given with a callable 'deformed'",
                                       "cache_start only with a point cache (.pc2, .mdd)"));
    }
    if (!progress.is_none() && !PyCallable_Check(progress.ptr())) {
        throw InvalidInput(formatError(kShot, "progress", "is " + aTypeName(progress),
                                       "None or a callable (done, total, unit) -> bool"));
    }
    std::ofstream logFile;
    std::filesystem::path logPath;
    if (!log.is_none()) {
        if (!isPath(log)) {
            throw InvalidInput(formatError(kShot, "log", "is " + aTypeName(log), "None or a file path"));
        }
        logPath = log.cast<std::filesystem::path>();
        job.log = &logFile;
        job.callerFiles.push_back({logPath, "the log (log)", true});
        job.planned = [&] { uvwarp::openShotLog(logPath, logFile); };  // once the job is checked
    }

    const auto vertices = static_cast<py::ssize_t>(rest.numVertices());
    std::vector<glm::vec3> points;
    const uvwarp::DeformedFrames deformedFrames = [&](int frame,
                                                      std::string& name) -> std::span<const glm::vec3> {
        if (sequence) return sequence(frame, name);
        const py::gil_scoped_acquire gil;
        const std::string element = "deformed(" + std::to_string(frame) + ")";
        const char* expected = "(N, 3) float32 positions of the rest mesh's vertices, or (positions, name)";
        py::object result = deformed(frame);
        name = "frame " + std::to_string(frame);
        if (py::isinstance<py::tuple>(result)) {
            const auto pair = py::reinterpret_borrow<py::tuple>(result);
            if (pair.size() != 2) {
                throw InvalidInput(formatError(
                    kShot, element, "returned a tuple of " + std::to_string(pair.size()), expected));
            }
            name = py::str(pair[1]);
            result = pair[0];
        }
        const std::optional<FloatArray> array = floatArrayOf(result);
        if (!array)
            throw InvalidInput(formatError(kShot, element, "returned " + aTypeName(result), expected));
        requireFloats(*array, kShot, element);
        if (array->ndim() != 2 || array->shape(1) != 3 || array->shape(0) != vertices) {
            const std::string what = py::isinstance<py::array>(result) ? "" : aTypeName(result) + " of ";
            throw InvalidInput(formatError(kShot, element, "returned " + what + "shape " + shapeOf(*array),
                                           "(" + std::to_string(vertices) + ", 3), one row per rest vertex"));
        }
        points.resize(static_cast<size_t>(vertices));
        if (!points.empty()) std::memcpy(points.data(), array->data(), points.size() * sizeof(glm::vec3));
        return points;
    };

    std::optional<PyProgress> interrupter;
    if (!progress.is_none()) interrupter.emplace(progress);
    uvwarp::ShotReport report;
    {
        const py::gil_scoped_release release;
        report = uvwarp::runShotJob(job, deformedFrames, interrupter ? &*interrupter : nullptr);
    }
    if (logFile.is_open() && !logFile.flush()) {
        throw StorageError(
            formatError(logPath.string(), "", "cannot write the log", "enough space to write"));
    }
    py::dict result;
    for (const uvwarp::ShotTileReport& t : report.tiles)
        result[py::int_(t.tile)] = tileReportDict(t);
    return result;
}

constexpr const char* kSolverDoc =
    "The content-aware UV warp (Koniaris et al.) of one UDIM tile, bound once to the rest mesh and the\n"
    "tile's maps, solved frame after frame: each solve warm-starts from the last warp, so a static pose\n"
    "gives a static warp and an animation changes smoothly.\n\n"
    "UvWarpSolver(points, face_counts, face_indices, uvs, uv_indices, tile, rigidity, mask=None,\n"
    "             resolution=None, orientation=None, **options)\n"
    "UvWarpSolver(mesh, tile, rigidity, mask=None, resolution=None, orientation=None, **options)\n\n"
    "points (N, 3) float32 rest positions; face_counts (F,), face_indices (sum of counts,) int32; uvs (K, "
    "2)\n"
    "float32 and uv_indices (sum of counts,) int32 (absolute UDIM UVs), or a deformkit.Mesh with UVs.\n"
    "tile: the UDIM tile (1001, ...). Maps are (T, T) or (T, T, 1) float32 images, row 0 at v = 1:\n"
    "rigidity in [0, 1] (1 = as rigid as possible); mask (>= 0.5 may warp; None derives one from the UVs:\n"
    "texels outside every UV triangle and on chart borders stay fixed); orientation in [0, 1] scales\n"
    "orientation_preservation (None: 1, or the density heuristic's map where orientation_density turns it\n"
    "on, as the shot preset does). resolution: grid cells per side n, a power of two (None: T).\n";

constexpr const char* kSolveDoc =
    "Solve one frame: deformed_points (N, 3) float32, the rest mesh's vertices moved (scene units).\n"
    "Returns the warp grid W as (n + 1, n + 1, 2) float32: n cells per side means n + 1 grid points per\n"
    "side (deformkit/uvwarp/grid.h). [j, i] holds the tile-local (u, v) of grid point (i, j), which rests\n"
    "at (i / n, j / n): row j = 0 lies on v = 0 (unlike images, whose row 0 is v = 1).";

constexpr const char* kShotDoc =
    "The UV warp over a shot, written as files: for every UDIM tile and frame the redirect map (and the\n"
    "tile's texture baked through it), the job of `deformkit uvwarp` and of scenes (uvwarp/shot_job.h).\n\n"
    "uvwarp_shot(mesh, frames, deformed, rigidity, out, mask=None, orientation=None, texture=None,\n"
    "            bake=None, tiles=None, resolution=None, filter='bilinear', skip_existing=True, log=None,\n"
    "            progress=None, rest_name='rest mesh', cache_start=None, **options)\n"
    "uvwarp_shot(points, face_counts, face_indices, uvs, uv_indices, frames, deformed, rigidity, out,\n"
    "            ...)\n\n"
    "mesh: a deformkit.Mesh with UVs, or its arrays as UvWarpSolver takes them. frames: ascending ints.\n"
    "deformed: a callable frame -> (N, 3) float32 positions of the rest mesh's vertices, or -> (positions,\n"
    "name) to name the frame's input in the headers; called once per frame the job solves, in order: the\n"
    "frames whose outputs are missing (warm-started, every frame up to the last of them). Or an OBJ\n"
    "sequence pattern ('anim.####.obj', '%04d'), or a point cache ('anim.pc2', 'anim.mdd'; cache_start:\n"
    "the frame of its first sample, default a PC2's start frame, an MDD's 1).\n"
    "rigidity, mask, orientation, texture: a UDIM pattern ('rig.<UDIM>.exr'), or images in memory as\n"
    "{tile: (T, T) or (T, T, C) float32} (row 0 at v = 1, channel 0 used except for the texture), named\n"
    "by the argument in messages and headers, or (label, {tile: array}) to name them. A tile without a\n"
    "rigidity map is left unwarped (a note); without a mask the mask is derived from the UVs.\n"
    "out, bake: patterns with a UDIM token and a frame token ('out/redirect.<UDIM>.####.exr'); out is a\n"
    "2-channel float EXR, bake (with texture) any format; missing folders are made. tiles: None for every\n"
    "tile of the UVs, or a list naming each tile once. resolution and options as UvWarpSolver, but "
    "warm_start defaults to False: each frame\n"
    "is solved from the identity, so its maps depend on that frame alone, whatever range the job covers\n"
    "(warm_start=True: from the last frame's warp). filter of the bake: 'bilinear', 'bicubic'.\n"
    "skip_existing: keep outputs that exist (warm-started, the warm start is replayed), so a rerun after a\n"
    "cancellation or a crash writes the bytes an uninterrupted run writes; False writes every output again.\n"
    "log: a file to append JSON lines to (one per tile and frame). progress: a callable (done, total,\n"
    "unit) called after each tile and frame (unit: 'tile 1001 frame 12 written'); a true result cancels:\n"
    "deformkit.Cancelled is raised and every file written is complete. The solve runs without the GIL;\n"
    "the callables are called with it.\n\n"
    "Every output is written atomically, with its provenance in the EXR header (deformkit:version,\n"
    "deformkit:uvwarp:tile, deformkit:uvwarp:frame, deformkit:uvwarp:solver and deformkit:uvwarp:inputs,\n"
    "the last two JSON; see read_image_info). Returns {tile: report}, ascending, each a dict: warped,\n"
    "written (frames written), baked, replayed (existed, solved for the warm start), skipped (existed, not\n"
    "solved), last_frame (the last solved), last_written_frame and metrics (its redirect map's figures and\n"
    "its grid's, as UvWarpSolver.metrics; None when nothing was written), files (written, in order), notes\n"
    "(an unwarped tile, a derived mask, a texture not baked) and summary (printable lines).";

}  // namespace

py::dict uvwarpOptionsDict(const TileWarpOptions& options, bool snakeCase) {
    py::dict d;
    for (const uvwarp::OptionSpec& spec : uvwarp::optionSpecs()) {
        const std::string name = snakeCase ? uvwarp::pythonName(spec) : std::string(spec.name);
        d[py::str(name)] = optionObject(spec, options);
    }
    return d;
}

void bindUvWarp(py::module_& m) {
    static const std::string solverDoc = std::string(kSolverDoc) + optionsDoc();
    py::class_<PyUvWarpSolver>(m, "UvWarpSolver", solverDoc.c_str())
        .def(py::init<const geom::Mesh&, int, const FloatArray&, const std::optional<FloatArray>&,
                      const std::optional<int64_t>&, const std::optional<FloatArray>&, const py::kwargs&>(),
             py::arg("mesh"), py::arg("tile"), py::arg("rigidity"), py::arg("mask") = py::none(),
             py::arg("resolution") = py::none(), py::arg("orientation") = py::none())
        .def(py::init([](const FloatArray& points, const IntArray& counts, const IntArray& indices,
                         const std::optional<FloatArray>& uvs, const std::optional<IntArray>& uvIndices,
                         int tile, const FloatArray& rigidity, const std::optional<FloatArray>& mask,
                         const std::optional<int64_t>& resolution,
                         const std::optional<FloatArray>& orientation, const py::kwargs& kwargs) {
                 const geom::Mesh mesh = meshOf(points, counts, indices, uvs, uvIndices, "UvWarpSolver",
                                                std::string("UvWarpSolver") + " mesh");
                 return std::make_unique<PyUvWarpSolver>(mesh, tile, rigidity, mask, resolution, orientation,
                                                         kwargs);
             }),
             py::arg("points"), py::arg("face_counts"), py::arg("face_indices"), py::arg("uvs"),
             py::arg("uv_indices"), py::arg("tile"), py::arg("rigidity"), py::arg("mask") = py::none(),
             py::arg("resolution") = py::none(), py::arg("orientation") = py::none())
        .def("solve", &PyUvWarpSolver::solve, py::arg("deformed_points"), kSolveDoc)
        .def("redirect_map", &PyUvWarpSolver::redirectMap,
             "W^-1 of the last solve as a (T, T, 2) float32 image (row 0 at v = 1): texel (x, y) holds the\n"
             "tile-local (u', v') to read the unwarped texture at for the texel centre ((x + 0.5) / T,\n"
             "1 - (y + 0.5) / T), made fold-free with no chart texel showing off-chart content (the fold\n"
             "repair, uvwarp/redirect_repair.h). The identity before any solve.")
        .def("metrics", &PyUvWarpSolver::metrics,
             "What the last solve delivers, measured on its redirect map (redirect_metrics.h):\n"
             "rigid_stretch_error and identity_stretch_error (mean | |f_D(q_b) - f_D(q_a)| / |f_O(r_b) -\n"
             "f_O(r_a)| - 1 | over 4-connected texel edges in one chart whose content r = R(q) is rigid, "
             "with the\n"
             "map and with none), rigid_stretch_removed, rigid_edges, identity_rigid_edges, "
             "inverted_triangles\n"
             "(of the map's texel-centre grid, both diagonals), off_chart_texels, chart_texels; what the "
             "fold\n"
             "repair did to the map (repair_inverted_found, repair_texels_moved, repair_passes,\n"
             "repair_folds_scaled_locally, repair_regions_scaled, repair_smallest_scale); the solver's grid\n"
             "figures as diagnostics (grid_rigid_stretch_error, grid_fold_overs, "
             "grid_max_masked_displacement,\n"
             "...); and the solve's iterations, levels, untangled_points, reverted_points,\n"
             "shortened_steps, shortened_everywhere, cold_restart, remaining_folds, last_move (cells) and "
             "converged.")
        .def("reset", &PyUvWarpSolver::reset, "Back to the identity warp (a cut in the shot).")
        .def_property_readonly("warp", &PyUvWarpSolver::warp, "The current warp grid, as solve returns it.")
        .def_property_readonly("tile", [](const PyUvWarpSolver& s) { return s.tileWarp().tile(); })
        .def_property_readonly(
            "texels", [](const PyUvWarpSolver& s) { return s.tileWarp().texels(); },
            "T, the maps' and redirect map's texels per side")
        .def_property_readonly(
            "cells", [](const PyUvWarpSolver& s) { return s.tileWarp().cells(); },
            "n, the warp grid's cells per side")
        .def_property_readonly("num_vertices", &PyUvWarpSolver::vertices)
        .def_property_readonly(
            "options", [](const PyUvWarpSolver& s) { return uvwarpOptionsDict(s.options(), true); },
            "Every option the solver was made with, {snake_case name: value}, resolution included (0: the\n"
            "rigidity map's size).")
        .def("__repr__", [](const PyUvWarpSolver& s) {
            return "<deformkit.UvWarpSolver tile " + std::to_string(s.tileWarp().tile()) + ", " +
                   std::to_string(s.tileWarp().texels()) + " texels, " +
                   std::to_string(s.tileWarp().cells()) + " cells>";
        });

    constexpr const char* uvWarpDoc =
        "One frame of the UV warp, from scratch: the inputs of UvWarpSolver plus deformed_points (N, 3)\n"
        "float32. Returns the redirect map (T, T, 2) float32 (see UvWarpSolver.redirect_map).";
    m.def("uv_warp", &uvWarp, py::arg("mesh"), py::arg("tile"), py::arg("rigidity"),
          py::arg("deformed_points"), py::arg("mask") = py::none(), py::arg("resolution") = py::none(),
          py::arg("orientation") = py::none(), uvWarpDoc);
    m.def(
        "uv_warp",
        [](const FloatArray& points, const IntArray& counts, const IntArray& indices,
           const std::optional<FloatArray>& uvs, const std::optional<IntArray>& uvIndices, int tile,
           const FloatArray& rigidity, const FloatArray& deformed, const std::optional<FloatArray>& mask,
           const std::optional<int64_t>& resolution, const std::optional<FloatArray>& orientation,
           const py::kwargs& kwargs) {
            const geom::Mesh mesh =
                meshOf(points, counts, indices, uvs, uvIndices, "uv_warp", "uv_warp mesh");
            return uvWarp(mesh, tile, rigidity, deformed, mask, resolution, orientation, kwargs);
        },
        py::arg("points"), py::arg("face_counts"), py::arg("face_indices"), py::arg("uvs"),
        py::arg("uv_indices"), py::arg("tile"), py::arg("rigidity"), py::arg("deformed_points"),
        py::arg("mask") = py::none(), py::arg("resolution") = py::none(), py::arg("orientation") = py::none(),
        uvWarpDoc);

    m.def(
        "uv_warp_live_options",
        [](int64_t cells) {
            // The grids the solver takes (requireCells): a preset for another size would name a grid that
            // cannot be.
            if (cells < 1 || cells > (int64_t{1} << 15) || (cells & (cells - 1)) != 0)
                throw InvalidInput(formatError("uv_warp_live_options", "cells", "is " + std::to_string(cells),
                                               "a power of two from 1 to 32768"));
            const TileWarpOptions o =
                uvwarp::presetOptions(uvwarp::Preset::Live, static_cast<int32_t>(cells));
            py::dict options;
            for (const uvwarp::OptionSpec& spec : uvwarp::optionSpecs()) {
                if (spec.solver || spec.name == "refinementSweeps" || spec.name == "orientationDensity")
                    options[py::str(uvwarp::pythonName(spec))] = optionObject(spec, o);
            }
            return options;
        },
        py::arg("cells"),
        "The live-preview preset for a grid of `cells` cells per side, as UvWarpSolver keyword options\n"
        "(every solver option, refinement_sweeps and orientation_density, both 0): one warm-started "
        "iteration\n"
        "a frame, the coarse levels over-relaxed by 1.4, sweeps per level by grid size, no refinement, a\n"
        "uniform orientation turn (uvwarp::presetOptions; on its delivered maps up to 4.2 points behind the\n"
        "shot preset on a smooth animation at 1024^2, more on rigged characters: docs/uvwarp.md).");

    m.def(
        "redirect_metrics",
        [](const geom::Mesh& mesh, int tile, const FloatArray& rigidity, const FloatArray& deformed,
           const FloatArray& redirect) {
            const std::string source = "redirect_metrics";
            const io::Image rigidityMap = mapOf(rigidity, source, "rigidity");
            const std::vector<glm::vec3> points = deformedOf(deformed, mesh.numVertices(), source);
            const io::Image map = redirectOf(redirect, source, "(T, T, 2) float32");
            uvwarp::DeliveredMetrics out;
            {
                py::gil_scoped_release release;
                out = uvwarp::RedirectMetrics(mesh, tile, rigidityMap, source).measure(points, map);
            }
            py::dict d;
            addFigures(d, uvwarp::reportedFigures(out));
            return d;
        },
        py::arg("mesh"), py::arg("tile"), py::arg("rigidity"), py::arg("deformed_points"),
        py::arg("redirect"),
        "What a redirect map delivers (deformkit/uvwarp/redirect_metrics.h), for any map: mesh with UVs,\n"
        "tile, rigidity (T, T) float32, deformed_points (N, 3) float32 (the rest mesh's vertices moved),\n"
        "redirect (T, T, 2) float32 as redirect_map returns it. Returns {rigid_stretch_error,\n"
        "identity_stretch_error, rigid_stretch_removed, rigid_edges, identity_rigid_edges, "
        "inverted_triangles,\n"
        "off_chart_texels, chart_texels}, the figures UvWarpSolver.metrics() and the shot log report.");

    m.def(
        "uv_warp_options",
        [] {
            py::list out;
            const TileWarpOptions defaults;
            const TileWarpOptions shot = uvwarp::shotOptions();
            for (const uvwarp::OptionSpec& spec : uvwarp::optionSpecs()) {
                py::dict d;
                d["name"] = std::string(spec.name);
                d["python"] = uvwarp::pythonName(spec);
                d["cli"] = uvwarp::cliName(spec);
                d["type"] = spec.type == uvwarp::OptionType::Flag          ? "flag"
                            : spec.type == uvwarp::OptionType::IntegerList ? "integer list"
                            : spec.type == uvwarp::OptionType::Integer     ? "integer"
                                                                           : "number";
                d["low"] = spec.low;
                d["high"] = spec.high;
                d["low_open"] = spec.lowOpen;
                d["power_of_two"] = spec.powerOfTwo;
                d["default"] = optionObject(spec, defaults);
                d["shot_default"] = optionObject(spec, shot);
                d["expected"] = uvwarp::expectedValue(spec);
                d["meaning"] = std::string(spec.meaning);
                out.append(d);
            }
            return out;
        },
        "The UV warp's options as declared once in the library (deformkit/uvwarp/options.h), in reference\n"
        "order: a list of dicts with name (camelCase: scenes, Maya, shot headers), python (the keyword\n"
        "name), cli (the `deformkit uvwarp` option), type ('integer', 'number', 'flag', 'integer list'),\n"
        "low, high, low_open, power_of_two (the range of a value, of each element of a list), default,\n"
        "shot_default (uvwarp_shot's, every frame from the identity), expected and meaning (text).");

    m.def(
        "apply_redirect",
        [](const FloatArray& texture, const FloatArray& redirect, const std::string& filter) {
            const std::string source = "apply_redirect";
            const uvwarp::BakeOptions options = bakeOptionsOf(filter, source);
            const io::Image tex = imageOf(texture, source, "texture", "(H, W) or (H, W, C) float32");
            const io::Image map = redirectOf(redirect, source, "(R, R, 2) float32");
            io::Image out;
            {
                py::gil_scoped_release release;
                uvwarp::bakeTexture(tex, map, out, options);
            }
            return imageArray(std::move(out), texture.ndim() == 2);
        },
        py::arg("texture"), py::arg("redirect"), py::arg("filter") = "bilinear",
        "Bake texture (H, W) or (H, W, C) float32 (one UDIM tile, row 0 at v = 1) through redirect (R, R, "
        "2),\n"
        "as redirect_map returns it: out(texel) = texture(redirect(uv of the texel's centre)), sampled with\n"
        "filter 'bilinear' or 'bicubic' (Catmull-Rom), clamped to the tile's edge texels. Returns an array\n"
        "of the texture's shape.");

    m.def("uvwarp_shot", &uvwarpShot, py::arg("mesh"), py::arg("frames"), py::arg("deformed"),
          py::arg("rigidity"), py::arg("out"), py::arg("mask") = py::none(),
          py::arg("orientation") = py::none(), py::arg("texture") = py::none(), py::arg("bake") = py::none(),
          py::arg("tiles") = py::none(), py::arg("resolution") = py::none(), py::arg("filter") = "bilinear",
          py::arg("skip_existing") = true, py::arg("log") = py::none(), py::arg("progress") = py::none(),
          py::arg("rest_name") = "rest mesh", py::arg("cache_start") = py::none(), kShotDoc);
    m.def(
        "uvwarp_shot",
        [](const FloatArray& points, const IntArray& counts, const IntArray& indices,
           const std::optional<FloatArray>& uvs, const std::optional<IntArray>& uvIndices,
           const std::vector<int>& frames, const py::object& deformed, const py::object& rigidity,
           const py::object& out, const py::object& mask, const py::object& orientation,
           const py::object& texture, const py::object& bake, const std::optional<std::vector<int>>& tiles,
           const std::optional<int64_t>& resolution, const std::string& filter, bool skipExisting,
           const py::object& log, const py::object& progress, const std::string& restName,
           const std::optional<double>& cacheStart, const py::kwargs& kwargs) {
            const geom::Mesh mesh =
                meshOf(points, counts, indices, uvs, uvIndices, kShot, std::string(kShot) + " mesh");
            return uvwarpShot(mesh, frames, deformed, rigidity, out, mask, orientation, texture, bake, tiles,
                              resolution, filter, skipExisting, log, progress, restName, cacheStart, kwargs);
        },
        py::arg("points"), py::arg("face_counts"), py::arg("face_indices"), py::arg("uvs"),
        py::arg("uv_indices"), py::arg("frames"), py::arg("deformed"), py::arg("rigidity"), py::arg("out"),
        py::arg("mask") = py::none(), py::arg("orientation") = py::none(), py::arg("texture") = py::none(),
        py::arg("bake") = py::none(), py::arg("tiles") = py::none(), py::arg("resolution") = py::none(),
        py::arg("filter") = "bilinear", py::arg("skip_existing") = true, py::arg("log") = py::none(),
        py::arg("progress") = py::none(), py::arg("rest_name") = "rest mesh",
        py::arg("cache_start") = py::none(), kShotDoc);
    m.def(
        "tile_frame_path",
        [](const std::filesystem::path& pattern, int tile, int frame) {
            return uvwarp::tileFramePath(pattern, tile, frame).string();
        },
        py::arg("pattern"), py::arg("tile"), py::arg("frame"),
        "The file of a tile and frame for a pattern with a UDIM and a frame token, as uvwarp_shot names its\n"
        "outputs: tile_frame_path('out/redirect.<UDIM>.####.exr', 1001, 7) is 'out/redirect.1001.0007.exr'.");
}

}  // namespace deformkit::python
