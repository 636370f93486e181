#include "scene_uvwarp.h"

#include <algorithm>
#include <system_error>

#include "deformkit/error.h"
#include "deformkit/io/udim.h"
#include "eval_command.h"

namespace deformkit::harness {

namespace fs = std::filesystem;

namespace {

bool fileExists(const fs::path& path) {
    std::error_code ec;
    return fs::exists(path, ec);
}

fs::path tileFile(const fs::path& pattern, int tile) {
    return io::expandUdim(pattern.string(), tile);
}

}  // namespace

std::string uvwarpRedirectName(const std::string& object, int tile, int frame) {
    return evalFileName(object + ".redirect." + std::to_string(tile), frame, ".exr");
}

std::string uvwarpBakeName(const scene::SceneObject& object, int tile, int frame) {
    return evalFileName(object.name + ".bake." + std::to_string(tile), frame,
                        object.uvwarp->texture->extension().string());
}

std::vector<int> uvwarpWarpedTiles(const scene::SceneUvWarp& stage) {
    std::vector<int> tiles;
    for (int tile : stage.tiles) {
        if (fileExists(tileFile(stage.rigidity, tile))) tiles.push_back(tile);
    }
    return tiles;
}

std::vector<std::string> uvwarpOutputs(const scene::SceneObject& object, int tile, int frame) {
    if (!object.uvwarp) return {};
    const scene::SceneUvWarp& stage = *object.uvwarp;
    if (!std::binary_search(stage.tiles.begin(), stage.tiles.end(), tile) ||
        !fileExists(tileFile(stage.rigidity, tile)))
        return {};
    std::vector<std::string> outputs = {uvwarpRedirectName(object.name, tile, frame)};
    if (stage.texture && fileExists(tileFile(*stage.texture, tile)))
        outputs.push_back(uvwarpBakeName(object, tile, frame));
    return outputs;
}

UvWarpReport runSceneUvWarp(scene::SceneEvaluator& evaluator, size_t object, const SceneUvWarpRun& run) {
    const scene::Scene& scene = evaluator.scene();
    const scene::SceneObject& o = scene.objects.at(object);
    if (!o.uvwarp) {
        throw InvalidInput(formatError(scene.source, o.path + ".stack", "has no UV-warp stage",
                                       "a stack whose last entry has type \"uvwarp\""));
    }
    const scene::SceneUvWarp& stage = *o.uvwarp;
    UvWarpJob job;
    job.rest = &o.rest;
    job.restName = o.meshFile.string();
    job.frames = run.frames;
    for (int tile : run.tiles) {
        if (std::binary_search(stage.tiles.begin(), stage.tiles.end(), tile)) job.tiles.push_back(tile);
    }
    if (job.tiles.empty() || job.frames.empty()) return {};
    job.rigidity = stage.rigidity;
    job.mask = stage.mask;
    job.orientation = stage.orientation;
    job.texture = stage.texture;
    job.rigidityOption = scene.source + ": " + stage.path + ".rigidity";
    const std::string name = o.name;
    const fs::path outDir = run.outDir;
    job.outPath = [&](int tile, int frame) { return outDir / uvwarpRedirectName(name, tile, frame); };
    if (stage.texture)
        job.bakePath = [&](int tile, int frame) { return outDir / uvwarpBakeName(o, tile, frame); };
    job.options = stage.options;
    job.filter = stage.filter;
    job.skipExisting = run.skipExisting;
    // The header records the deformed mesh as the OBJ eval writes for the frame.
    job.deformed = [&](int frame, std::string& frameName) -> std::span<const glm::vec3> {
        frameName = evalFileName(name, frame);
        return evaluator.evaluate(object, frame).points();
    };
    job.log = run.log;
    job.logTask = run.logTask;
    job.logObject = name;
    try {
        return runUvWarpJob(job);
    } catch (const InvalidInput& e) {
        const std::string what = e.what();
        if (what.rfind(scene.source, 0) == 0) throw;
        throw InvalidInput(formatError(scene.source, stage.path, what, ""));
    }
}

}  // namespace deformkit::harness
