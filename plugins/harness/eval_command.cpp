#include "eval_command.h"
#include <iostream>
#include "cli.h"
#include "report_command.h"
#include "uvwarp_command.h"

#include "commands.h"
#include "process.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string_view>

#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/point_cache.h"
#include "deformkit/io/preview.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "deformkit/uvwarp/html_report.h"

namespace deformkit::harness {

namespace fs = std::filesystem;

namespace {

// The box whose default-view camera shows a frame: the rest box while the deformed mesh stays inside it
// (the rest camera, exactly). Otherwise a box about the rest centre that holds the deformed mesh with the
// rest box's diagonal when one exists (the same camera up to float rounding of the corners), else the
// smallest box about the rest centre holding it (the camera backs off along the same line for that frame
// only, rather than cutting the mesh off).
geom::Box3 framingBox(const geom::Box3& rest, const geom::Box3& frame) {
    if (glm::all(glm::greaterThanEqual(frame.min, rest.min)) &&
        glm::all(glm::lessThanEqual(frame.max, rest.max)))
        return rest;
    const glm::dvec3 centre(rest.center());
    const glm::dvec3 restHalf = 0.5 * glm::dvec3(rest.extent());
    const glm::dvec3 needed = glm::max(centre - glm::dvec3(frame.min), glm::dvec3(frame.max) - centre);
    glm::dvec3 half = needed;
    const double target = glm::dot(restHalf, restHalf);
    if (glm::dot(needed, needed) < target) {
        // |max(needed, s * restHalf)| grows with s from |needed| to >= |restHalf|: bisect for equality.
        double lo = 0.0, hi = 1.0;
        for (int i = 0; i < 60; ++i) {
            const double s = 0.5 * (lo + hi);
            const glm::dvec3 h = glm::max(needed, s * restHalf);
            (glm::dot(h, h) < target ? lo : hi) = s;
        }
        half = glm::max(needed, hi * restHalf);
    }
    geom::Box3 box;
    box.min = glm::vec3(centre - half);
    box.max = glm::vec3(centre + half);
    box.extend(frame);  // float rounding of the corners must not leave a vertex outside
    return box;
}

uint32_t toByte(float v) {
    return static_cast<uint32_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

// Pastes `preview` (8-bit values as read from its PNG) shrunk by layout.factor into column `column` of
// `band`, one row of the contact sheet's tiles.
void pasteTile(io::Image& band, const io::Image& preview, const ContactSheetLayout& layout, int32_t column) {
    const int32_t k = layout.factor;
    const uint32_t area = static_cast<uint32_t>(k) * k;
    const int32_t x0 = column * layout.tileWidth;
    for (int32_t y = 0; y < layout.tileHeight; ++y) {
        for (int32_t x = 0; x < layout.tileWidth; ++x) {
            for (int32_t c = 0; c < 3; ++c) {
                uint32_t sum = 0;
                for (int32_t j = 0; j < k; ++j)
                    for (int32_t i = 0; i < k; ++i)
                        sum += toByte(preview.at(x * k + i, y * k + j, c));
                band.at(x0 + x, y, c) = static_cast<float>((sum + area / 2) / area) / 255.0f;
            }
        }
    }
}

// The contact sheet of an object's previews, written a row of tiles at a time: only one row is in memory,
// whatever the frame count. Tiles are made from the files as written (8-bit), so a tile is reproducible
// from its preview.
void writeContactSheet(const fs::path& sheet, const std::vector<fs::path>& previews,
                       const ContactSheetLayout& layout, const io::PreviewOptions& view) {
    const glm::vec3 background(static_cast<float>(toByte(view.background[0])) / 255.0f,
                               static_cast<float>(toByte(view.background[1])) / 255.0f,
                               static_cast<float>(toByte(view.background[2])) / 255.0f);
    io::writeImageInBands(
        sheet, layout.columns * layout.tileWidth, layout.rows * layout.tileHeight, 3, layout.tileHeight,
        [&](int32_t y0, io::Image& band) {
            for (int32_t i = 0; i < band.width * band.height; ++i)
                for (int32_t c = 0; c < 3; ++c)
                    band.pixels[3 * static_cast<size_t>(i) + c] = background[c];
            const size_t first = static_cast<size_t>(y0 / layout.tileHeight) * layout.columns;
            for (int32_t column = 0; column < layout.columns; ++column) {
                if (first + column >= previews.size()) break;
                pasteTile(band, io::readImage(previews[first + column], {3, "preview"}), layout, column);
            }
        });
}

// Removes a folder and its contents when leaving scope, on success or error.
struct RemoveOnExit {
    fs::path dir;
    ~RemoveOnExit() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

// Encodes `pngs` in order into `movie` with ffmpeg. The previews are linked (or copied) under sequential
// names into a scratch folder first, so frame lists with gaps or negative frames make a plain pattern.
void encodeMovie(const fs::path& ffmpeg, const std::vector<fs::path>& pngs, const fs::path& movie,
                 int32_t fps) {
    std::string scratchName = movie.filename().string();
    scratchName.insert(0, 1, '.');
    scratchName += ".frames.tmp";
    RemoveOnExit scratch{movie.parent_path() / scratchName};
    std::error_code ec;
    fs::remove_all(scratch.dir, ec);
    if (!fs::create_directory(scratch.dir, ec)) {
        throw IoError(formatError(scratch.dir.string(), "", "cannot be created: " + ec.message(),
                                  "a writable output folder"));
    }
    for (size_t i = 0; i < pngs.size(); ++i) {
        char name[32];
        std::snprintf(name, sizeof(name), "%06zu.png", i);
        const fs::path link = scratch.dir / name;
        fs::create_hard_link(pngs[i], link, ec);
        if (ec && !fs::copy_file(pngs[i], link, ec)) {
            throw IoError(formatError(link.string(), "", "cannot be written: " + ec.message(),
                                      "a writable output folder"));
        }
    }
    io::writeAtomically(movie, [&](const fs::path& tmp) {
        const std::string command =
            shellQuote(ffmpeg.string()) + " -nostdin -y -loglevel error -framerate " + std::to_string(fps) +
            " -i " + shellQuote((scratch.dir / "%06d.png").string()) +
            " -pix_fmt yuv420p -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' " + shellQuote(tmp.string());
        const int status = std::system(command.c_str());
        std::error_code ec;
        if (status != 0 || !fs::is_regular_file(tmp, ec)) {
            std::string what = "wrote no file";
            if (status == -1) {
                what = "could not be started";
            } else if (status != 0) {
                what = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                         : "was stopped by a signal";
            }
            throw IoError(
                formatError(command, "", what, "ffmpeg to encode the previews into " + movie.string()));
        }
    });
}

void checkSize(const char* what, int32_t value, int32_t lo, int32_t hi) {
    if (value < lo || value > hi) {
        throw InvalidInput(formatError("eval", what, "is " + std::to_string(value),
                                       std::to_string(lo) + " to " + std::to_string(hi)));
    }
}

constexpr const char* kUvwarpLogName = "uvwarp.jsonl";  // in the output folder

// The UV-warp stages' log written as DIR/uvwarp.jsonl and the shot's page (EvalCommand::report).
void writeShotPage(const EvalCommand& command, EvalReport& report, const std::string& logText,
                   std::ostream* progress) {
    if (logText.empty()) {
        report.notes.push_back("no UV-warp stage wrote a frame: no report");
        return;
    }
    const fs::path logFile = command.outDir / kUvwarpLogName;
    io::writeFileAtomically(logFile, logText);
    report.files.push_back(logFile);
    uvwarp::ShotLog log;
    std::istringstream lines(logText);
    uvwarp::readShotLog(lines, logFile.string(), log);
    uvwarp::HtmlReportOptions options;
    options.title = "Shot " + command.scene.stem().string();
    // The heatmaps' geometry from the scene itself: the shot may be written as point caches alone.
    options.geometry = sceneGeometry(io::absolutePath(command.scene));
    std::string frames;
    if (!report.frames.empty()) {
        frames =
            " --frames " + std::to_string(report.frames.front()) + "-" + std::to_string(report.frames.back());
    }
    options.rerun.push_back("deformkit eval " + fs::absolute(command.scene).string() + frames + " --out " +
                            fs::absolute(command.outDir).string() + " --report " +
                            fs::absolute(*command.report).string());
    const uvwarp::HtmlReportResult page = uvwarp::writeHtmlReport(log, *command.report, options);
    report.files.insert(report.files.end(), page.files.begin(), page.files.end());
    for (const std::string& note : page.notes)
        report.notes.push_back("report: " + note);
    if (progress) *progress << "eval: report " << command.report->string() << " written\n";
}

}  // namespace

ContactSheetLayout contactSheetLayout(int32_t tiles, int32_t previewWidth, int32_t previewHeight,
                                      int32_t maxColumns, int32_t maxWidth) {
    checkSize("contact sheet tiles", tiles, 1, 1 << 30);
    checkSize("preview width", previewWidth, 1, 16384);
    checkSize("preview height", previewHeight, 1, 16384);
    checkSize("contact sheet columns", maxColumns, 1, 1 << 30);
    ContactSheetLayout layout;
    layout.columns = std::min(tiles, maxColumns);
    layout.rows = (tiles + layout.columns - 1) / layout.columns;
    const int64_t wide = static_cast<int64_t>(layout.columns) * previewWidth;
    layout.factor =
        maxWidth < 1 ? 0 : static_cast<int32_t>(std::max<int64_t>(1, (wide + maxWidth - 1) / maxWidth));
    if (layout.factor < 1 || layout.factor > std::min(previewWidth, previewHeight)) {
        throw InvalidInput(formatError("eval", "contact sheet width",
                                       "is " + std::to_string(maxWidth) + " pixels for " +
                                           std::to_string(layout.columns) + " columns of " +
                                           std::to_string(previewWidth) + "x" +
                                           std::to_string(previewHeight) + " previews",
                                       "room for tiles at least one pixel wide and high"));
    }
    layout.tileWidth = previewWidth / layout.factor;
    layout.tileHeight = previewHeight / layout.factor;
    return layout;
}

EvalReport evalCommand(const EvalCommand& command, std::ostream* progress) {
    // The scene by its absolute path, as farm plans hold it: inputs resolve to absolute paths, so the
    // provenance headers of eval's maps equal those a farm task writes.
    scene::SceneEvaluator evaluator(readScene(io::absolutePath(command.scene)));
    const scene::Scene& scene = evaluator.scene();
    EvalReport report;
    if (command.frames.empty()) {
        for (int f = scene.firstFrame; f <= scene.lastFrame; ++f)
            report.frames.push_back(f);
    } else {
        report.frames = command.frames;
    }
    const size_t numObjects = evaluator.numObjects();
    const bool previews = command.previews && !report.frames.empty() && numObjects > 0;
    io::PreviewOptions view;
    ContactSheetLayout layout;
    if (previews) {
        checkSize("preview width", command.previewWidth, 1, 16384);
        checkSize("preview height", command.previewHeight, 1, 16384);
        view.width = command.previewWidth;
        view.height = command.previewHeight;
        layout = contactSheetLayout(static_cast<int32_t>(report.frames.size()), view.width, view.height,
                                    command.contactColumns, command.contactMaxWidth);
        if (command.movie) checkSize("movie frame rate", command.movieFrameRate, 1, 1000);
    }
    if (!command.cache.empty() && command.cache != "pc2" && command.cache != "mdd") {
        throw InvalidInput(
            formatError("--cache", command.cache, "is not a point cache format", "pc2 or mdd"));
    }
    if (!command.objs && command.cache.empty()) {
        throw InvalidInput(formatError("--no-objs", "", "is given without --cache",
                                       "--cache pc2 or --cache mdd to write the frames instead of OBJs"));
    }
    if (!command.cache.empty()) {
        for (size_t i = 1; i < report.frames.size(); ++i) {
            if (report.frames[i] != report.frames[i - 1] + 1) {
                throw InvalidInput(formatError("--cache", command.cache,
                                               "cannot hold the frames " +
                                                   std::to_string(report.frames[i - 1]) + " and " +
                                                   std::to_string(report.frames[i]) + " with a gap",
                                               "consecutive frames (a cache has one frame per sample)"));
            }
        }
        if (command.cache == "mdd") checkSize("frame rate", command.movieFrameRate, 1, 1000);
    }
    // Every input checked before anything is written: the stacks bound (vertex ranges, bind-time values),
    // sequence files, and below the UV-warp stages' maps.
    evaluator.check(report.frames);
    // eval's outputs, each a file of its own and none a file it reads (written over as the shot runs); the
    // UV-warp stages check their maps against both.
    std::vector<uvwarp::ShotJob::CallerFile> files = scene::sceneInputFiles(scene, report.frames);
    const auto output = [&](const fs::path& file, const std::string& what) {
        files.push_back({file, what, true});
    };
    for (const scene::SceneObject& object : scene.objects) {
        for (const int frame : report.frames) {
            const std::string at = " of " + object.name + " at frame " + std::to_string(frame);
            if (command.objs)
                output(command.outDir / scene::frameFileName(object.name, frame), "the deformed mesh" + at);
            if (previews)
                output(command.outDir / scene::frameFileName(object.name, frame, ".png"), "the preview" + at);
        }
        if (!command.cache.empty() && !report.frames.empty())
            output(command.outDir / (object.name + "." + command.cache), "the point cache of " + object.name);
        if (previews)
            output(command.outDir / (object.name + ".contact.png"), "the contact sheet of " + object.name);
        if (previews && command.movie)
            output(command.outDir / (object.name + ".mp4"), "the movie of " + object.name);
    }
    if (command.report) {
        output(command.outDir / kUvwarpLogName, "the UV-warp stages' log");
        output(*command.report, "the report (--report)");
    }
    io::requireFilesApart(files);
    // The UV-warp stages: one shot solver per object with a stage, fed the frame the OBJ is written from.
    std::vector<std::optional<uvwarp::ShotSolver>> stages(numObjects);
    std::ostringstream uvwarpLog;
    for (size_t o = 0; o < numObjects; ++o) {
        const scene::SceneObject& object = scene.objects[o];
        if (!object.uvwarp || report.frames.empty()) continue;
        scene::UvWarpStageRun run;
        run.frames = report.frames;
        run.tiles = object.uvwarp->tiles;
        run.outDir = command.outDir;
        if (command.report) run.log = &uvwarpLog;
        run.callerFiles = files;
        stages[o] = scene::uvwarpStageSolver(scene, o, run);
    }
    // The page is written after the last frame: a folder that cannot be made fails now.
    const bool anyStage =
        std::any_of(stages.begin(), stages.end(), [](const auto& s) { return s.has_value(); });
    if (command.report && anyStage) uvwarp::prepareHtmlReport(*command.report);
    io::createFolder(command.outDir);

    // One point cache per object, moved into place complete when every frame is in.
    std::vector<std::unique_ptr<io::PointCacheWriter>> caches(numObjects);
    if (!command.cache.empty() && !report.frames.empty()) {
        for (size_t o = 0; o < numObjects; ++o) {
            caches[o] = std::make_unique<io::PointCacheWriter>(
                command.outDir / (scene.objects[o].name + "." + command.cache),
                scene.objects[o].rest.numVertices(), static_cast<int32_t>(report.frames.size()),
                report.frames.front(), command.movieFrameRate);
        }
    }

    std::vector<geom::Box3> restBounds;       // per object
    std::vector<std::vector<fs::path>> pngs;  // per object, frame by frame
    if (previews) {
        for (const scene::SceneObject& object : scene.objects)
            restBounds.push_back(object.rest.bounds());
        pngs.resize(numObjects);
    }

    for (size_t i = 0; i < report.frames.size(); ++i) {
        const int frame = report.frames[i];
        for (size_t o = 0; o < numObjects; ++o) {
            const geom::Mesh& mesh = evaluator.evaluate(o, frame);
            if (command.objs) {
                const fs::path file = command.outDir / scene::frameFileName(scene.objects[o].name, frame);
                io::writeObj(file, mesh, scene.objects[o].groups);
                report.files.push_back(file);
            }
            if (caches[o]) caches[o]->append(mesh.points());
            if (previews) {
                io::PreviewOptions frameView = view;
                frameView.frame = framingBox(restBounds[o], mesh.bounds());
                const fs::path png =
                    command.outDir / scene::frameFileName(scene.objects[o].name, frame, ".png");
                io::writeImage(png, io::renderPreview(mesh, frameView));
                report.files.push_back(png);
                pngs[o].push_back(png);
            }
            if (stages[o]) scene::solveStageFrame(*stages[o], scene, o, frame, mesh.points());
        }
        if (progress) {
            *progress << "eval: frame " << frame << " (" << (i + 1) << "/" << report.frames.size()
                      << "): " << numObjects << (numObjects == 1 ? " object" : " objects") << " written\n";
        }
    }
    for (size_t o = 0; o < numObjects; ++o) {
        if (!stages[o]) continue;
        const uvwarp::ShotReport warped = stages[o]->finish();
        for (const uvwarp::ShotTileReport& tile : warped.tiles)
            report.files.insert(report.files.end(), tile.files.begin(), tile.files.end());
        for (const std::string& line : uvwarp::shotSummary(warped)) {
            if (progress) *progress << "eval: " << scene.objects[o].name << " uvwarp " << line << "\n";
            report.uvwarpLines.push_back(scene.objects[o].name + " " + line);
        }
    }
    for (const auto& cache : caches) {
        if (!cache) continue;
        cache->finish();
        report.files.push_back(cache->path());
        if (progress) *progress << "eval: point cache " << cache->path().string() << " written\n";
    }
    if (command.report) writeShotPage(command, report, uvwarpLog.str(), progress);
    for (size_t o = 0; o < numObjects; ++o)
        report.binds.push_back(evaluator.stack(o).bindCount());
    for (size_t o = 0; o < numObjects; ++o)
        report.evaluations.push_back(evaluator.evaluations(o));
    if (!previews) return report;

    for (size_t o = 0; o < numObjects; ++o) {
        const fs::path sheet = command.outDir / (scene.objects[o].name + ".contact.png");
        writeContactSheet(sheet, pngs[o], layout, view);
        report.files.push_back(sheet);
    }
    if (command.movie) {
        const fs::path ffmpeg = findProgram("ffmpeg");
        if (ffmpeg.empty()) {
            report.notes.push_back("no ffmpeg on PATH: movies not written");
            return report;
        }
        for (size_t o = 0; o < numObjects; ++o) {
            const fs::path movie = command.outDir / (scene.objects[o].name + ".mp4");
            encodeMovie(ffmpeg, pngs[o], movie, command.movieFrameRate);
            report.files.push_back(movie);
            if (progress) *progress << "eval: movie " << movie.string() << " written\n";
        }
    }
    return report;
}

void addEvalCommand(CommandLine& cli) {
    struct Options {
        EvalCommand command;
        std::string scene, out, report;
        bool noPreviews = false, noObjs = false;
    };
    auto o = std::make_shared<Options>();
    o->out = o->command.outDir.string();
    Command eval = cli.add(
        "eval", "Evaluate a scene's deformer stacks frame by frame and write one OBJ per object and frame",
        [o] {
            EvalCommand& c = o->command;
            c.scene = o->scene;
            c.outDir = o->out;
            c.previews = !o->noPreviews;
            c.objs = !o->noObjs;
            if (!o->report.empty()) c.report = o->report;
            const EvalReport report = evalCommand(c, &std::cout);
            std::cout << "eval: wrote " << report.files.size() << " files to " << o->out << "/\n";
            for (const std::string& note : report.notes)
                std::cout << "eval: " << note << "\n";
            return 0;
        });
    eval.option("SCENE", o->scene, "scene (.json, docs/scene.md)").required();
    eval.option(
        "--frames", [o](const std::string& value) { o->command.frames = parseFrames(value); }, "the scene's",
        "frames: 1-24, or a list such as 1-10,15 (an empty value is refused)");
    eval.option("--out", o->out,
                "output folder: <object>.<frame>.obj and .png, <object>.contact.png, <object>.mp4")
        .showDefault();
    eval.flag("--no-previews", o->noPreviews,
              "write only the OBJs (no PNG previews, contact sheets or movies)");
    eval.option("--preview-width", o->command.previewWidth, "preview width in pixels").showDefault();
    eval.option("--preview-height", o->command.previewHeight, "preview height in pixels").showDefault();
    eval.flag("--movie", o->command.movie,
              "also encode <object>.mp4 from the previews when ffmpeg is on PATH");
    eval.option(
            "--cache", o->command.cache,
            "also write <object>.pc2 or <object>.mdd: every frame in one point cache (consecutive frames)")
        .choices({"pc2", "mdd"});
    eval.option(
        "--report", o->report,
        "with UV-warp stages: an HTML page of the shot (deformkit report), their log as <out>/uvwarp.jsonl");
    eval.flag("--no-objs", o->noObjs, "write the point cache instead of the per-frame OBJs (needs --cache)");
    eval.option("--fps", o->command.movieFrameRate, "frame rate of the movies and of an MDD cache's times")
        .showDefault();
}

}  // namespace deformkit::harness
