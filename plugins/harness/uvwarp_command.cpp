#include "uvwarp_command.h"
#include <unistd.h>
#include <iostream>
#include "cli.h"
#include "progress_bar.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <deque>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/udim.h"
#include "deformkit/scene/scene.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/grid.h"
#include "deformkit/uvwarp/html_report.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/shot_log.h"
#include "deformkit/version.h"

namespace deformkit::harness {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

using scene::kMaxFrames;

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

}  // namespace

std::vector<double> parseNumberList(const std::vector<std::string>& values, const std::string& option) {
    std::vector<double> numbers;
    for (const std::string& value : values) {
        // Commas and spaces both separate ("4, 8" and "4 8" as one argument); a comma with nothing before or
        // after it is an empty item.
        std::string commas = value;
        for (size_t k = 0; k < commas.size(); ++k) {
            if (commas[k] != ' ' && commas[k] != '\t') continue;
            const size_t end = commas.find_first_not_of(" \t", k);
            const bool joined =
                k > 0 && commas[k - 1] != ',' && end != std::string::npos && commas[end] != ',';
            commas.replace(k, (end == std::string::npos ? commas.size() : end) - k, joined ? "," : "");
        }
        forEachItem(commas, [&](std::string_view item) {
            if (!item.empty() && item.front() == '+') item.remove_prefix(1);
            double number = 0.0;
            const auto [end, error] = std::from_chars(item.data(), item.data() + item.size(), number);
            if (item.empty() || error != std::errc() || end != item.data() + item.size()) {
                throw InvalidInput(
                    formatError(option, "",
                                "'" + value + "' has " +
                                    (item.empty() ? std::string("an empty item")
                                                  : "'" + std::string(item) + "', not a number"),
                                "numbers separated by commas or spaces, such as 4,8,16"));
            }
            numbers.push_back(number);
        });
    }
    return numbers;
}

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
        constexpr int64_t limit = scene::kMaxFrameNumber;
        if (first < -limit || first > limit || last < -limit || last > limit) {
            throw InvalidInput(formatError(option, "", quoted + " is out of range",
                                           "frames from -" + std::to_string(scene::kMaxFrameNumber) + " to " +
                                               std::to_string(scene::kMaxFrameNumber)));
        }
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
        // Each tile once, as a scene's "tiles" (a tile named twice is most likely a typo for another).
        if (std::find(tiles.begin(), tiles.end(), tile) != tiles.end()) {
            throw InvalidInput(formatError(option, "", "lists tile " + std::to_string(tile) + " twice",
                                           "each tile once, comma separated"));
        }
        tiles.push_back(static_cast<int>(tile));
    });
    std::sort(tiles.begin(), tiles.end());
    return tiles;
}

uvwarp::ShotReport uvwarpCommand(const UvWarpCommand& command, Interrupter* interrupter) {
    // Everything that can be checked without solving is checked before the first output is written.
    if (command.frames.empty())
        throw InvalidInput(formatError("--frames", "", "no frames", "at least one frame"));
    if (command.texture.has_value() != command.bake.has_value()) {
        throw InvalidInput(formatError(command.bake ? "--bake" : "--texture", "",
                                       command.bake ? "given without --texture" : "given without --bake",
                                       "--texture and --bake together"));
    }
    uvwarp::ShotJob job;
    uvwarp::setOutputPatterns(job, command.out, command.bake.value_or(fs::path()), "--out", "--bake");

    const io::ObjContent restObj = io::readMesh(command.rest);
    const geom::Mesh& rest = restObj.mesh;
    (void)uvwarp::shotTiles(rest, command.rest.string(), command.tiles,
                            "--tiles");  // before the frames are read

    const uvwarp::DeformedFrames frames = uvwarp::animatedFrames(
        command.deformed, command.frames, "--deformed", rest, command.rest.string(), command.cacheStart);

    job.rest = &rest;
    job.restName = command.rest.string();
    job.frames = command.frames;
    job.tiles = command.tiles;
    job.rigidity = {command.rigidity, {}, "--rigidity"};
    if (command.mask) job.mask = {*command.mask, {}, "--mask"};
    if (command.orientation) job.orientation = {*command.orientation, {}, "--orientation"};
    if (command.texture) job.texture = {*command.texture, {}, "--texture"};
    job.options = command.options;
    job.preset = command.preset;
    job.presetOwn = command.presetOwn;
    job.filter = command.filter;
    // The command's own files are not the job's outputs: a map written over the deformed frames, the log or
    // the report (which a resumed job would then skip as done) is refused before anything is written.
    if (command.log) job.callerFiles.push_back({*command.log, "the log (--log)", true});
    if (command.report) job.callerFiles.push_back({*command.report, "the report (--report)", true});
    for (uvwarp::ShotJob::CallerFile& file :
         uvwarp::deformedShotFiles(command.deformed, command.frames, " (--deformed)"))
        job.callerFiles.push_back(std::move(file));
    std::ofstream logFile;
    std::ostringstream logLines;  // for the page when there is no log file
    if (command.log) job.log = &logFile;
    if (!command.log && command.report) job.log = &logLines;
    job.planned = [&] {  // folders of the page made, and the log opened, once nothing else is refused
        if (command.report) uvwarp::prepareHtmlReport(*command.report);
        if (command.log) uvwarp::openShotLog(*command.log, logFile);
    };
    uvwarp::ShotReport report = uvwarp::runShotJob(job, frames, interrupter);
    if (command.log && !logFile.flush()) {
        throw StorageError(
            formatError(command.log->string(), "", "cannot write the log", "enough space to write"));
    }
    if (command.report) {
        uvwarp::ShotLog log;
        if (command.log) {
            logFile.close();
            uvwarp::readShotLogFile(*command.log, log);
        } else {
            std::istringstream in(logLines.str());
            uvwarp::readShotLog(in, "this run", log);
        }
        (void)uvwarp::writeHtmlReport(log, *command.report);
    }
    return report;
}

