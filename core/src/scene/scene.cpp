#include "deformkit/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <utility>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/io/animated_positions.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/read_file.h"
#include "deformkit/io/udim.h"
#include "deformkit/scene/weight_maps.h"
#include "deformkit/scene/weights_file.h"
#include "deformkit/uvwarp/grid.h"
#include "deformkit/uvwarp/options.h"
#include "scene/json_reading.h"

namespace deformkit::scene {

std::vector<double> SceneValue::at(double frame) const {
    if (curves.empty()) return constant;
    std::vector<double> v(curves.size());
    for (size_t c = 0; c < curves.size(); ++c)
        v[c] = curves[c].evaluate(frame);
    return v;
}

namespace {

namespace fs = std::filesystem;
using detail::json;

// Reads one scene: every reader names the JSON path of what it reads.
class Reader {
  public:
    Reader(std::string source, fs::path folder, const SceneReadOptions& options)
        : source_(std::move(source)), folder_(std::move(folder)), options_(options) {}

    [[noreturn]] void fail(const std::string& path, const std::string& problem,
                           const std::string& expected) const {
        throw InvalidInput(formatError(source_, path, problem, expected));
    }

    // "which does not exist", or what stands there instead of a file.
    static std::string missingFile(const fs::path& file) {
        std::error_code ec;
        return fs::is_directory(file, ec) ? ", which is a folder, not a file" : ", which does not exist";
    }

    // Whether `file` is a regular file; a path the system cannot even look up (a name too long, a folder
    // without permission) is an error naming the JSON path.
    bool isRegularFile(const fs::path& file, const std::string& path) const {
        std::error_code ec;
        const fs::file_status status = fs::status(file, ec);
        if (ec && status.type() != fs::file_type::not_found) {
            fail(path, "names " + file.string() + ", which cannot be looked up: " + ec.message(),
                 "a readable OBJ file");
        }
        return fs::is_regular_file(status);
    }

    void requireObject(const json& v, const std::string& path, const std::string& expected) const {
        if (!v.is_object()) fail(path, "is " + detail::jsonKind(v), expected);
    }

    // Rejects keys outside `known` (a typo would otherwise be ignored silently).
    void onlyKeys(const json& v, const std::string& path, std::initializer_list<const char*> known) const {
        detail::requireKnownKeys(v, source_, path, known);
    }

    double number(const json& v, const std::string& path) const {
        if (!v.is_number()) fail(path, "is " + detail::jsonKind(v), "a number");
        const double d = v.get<double>();
        if (!std::isfinite(d)) fail(path, "is " + v.dump(), "a finite number");
        return d;
    }

    int integer(const json& v, const std::string& path) const {
        const double d = number(v, path);
        if (d != std::floor(d) || std::abs(d) > static_cast<double>(kMaxFrameNumber)) {
            fail(path, "is " + v.dump(),
                 "a whole frame number from -" + std::to_string(kMaxFrameNumber) + " to " +
                     std::to_string(kMaxFrameNumber));
        }
        return static_cast<int>(d);
    }

    std::string string(const json& v, const std::string& path, const std::string& expected) const {
        if (!v.is_string()) fail(path, "is " + detail::jsonKind(v), expected);
        if (v.get<std::string>().empty()) fail(path, "is empty", expected);
        return v.get<std::string>();
    }

    // A number or an array of numbers.
    std::vector<double> numbers(const json& v, const std::string& path) const {
        if (v.is_number()) return {number(v, path)};
        if (!v.is_array() || v.empty())
            fail(path, "is " + detail::jsonKind(v), "a number or a non-empty array of numbers");
        std::vector<double> out(v.size());
        for (size_t i = 0; i < v.size(); ++i)
            out[i] = number(v[i], detail::jsonIndex(path, i));
        return out;
    }

