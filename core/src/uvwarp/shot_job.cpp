#include "deformkit/uvwarp/shot_job.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/animated_positions.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/udim.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/geometry_image.h"
#include "deformkit/uvwarp/grid.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/version.h"

namespace deformkit::uvwarp {
// The tile types ShotSolver::Impl holds, in a named namespace: a class's fields must not have types of an
// anonymous namespace when the source is compiled as part of a unity batch (-Wsubobject-linkage).
namespace detail {

// One tile's map from its source: a file of the pattern or an image in memory. `name` says where it came
// from, for messages and headers.
struct TileMap {
    std::optional<std::filesystem::path> file;  // an animated map: its file at the job's first frame
    std::string framePattern;  // an animated map: the tile's files, a frame token in the name
    const io::Image* image = nullptr;
    std::string name;
    int32_t width = 0, height = 0, channels = 0;
    std::string firstChannel;  // the file's name for channel 0 (EXR sorts channels by name), "" for an image

    [[nodiscard]] bool found() const { return file.has_value() || image != nullptr; }
};

// What a job does for one tile, worked out before anything is written.
struct TilePlan {
    int tile = 0;
    TileMap rigidity, mask, orientation, texture;
    std::vector<std::filesystem::path> outPaths, bakePaths;  // per frame
    std::vector<bool> needed;                                // per frame: an output to write
    int lastNeeded = -1;                                     // index of the last needed frame
    TileWarpOptions options;                                 // the job's, or its preset's for this tile
    std::optional<TileWarp> warp;                            // bound at the first frame it solves
    io::Image texturePixels, redirect, baked;
    io::PixelType texturePixelType = io::PixelType::Auto;  // the texture file's, kept by a bake of its format
    bool saidWorseThanIdentity = false;                    // the note of a map worse than no warp, once
    // Animated maps: the rigidity, mask and orientation images last given to the warp, to tell a change.
    io::Image lastRigidity, lastMask, lastOrientation;
    nlohmann::json inputs;
    ShotTileReport report;
};

}  // namespace detail
using detail::TileMap;
using detail::TilePlan;

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// A file (or a link to one): a folder with an output's name is not a written output.
bool fileExists(const fs::path& path) {
    std::error_code ec;
    return fs::is_regular_file(path, ec);
}

// A float option as JSON: the shortest decimal that reads back as the float (0.05, not 0.0500000007).
double tidy(float value) {
    char text[32];
    const auto [end, ec] = std::to_chars(text, text + sizeof(text), value);
    return ec == std::errc() ? std::strtod(std::string(text, end).c_str(), nullptr)
                             : static_cast<double>(value);
}

// The figures of a frame: the redirect map's and its fold repair's when it was made (a frame written), then
// the grid's and the solver's.
json metricsJson(const DeliveredMetrics* delivered, const FoldRepair* repair, const WarpMetrics& m,
                 const SolveStats& s) {
    json j = json::object();
    std::vector<std::vector<ReportedFigure>> lists;
    if (delivered) lists.push_back(reportedFigures(*delivered));
    if (repair) lists.push_back(reportedFigures(*repair));
    lists.push_back(reportedFigures(m));
    lists.push_back(reportedFigures(s));
    for (const std::vector<ReportedFigure>& figures : lists) {
        for (const ReportedFigure& f : figures) {
            json& slot = j[std::string(f.name)];
            if (f.kind == ReportedFigure::Kind::Count) {
                slot = static_cast<int64_t>(f.value);
            } else if (f.kind == ReportedFigure::Kind::Flag) {
                slot = f.value != 0;
            } else {
                slot = f.value;
            }
        }
    }
    return j;
}

// The options a map was made with, by their declared names (uvwarp/options.h), and the grid in use.
json solverJson(const TileWarpOptions& o, int32_t cells, int32_t texels, int32_t levelsUsed) {
    json j = {{"cells", cells}, {"texels", texels}, {"levelsUsed", levelsUsed}};
    for (const OptionSpec& spec : optionSpecs()) {
        if (!spec.recorded) continue;
        const std::vector<double> v = spec.get(o);
        json& slot = j[std::string(spec.name)];
        switch (spec.type) {
            case OptionType::Flag:
                slot = v.front() != 0;
                break;
            case OptionType::IntegerList:
                slot = std::vector<int64_t>(v.begin(), v.end());
                break;
            case OptionType::Integer:
                slot = static_cast<int64_t>(v.front());
                break;
            case OptionType::Number:
                slot = tidy(static_cast<float>(v.front()));
                break;
        }
    }
    return j;
}

std::string texelsText(int32_t width, int32_t height) {
    return std::to_string(width) + " x " + std::to_string(height) + " texels";
}

// Finds `tile` in `source` and reads its size (a file's header only, so a wrong size stops the job before
// anything is written).
TileMap findTileMap(const TileMapSource& source, int tile, const std::vector<int>& frames) {
    TileMap map;
    if (!source.pattern.empty()) {
        const std::string tilePattern = io::expandUdim(source.pattern.string(), tile);
        if (io::ObjSequence::isPattern(tilePattern)) {
            // Animated: one file per frame. Found when any frame's is there (whether a tile is warped does
            // not depend on the frame a run starts at); then every frame's must be, with the same size
            // (headers only), before anything is written.
            const io::ObjSequence sequence(tilePattern);
            map.name = tilePattern;
            const auto any = std::find_if(frames.begin(), frames.end(),
                                          [&](int frame) { return fileExists(sequence.framePath(frame)); });
            if (any == frames.end()) return map;
            const fs::path first = sequence.framePath(*any);
            const io::ImageInfo info = io::readImageInfo(first);
            map.file = first;
            map.framePattern = tilePattern;
            map.width = info.width;
            map.height = info.height;
            map.channels = info.channels;
            if (!info.channelNames.empty()) map.firstChannel = info.channelNames.front();
            for (int frame : frames) {
                const fs::path path = sequence.framePath(frame);
                if (!fileExists(path)) {
                    throw IoError(
                        formatError(path.string(), "frame " + std::to_string(frame), "does not exist",
                                    "a map for every frame of an animated map '" + tilePattern + "'"));
                }
                const io::ImageInfo frameInfo = io::readImageInfo(path);
                if (frameInfo.width != info.width || frameInfo.height != info.height) {
                    throw InvalidInput(formatError(
                        path.string(), "frame " + std::to_string(frame),
                        texelsText(frameInfo.width, frameInfo.height),
                        texelsText(info.width, info.height) + ", the size of '" + first.string() + "'"));
                }
            }
            return map;
        }
        const fs::path path = tilePattern;
        map.name = path.string();
        if (!fileExists(path)) return map;
        const io::ImageInfo info = io::readImageInfo(path);
        map.file = path;
        map.width = info.width;
        map.height = info.height;
        map.channels = info.channels;
        if (!info.channelNames.empty()) map.firstChannel = info.channelNames.front();
        return map;
    }
    map.name = (source.name.empty() ? std::string("map") : source.name) + " tile " + std::to_string(tile);
    const auto it = source.images.find(tile);
    if (it == source.images.end()) return map;
    map.image = &it->second;
    map.width = it->second.width;
    map.height = it->second.height;
    map.channels = it->second.channels;
    return map;
}

}  // namespace

