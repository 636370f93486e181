#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/interrupter.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "deformkit/uvwarp/shot_job.h"

// The files a scene evaluation writes, and the UV-warp stage of a scene object (SceneUvWarp, docs/scene.md)
// as `deformkit eval` and farm tasks run it: the shot job (uvwarp/shot_job.h) fed with the object's stack
// output at each frame. Files in the output folder:
//
//   <object>.<frame>.obj                      the deformed mesh (frameFileName)
//   <object>.redirect.<tile>.<frame>.exr      the redirect map W^-1 (2 float channels, header attributes)
//   <object>.bake.<tile>.<frame><extension>   the texture baked through it, the texture's file extension
//
// Within one run the frames of a tile are solved in ascending order, each warm-started from the previous
// one; a run starts cold at its first frame. So a farm task writes the bytes `deformkit eval` writes over
// the task's frame range.
namespace deformkit::scene {

// "<object>.<frame><extension>" with the frame zero padded to 4 digits, a sign before the padding
// ("body.0012.obj", "body.-0003.obj").
[[nodiscard]] std::string frameFileName(const std::string& object, int frame,
                                        const std::string& extension = ".obj");

// "<object>.redirect.<tile>.<frame>.exr".
[[nodiscard]] std::string uvwarpRedirectName(const std::string& object, int tile, int frame);
// "<object>.bake.<tile>.<frame><texture extension>" (the stage must have a texture).
[[nodiscard]] std::string uvwarpBakeName(const SceneObject& object, int tile, int frame);

// For a farm task's outputs as planned: the first map file a planned output needs that is not there (the
// rigidity map of a planned redirect map, the texture of a planned bake), as "<scene>: <JSON path>: <file>
// does not exist"; empty when every one is. A map removed after planning names itself this way instead of
// a plan that no longer matches the scene.
[[nodiscard]] std::string missingPlannedMap(const Scene& scene,
                                            const std::vector<std::string>& plannedOutputs, int firstFrame,
                                            int lastFrame, const std::vector<int>& tiles);

// The warp masks and orientation maps the UV-warp stages find for `tiles` over frames first..last, each file
// once, in scene, tile and frame order. Either map is optional per tile (without one a tile takes a derived
// mask, or the density heuristic), so a farm plan records the ones there when it is made and each task
// checks them (FarmTask::maps): a map removed or added in between would change the task's warp silently.
[[nodiscard]] std::vector<std::string> uvwarpOptionalMaps(const Scene& scene, int firstFrame, int lastFrame,
                                                          const std::vector<int>& tiles);

// The stage's tiles that are warped over `frames`: those with a rigidity map on disk (an animated map: its
// file at any of the frames; the stage then requires it at every one), ascending. A tile without one is
// left unwarped (no outputs). Whether a tile is warped does not depend on which frame a run starts at.
[[nodiscard]] std::vector<int> uvwarpWarpedTiles(const SceneUvWarp& stage, std::span<const int> frames);
// Throws IoError, as eval's stage does, when no tile of object `object`'s stage has a rigidity map over
// `frames`: farm plans check what eval checks.
void requireRigidityMaps(const Scene& scene, size_t object, std::span<const int> frames);

// The files the object's stage writes for `tile` at `frame`: the redirect map, then the bake when the
// stage has a texture and the tile's texture exists. Empty without a stage or for a tile it does not warp.
[[nodiscard]] std::vector<std::string> uvwarpOutputs(const SceneObject& object, int tile, int frame);

struct UvWarpStageRun {
    std::vector<int> frames;   // ascending
    int32_t warmUpFrames = 0;  // the first this many frames only warm-start the rest (ShotJob::warmUpFrames)
    std::vector<int> tiles;    // ascending; tiles the stage does not warp are ignored
    std::filesystem::path outDir;
    bool skipExisting = false;    // true: keep existing outputs and replay the warm start (farm tasks)
    std::ostream* log = nullptr;  // JSON lines per tile x frame (ShotJob::log)
    int logTask = -1;
    // The caller's own files (ShotJob::callerFiles): those it writes beside the maps and those it reads,
    // checked with the stage's outputs and inputs before anything is written.
    std::vector<uvwarp::ShotJob::CallerFile> callerFiles;
};

// The files a job over `frames` reads from the scene, as ShotJob::callerFiles (not written): the scene file
// (when `scene.source` names one), each object's rest mesh, its animated input at those frames (an OBJ
// sequence's files, or the point cache) and its stack's weights files. The UV-warp stages' maps are the
// stages' own inputs (ShotJob).
[[nodiscard]] std::vector<uvwarp::ShotJob::CallerFile> sceneInputFiles(const Scene& scene,
                                                                       const std::vector<int>& frames);

// The shot job of object `object`'s UV-warp stage (it must have one) over the run, its outputs named as
// above. Throws InvalidInput naming the scene and the object when it has no stage.
[[nodiscard]] uvwarp::ShotJob uvwarpStageJob(const Scene& scene, size_t object, const UvWarpStageRun& run);

// The stage's shot solver, with messages naming the scene and the stage's JSON path: feed it the object's
// evaluated frames in order (ShotSolver::solveFrame with frameFileName as the input's name). Empty when
// the run has no frame or none of its tiles is the stage's.
[[nodiscard]] std::optional<uvwarp::ShotSolver> uvwarpStageSolver(const Scene& scene, size_t object,
                                                                  const UvWarpStageRun& run);

// Feeds `solver` (uvwarpStageSolver's) object `object`'s deformed positions at `frame`, the run's next frame,
// unless the solver needs no more frames; errors name the scene and the stage's JSON path.
void solveStageFrame(uvwarp::ShotSolver& solver, const Scene& scene, size_t object, int frame,
                     std::span<const glm::vec3> deformed, Interrupter* interrupter = nullptr);

// The whole stage over the run: each needed frame evaluated once and fed to every tile.
uvwarp::ShotReport runUvWarpStage(SceneEvaluator& evaluator, size_t object, const UvWarpStageRun& run,
                                  Interrupter* interrupter = nullptr);

}  // namespace deformkit::scene