    // A constant (number or array) or {"keys": [...]}.
    SceneValue value(const json& v, const std::string& path) const {
        SceneValue out;
        if (!v.is_object()) {
            out.constant = numbers(v, path);
            return out;
        }
        onlyKeys(v, path, {"keys"});
        if (!v.contains("keys")) fail(path + ".keys", "is missing", "an array of keys");
        const json& keys = v.at("keys");
        const std::string keysPath = path + ".keys";
        if (!keys.is_array() || keys.empty())
            fail(keysPath, "is " + detail::jsonKind(keys), "a non-empty array of keys");
        std::vector<std::vector<Key>> perComponent;
        for (size_t k = 0; k < keys.size(); ++k) {
            const std::string kp = detail::jsonIndex(keysPath, k);
            const json& key = keys[k];
            requireObject(key, kp, "{\"frame\": ..., \"value\": ...}");
            onlyKeys(key, kp, {"frame", "value", "interpolation", "tangent", "in", "out"});
            if (!key.contains("frame")) fail(kp + ".frame", "is missing", "a number");
            if (!key.contains("value")) fail(kp + ".value", "is missing", "a number or an array of numbers");
            Key base;
            base.time = number(key.at("frame"), kp + ".frame");
            if (k > 0 && !(base.time > perComponent[0].back().time)) {
                fail(kp + ".frame",
                     "is " + numberText(base.time) + ", not after the previous key's " +
                         numberText(perComponent[0].back().time),
                     "increasing frames");
            }
            const std::vector<double> values = numbers(key.at("value"), kp + ".value");
            if (k == 0) {
                perComponent.resize(values.size());
            } else if (values.size() != perComponent.size()) {
                fail(kp + ".value", "has " + std::to_string(values.size()) + " components",
                     std::to_string(perComponent.size()) + ", as keys[0]");
            }
            if (key.contains("interpolation")) {
                const std::string s = string(key.at("interpolation"), kp + ".interpolation",
                                             "\"constant\", \"linear\" or \"bezier\"");
                if (s == "constant") {
                    base.interpolation = Interpolation::Constant;
                } else if (s == "linear") {
                    base.interpolation = Interpolation::Linear;
                } else if (s == "bezier") {
                    base.interpolation = Interpolation::Bezier;
                } else {
                    fail(kp + ".interpolation", "is \"" + s + "\"", "\"constant\", \"linear\" or \"bezier\"");
                }
            }
            if (key.contains("tangent")) {
                const std::string s =
                    string(key.at("tangent"), kp + ".tangent", "\"auto\", \"flat\" or \"explicit\"");
                if (s == "auto") {
                    base.tangent = TangentMode::Auto;
                } else if (s == "flat") {
                    base.tangent = TangentMode::Flat;
                } else if (s == "explicit") {
                    base.tangent = TangentMode::Explicit;
                } else {
                    fail(kp + ".tangent", "is \"" + s + "\"", "\"auto\", \"flat\" or \"explicit\"");
                }
            }
            // Slopes: value units per frame, a number for every component or one per component.
            auto slopes = [&](const char* name) {
                std::vector<double> s(values.size(), 0.0);
                const std::string sp = kp + "." + name;
                if (!key.contains(name)) {
                    if (base.tangent == TangentMode::Explicit)
                        fail(sp, "is missing", "a slope, as the tangent is \"explicit\"");
                    return s;
                }
                if (base.tangent != TangentMode::Explicit)
                    fail(sp, "is given", "slopes only with \"tangent\": \"explicit\"");
                const std::vector<double> given = numbers(key.at(name), sp);
                if (key.at(name).is_number()) return std::vector<double>(values.size(), given[0]);
                if (given.size() != values.size()) {
                    fail(sp, "has " + std::to_string(given.size()) + " slopes",
                         std::to_string(values.size()) + ", one per component of the value");
                }
                return given;
            };
            const std::vector<double> in = slopes("in"), outSlopes = slopes("out");
            for (size_t c = 0; c < values.size(); ++c) {
                Key key1 = base;
                key1.value = values[c];
                key1.inSlope = in[c];
                key1.outSlope = outSlopes[c];
                perComponent[c].push_back(key1);
            }
        }
        for (size_t c = 0; c < perComponent.size(); ++c) {
            try {
                out.curves.emplace_back(std::move(perComponent[c]), "component " + std::to_string(c));
            } catch (const Error& e) {
                fail(keysPath, e.what(), "valid keys");  // a backstop: the checks above come first
            }
        }
        return out;
    }