struct ShotSolver::Impl {
    ShotJob job;
    std::vector<TilePlan> plans;
    size_t nextFrame = 0;  // index of the next frame in job.frames
    int64_t unitsDone = 0;

    void writeLog(json line) const {
        if (!job.log) return;
        if (job.logTask >= 0) line["task"] = job.logTask;
        if (!job.logObject.empty()) line["object"] = job.logObject;
        *job.log << line.dump() << "\n" << std::flush;
    }
    json baseLine(const TilePlan& plan, size_t k, const char* status) const {
        json line = {{"tile", plan.tile}, {"frame", job.frames[k]}, {"status", status}};
        if (warmUp(k)) return line;  // no outputs
        if (!plan.outPaths.empty()) line["redirect"] = plan.outPaths[k].string();
        if (plan.texture.found()) line["bake"] = plan.bakePaths[k].string();
        return line;
    }
    [[nodiscard]] bool warmUp(size_t k) const { return k < static_cast<size_t>(job.warmUpFrames); }
    // The units of frame k that need no solve: unwarped tiles and frames after a tile's last needed one.
    void logUnsolved(TilePlan& plan, size_t k) {
        if (warmUp(k)) return;  // nothing to warm up: the tile has no output to write
        if (!plan.report.warped) {
            json line = baseLine(plan, k, "unwarped");
            line["reason"] = "no rigidity map '" + plan.rigidity.name + "'";
            writeLog(line);
        } else {
            ++plan.report.skipped;
            writeLog(baseLine(plan, k, "skipped"));
        }
    }
    // Does `plan` solve frame k? Warm-started frames carry the warm start up to the tile's last output;
    // frames solved from the identity (SolverOptions::warmStart false) depend on nothing before them: only
    // the outputs are solved.
    [[nodiscard]] bool solves(const TilePlan& plan, size_t k) const {
        return plan.report.warped &&
               (plan.options.solver.warmStart ? static_cast<int>(k) <= plan.lastNeeded : plan.needed[k]);
    }
    void bind(TilePlan& plan, int frame);
    // Animated maps: gives the warp the frame's maps when they differ from the last ones.
    void animateMaps(TilePlan& plan, int frame);
    void solveTile(TilePlan& plan, size_t k, std::span<const glm::vec3> deformed,
                   const std::string& inputName);
};

namespace {

// Every output of the job has a name of its own, none the name of an input (the rest mesh, a map's file at
// any frame, the caller's files).
void requireOutputsApart(const std::vector<detail::TilePlan>& plans, const ShotJob& j) {
    io::FileNames names;
    for (const detail::TilePlan& plan : plans) {
        if (!plan.report.warped) continue;
        for (size_t k = 0; k < j.frames.size(); ++k) {
            const std::string at =
                "tile " + std::to_string(plan.tile) + ", frame " + std::to_string(j.frames[k]);
            names.output(plan.outPaths[k], "the redirect map of " + at);
            if (!plan.bakePaths[k].empty()) names.output(plan.bakePaths[k], "the bake of " + at);
        }
    }
    for (const ShotJob::CallerFile& file : j.callerFiles)
        if (file.written) names.output(file.path, file.what);
    std::error_code error;
    if (fs::is_regular_file(j.restName, error))
        names.input(j.restName, "the rest mesh");  // not a host's label
    for (const ShotJob::CallerFile& file : j.callerFiles)
        if (!file.written) names.input(file.path, file.what);
    for (const detail::TilePlan& plan : plans) {
        for (const auto& [map, what] :
             {std::pair{&plan.rigidity, "rigidity map"}, std::pair{&plan.mask, "warp mask"},
              std::pair{&plan.orientation, "orientation map"}, std::pair{&plan.texture, "texture"}}) {
            if (!map->file) continue;
            const std::string of = std::string("the ") + what + " of tile " + std::to_string(plan.tile);
            if (map->framePattern.empty()) {
                names.input(*map->file, of);
                continue;
            }
            const io::ObjSequence sequence(map->framePattern);
            for (const int frame : j.frames)
                names.input(sequence.framePath(frame), of + " at frame " + std::to_string(frame));
        }
    }
}

}  // namespace