// Older names of options that the command still takes.
constexpr std::pair<std::string_view, const char*> kOptionAliases[] = {{"sweepsPerLevel", "--sweeps"},
                                                                       {"maskBorderWidth", "--border-width"}};

void addUvWarpCommand(CommandLine& cli) {
    struct Options {
        UvWarpCommand command;
        std::string frames, tiles, mask, orientation, texture, bake, log, report, filter = "bilinear", rest,
                                                                                  deformed, rigidity, out;
        // The UV-warp options as parsed, one per declaration (uvwarp/options.h), from the shot's defaults;
        // checked by the library when the command runs.
        std::vector<std::vector<double>> values;
        std::deque<bool> flags;     // the flags' values (a deque keeps each element's address)
        std::vector<Option> given;  // per option, to tell what the command line set
        std::string preset;
        double cacheStart = 0.0;
        std::optional<Option> cacheStartGiven;
    };
    auto o = std::make_shared<Options>();
    const std::span<const uvwarp::OptionSpec> specs = uvwarp::optionSpecs();
    for (const uvwarp::OptionSpec& spec : specs) {
        o->values.push_back(spec.get(o->command.options));
        o->flags.push_back(spec.type == uvwarp::OptionType::Flag && o->values.back().front() != 0);
    }
    Command uvwarp = cli.add(
        "uvwarp",
        "Content-aware UV warp over a shot: per UDIM tile and frame a redirect map (and a baked texture)",
        [o, specs] {
            UvWarpCommand& c = o->command;
            c.rest = o->rest;
            c.deformed = o->deformed;
            c.frames = parseFrames(o->frames);
            c.rigidity = o->rigidity;
            c.out = o->out;
            if (!o->mask.empty()) c.mask = o->mask;
            if (!o->orientation.empty()) c.orientation = o->orientation;
            if (!o->texture.empty()) c.texture = o->texture;
            if (!o->bake.empty()) c.bake = o->bake;
            if (!o->tiles.empty()) c.tiles = parseTiles(o->tiles);
            if (!o->log.empty()) c.log = o->log;
            if (!o->report.empty()) c.report = o->report;
            if (o->cacheStartGiven->given()) c.cacheStart = o->cacheStart;
            c.filter = o->filter == "bicubic" ? io::SampleFilter::Bicubic : io::SampleFilter::Bilinear;
            for (size_t i = 0; i < specs.size(); ++i) {
                uvwarp::OptionValue value;
                value.numbers = o->values[i];
                if (specs[i].type == uvwarp::OptionType::Flag) {
                    value.kind = uvwarp::OptionValue::Kind::Boolean;
                    value.numbers = {o->flags[i] ? 1.0 : 0.0};
                } else if (specs[i].type == uvwarp::OptionType::IntegerList) {
                    value.kind = uvwarp::OptionValue::Kind::List;
                }
                uvwarp::setOption(c.options, specs[i], value, "", uvwarp::cliName(specs[i]));
                if (o->given[i].given()) c.presetOwn.emplace_back(specs[i].name);
            }
            if (!o->preset.empty()) c.preset = uvwarp::presetNamed(o->preset, "", "--preset");
            // The progress bar redraws one line in place: only for a person watching a terminal.
            ProgressBar bar(std::cerr);
            const uvwarp::ShotReport report = uvwarpCommand(c, ::isatty(STDERR_FILENO) ? &bar : nullptr);
            for (const std::string& line : uvwarp::shotSummary(report))
                std::cout << "uvwarp: " << line << "\n";
            if (c.report) std::cout << "uvwarp: report " << c.report->string() << "\n";
            return 0;
        });
    uvwarp.option("--rest", o->rest, "rest mesh with UVs (.obj, .gltf, .glb, .fbx, .ply, .dae)").required();
    uvwarp
        .option("--deformed", o->deformed,
                "deformed frames: an OBJ sequence 'anim.####.obj' (# per digit) or %04d, or a point cache "
                "'anim.pc2' / 'anim.mdd'")
        .required();
    o->cacheStartGiven.emplace(
        uvwarp.option("--cache-start", o->cacheStart,
                      "frame of a point cache's first sample (default: a PC2's start frame, an "
                      "MDD's 1)"));
    uvwarp.option("--frames", o->frames, "frames: 1-24, or a list such as 1-10,15").required();
    uvwarp.option("--rigidity", o->rigidity, "rigidity maps, e.g. 'rig.<UDIM>.exr' (1 = rigid)").required();
    uvwarp.option("--mask", o->mask,
                  "warp masks, e.g. 'mask.<UDIM>.exr' (>= 0.5 may warp); default: from the UVs");
    uvwarp.option("--orientation", o->orientation,
                  "orientation-preservation maps, e.g. 'orient.<UDIM>.exr' (in [0, 1], scales "
                  "--orientation-preservation per texel)");
    Option texture =
        uvwarp.option("--texture", o->texture, "texture to bake, e.g. 'col.<UDIM>.exr' (needs --bake)");
    uvwarp.option("--out", o->out, "redirect maps, e.g. 'out/redirect.<UDIM>.####.exr' (2-channel float EXR)")
        .required();
    Option bake =
        uvwarp.option("--bake", o->bake, "baked textures, e.g. 'out/col.<UDIM>.####.exr' (needs --texture)");
    texture.needs(bake);
    bake.needs(texture);
    uvwarp.option("--tiles", o->tiles,
                  "UDIM tiles, each once, e.g. 1001,1002; default: every tile of the rest UVs");
    uvwarp.option("--log", o->log, "JSON-lines log, appended: one line per tile and frame");
    uvwarp.option(
        "--report", o->report,
        "HTML page of the shot, written at the end (deformkit report): plots over frames, heatmaps at "
        "the worst frame");
    uvwarp.option("--filter", o->filter, "bake filter: bilinear or bicubic")
        .choices({"bilinear", "bicubic"})
        .showDefault();
    for (size_t i = 0; i < specs.size(); ++i) {
        const uvwarp::OptionSpec& spec = specs[i];
        std::string names = uvwarp::cliName(spec);
        for (const auto& [option, alias] : kOptionAliases) {
            if (option == spec.name) names.append(",").append(alias);
        }
        const std::string help = std::string(spec.meaning) + " (" + uvwarp::expectedValue(spec) + ")";
        switch (spec.type) {
            case uvwarp::OptionType::Flag:
                o->given.push_back(uvwarp.flag(
                    names, o->flags[i],
                    std::string(spec.meaning) + " (" + uvwarp::cliName(spec) + "=false turns it off)"));
                break;
            case uvwarp::OptionType::IntegerList: {
                std::string shown;
                for (const double v : o->values[i])
                    shown += (shown.empty() ? "" : ",") + numberText(v);
                o->given.push_back(
                    uvwarp
                        .listOption(
                            names,
                            [o, i, name = uvwarp::cliName(spec)](const std::vector<std::string>& values) {
                                o->values[i] = parseNumberList(values, name);
                            },
                            "[" + shown + "]", help)
                        .typeName("INT"));
                break;
            }
            case uvwarp::OptionType::Integer:
                o->given.push_back(
                    uvwarp.option(names, o->values[i].front(), help).typeName("INT").showDefault());
                break;
            case uvwarp::OptionType::Number:
                o->given.push_back(
                    uvwarp.option(names, o->values[i].front(), help).typeName("FLOAT").showDefault());
                break;
        }
    }
    uvwarp
        .option(
            "--preset", o->preset,
            "the library's options for a use: shot (the default schedule, each frame from the identity) or "
            "live (one warm-started iteration a frame, by grid size); options given beside it keep their "
            "values")
        .choices({"shot", "live"});
    uvwarp.listing(
        "--list-options", "text",
        "print every UV-warp option (its name here, in scenes and Python, range, default, meaning) "
        "and exit; --list-options markdown prints the table of docs/uvwarp.md",
        [](const std::string& format) {
            if (format != "text" && format != "markdown") {
                throw InvalidInput(
                    formatError("--list-options", "", "is '" + format + "'", "text or markdown"));
            }
            std::cout << uvwarp::optionReference(format == "markdown");
        });
}

}  // namespace deformkit::harness