    fs::path file(const json& v, const std::string& path, const std::string& expected) const {
        const fs::path p = string(v, path, expected);
        return p.is_absolute() ? p : folder_ / p;
    }

    // Painted weights: a JSON file of one number per vertex, or {"image": pattern, "channel": c} sampled
    // through the rest mesh's UVs (weight_maps.h).
    std::vector<float> weights(const json& v, const std::string& path, const geom::Mesh& rest,
                               const fs::path& meshFile, fs::path& file) const {
        const int32_t count = rest.numVertices();
        if (v.is_object()) {
            onlyKeys(v, path, {"image", "ptex", "channel"});
            if (v.contains("image") == v.contains("ptex"))
                fail(path,
                     v.contains("image") ? "has both \"image\" and \"ptex\""
                                         : "has neither \"image\" nor \"ptex\"",
                     "one of an image file name or UDIM pattern (\"image\") and a Ptex file (\"ptex\")");
            const int32_t channel =
                v.contains("channel") ? static_cast<int32_t>(ranged(v.at("channel"), path + ".channel", 0, 64,
                                                                    true, "a whole number from 0 to 64"))
                                      : 0;
            if (v.contains("ptex")) {
                file = this->file(v.at("ptex"), path + ".ptex", "a Ptex file name");
                if (!options_.ptexWeights)
                    fail(path + ".ptex", "names a Ptex file, which this application cannot read",
                         "the deformkit CLI or Python module, which read Ptex weights");
                std::vector<float> weights;
                try {
                    weights = options_.ptexWeights(rest, meshFile.string(), file, channel,
                                                   source_ + ": " + path + ".ptex");
                } catch (const InvalidInput&) {
                    throw;
                } catch (const Error& e) {
                    throw InvalidInput(e.what());  // an unreadable file; the message names the JSON path
                }
                if (weights.size() != static_cast<size_t>(count))
                    fail(path + ".ptex", "gives " + std::to_string(weights.size()) + " weights",
                         std::to_string(count) + ", one per vertex");
                return weights;
            }
            file = this->file(v.at("image"), path + ".image", "an image file name or UDIM pattern");
            try {
                return weightsFromMaps(rest, file, channel, source_ + ": " + path + ".image");
            } catch (const InvalidInput&) {
                throw;
            } catch (const Error& e) {
                fail(path + ".image", e.what(), "a readable weight map");
            }
        }
        file = this->file(v, path, "a weights file name (JSON), or {\"image\": ...}");
        // The file's own messages name it; the scene's add the JSON path. Every error is InvalidInput here:
        // the scene is what is wrong, whatever the file's problem.
        try {
            return readWeightsFile(file, static_cast<size_t>(count));
        } catch (const Error& e) {
            fail(path, e.what(), "");  // the file's message says what it expected
        }
    }

