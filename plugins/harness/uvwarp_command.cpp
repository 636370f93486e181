#include "uvwarp_command.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/udim.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/grid.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/version.h"

namespace deformkit::harness {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr int64_t kMaxFrames = 1000000;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// A decimal integer at text[pos] (an optional leading '-'), advancing pos; false when there is none.
bool parseInteger(std::string_view text, size_t& pos, int64_t& value) {
    const char* begin = text.data() + pos;
    const auto [ptr, ec] = std::from_chars(begin, text.data() + text.size(), value);
    if (ec != std::errc() || ptr == begin) return false;
    pos = static_cast<size_t>(ptr - text.data());
    return true;
}

// Comma-separated items, each handed to `item`.
template <class Item>
void forEachItem(std::string_view text, Item&& item) {
    size_t start = 0;
    while (true) {
        const size_t comma = text.find(',', start);
        item(text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
        if (comma == std::string_view::npos) return;
        start = comma + 1;
    }
}

// A float option as JSON: the shortest decimal that reads back as the float (0.05, not 0.0500000007).
double tidy(float value) {
    char text[32];
    const auto [end, ec] = std::to_chars(text, text + sizeof(text), value);
    return ec == std::errc() ? std::strtod(std::string(text, end).c_str(), nullptr)
                             : static_cast<double>(value);
}

std::string clockText(double seconds) {
    const auto total = static_cast<int64_t>(seconds + 0.5);
    const int64_t h = total / 3600, m = (total / 60) % 60, s = total % 60;
    std::ostringstream out;
    if (h > 0) out << h << ":" << (m < 10 ? "0" : "");
    out << m << ":" << (s < 10 ? "0" : "") << s;
    return out.str();
}

// Frames x tiles on one line, redrawn in place. The ETA extrapolates the time per solved frame over the
// solves still planned: frames skipped because their outputs exist take no time.
class ProgressBar {
  public:
    ProgressBar(std::ostream* out, int64_t steps, int64_t plannedSolves)
        : out_(out), steps_(steps), plannedSolves_(plannedSolves), start_(Clock::now()) {}
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;
    ~ProgressBar() {
        if (out_ && drawn_) *out_ << "\n" << std::flush;
    }

    void step(int tile, int frame, bool solved) {
        ++done_;
        if (solved) ++solved_;
        if (!out_) return;
        const double elapsed = secondsSince(start_);
        const int64_t remaining = std::max<int64_t>(plannedSolves_ - solved_, 0);
        const double eta =
            solved_ > 0 ? elapsed / static_cast<double>(solved_) * static_cast<double>(remaining) : 0.0;
        constexpr int64_t kWidth = 24;
        const int64_t filled = steps_ > 0 ? kWidth * done_ / steps_ : kWidth;
        *out_ << "\ruvwarp [" << std::string(static_cast<size_t>(filled), '#')
              << std::string(static_cast<size_t>(kWidth - filled), '-') << "] " << done_ << "/" << steps_
              << "  tile " << tile << " frame " << frame << "  elapsed " << clockText(elapsed) << "  ETA "
              << (solved_ > 0 || remaining == 0 ? clockText(eta) : "-") << "   " << std::flush;
        drawn_ = true;
    }

  private:
    std::ostream* out_;
    int64_t steps_, plannedSolves_, done_ = 0, solved_ = 0;
    Clock::time_point start_;
    bool drawn_ = false;
};

// What a run does for one tile, worked out before anything is written.
struct TilePlan {
    int tile = 0;
    fs::path rigidity;
    std::optional<fs::path> mask;         // an existing mask file
    std::optional<fs::path> orientation;  // an existing orientation map
    std::optional<fs::path> texture;      // an existing texture file, baked
    std::vector<fs::path> outPaths, bakePaths;
    std::vector<bool> needed;  // per frame: an output to write
    int lastNeeded = -1;       // index of the last needed frame
    UvWarpTileReport report;
};

bool fileExists(const fs::path& path) {
    std::error_code ec;
    return fs::exists(path, ec);
}

void requireOutputPattern(const fs::path& pattern, const std::string& option) {
    const std::string text = pattern.string();
    if (!io::hasUdimToken(text)) {
        throw InvalidInput(
            formatError(option, text, "has no UDIM token", "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_"));
    }
    if (!io::ObjSequence::isPattern(io::expandUdim(text, 1001))) {
        throw InvalidInput(formatError(option, text, "has no frame token in its file name",
                                       "one token such as #### (one # per digit) or %04d"));
    }
}

// Header-only checks of a tile's maps, so that a wrong size stops the run before anything is written.
int32_t checkRigidityHeader(const fs::path& path, int32_t resolution) {
    const io::ImageInfo info = io::readImageInfo(path);
    if (info.width != info.height || info.width < 2) {
        throw InvalidInput(
            formatError(path.string(), "rigidity map",
                        std::to_string(info.width) + " x " + std::to_string(info.height) + " texels",
                        "a square map of at least 2 x 2 texels"));
    }
    if (resolution == 0 && !uvwarp::isPowerOfTwo(info.width)) {
        throw InvalidInput(formatError(path.string(), "rigidity map",
                                       std::to_string(info.width) + " texels per side, not a power of two",
                                       "a power-of-two size, or --resolution to set the grid"));
    }
    return info.width;
}

// A map that must have the rigidity map's size (`what`: "warp mask", "orientation map").
void checkMapHeader(const fs::path& path, const char* what, int32_t texels, const fs::path& rigidity) {
    const io::ImageInfo info = io::readImageInfo(path);
    if (info.width != texels || info.height != texels) {
        throw InvalidInput(formatError(
            path.string(), what, std::to_string(info.width) + " x " + std::to_string(info.height) + " texels",
            std::to_string(texels) + " x " + std::to_string(texels) + ", the size of '" + rigidity.string() +
                "'"));
    }
}

json metricsJson(const uvwarp::WarpMetrics& m, const uvwarp::SolveStats& s) {
    return {{"rigid_stretch_error", m.rigidStretchError},
            {"identity_stretch_error", m.identityStretchError},
            {"rigid_edges", m.rigidEdges},
            {"skipped_edges", m.skippedEdges},
            {"fold_overs", m.foldOvers},
            {"max_masked_displacement", m.maxMaskedDisplacement},
            {"max_border_displacement", m.maxBorderDisplacement},
            {"points_outside", m.pointsOutside},
            {"iterations", s.iterations},
            {"levels", s.levels},
            {"untangled_points", s.untangledPoints},
            {"remaining_folds", s.remainingFolds}};
}

json solverJson(const uvwarp::TileWarpOptions& o, int32_t cells, int32_t texels, int32_t levelsUsed,
                bool derivedMask) {
    json j = {{"cells", cells},
              {"texels", texels},
              {"levels", o.solver.levels},
              {"levelsUsed", levelsUsed},
              {"iterations", o.solver.iterations},
              {"sweepsPerLevel", o.solver.sweepsPerLevel},
              {"orientationPreservation", tidy(o.solver.orientationPreservation)},
              {"smoothing", tidy(o.solver.smoothing)},
              {"damping", tidy(o.solver.damping)},
              {"coarseStiffness", tidy(o.solver.coarseStiffness)},
              {"dilationRings", o.dilationRings},
              {"warmStart", true}};
    if (derivedMask) j["derivedMaskBorderWidth"] = o.derivedMask.borderWidth;
    return j;
}

}  // namespace

std::vector<int> parseFrames(std::string_view text, const std::string& option) {
    const char* expected = "frames such as 1-24, 7 or 1-10,15 (first-last)";
    std::vector<int> frames;
    forEachItem(text, [&](std::string_view item) {
        std::string quoted = "'";
        quoted.append(item).append("'");
        size_t pos = 0;
        int64_t first = 0, last = 0;
        if (!parseInteger(item, pos, first))
            throw InvalidInput(formatError(option, "", quoted + " is not a frame", expected));
        last = first;
        if (pos < item.size()) {
            if (item[pos] != '-' || !parseInteger(item, ++pos, last) || pos != item.size()) {
                throw InvalidInput(formatError(option, "", quoted + " is not a frame range", expected));
            }
        }
        constexpr int64_t lo = std::numeric_limits<int>::min(), hi = std::numeric_limits<int>::max();
        if (first < lo || first > hi || last < lo || last > hi)
            throw InvalidInput(
                formatError(option, "", quoted + " is out of range", "frames that fit in 32 bits"));
        if (last < first)
            throw InvalidInput(formatError(option, "", quoted + " ends before it starts", expected));
        if (static_cast<int64_t>(frames.size()) + (last - first + 1) > kMaxFrames) {
            throw InvalidInput(formatError(option, "",
                                           "'" + std::string(text) + "' has more than 1000000 frames",
                                           "at most 1000000 frames"));
        }
        for (int64_t f = first; f <= last; ++f)
            frames.push_back(static_cast<int>(f));
    });
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    return frames;
}

std::vector<int> parseTiles(std::string_view text, const std::string& option) {
    std::vector<int> tiles;
    forEachItem(text, [&](std::string_view item) {
        size_t pos = 0;
        int64_t tile = 0;
        if (!parseInteger(item, pos, tile) || pos != item.size() || tile < 1001 || tile > 9999) {
            throw InvalidInput(formatError(option, "", "'" + std::string(item) + "' is not a UDIM tile",
                                           "tile numbers 1001..9999, comma separated"));
        }
        tiles.push_back(static_cast<int>(tile));
    });
    std::sort(tiles.begin(), tiles.end());
    tiles.erase(std::unique(tiles.begin(), tiles.end()), tiles.end());
    return tiles;
}

fs::path tileFramePath(const fs::path& pattern, int tile, int frame) {
    return io::ObjSequence(io::expandUdim(pattern.string(), tile)).framePath(frame);
}

UvWarpReport uvwarpCommand(const UvWarpCommand& command, std::ostream* progress) {
    // Everything that can be checked without solving is checked before the first output is written.
    if (command.frames.empty())
        throw InvalidInput(formatError("--frames", "", "no frames", "at least one frame"));
    if (command.resolution != 0 && (!uvwarp::isPowerOfTwo(command.resolution) || command.resolution < 2)) {
        throw InvalidInput(formatError("--resolution", "", std::to_string(command.resolution),
                                       "a power of two, at least 2 (grid cells per side)"));
    }
    if (command.texture.has_value() != command.bake.has_value()) {
        throw InvalidInput(formatError(command.bake ? "--bake" : "--texture", "",
                                       command.bake ? "given without --texture" : "given without --bake",
                                       "--texture and --bake together"));
    }
    if (!io::hasUdimToken(command.rigidity.string())) {
        throw InvalidInput(formatError("--rigidity", command.rigidity.string(), "has no UDIM token",
                                       "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_"));
    }
    for (const auto& [option, pattern] :
         {std::pair{"--mask", command.mask}, std::pair{"--orientation", command.orientation},
          std::pair{"--texture", command.texture}}) {
        if (pattern && !io::hasUdimToken(pattern->string())) {
            throw InvalidInput(formatError(option, pattern->string(), "has no UDIM token",
                                           "<UDIM>, <UVTILE>, %(UDIM)d or _MAPID_"));
        }
    }
    requireOutputPattern(command.out, "--out");
    std::string outExtension = command.out.extension().string();
    std::transform(outExtension.begin(), outExtension.end(), outExtension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (outExtension != ".exr") {
        throw InvalidInput(
            formatError("--out", command.out.string(), "is not an .exr file",
                        "an OpenEXR file: the redirect map is 2 float channels with header attributes"));
    }
    if (command.bake) {
        requireOutputPattern(*command.bake, "--bake");
        if (*command.bake == command.out)
            throw InvalidInput(
                formatError("--bake", command.bake->string(), "is the --out pattern", "another pattern"));
    }

    const io::ObjContent restObj = io::readObj(command.rest);
    const geom::Mesh& rest = restObj.mesh;
    if (!rest.hasUVs()) {
        throw InvalidInput(formatError(command.rest.string(), "", "has no UVs",
                                       "a rest mesh with texture coordinates (vt) on its faces"));
    }
    const std::vector<int> meshTiles = rest.udimTiles();
    std::vector<int> tiles = command.tiles.empty() ? meshTiles : command.tiles;
    for (int tile : tiles) {
        if (!std::binary_search(meshTiles.begin(), meshTiles.end(), tile)) {
            std::string have;
            for (int t : meshTiles)
                have.append(have.empty() ? "" : " ").append(std::to_string(t));
            throw InvalidInput(
                formatError("--tiles", "tile " + std::to_string(tile),
                            "the rest mesh '" + command.rest.string() + "' has no UV face in it",
                            "tiles of the rest mesh: " + have));
        }
    }

    io::ObjSequence sequence(command.deformed);
    for (int frame : command.frames) {
        const fs::path path = sequence.framePath(frame);
        if (!fileExists(path)) {
            throw IoError(
                formatError(path.string(), "frame " + std::to_string(frame), "is missing",
                            "a file for every frame of '" + command.deformed.string() + "' in --frames"));
        }
    }

    UvWarpJob job;
    job.rest = &rest;
    job.restName = command.rest.string();
    job.frames = command.frames;
    job.tiles = tiles;
    job.rigidity = command.rigidity;
    job.mask = command.mask;
    job.orientation = command.orientation;
    job.texture = command.texture;
    job.outPath = [&](int tile, int frame) { return tileFramePath(command.out, tile, frame); };
    if (command.bake) {
        job.bakePath = [&](int tile, int frame) { return tileFramePath(*command.bake, tile, frame); };
    }
    job.options = command.options;
    job.options.cells = command.resolution;
    job.filter = command.filter;
    io::ObjContent deformed;
    job.deformed = [&](int frame, std::string& name) -> std::span<const glm::vec3> {
        const fs::path framePath = sequence.framePath(frame);
        name = framePath.string();
        deformed = sequence.read(frame);
        if (deformed.mesh.numVertices() != rest.numVertices()) {
            throw InvalidInput(formatError(
                framePath.string(), "", "has " + std::to_string(deformed.mesh.numVertices()) + " vertices",
                std::to_string(rest.numVertices()) + ", the vertex count of the rest mesh '" +
                    command.rest.string() + "'"));
        }
        return deformed.mesh.points();
    };
    std::ofstream logFile;
    if (command.log) {
        logFile.open(*command.log, std::ios::app | std::ios::binary);
        if (!logFile) {
            throw IoError(formatError(command.log->string(), "", "cannot open the log for appending",
                                      "a writable file in an existing folder"));
        }
        job.log = &logFile;
    }
    UvWarpReport report = runUvWarpJob(job, progress);
    if (command.log && !logFile.flush()) {
        throw IoError(formatError(command.log->string(), "", "cannot write the log", "a writable file"));
    }
    return report;
}

UvWarpReport runUvWarpJob(const UvWarpJob& job, std::ostream* progress) {
    if (!job.rest || job.frames.empty() || !job.outPath || !job.deformed ||
        (job.texture.has_value() && !job.bakePath)) {
        throw InvalidInput(formatError("uvwarp", "job", "incomplete",
                                       "a rest mesh, frames, an output path, deformed positions, and a bake "
                                       "path with a texture"));
    }
    const geom::Mesh& rest = *job.rest;
    const int32_t resolution = job.options.cells;
    const bool wantBake = job.texture.has_value();
    std::vector<TilePlan> plans;
    int64_t plannedSolves = 0;
    for (int tile : job.tiles) {
        TilePlan plan;
        plan.tile = tile;
        plan.report.tile = tile;
        plan.rigidity = io::expandUdim(job.rigidity.string(), tile);
        std::vector<fs::path> folders = {job.outPath(tile, job.frames.front()).parent_path()};
        if (wantBake) folders.push_back(job.bakePath(tile, job.frames.front()).parent_path());
        for (const fs::path& folder : folders) {
            std::error_code ec;
            if (!folder.empty() && !fs::is_directory(folder, ec)) {
                throw IoError(formatError(folder.string(), "output folder", "does not exist",
                                          "an existing folder for the outputs"));
            }
        }
        if (!fileExists(plan.rigidity)) {
            plan.report.warped = false;
            plan.report.notes.push_back("left unwarped: no rigidity map '" + plan.rigidity.string() + "'");
            plans.push_back(std::move(plan));
            continue;
        }
        const int32_t texels = checkRigidityHeader(plan.rigidity, resolution);
        if (job.mask) {
            const fs::path mask = io::expandUdim(job.mask->string(), tile);
            if (fileExists(mask)) {
                checkMapHeader(mask, "warp mask", texels, plan.rigidity);
                plan.mask = mask;
            } else {
                plan.report.notes.push_back("no warp mask '" + mask.string() + "': derived from the UVs");
            }
        }
        if (job.orientation) {
            const fs::path orientation = io::expandUdim(job.orientation->string(), tile);
            if (fileExists(orientation)) {
                checkMapHeader(orientation, "orientation map", texels, plan.rigidity);
                plan.orientation = orientation;
            } else {
                plan.report.notes.push_back("no orientation map '" + orientation.string() +
                                            "': orientation preservation as given everywhere");
            }
        }
        if (job.texture) {
            const fs::path texture = io::expandUdim(job.texture->string(), tile);
            if (fileExists(texture)) {
                (void)io::readImageInfo(texture);  // readable
                plan.texture = texture;
            } else {
                plan.report.notes.push_back("no texture '" + texture.string() + "': not baked");
            }
        }
        for (size_t k = 0; k < job.frames.size(); ++k) {
            const int frame = job.frames[k];
            plan.outPaths.push_back(job.outPath(tile, frame));
            plan.bakePaths.push_back(plan.texture ? job.bakePath(tile, frame) : fs::path());
            const bool needed = !job.skipExisting || !fileExists(plan.outPaths.back()) ||
                                (plan.texture && !fileExists(plan.bakePaths.back()));
            plan.needed.push_back(needed);
            if (needed) plan.lastNeeded = static_cast<int>(k);
        }
        plannedSolves += plan.lastNeeded + 1;
        plans.push_back(std::move(plan));
    }
    if (!plans.empty() &&
        std::none_of(plans.begin(), plans.end(), [](const TilePlan& p) { return p.report.warped; })) {
        std::string list;
        for (const TilePlan& p : plans)
            list += (list.empty() ? "'" : ", '") + p.rigidity.string() + "'";
        throw IoError(formatError(job.rigidityOption, job.rigidity.string(), "no tile has a rigidity map",
                                  "at least one of " + list));
    }

    auto writeLog = [&](json line) {
        if (!job.log) return;
        if (job.logTask >= 0) line["task"] = job.logTask;
        if (!job.logObject.empty()) line["object"] = job.logObject;
        *job.log << line.dump() << "\n" << std::flush;
    };
    ProgressBar bar(progress, static_cast<int64_t>(plans.size() * job.frames.size()), plannedSolves);
    UvWarpReport report;
    for (TilePlan& plan : plans) {
        UvWarpTileReport& r = plan.report;
        auto baseLine = [&](size_t k, const char* status) {
            json line = {{"tile", plan.tile}, {"frame", job.frames[k]}, {"status", status}};
            if (!plan.outPaths.empty()) line["redirect"] = plan.outPaths[k].string();
            if (plan.texture) line["bake"] = plan.bakePaths[k].string();
            return line;
        };
        if (!r.warped) {
            for (size_t k = 0; k < job.frames.size(); ++k) {
                json line = baseLine(k, "unwarped");
                line["reason"] = "no rigidity map '" + plan.rigidity.string() + "'";
                writeLog(line);
                bar.step(plan.tile, job.frames[k], false);
            }
            report.tiles.push_back(std::move(r));
            continue;
        }
        std::optional<uvwarp::TileWarp> warp;
        io::Image texture, redirect, baked;
        if (plan.lastNeeded >= 0) {
            const io::Image rigidity = uvwarp::readRigidityMap(plan.rigidity, plan.tile);
            const io::Image mask = plan.mask ? uvwarp::readWarpMask(*plan.mask, plan.tile) : io::Image{};
            // In [0, 1] and finite, as a rigidity map; errors name the file and texel.
            const io::Image orientation =
                plan.orientation ? uvwarp::readRigidityMap(*plan.orientation, plan.tile, "orientation map")
                                 : io::Image{};
            if (plan.texture) texture = io::readImage(*plan.texture);
            warp.emplace(rest, plan.tile, rigidity, mask, job.options, orientation, job.restName);
        }
        const json inputs = {
            {"rest", job.restName},
            {"rigidity", plan.rigidity.string()},
            {"mask", plan.mask ? plan.mask->string() : std::string("derived")},
            {"orientation", plan.orientation ? plan.orientation->string() : std::string("none")}};
        for (size_t k = 0; k < job.frames.size(); ++k) {
            const int frame = job.frames[k];
            if (static_cast<int>(k) > plan.lastNeeded) {
                ++r.skipped;
                writeLog(baseLine(k, "skipped"));
                bar.step(plan.tile, frame, false);
                continue;
            }
            const Clock::time_point start = Clock::now();
            std::string frameName;
            const std::span<const glm::vec3> points = job.deformed(frame, frameName);
            const double readSeconds = secondsSince(start);
            Clock::time_point t = Clock::now();
            warp->solve(points);
            const double solveSeconds = secondsSince(t);
            const uvwarp::WarpMetrics metrics = warp->metrics();
            r.lastMetrics = metrics;
            r.lastFrame = frame;
            json seconds = {{"read", readSeconds}, {"solve", solveSeconds}};
            const bool needed = plan.needed[k];
            if (needed) {
                t = Clock::now();
                warp->redirect(redirect);
                seconds["invert"] = secondsSince(t);
                io::ImageWriteOptions attributes;
                json frameInputs = inputs;
                frameInputs["deformed"] = frameName;
                attributes.attributes = {
                    {"deformkit:version", kVersionString},
                    {"deformkit:uvwarp:tile", std::to_string(plan.tile)},
                    {"deformkit:uvwarp:frame", std::to_string(frame)},
                    {"deformkit:uvwarp:solver",
                     solverJson(job.options, warp->cells(), warp->texels(), warp->stats().levels, !plan.mask)
                         .dump()},
                    {"deformkit:uvwarp:inputs", frameInputs.dump()}};
                t = Clock::now();
                if (!job.skipExisting || !fileExists(plan.outPaths[k])) {
                    io::ImageWriteOptions write = attributes;
                    write.type = io::PixelType::Float;
                    io::writeImage(plan.outPaths[k], redirect, write);
                    r.files.push_back(plan.outPaths[k]);
                }
                double writeSeconds = secondsSince(t);
                if (plan.texture && (!job.skipExisting || !fileExists(plan.bakePaths[k]))) {
                    t = Clock::now();
                    uvwarp::BakeOptions bakeOptions;
                    bakeOptions.filter = job.filter;
                    uvwarp::bakeTexture(texture, redirect, baked, bakeOptions);
                    seconds["bake"] = secondsSince(t);
                    std::string extension = plan.bakePaths[k].extension().string();
                    std::transform(extension.begin(), extension.end(), extension.begin(),
                                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
                    // Only EXR keeps arbitrary header attributes; other formats get the pixels alone.
                    t = Clock::now();
                    io::writeImage(plan.bakePaths[k], baked,
                                   extension == ".exr" ? attributes : io::ImageWriteOptions{});
                    r.files.push_back(plan.bakePaths[k]);
                    writeSeconds += secondsSince(t);
                    ++r.baked;
                }
                seconds["write"] = writeSeconds;
                ++r.written;
            } else {
                ++r.replayed;
            }
            seconds["total"] = secondsSince(start);
            json line = baseLine(k, needed ? "written" : "replayed");
            line["metrics"] = metricsJson(metrics, warp->stats());
            line["seconds"] = seconds;
            writeLog(line);
            bar.step(plan.tile, frame, true);
        }
        report.tiles.push_back(std::move(r));
    }
    return report;
}

std::vector<std::string> uvwarpSummary(const UvWarpReport& report) {
    std::vector<std::string> lines;
    for (const UvWarpTileReport& t : report.tiles) {
        const std::string tile = "tile " + std::to_string(t.tile) + ": ";
        if (t.warped) {
            std::ostringstream line;
            line.precision(3);
            line << tile << t.written << (t.written == 1 ? " frame" : " frames") << " written";
            if (t.baked > 0) line << " (" << t.baked << " baked)";
            line << ", " << t.replayed << " replayed, " << t.skipped << " skipped (outputs exist)";
            if (t.written + t.replayed > 0) {
                line << "; frame " << t.lastFrame << ": rigid stretch error "
                     << t.lastMetrics.rigidStretchError << " (identity " << t.lastMetrics.identityStretchError
                     << "), " << t.lastMetrics.foldOvers << " fold-overs";
            }
            lines.push_back(line.str());
        }
        for (const std::string& note : t.notes)
            lines.push_back(tile + note);
    }
    return lines;
}

}  // namespace deformkit::harness
