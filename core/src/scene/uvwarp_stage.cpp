#include "deformkit/scene/uvwarp_stage.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <system_error>
#include <utility>

#include "deformkit/error.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/udim.h"

namespace deformkit::scene {
namespace {

namespace fs = std::filesystem;

bool fileExists(const fs::path& path) {
    std::error_code ec;
    return fs::exists(path, ec);
}

// The file of a per-tile map pattern for `tile` at `frame`: an animated map (a frame token in its file name
// as well, uvwarp::ShotJob) has one per frame.
fs::path tileFile(const fs::path& pattern, int tile, int frame) {
    const std::string expanded = io::expandUdim(pattern.string(), tile);
    if (io::ObjSequence::isPattern(expanded)) return io::ObjSequence(expanded).framePath(frame);
    return expanded;
}

const SceneObject& stageObject(const Scene& scene, size_t object) {
    const SceneObject& o = scene.objects.at(object);
    if (!o.uvwarp) {
        throw InvalidInput(formatError(scene.source, o.path + ".stack", "has no UV-warp stage",
                                       "a stack whose last entry has type \"uvwarp\""));
    }
    return o;
}

// Runs `work`, naming the scene and the stage's JSON path in an InvalidInput that does not name the scene.
template <class Work>
auto inStage(const Scene& scene, const SceneUvWarp& stage, Work&& work) {
    try {
        return work();
    } catch (const InvalidInput& e) {
        const std::string what = e.what();
        if (what.rfind(scene.source, 0) == 0) throw;
        throw InvalidInput(formatError(scene.source, stage.path, what, ""));
    } catch (const IoError& e) {  // a map's file missing or unreadable: the stage that names it said too
        const std::string what = e.what();
        if (what.rfind(scene.source, 0) == 0 || dynamic_cast<const StorageError*>(&e)) throw;
        throw IoError(formatError(scene.source, stage.path, what, ""));
    }
}

}  // namespace

std::string frameFileName(const std::string& object, int frame, const std::string& extension) {
    char digits[32];
    std::snprintf(digits, sizeof(digits), "%s%04lld", frame < 0 ? "-" : "",
                  std::llabs(static_cast<long long>(frame)));
    return object + "." + digits + extension;
}

std::string uvwarpRedirectName(const std::string& object, int tile, int frame) {
    return frameFileName(object + ".redirect." + std::to_string(tile), frame, ".exr");
}

std::string uvwarpBakeName(const SceneObject& object, int tile, int frame) {
    return frameFileName(object.name + ".bake." + std::to_string(tile), frame,
                         object.uvwarp->texture->extension().string());
}

std::vector<int> uvwarpWarpedTiles(const SceneUvWarp& stage, std::span<const int> frames) {
    std::vector<int> tiles;
    for (int tile : stage.tiles) {
        if (std::any_of(frames.begin(), frames.end(),
                        [&](int frame) { return fileExists(tileFile(stage.rigidity, tile, frame)); }))
            tiles.push_back(tile);
    }
    return tiles;
}

void requireRigidityMaps(const Scene& scene, size_t object, std::span<const int> frames) {
    const SceneObject& so = scene.objects.at(object);
    if (!so.uvwarp || so.uvwarp->tiles.empty() || frames.empty() ||
        !uvwarpWarpedTiles(*so.uvwarp, frames).empty())
        return;
    const SceneUvWarp& stage = *so.uvwarp;
    std::string list;
    for (int tile : stage.tiles)
        list += (list.empty() ? "'" : ", '") + tileFile(stage.rigidity, tile, frames.front()).string() + "'";
    throw IoError(formatError(scene.source + ": " + stage.path + ".rigidity", stage.rigidity.string(),
                              "no tile has a rigidity map", "at least one of " + list));
}

std::string missingPlannedMap(const Scene& scene, const std::vector<std::string>& plannedOutputs,
                              int firstFrame, int lastFrame, const std::vector<int>& tiles) {
    const std::set<std::string> planned(plannedOutputs.begin(), plannedOutputs.end());
    for (const SceneObject& object : scene.objects) {
        if (!object.uvwarp) continue;
        const SceneUvWarp& stage = *object.uvwarp;
        for (const int tile : tiles) {
            for (int frame = firstFrame; frame <= lastFrame; ++frame) {
                const auto missing = [&](const fs::path& pattern, const char* key) {
                    const fs::path file = tileFile(pattern, tile, frame);
                    return fileExists(file) ? std::string()
                                            : scene.source + ": " + stage.path + "." + key + ": " +
                                                  file.string() + " does not exist";
                };
                if (planned.contains(uvwarpRedirectName(object.name, tile, frame))) {
                    if (std::string m = missing(stage.rigidity, "rigidity"); !m.empty()) return m;
                }
                if (stage.texture && planned.contains(uvwarpBakeName(object, tile, frame))) {
                    if (std::string m = missing(*stage.texture, "texture"); !m.empty()) return m;
                }
            }
        }
    }
    return {};
}

std::vector<std::string> uvwarpOptionalMaps(const Scene& scene, int firstFrame, int lastFrame,
                                            const std::vector<int>& tiles) {
    std::vector<std::string> maps;
    std::set<std::string> seen;
    for (const SceneObject& object : scene.objects) {
        if (!object.uvwarp) continue;
        const SceneUvWarp& stage = *object.uvwarp;
        for (const int tile : tiles) {
            if (!std::binary_search(stage.tiles.begin(), stage.tiles.end(), tile)) continue;
            for (int frame = firstFrame; frame <= lastFrame; ++frame) {
                for (const auto* pattern : {&stage.mask, &stage.orientation}) {
                    if (!*pattern) continue;
                    const std::string file = tileFile(**pattern, tile, frame).string();
                    if (fileExists(file) && seen.insert(file).second) maps.push_back(file);
                }
            }
        }
    }
    return maps;
}

std::vector<std::string> uvwarpOutputs(const SceneObject& object, int tile, int frame) {
    if (!object.uvwarp) return {};
    const SceneUvWarp& stage = *object.uvwarp;
    if (!std::binary_search(stage.tiles.begin(), stage.tiles.end(), tile) ||
        !fileExists(tileFile(stage.rigidity, tile, frame)))
        return {};
    std::vector<std::string> outputs = {uvwarpRedirectName(object.name, tile, frame)};
    if (stage.texture && fileExists(tileFile(*stage.texture, tile, frame)))
        outputs.push_back(uvwarpBakeName(object, tile, frame));
    return outputs;
}

uvwarp::ShotJob uvwarpStageJob(const Scene& scene, size_t object, const UvWarpStageRun& run) {
    const SceneObject& o = stageObject(scene, object);
    const SceneUvWarp& stage = *o.uvwarp;
    uvwarp::ShotJob job;
    job.rest = &o.rest;
    job.restName = o.meshFile.string();
    job.frames = run.frames;
    job.warmUpFrames = run.warmUpFrames;
    for (int tile : run.tiles) {
        if (std::binary_search(stage.tiles.begin(), stage.tiles.end(), tile)) job.tiles.push_back(tile);
    }
    job.rigidity.pattern = stage.rigidity;
    if (stage.mask) job.mask.pattern = *stage.mask;
    if (stage.orientation) job.orientation.pattern = *stage.orientation;
    if (stage.texture) job.texture.pattern = *stage.texture;
    job.rigidity.name = scene.source + ": " + stage.path + ".rigidity";
    if (stage.mask) job.mask.name = scene.source + ": " + stage.path + ".mask";
    if (stage.orientation) job.orientation.name = scene.source + ": " + stage.path + ".orientation";
    if (stage.texture) job.texture.name = scene.source + ": " + stage.path + ".texture";
    const std::string name = o.name;
    const fs::path outDir = run.outDir;
    job.outPath = [name, outDir](int tile, int frame) {
        return outDir / uvwarpRedirectName(name, tile, frame);
    };
    if (stage.texture) {
        const std::string extension = stage.texture->extension().string();
        job.bakePath = [name, outDir, extension](int tile, int frame) {
            return outDir / frameFileName(name + ".bake." + std::to_string(tile), frame, extension);
        };
    }
    job.options = stage.options;
    job.preset = stage.preset;
    job.presetOwn = stage.presetOwn;
    job.filter = stage.filter;
    job.skipExisting = run.skipExisting;
    job.log = run.log;
    job.logTask = run.logTask;
    job.logObject = name;
    job.callerFiles = run.callerFiles;
    return job;
}

std::vector<uvwarp::ShotJob::CallerFile> sceneInputFiles(const Scene& scene, const std::vector<int>& frames) {
    std::vector<uvwarp::ShotJob::CallerFile> files;
    std::error_code error;
    if (fs::is_regular_file(scene.source, error)) files.push_back({scene.source, "the scene"});
    for (const SceneObject& object : scene.objects) {
        const std::string of = " of " + scene.source + ": " + object.path;
        files.push_back({object.meshFile, "the rest mesh" + of});
        if (!object.sequence.empty()) {
            for (uvwarp::ShotJob::CallerFile& file :
                 uvwarp::deformedShotFiles(object.sequence, frames, of + " (animated input)"))
                files.push_back(std::move(file));
        }
        for (const SceneDeformer& deformer : object.stack) {
            if (!deformer.weightsFile.empty() && fs::is_regular_file(deformer.weightsFile, error))
                files.push_back(
                    {deformer.weightsFile, "the weights of " + scene.source + ": " + deformer.path});
        }
    }
    return files;
}

std::optional<uvwarp::ShotSolver> uvwarpStageSolver(const Scene& scene, size_t object,
                                                    const UvWarpStageRun& run) {
    uvwarp::ShotJob job = uvwarpStageJob(scene, object, run);
    if (job.tiles.empty() || job.frames.empty()) return std::nullopt;
    return inStage(scene, *scene.objects[object].uvwarp,
                   [&] { return std::optional<uvwarp::ShotSolver>(std::in_place, std::move(job)); });
}

void solveStageFrame(uvwarp::ShotSolver& solver, const Scene& scene, size_t object, int frame,
                     std::span<const glm::vec3> deformed, Interrupter* interrupter) {
    const SceneObject& o = stageObject(scene, object);
    const std::optional<int> last = solver.lastNeededFrame();
    if (!last || frame > *last) return;
    inStage(scene, *o.uvwarp,
            [&] { solver.solveFrame(frame, deformed, frameFileName(o.name, frame), interrupter); });
}

uvwarp::ShotReport runUvWarpStage(SceneEvaluator& evaluator, size_t object, const UvWarpStageRun& run,
                                  Interrupter* interrupter) {
    const Scene& scene = evaluator.scene();
    std::optional<uvwarp::ShotSolver> solver = uvwarpStageSolver(scene, object, run);
    if (!solver) return {};
    const std::optional<int> last = solver->lastNeededFrame();
    const InterrupterScope scope(interrupter, "uvwarp", solver->units());
    for (int frame : run.frames) {
        if (!last || frame > *last) break;
        // Frames no tile solves (warm-up, or outputs that exist) are not evaluated.
        const std::span<const glm::vec3> deformed = solver->needsPositions()
                                                        ? evaluator.evaluate(object, frame).points()
                                                        : std::span<const glm::vec3>();
        solveStageFrame(*solver, scene, object, frame, deformed, interrupter);
    }
    return solver->finish();
}

}  // namespace deformkit::scene