    SceneDeformer deformer(const json& v, const std::string& path, size_t entry, const geom::Mesh& rest,
                           const fs::path& meshFile) const {
        requireObject(v, path, "{\"type\": ..., \"params\": {...}}");
        onlyKeys(v, path, {"type", "label", "envelope", "weights", "params"});
        SceneDeformer d;
        d.path = path;
        const std::string known = knownTypes();
        if (!v.contains("type")) fail(path + ".type", "is missing", "one of: " + known);
        d.type = string(v.at("type"), path + ".type", "one of: " + known);
        bool typeKnown = false;
        for (const host::DeformerType& t : host::deformerTypes())
            typeKnown = typeKnown || t.name == d.type;
        if (!typeKnown) fail(path + ".type", "is \"" + d.type + "\"", "one of: " + known);
        d.label = v.contains("label") ? string(v.at("label"), path + ".label", "a non-empty string")
                                      : d.type + std::to_string(entry + 1);
        d.envelope.constant = {1.0};
        if (v.contains("envelope")) {
            d.envelope = value(v.at("envelope"), path + ".envelope");
            const size_t n = d.envelope.animated() ? d.envelope.curves.size() : d.envelope.constant.size();
            if (n != 1) fail(path + ".envelope", "has " + std::to_string(n) + " components", "one number");
        }
        if (v.contains("weights"))
            d.weights = weights(v.at("weights"), path + ".weights", rest, meshFile, d.weightsFile);

        // Parameters are checked by a probe deformer's own set(), in its parameters() order (bind-time
        // inputs first, as a host sets them): the constant, or every key's value.
        std::unique_ptr<host::Deformer> probe = host::makeDeformer(d.type, d.label);
        const std::string paramsPath = path + ".params";
        if (v.contains("params")) {
            const json& params = v.at("params");
            requireObject(params, paramsPath, "an object of parameter values by name");
            for (const auto& item : params.items()) {
                if (!probe->hasParameter(item.key())) {
                    try {
                        (void)probe->parameter(item.key());
                    } catch (const Error& e) {
                        fail(paramsPath + "." + item.key(), e.what(), "a parameter of " + d.type);
                    }
                }
            }
            for (const host::ParamInfo& info : probe->parameters()) {
                if (!params.contains(info.name)) continue;
                SceneParameter p;
                p.name = info.name;
                p.path = paramsPath + "." + info.name;
                p.value = value(params.at(info.name), p.path);
                try {
                    if (!p.value.animated()) {
                        probe->set(p.name, p.value.constant);
                    } else {
                        const size_t keyCount = p.value.curves[0].size();
                        const auto keyValue = [&](size_t k) {
                            std::vector<double> x(p.value.curves.size());
                            for (size_t c = 0; c < x.size(); ++c)
                                x[c] = p.value.curves[c].keys()[k].value;
                            return x;
                        };
                        for (size_t k = 0; k < keyCount; ++k) {
                            try {
                                probe->set(p.name, keyValue(k));
                            } catch (const Error& e) {
                                fail(detail::jsonIndex(p.path + ".keys", k) + ".value", e.what(), "");
                            }
                        }
                        requireSettableBetweenKeys(*probe, p);
                        probe->set(p.name, keyValue(keyCount - 1));  // as the keys left it
                    }
                } catch (const InvalidInput& e) {
                    const std::string what = e.what();
                    if (what.rfind(source_ + ": ", 0) == 0) throw;  // already names the key
                    fail(p.path, what, "");
                }
                d.params.push_back(std::move(p));
            }
        }
        return d;
    }

    // The deformer types and the UV-warp stage, for messages.
    static std::string knownTypes() {
        std::string known;
        for (const host::DeformerType& t : host::deformerTypes())
            known += (known.empty() ? "" : ", ") + std::string(t.name);
        return known + ", uvwarp (last entry)";
    }

    // A curve between its keys can leave what its parameter takes: a whole-number parameter (FFD divisions, a
    // slide's vertex) between two whole keys, a Bezier overshooting a range. Such a scene would parse, then
    // fail at the first frame between those keys. Every segment that is not a step is set at two frames
    // inside it (its middle, and 0.318 of the way, where a line between whole numbers less than 1000 apart
    // is not whole): a scene that parses can be set at those frames.
    void requireSettableBetweenKeys(host::Deformer& probe, const SceneParameter& p) const {
        const std::vector<Key>& keys = p.value.curves[0].keys();
        for (size_t k = 0; k + 1 < keys.size(); ++k) {
            if (keys[k].interpolation == Interpolation::Constant) continue;
            for (const double along : {0.5, 0.3183098861837907}) {
                const double frame = keys[k].time + along * (keys[k + 1].time - keys[k].time);
                const std::vector<double> x = p.value.at(frame);
                try {
                    probe.set(p.name, x);
                } catch (const Error& e) {
                    std::string value;
                    for (const double c : x)
                        value += (value.empty() ? "" : ", ") + numberText(c);
                    fail(detail::jsonIndex(p.path + ".keys", k),
                         "interpolates to " + (x.size() > 1 ? "(" + value + ")" : value) + " at frame " +
                             numberText(frame) + " on its way to keys[" + std::to_string(k + 1) +
                             "], which the parameter refuses: " + e.what(),
                         "\"interpolation\": \"constant\" on this key for a whole-number parameter, or keys "
                         "whose curve stays within what the parameter takes");
                }
            }
        }
    }