ShotSolver::ShotSolver(ShotJob job) : impl_(std::make_unique<Impl>()) {
    Impl& s = *impl_;
    s.job = std::move(job);
    const ShotJob& j = s.job;
    if (!j.rest || j.frames.empty() || !j.outPath || !j.rigidity.given() ||
        (j.texture.given() && !j.bakePath)) {
        throw InvalidInput(formatError("uvwarp", "job", "is incomplete",
                                       "a rest mesh, frames, a rigidity map, an output path, and a bake path "
                                       "with a texture"));
    }
    if (j.warmUpFrames < 0 || static_cast<size_t>(j.warmUpFrames) >= j.frames.size()) {
        throw InvalidInput(
            formatError("uvwarp", "warm-up frames", "are " + std::to_string(j.warmUpFrames),
                        "0 to one less than the job's " + std::to_string(j.frames.size()) + " frames"));
    }
    if (!std::is_sorted(j.frames.begin(), j.frames.end()) ||
        std::adjacent_find(j.frames.begin(), j.frames.end()) != j.frames.end()) {
        throw InvalidInput(formatError("uvwarp", "frames", "are not ascending", "frames in ascending order"));
    }
    checkOptions(j.options, "uvwarp");
    const std::vector<int> tiles = shotTiles(*j.rest, j.restName, j.tiles, "tiles");
    for (const auto& [source, role] :
         {std::pair{&j.rigidity, "rigidity"}, std::pair{&j.mask, "mask"},
          std::pair{&j.orientation, "orientation"}, std::pair{&j.texture, "texture"}}) {
        if (!source->pattern.empty() && !io::hasUdimToken(source->pattern.string())) {
            throw InvalidInput(formatError(source->name.empty() ? role : source->name,
                                           source->pattern.string(), "has no UDIM token",
                                           "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_"));
        }
    }
    // A mask, orientation or texture pattern that matches no file for any of the mesh's tiles is a typo, not
    // a choice (a tile without one falls back, or is not baked, with a note): refused before anything is
    // written. Any of the mesh's tiles, not only the job's: a farm task of one tile may have none where
    // another tile has its map.
    const std::vector<int> meshTiles = j.mask.given() || j.orientation.given() || j.texture.given()
                                           ? shotTiles(*j.rest, j.restName, {}, "tiles")
                                           : std::vector<int>{};
    for (const auto& [source, what] :
         {std::pair{&j.mask, "warp mask"}, std::pair{&j.orientation, "orientation map"},
          std::pair{&j.texture, "texture"}}) {
        if (!source->given()) continue;
        if (std::none_of(meshTiles.begin(), meshTiles.end(),
                         [&](int tile) { return findTileMap(*source, tile, j.frames).found(); })) {
            std::string list;
            for (const int tile : meshTiles)
                list += (list.empty() ? "" : ", ") + std::to_string(tile);
            throw InvalidInput(formatError(source->name.empty() ? what : source->name,
                                           source->pattern.empty() ? "" : source->pattern.string(),
                                           "matches no file for any of the mesh's tiles (" + list + ")",
                                           std::string(what) + "s for some tiles, or none given"));
        }
    }
    const int32_t resolution = j.options.cells;
    const bool wantBake = j.texture.given();
    bool saidNoUVs = false;
    for (int tile : tiles) {
        TilePlan plan;
        plan.tile = tile;
        plan.report.tile = tile;
        plan.rigidity = findTileMap(j.rigidity, tile, j.frames);
        if (!plan.rigidity.found()) {
            plan.report.warped = false;
            plan.report.notes.push_back("left unwarped: no rigidity map '" + plan.rigidity.name + "'");
            s.plans.push_back(std::move(plan));
            continue;
        }
        if (!saidNoUVs && j.rest->numFacesWithoutUVs() > 0) {  // said once, with the first warped tile
            saidNoUVs = true;
            const int32_t n = j.rest->numFacesWithoutUVs();
            plan.report.notes.push_back(std::to_string(n) + (n == 1 ? " face has" : " faces have") +
                                        " no UVs: in no tile, left unwarped");
        }
        const geom::UdimOverhang overhang = geom::udimOverhang(*j.rest, tile);
        if (overhang.faces > 0) {
            std::ostringstream note;
            note << overhang.faces << (overhang.faces == 1 ? " face overhangs" : " faces overhang")
                 << " the tile, by up to " << overhang.worst << " of a tile (face " << overhang.worstFace
                 << "): warped as far as the tile reaches";
            plan.report.notes.push_back(note.str());
        }
        const TileMap& r = plan.rigidity;
        if (r.width != r.height || r.width < 2) {
            throw InvalidInput(formatError(r.name, "rigidity map", texelsText(r.width, r.height),
                                           "a square map of at least 2 x 2 texels"));
        }
        if (resolution == 0 && !isPowerOfTwo(r.width)) {
            throw InvalidInput(formatError(r.name, "rigidity map",
                                           std::to_string(r.width) + " texels per side, not a power of two",
                                           "a power-of-two size, or a grid resolution"));
        }
        plan.options =
            j.preset ? withPreset(*j.preset, resolution != 0 ? resolution : r.width, j.options, j.presetOwn)
                     : j.options;
        // Maps that must have the rigidity map's size.
        const auto sameSize = [&](const TileMap& map, const char* what) {
            if (map.width != r.width || map.height != r.height) {
                throw InvalidInput(formatError(map.name, what, texelsText(map.width, map.height),
                                               std::to_string(r.width) + " x " + std::to_string(r.height) +
                                                   ", the size of '" + r.name + "'"));
            }
        };
        // A map of several channels (an RGB or RGBA export of a painted map): channel 0 is read, said once.
        const auto noteChannels = [&](const TileMap& map, const char* what) {
            if (map.channels > 1) {
                // Named as the file names it: an EXR stores channels sorted by name, so its channel 0 is not
                // always red ("mask.Y" before "rigidity.Y").
                const std::string first = map.firstChannel.empty() || map.firstChannel == "R"
                                              ? "red"
                                              : "'" + map.firstChannel + "'";
                plan.report.notes.push_back(std::string(what) + " '" + map.name + "' has " +
                                            std::to_string(map.channels) + " channels: channel 0 (" + first +
                                            ") is read");
            }
        };
        noteChannels(r, "rigidity map");
        if (j.mask.given()) {
            plan.mask = findTileMap(j.mask, tile, j.frames);
            if (plan.mask.found()) {
                sameSize(plan.mask, "warp mask");
                noteChannels(plan.mask, "warp mask");
            } else {
                plan.report.notes.push_back("no warp mask '" + plan.mask.name + "': derived from the UVs");
            }
        }
        if (j.orientation.given()) {
            plan.orientation = findTileMap(j.orientation, tile, j.frames);
            if (plan.orientation.found()) {
                sameSize(plan.orientation, "orientation map");
                noteChannels(plan.orientation, "orientation map");
            } else {
                const int32_t cells = plan.options.cells != 0 ? plan.options.cells : r.width;
                const bool density =
                    orientationDensityFor(plan.options.orientationDensity, r.width, cells) > 0;
                plan.report.notes.push_back("no orientation map '" + plan.orientation.name + "': " +
                                            (density ? "the density heuristic's (orientationDensity)"
                                                     : "orientation preservation as given everywhere"));
            }
        }
        if (wantBake) {
            plan.texture = findTileMap(j.texture, tile, j.frames);
            if (!plan.texture.found())
                plan.report.notes.push_back("no texture '" + plan.texture.name + "': not baked");
            else
                io::requireImageWriter(j.bakePath(tile, j.frames.front()));  // before any frame is solved
        }
        for (size_t k = 0; k < j.frames.size(); ++k) {
            const int frame = j.frames[k];
            plan.outPaths.push_back(j.outPath(tile, frame));
            plan.bakePaths.push_back(plan.texture.found() ? j.bakePath(tile, frame) : fs::path());
            const bool warmUp = k < static_cast<size_t>(j.warmUpFrames);
            const bool needed = !warmUp && (!j.skipExisting || !fileExists(plan.outPaths.back()) ||
                                            (plan.texture.found() && !fileExists(plan.bakePaths.back())));
            plan.needed.push_back(needed);
            if (needed) plan.lastNeeded = static_cast<int>(k);
        }
        plan.inputs = {
            {"rest", j.restName},
            {"rigidity", plan.rigidity.name},
            {"mask", plan.mask.found() ? plan.mask.name : std::string("derived")},
            {"orientation", plan.orientation.found() ? plan.orientation.name : std::string("none")}};
        if (plan.texture.found()) plan.inputs["texture"] = plan.texture.name;
        s.plans.push_back(std::move(plan));
    }
    requireOutputsApart(s.plans, j);
    // Output folders made when missing (as eval makes its own), once nothing is refused and before any work:
    // a path that cannot be a folder fails here, naming it.
    for (const TilePlan& plan : s.plans) {
        std::vector<fs::path> folders = {j.outPath(plan.tile, j.frames.front()).parent_path()};
        if (wantBake) folders.push_back(j.bakePath(plan.tile, j.frames.front()).parent_path());
        for (const fs::path& folder : folders) {
            if (!folder.empty()) io::createFolder(folder);
        }
    }
    if (!s.plans.empty() &&
        std::none_of(s.plans.begin(), s.plans.end(), [](const TilePlan& p) { return p.report.warped; })) {
        std::string list;
        for (const TilePlan& p : s.plans)
            list += (list.empty() ? "'" : ", '") + p.rigidity.name + "'";
        throw IoError(formatError(j.rigidity.name.empty() ? "rigidity" : j.rigidity.name,
                                  j.rigidity.pattern.string(), "no tile has a rigidity map",
                                  "at least one of " + list));
    }
}

