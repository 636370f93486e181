#pragma once

#include <cstddef>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "uvwarp_command.h"

// The UV-warp stage of a scene object (scene::SceneUvWarp, docs/scene.md) as `deformkit eval` and farm
// tasks run it: the engine of `deformkit uvwarp` (runUvWarpJob) fed with the object's stack output at each
// frame. Files in the output folder, frames as evalFileName writes them:
//
//   <object>.redirect.<tile>.<frame>.exr      the redirect map W^-1 (2 float channels, header attributes)
//   <object>.bake.<tile>.<frame><extension>   the texture baked through it, the texture's file extension
//
// Within one run the frames of a tile are solved in ascending order, each warm-started from the previous
// one; a run starts cold at its first frame. So a farm task writes the bytes `deformkit eval` writes over
// the task's frame range.
namespace deformkit::harness {

// "<object>.redirect.<tile>.<frame>.exr".
[[nodiscard]] std::string uvwarpRedirectName(const std::string& object, int tile, int frame);
// "<object>.bake.<tile>.<frame><texture extension>" (the stage must have a texture).
[[nodiscard]] std::string uvwarpBakeName(const scene::SceneObject& object, int tile, int frame);

// The stage's tiles that are warped: those with a rigidity map on disk, ascending. A tile without one is
// left unwarped (no outputs), as `deformkit uvwarp` does.
[[nodiscard]] std::vector<int> uvwarpWarpedTiles(const scene::SceneUvWarp& stage);

// The files the object's stage writes for `tile` at `frame`: the redirect map, then the bake when the
// stage has a texture and the tile's texture exists. Empty without a stage or for a tile it does not warp.
[[nodiscard]] std::vector<std::string> uvwarpOutputs(const scene::SceneObject& object, int tile, int frame);

struct SceneUvWarpRun {
    std::vector<int> frames;  // ascending
    std::vector<int> tiles;   // ascending; tiles the stage does not warp are ignored
    std::filesystem::path outDir;
    bool skipExisting = false;    // true: keep existing outputs and replay the warm start (farm tasks)
    std::ostream* log = nullptr;  // JSON lines per tile x frame (runUvWarpJob)
    int logTask = -1;
};

// Runs object `object`'s UV-warp stage (it must have one) over the run's frames and tiles, one tile after
// the other. Throws as runUvWarpJob, with messages naming the scene and the stage's JSON path.
UvWarpReport runSceneUvWarp(scene::SceneEvaluator& evaluator, size_t object, const SceneUvWarpRun& run);

}  // namespace deformkit::harness