    // Adds a stack entry's label to `labels`, naming the entry when an earlier one has it: its "label", or,
    // where the entry has none, the default label it was given (its type and entry number).
    void requireNewLabel(std::set<std::string>& labels, const std::string& label, const json& entry,
                         const std::string& entryPath) const {
        if (labels.insert(label).second) return;
        if (entry.contains("label")) {
            fail(entryPath + ".label", "is \"" + label + "\", used by an earlier entry",
                 "a label unique in the stack");
        }
        fail(entryPath,
             "has no label, and its default one (type and entry number), \"" + label +
                 "\", is an earlier entry's",
             "a label unique in the stack: give this entry a \"label\"");
    }

    // A number in [lo, hi]; whole when `whole`.
    double ranged(const json& v, const std::string& path, double lo, double hi, bool whole,
                  const std::string& expected) const {
        const double d = number(v, path);
        if (d < lo || d > hi || (whole && d != std::floor(d))) fail(path, "is " + v.dump(), expected);
        return d;
    }

    // A UV-warp option from its JSON value, checked by the library (uvwarp/options.h).
    void uvwarpOption(uvwarp::TileWarpOptions& options, const uvwarp::OptionSpec& spec, const json& v,
                      const std::string& path) const {
        uvwarp::OptionValue value;
        using Kind = uvwarp::OptionValue::Kind;
        if (v.is_boolean()) {
            value.kind = Kind::Boolean;
            value.numbers = {v.get<bool>() ? 1.0 : 0.0};
        } else if (v.is_number()) {
            value.numbers = {v.get<double>()};
        } else if (v.is_array() &&
                   std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); })) {
            value.kind = Kind::List;
            for (const json& x : v)
                value.numbers.push_back(x.get<double>());
        } else {
            value.kind = Kind::Other;
            value.shown = detail::jsonKind(v);
        }
        if (value.kind != Kind::Other) value.shown = v.dump();  // as the scene writes it: 2.0, [0,0]
        uvwarp::setOption(options, spec, value, source_, path);
    }

    // A UDIM pattern ("rig.<UDIM>.exr"), resolved against the scene's folder.
    fs::path udimPattern(const json& v, const std::string& path) const {
        const fs::path p = file(v, path, "an image file name with a UDIM token");
        if (!io::hasUdimToken(p.filename().string())) {
            fail(path, "is \"" + v.get<std::string>() + "\", without a UDIM token",
                 "a file name with <UDIM>, <UVTILE>, %(UDIM)d or _MAPID_");
        }
        return p;
    }

    // Stack entry `entry` of type "uvwarp" (docs/scene.md): patterns, tiles and solver options.
    SceneUvWarp uvwarp(const json& v, const std::string& path, size_t entry, const geom::Mesh& rest) const {
        onlyKeys(v, path,
                 {"type", "label", "rigidity", "mask", "orientation", "texture", "tiles", "resolution",
                  "filter", "preset", "params"});
        SceneUvWarp u;
        u.path = path;
        u.label = v.contains("label") ? string(v.at("label"), path + ".label", "a non-empty string")
                                      : "uvwarp" + std::to_string(entry + 1);
        if (!rest.hasUVs()) {
            fail(path, "is a UV warp on a rest mesh without UVs",
                 "a rest mesh with texture coordinates (vt) on its faces");
        }
        if (!v.contains("rigidity")) fail(path + ".rigidity", "is missing", "a rigidity map pattern");
        u.rigidity = udimPattern(v.at("rigidity"), path + ".rigidity");
        if (v.contains("mask")) u.mask = udimPattern(v.at("mask"), path + ".mask");
        if (v.contains("orientation"))
            u.orientation = udimPattern(v.at("orientation"), path + ".orientation");
        if (v.contains("texture")) u.texture = udimPattern(v.at("texture"), path + ".texture");
        const std::vector<int> meshTiles = rest.udimTiles();
        if (v.contains("tiles")) {
            const json& tiles = v.at("tiles");
            if (!tiles.is_array() || tiles.empty())
                fail(path + ".tiles", "is " + detail::jsonKind(tiles),
                     "a non-empty array of UDIM tile numbers");
            std::string have;
            for (int t : meshTiles)
                have.append(have.empty() ? "" : " ").append(std::to_string(t));
            for (size_t i = 0; i < tiles.size(); ++i) {
                const std::string tp = detail::jsonIndex(path + ".tiles", i);
                const int tile =
                    static_cast<int>(ranged(tiles[i], tp, 1001, 9999, true, "a UDIM tile, 1001..9999"));
                if (!std::binary_search(meshTiles.begin(), meshTiles.end(), tile))
                    fail(tp, "is " + std::to_string(tile) + ", a tile without UV faces",
                         "a tile of the rest mesh: " + have);
                if (std::find(u.tiles.begin(), u.tiles.end(), tile) != u.tiles.end())
                    fail(tp, "is " + std::to_string(tile) + ", listed before", "each tile once");
                u.tiles.push_back(tile);
            }
            std::sort(u.tiles.begin(), u.tiles.end());
            u.tiles.erase(std::unique(u.tiles.begin(), u.tiles.end()), u.tiles.end());
        } else {
            u.tiles = meshTiles;
        }
        if (v.contains("resolution")) {
            uvwarpOption(u.options, *uvwarp::findOption("resolution"), v.at("resolution"),
                         path + ".resolution");
            u.presetOwn.emplace_back("resolution");
        }
        if (v.contains("preset")) {
            u.preset = uvwarp::presetNamed(string(v.at("preset"), path + ".preset", "\"shot\" or \"live\""),
                                           source_, path + ".preset");
        }
        if (v.contains("filter")) {
            const std::string f = string(v.at("filter"), path + ".filter", "\"bilinear\" or \"bicubic\"");
            if (f == "bilinear") {
                u.filter = io::SampleFilter::Bilinear;
            } else if (f == "bicubic") {
                u.filter = io::SampleFilter::Bicubic;
            } else {
                fail(path + ".filter", "is \"" + f + "\"", "\"bilinear\" or \"bicubic\"");
            }
        }
        if (v.contains("params")) {
            const json& params = v.at("params");
            const std::string pp = path + ".params";
            requireObject(params, pp, "an object of UV-warp options by name");
            for (const auto& item : params.items()) {
                const uvwarp::OptionSpec* spec = uvwarp::findOption(item.key());
                if (spec == nullptr) {
                    std::string known;
                    for (const uvwarp::OptionSpec& s : uvwarp::optionSpecs())
                        known += (known.empty() ? "" : ", ") + std::string(s.name);
                    fail(pp + "." + item.key(), "is not a UV-warp option", "one of: " + known);
                }
                if (spec == uvwarp::findOption("resolution") && v.contains("resolution")) {
                    fail(pp + ".resolution", "is given as well as " + path + ".resolution",
                         "the resolution given once, in either place");
                }
                uvwarpOption(u.options, *spec, item.value(), pp + "." + item.key());
                u.presetOwn.emplace_back(spec->name);
            }
        }
        return u;
    }

    SceneObject object(const json& v, const std::string& path, int firstFrame) const {
        requireObject(v, path, "{\"name\": ..., \"mesh\": ..., \"stack\": [...]}");
        onlyKeys(v, path, {"name", "mesh", "restFrame", "deformed", "cacheStart", "stack"});
        SceneObject o;
        o.path = path;
        if (!v.contains("name")) fail(path + ".name", "is missing", "a name");
        o.name = string(v.at("name"), path + ".name", "a non-empty name");
        for (char c : o.name) {
            const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                            c == '_' || c == '-' || c == '.';
            if (!ok || o.name[0] == '.') {
                fail(path + ".name", "is \"" + o.name + "\"",
                     "letters, digits, '_', '-' and '.' only, not starting with '.' (it names output files)");
            }
        }
        if (!v.contains("mesh"))
            fail(path + ".mesh", "is missing", "a mesh file name (.obj, .gltf, .glb, .fbx, .ply, .dae)");
        o.meshFile =
            file(v.at("mesh"), path + ".mesh", "a mesh file name (.obj, .gltf, .glb, .fbx, .ply, .dae)");
        const bool meshIsSequence = io::ObjSequence::isPattern(o.meshFile.filename().string());
        if (v.contains("deformed")) {
            if (meshIsSequence) {
                fail(path + ".deformed", "is given with the sequence " + o.meshFile.string() + " as the mesh",
                     "either \"mesh\" a frame sequence, or \"mesh\" the rest OBJ and \"deformed\" its "
                     "animation");
            }
            o.sequence = file(v.at("deformed"), path + ".deformed",
                              "an OBJ sequence ('anim.####.obj') or a point cache ('anim.pc2', 'anim.mdd')");
            o.sequenceElement = path + ".deformed";
            if (!io::AnimatedPositions::accepts(o.sequence)) {
                fail(path + ".deformed",
                     "is " + o.sequence.string() + ", which has no frame token and is no point cache",
                     io::AnimatedPositions::kForms);
            }
        }
        if (v.contains("cacheStart")) {
            if (!io::pointCacheFormat(o.sequence)) {
                fail(path + ".cacheStart", "is given without a point cache",
                     "cacheStart only with \"deformed\" a point cache (.pc2, .mdd)");
            }
            o.cacheStart = number(v.at("cacheStart"), path + ".cacheStart");
        }
        if (meshIsSequence) {
            o.sequence = o.meshFile;
            o.sequenceElement = path + ".mesh";
            o.restFrame =
                v.contains("restFrame") ? integer(v.at("restFrame"), path + ".restFrame") : firstFrame;
            o.meshFile = io::ObjSequence(o.sequence).framePath(o.restFrame);
            if (!isRegularFile(o.meshFile, path + ".mesh")) {
                fail(path + ".mesh",
                     "names the sequence " + o.sequence.string() + ", whose rest frame " +
                         std::to_string(o.restFrame) + " (" + o.meshFile.string() + ") does not exist",
                     "an OBJ file for the rest frame (restFrame, default the scene's first frame)");
            }
        } else if (v.contains("restFrame")) {
            fail(path + ".restFrame", "is given for the single mesh " + o.meshFile.string(),
                 "restFrame only with a frame sequence (\"mesh\": \"anim.####.obj\")");
        }
        if (!isRegularFile(o.meshFile, path + ".mesh"))
            fail(path + ".mesh", "names " + o.meshFile.string() + missingFile(o.meshFile), "a mesh file");
        try {
            io::ObjContent content = io::readMesh(o.meshFile);
            o.rest = std::move(content.mesh);
            o.groups = std::move(content.groups);
        } catch (const Error& e) {
            fail(path + ".mesh", e.what(), "");
        }
        if (!v.contains("stack")) fail(path + ".stack", "is missing", "an array of deformers");
        const json& stack = v.at("stack");
        if (!stack.is_array())
            fail(path + ".stack", "is " + detail::jsonKind(stack), "an array of deformers");
        std::set<std::string> labels;
        for (size_t i = 0; i < stack.size(); ++i) {
            const std::string entryPath = detail::jsonIndex(path + ".stack", i);
            if (stack[i].is_object() && stack[i].contains("type") && stack[i].at("type") == "uvwarp") {
                if (i + 1 != stack.size()) {
                    fail(
                        entryPath + ".type",
                        "is \"uvwarp\" at entry " + std::to_string(i) + " of " + std::to_string(stack.size()),
                        "the UV warp as the last entry: it works in texture space on the stack's result");
                }
                o.uvwarp = uvwarp(stack[i], entryPath, i, o.rest);
                requireNewLabel(labels, o.uvwarp->label, stack[i], entryPath);
                continue;
            }
            SceneDeformer d = deformer(stack[i], entryPath, i, o.rest, o.meshFile);
            requireNewLabel(labels, d.label, stack[i], entryPath);
            o.stack.push_back(std::move(d));
        }
        return o;
    }

    Scene scene(const json& root) const {
        requireObject(root, "(top level)", "an object");
        if (!root.contains("deformkit_scene")) {
            fail("deformkit_scene", "is missing",
                 std::to_string(kSceneVersion) + ", the scene format version (a DeformKit scene file)");
        }
        const json& version = root.at("deformkit_scene");
        if (!version.is_number() || version.get<double>() != kSceneVersion) {
            fail("deformkit_scene", "is " + version.dump(),
                 std::to_string(kSceneVersion) + ", the version this DeformKit reads");
        }
        onlyKeys(root, "", {"deformkit_scene", "frames", "objects"});
        Scene s;
        s.source = source_;
        if (!root.contains("frames")) fail("frames", "is missing", "[first, last]");
        const json& frames = root.at("frames");
        if (!frames.is_array() || frames.size() != 2)
            fail("frames", "is " + detail::jsonKind(frames), "[first, last]");
        s.firstFrame = integer(frames[0], "frames[0]");
        s.lastFrame = integer(frames[1], "frames[1]");
        if (s.lastFrame < s.firstFrame) {
            fail("frames", "is " + frames.dump(), "[first, last] with last >= first");
        }
        const int64_t count = static_cast<int64_t>(s.lastFrame) - s.firstFrame + 1;
        if (count > kMaxFrames) {
            fail("frames", "is " + frames.dump() + ", " + std::to_string(count) + " frames",
                 "at most " + std::to_string(kMaxFrames) + " frames");
        }
        if (!root.contains("objects")) fail("objects", "is missing", "an array of objects");
        const json& objects = root.at("objects");
        if (!objects.is_array()) fail("objects", "is " + detail::jsonKind(objects), "an array of objects");
        std::set<std::string> names;
        for (size_t i = 0; i < objects.size(); ++i) {
            SceneObject o = object(objects[i], detail::jsonIndex("objects", i), s.firstFrame);
            if (!names.insert(o.name).second) {
                fail(detail::jsonIndex("objects", i) + ".name",
                     "is \"" + o.name + "\", used by an earlier object", "a unique name");
            }
            s.objects.push_back(std::move(o));
        }
        return s;
    }

  private:
    std::string source_;
    fs::path folder_;
    const SceneReadOptions& options_;
};

}  // namespace

Scene parseScene(std::string_view text, const fs::path& source) {
    return parseScene(text, source, SceneReadOptions{});
}

Scene parseScene(std::string_view text, const fs::path& source, const SceneReadOptions& options) {
    const json root = detail::parseJson(text, source.string(), "a JSON scene (docs/scene.md)");
    return Reader(source.string(), source.parent_path(), options).scene(root);
}

Scene readScene(const fs::path& path) {
    return readScene(path, SceneReadOptions{});
}

Scene readScene(const fs::path& path, const SceneReadOptions& options) {
    return parseScene(io::readFile(path, "JSON scene file"), path, options);
}

}  // namespace deformkit::scene