ShotSolver::~ShotSolver() = default;
ShotSolver::ShotSolver(ShotSolver&&) noexcept = default;
ShotSolver& ShotSolver::operator=(ShotSolver&&) noexcept = default;

int64_t ShotSolver::units() const {
    return static_cast<int64_t>(impl_->plans.size() * impl_->job.frames.size());
}

std::vector<std::string> ShotSolver::plannedNotes() const {
    std::vector<std::string> lines;
    for (const TilePlan& plan : impl_->plans)
        for (const std::string& note : plan.report.notes)
            lines.push_back("tile " + std::to_string(plan.tile) + ": " + note);
    return lines;
}

bool ShotSolver::needsPositions() const {
    const Impl& s = *impl_;
    if (s.nextFrame >= s.job.frames.size()) return false;
    return std::any_of(s.plans.begin(), s.plans.end(),
                       [&](const TilePlan& plan) { return s.solves(plan, s.nextFrame); });
}

std::optional<int> ShotSolver::lastNeededFrame() const {
    int last = -1;
    for (const TilePlan& p : impl_->plans)
        last = std::max(last, p.lastNeeded);
    if (last < 0) return std::nullopt;
    return impl_->job.frames[static_cast<size_t>(last)];
}

namespace {

// A file name's extension in lower case (".exr").
std::string lowercaseExtension(const fs::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

// The pixel type an image file stores (Auto for one a writer cannot write as such).
io::PixelType pixelTypeOf(const fs::path& file) {
    return io::pixelTypeOf(io::readImageInfo(file));
}

// The file of `map` at `frame`: its frame's file when animated, its one file otherwise.
std::optional<fs::path> mapFile(const TileMap& map, int frame) {
    if (!map.framePattern.empty()) return io::ObjSequence(map.framePattern).framePath(frame);
    return map.file;
}

// The tile's texture file at `frame`, with its pixel type; refused before anything of the frame is baked when
// a texel is not finite (a baked texel filters its neighbours: one NaN would spread).
void readTexture(TilePlan& plan, int frame) {
    const fs::path file = *mapFile(plan.texture, frame);
    plan.texturePixels = io::readImage(file);
    io::requireFinitePixels(plan.texturePixels, file.string(),
                            "finite values (a baked texel filters its neighbours)");
    plan.texturePixelType = pixelTypeOf(file);
}

io::Image readMap(const TileMap& map, int frame, int tile, const char* role) {
    // Files are checked as they are read (values in [0, 1], finite; a mask's not NaN), naming the file and
    // texel; maps in memory likewise here, named as the caller named them ("mask tile 1001", a label).
    const bool mask = std::string_view(role) == "warp mask";
    if (const std::optional<fs::path> file = mapFile(map, frame))
        return mask ? readWarpMask(*file, tile) : readRigidityMap(*file, tile, role);
    if (!map.image) return {};
    if (mask)
        validateWarpMask(*map.image, MapLabel{map.name, 0});
    else
        validateRigidityMap(*map.image, MapLabel{map.name, 0});
    return *map.image;
}

// The headers name an animated map's file of the frame.
void nameFrameMaps(const TilePlan& plan, int frame, json& inputs) {
    for (const auto& [map, key] : {std::pair<const TileMap*, const char*>{&plan.rigidity, "rigidity"},
                                   {&plan.mask, "mask"},
                                   {&plan.orientation, "orientation"},
                                   {&plan.texture, "texture"}}) {
        if (!map->framePattern.empty()) inputs[key] = mapFile(*map, frame)->string();
    }
}

bool samePixels(const io::Image& a, const io::Image& b) {
    return a.width == b.width && a.height == b.height && a.channels == b.channels && a.pixels == b.pixels;
}

}  // namespace

void ShotSolver::Impl::bind(TilePlan& plan, int frame) {
    io::Image rigidity = readMap(plan.rigidity, frame, plan.tile, "rigidity map");
    // Nothing rigid: every map is the identity, correct but most likely a map painted on another channel or
    // tile. Said, as an unwarped tile is.
    if (std::ranges::all_of(rigidity.pixels, [](float v) { return v <= 0.0f; })) {
        plan.report.notes.push_back("rigidity map '" + plan.rigidity.name + "' is 0 at every texel" +
                                    (plan.rigidity.framePattern.empty() ? "" : " of its first frame") +
                                    ": nothing is held rigid, the redirect maps are the identity");
    }
    const io::Image mask = readMap(plan.mask, frame, plan.tile, "warp mask");
    const io::Image orientation = readMap(plan.orientation, frame, plan.tile, "orientation map");
    if (plan.texture.file) {
        readTexture(plan, frame);
    } else if (plan.texture.image) {
        plan.texturePixels = *plan.texture.image;
    }
    if (!plan.rigidity.framePattern.empty()) plan.lastRigidity = rigidity;
    plan.warp.emplace(*job.rest, plan.tile, std::move(rigidity), mask, plan.options, orientation,
                      job.restName);
    if (!plan.mask.framePattern.empty()) plan.lastMask = mask;
    if (!plan.orientation.framePattern.empty()) plan.lastOrientation = orientation;
}

void ShotSolver::Impl::animateMaps(TilePlan& plan, int frame) {
    const bool rigidityMoves = !plan.rigidity.framePattern.empty();
    const bool maskMoves = !plan.mask.framePattern.empty();
    const bool orientationMoves = !plan.orientation.framePattern.empty();
    if (!plan.texture.framePattern.empty()) readTexture(plan, frame);
    if (!rigidityMoves && !maskMoves && !orientationMoves) return;
    bool changed = false;
    const auto next = [&](const TileMap& map, io::Image& last, const char* role) {
        if (map.framePattern.empty()) return;
        io::Image image = readMap(map, frame, plan.tile, role);
        if (!samePixels(image, last)) {
            last = std::move(image);
            changed = true;
        }
    };
    next(plan.rigidity, plan.lastRigidity, "rigidity map");
    next(plan.mask, plan.lastMask, "warp mask");
    next(plan.orientation, plan.lastOrientation, "orientation map");
    if (!changed) return;
    // The maps that do not move are read again from their one file (or image) to hand the warp a full set.
    const io::Image rigidity =
        rigidityMoves ? plan.lastRigidity : readMap(plan.rigidity, frame, plan.tile, "rigidity map");
    const io::Image mask = maskMoves ? plan.lastMask : readMap(plan.mask, frame, plan.tile, "warp mask");
    const io::Image orientation = orientationMoves
                                      ? plan.lastOrientation
                                      : readMap(plan.orientation, frame, plan.tile, "orientation map");
    plan.warp->setMaps(rigidity, mask, orientation);
    ++plan.report.mapChanges;
}

void ShotSolver::Impl::solveTile(TilePlan& plan, size_t k, std::span<const glm::vec3> deformed,
                                 const std::string& inputName) {
    ShotTileReport& r = plan.report;
    const int frame = job.frames[k];
    const Clock::time_point start = Clock::now();
    json frameInputs = plan.inputs;
    nameFrameMaps(plan, frame, frameInputs);
    if (!plan.warp) {
        bind(plan, frame);
    } else {
        animateMaps(plan, frame);
    }
    TileWarp& warp = *plan.warp;
    Clock::time_point t = Clock::now();
    warp.solve(deformed);
    const double solveSeconds = secondsSince(t);
    const WarpMetrics metrics = warp.metrics();
    r.lastMetrics = metrics;
    r.lastFrame = frame;
    json seconds = {{"solve", solveSeconds}};
    const bool needed = plan.needed[k];
    std::optional<DeliveredMetrics> delivered;
    std::optional<FoldRepair> repair;
    if (needed) {
        t = Clock::now();
        repair = warp.redirect(plan.redirect);
        seconds["invert"] = secondsSince(t);
        t = Clock::now();
        delivered = warp.measure(plan.redirect);
        seconds["measure"] = secondsSince(t);
        r.lastDelivered = *delivered;
        // A delivered map with more rigid stretch than no warp at all (a mask or rigidity painted off the
        // charts): correct by its maps, but not what anyone wants; said once, with the first such frame.
        if (delivered->removed < 0.0 && !plan.saidWorseThanIdentity) {
            plan.saidWorseThanIdentity = true;
            std::ostringstream note;
            note.precision(3);
            note << "frame " << frame << ": the redirect map holds more rigid stretch than no warp (removed "
                 << 100.0 * delivered->removed << "%): are the mask and rigidity maps painted on the charts?";
            r.notes.push_back(note.str());
        }
        r.lastRepair = *repair;
        if (repair->regionsScaled > 0) ++r.scaledBack;
        r.lastWrittenFrame = frame;
        io::ImageWriteOptions attributes;
        frameInputs["deformed"] = inputName;
        attributes.attributes = {
            {"deformkit:version", kVersionString},
            {"deformkit:uvwarp:tile", std::to_string(plan.tile)},
            {"deformkit:uvwarp:frame", std::to_string(frame)},
            {"deformkit:uvwarp:solver",
             solverJson(plan.options, warp.cells(), warp.texels(), warp.stats().levels).dump()},
            {"deformkit:uvwarp:inputs", frameInputs.dump()},
            {"deformkit:uvwarp:metrics", metricsJson(&*delivered, &*repair, metrics, warp.stats()).dump()}};
        t = Clock::now();
        if (!job.skipExisting || !fileExists(plan.outPaths[k])) {
            io::ImageWriteOptions write = attributes;
            write.type = io::PixelType::Float;
            // The output folder is made when missing, as eval makes its own.
            if (plan.outPaths[k].has_parent_path()) io::createFolder(plan.outPaths[k].parent_path());
            io::writeImage(plan.outPaths[k], plan.redirect, write);
            r.files.push_back(plan.outPaths[k]);
        }
        double writeSeconds = secondsSince(t);
        if (plan.texture.found() && (!job.skipExisting || !fileExists(plan.bakePaths[k]))) {
            t = Clock::now();
            BakeOptions bakeOptions;
            bakeOptions.filter = job.filter;
            bakeTexture(plan.texturePixels, plan.redirect, plan.baked, bakeOptions);
            seconds["bake"] = secondsSince(t);
            const std::string extension = lowercaseExtension(plan.bakePaths[k]);
            // Only EXR keeps arbitrary header attributes; other formats get the pixels alone.
            t = Clock::now();
            if (plan.bakePaths[k].has_parent_path()) io::createFolder(plan.bakePaths[k].parent_path());
            // The texture's pixel type where the bake has the texture's format (a float EXR texture bakes to
            // a float EXR, a displacement map keeps its precision); the format's default otherwise.
            io::ImageWriteOptions bakeWrite = extension == ".exr" ? attributes : io::ImageWriteOptions{};
            if (plan.texture.file && lowercaseExtension(*plan.texture.file) == extension)
                bakeWrite.type = plan.texturePixelType;
            io::writeImage(plan.bakePaths[k], plan.baked, bakeWrite);
            r.files.push_back(plan.bakePaths[k]);
            writeSeconds += secondsSince(t);
            ++r.baked;
        }
        seconds["write"] = writeSeconds;
        ++r.written;
    } else if (warmUp(k)) {
        ++r.warmedUp;
    } else {
        ++r.replayed;
    }
    seconds["total"] = secondsSince(start);
    json line = baseLine(plan, k, needed ? "written" : warmUp(k) ? "warm-up" : "replayed");
    line["metrics"] =
        metricsJson(delivered ? &*delivered : nullptr, repair ? &*repair : nullptr, metrics, warp.stats());
    line["seconds"] = seconds;
    writeLog(line);
}

TileWarpOptions shotOptions() {
    TileWarpOptions options;
    options.solver.warmStart = false;
    options.refinementSweeps = kAutomaticRefinement;
    options.orientationDensity = kAutomaticDensity;
    options.seamSlide = true;
    return options;
}

void ShotSolver::solveFrame(int frame, std::span<const glm::vec3> deformed, const std::string& inputName,
                            Interrupter* interrupter) {
    Impl& s = *impl_;
    const std::vector<int>& frames = s.job.frames;
    if (s.nextFrame >= frames.size() || frames[s.nextFrame] != frame) {
        const std::string expected =
            s.nextFrame < frames.size()
                ? "frame " + std::to_string(frames[s.nextFrame]) + ", the next of the job"
                : "no more frames: the job's last is " + std::to_string(frames.back());
        throw InvalidInput(
            formatError("uvwarp", "frame " + std::to_string(frame), "is out of order", expected));
    }
    const auto vertices = static_cast<size_t>(s.job.rest->numVertices());
    if (deformed.size() != vertices && (needsPositions() || !deformed.empty())) {
        throw InvalidInput(formatError(
            inputName, "", "has " + std::to_string(deformed.size()) + " vertices",
            std::to_string(vertices) + ", the vertex count of the rest mesh '" + s.job.restName + "'"));
    }
    // Named here, by the frame's own input: the imager's own check names the rest mesh it was bound to. The
    // frame once: an input without a file ("frame 2") or a cache's frame ("anim.pc2 frame 2") names it.
    if (const size_t v = firstUnusablePoint(deformed); v < deformed.size()) {
        const std::string frameText = "frame " + std::to_string(frame);
        const bool frameNamed = inputName == frameText || inputName.ends_with(" " + frameText);
        const glm::vec3 p = deformed[v];
        const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
        throw InvalidInput(formatError(
            inputName, (frameNamed ? "" : frameText + ": ") + "vertex " + std::to_string(v),
            finite ? "is (" + numberText(p.x) + ", " + numberText(p.y) + ", " + numberText(p.z) + ")"
                   : std::string("is not finite"),
            "finite coordinates within +-1e15 (the solver squares lengths in float)"));
    }
    const size_t k = s.nextFrame++;
    for (TilePlan& plan : s.plans) {
        const bool solves = s.solves(plan, k);
        if (solves) {
            s.solveTile(plan, k, deformed, inputName);
        } else {
            s.logUnsolved(plan, k);
        }
        ++s.unitsDone;
        if (interrupter) {
            const char* status = !plan.report.warped ? "unwarped"
                                 : !solves           ? "skipped"
                                 : plan.needed[k]    ? "written"
                                 : s.warmUp(k)       ? "warm-up"
                                                     : "replayed";
            const std::string unit =
                "tile " + std::to_string(plan.tile) + " frame " + std::to_string(frame) + " " + status;
            if (interrupter->wasInterrupted(s.unitsDone, units(), unit)) {
                throw Cancelled(formatError("uvwarp", "frame " + std::to_string(frame), "cancelled",
                                            "outputs written so far are complete; a rerun resumes"));
            }
        }
    }
}

ShotReport ShotSolver::finish() {
    Impl& s = *impl_;
    for (; s.nextFrame < s.job.frames.size(); ++s.nextFrame) {
        for (TilePlan& plan : s.plans)
            s.logUnsolved(plan, s.nextFrame);
    }
    ShotReport report;
    for (TilePlan& plan : s.plans)
        report.tiles.push_back(plan.report);
    return report;
}

ShotReport runShotJob(const ShotJob& job, const DeformedFrames& deformed, Interrupter* interrupter) {
    if (!deformed) {
        throw InvalidInput(
            formatError("uvwarp", "job", "has no deformed positions", "a DeformedFrames function"));
    }
    ShotSolver solver(job);
    if (job.planned) job.planned();
    const std::optional<int> last = solver.lastNeededFrame();
    const InterrupterScope scope(interrupter, "uvwarp", solver.units());
    for (int frame : job.frames) {
        if (!last || frame > *last) break;
        std::string name;
        const std::span<const glm::vec3> points =
            solver.needsPositions() ? deformed(frame, name) : std::span<const glm::vec3>();
        solver.solveFrame(frame, points, name, interrupter);
    }
    return solver.finish();
}

std::vector<ShotJob::CallerFile> deformedShotFiles(const fs::path& deformed, const std::vector<int>& frames,
                                                   const std::string& named) {
    if (!io::ObjSequence::isPattern(deformed.string())) return {{deformed, "the deformed shot" + named}};
    const io::ObjSequence sequence(deformed);
    std::vector<ShotJob::CallerFile> files;
    for (const int frame : frames)
        files.push_back({sequence.framePath(frame), "the deformed frame " + std::to_string(frame) + named});
    return files;
}

fs::path tileFramePath(const fs::path& pattern, int tile, int frame) {
    return io::ObjSequence(io::expandUdim(pattern.string(), tile)).framePath(frame);
}

void setOutputPatterns(ShotJob& job, const fs::path& out, const fs::path& bake, const std::string& outName,
                       const std::string& bakeName) {
    const auto check = [](const fs::path& pattern, const std::string& name) {
        const std::string text = pattern.string();
        if (!io::hasUdimToken(text)) {
            throw InvalidInput(
                formatError(name, text, "has no UDIM token", "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_"));
        }
        if (!io::ObjSequence::isPattern(io::expandUdim(text, 1001))) {
            // No token, two, or a padding beyond 32 digits: the sequence's own reading says which.
            const std::string problem = io::ObjSequence::patternProblem(io::expandUdim(text, 1001));
            throw InvalidInput(
                formatError(name, text, problem, "one token such as #### (one # per digit) or %04d"));
        }
    };
    check(out, outName);
    if (lowercaseExtension(out) != ".exr") {
        throw InvalidInput(formatError(outName, out.string(), "is not an .exr file",
                                       "an OpenEXR file: the redirect map is 2 float channels with header "
                                       "attributes"));
    }
    job.outPath = [out](int tile, int frame) { return tileFramePath(out, tile, frame); };
    job.bakePath = nullptr;
    if (bake.empty()) return;
    check(bake, bakeName);
    if (bake == out) {
        throw InvalidInput(
            formatError(bakeName, bake.string(), "is the " + outName + " pattern", "another pattern"));
    }
    job.bakePath = [bake](int tile, int frame) { return tileFramePath(bake, tile, frame); };
}

std::vector<int> shotTiles(const geom::Mesh& rest, const std::string& restName, const std::vector<int>& tiles,
                           const std::string& tilesName) {
    if (!rest.hasUVs()) {
        throw InvalidInput(formatError(restName, "", "has no UVs",
                                       "a rest mesh with texture coordinates (vt) on its faces"));
    }
    const std::vector<int> meshTiles = rest.udimTiles();
    for (int tile : tiles) {
        if (!std::binary_search(meshTiles.begin(), meshTiles.end(), tile)) {
            std::string have;
            for (int t : meshTiles)
                have.append(have.empty() ? "" : " ").append(std::to_string(t));
            throw InvalidInput(formatError(tilesName, "tile " + std::to_string(tile),
                                           "the rest mesh '" + restName + "' has no UV face in it",
                                           "tiles of the rest mesh: " + have));
        }
    }
    return tiles.empty() ? meshTiles : tiles;
}

DeformedFrames animatedFrames(const fs::path& path, const std::vector<int>& frames, const std::string& name,
                              const geom::Mesh& rest, const std::string& restName,
                              std::optional<double> cacheFirstFrame) {
    // The rest mesh first: a cache's vertex order is checked against it, and a rest position beyond the
    // solver's range would be taken for a cache in another order.
    if (const size_t v = firstUnusablePoint(rest.points()); v < rest.points().size()) {
        const glm::vec3 p = rest.points()[v];
        throw InvalidInput(
            formatError(restName, "vertex " + std::to_string(v),
                        "is (" + numberText(p.x) + ", " + numberText(p.y) + ", " + numberText(p.z) + ")",
                        "finite coordinates within +-1e15 (the solver squares lengths in float)"));
    }
    auto source = std::make_shared<io::AnimatedPositions>(path, name, cacheFirstFrame);
    source->setReference(rest, restName);  // a cache in the rest mesh's order, a sequence its topology
    source->requireFrames(frames);
    auto points = std::make_shared<std::vector<glm::vec3>>();
    return [source, points](int frame, std::string& frameName) -> std::span<const glm::vec3> {
        frameName = source->frameName(frame);
        source->read(frame, *points);
        return *points;
    };
}

std::vector<std::string> shotSummary(const ShotReport& report) {
    std::vector<std::string> lines;
    for (const ShotTileReport& t : report.tiles) {
        const std::string tile = "tile " + std::to_string(t.tile) + ": ";
        if (t.warped) {
            std::ostringstream line;
            line.precision(3);
            line << tile << t.written << (t.written == 1 ? " frame" : " frames") << " written";
            if (t.baked > 0) line << " (" << t.baked << " baked)";
            line << ", " << t.replayed << " replayed, " << t.skipped << " skipped (outputs exist)";
            if (t.warmedUp > 0)
                line << ", " << t.warmedUp << " warm-up " << (t.warmedUp == 1 ? "frame" : "frames");
            if (t.mapChanges > 0)
                line << ", maps changed at " << t.mapChanges << (t.mapChanges == 1 ? " frame" : " frames");
            if (t.written > 0) {
                const DeliveredMetrics& d = t.lastDelivered;
                line << "; frame " << t.lastWrittenFrame << ": rigid stretch removed " << 100.0 * d.removed
                     << "% (error " << d.rigidStretchError << ", identity " << d.identityStretchError << "), "
                     << d.invertedTriangles << " inverted triangles, " << d.offChartTexels
                     << " off-chart texels in the redirect map (fold repair: " << t.lastRepair.texelsMoved
                     << (t.lastRepair.texelsMoved == 1 ? " smoothing move)" : " smoothing moves)");
            }
            if (t.scaledBack > 0) {
                line << "; " << t.scaledBack << (t.scaledBack == 1 ? " frame" : " frames")
                     << " had a region's warp scaled back to keep the map fold-free";
            }
            lines.push_back(line.str());
        }
        for (const std::string& note : t.notes)
            lines.push_back(tile + note);
    }
    return lines;
}

}  // namespace deformkit::uvwarp
