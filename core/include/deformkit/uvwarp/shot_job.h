#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/interrupter.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/image.h"
#include "deformkit/io/sampling.h"
#include "deformkit/uvwarp/metrics.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/redirect_metrics.h"
#include "deformkit/uvwarp/redirect_repair.h"
#include "deformkit/uvwarp/tile_warp.h"

namespace deformkit::uvwarp {

// The content-aware UV warp over a shot: for every UDIM tile and frame, the redirect map W^-1 (and the
// tile's texture baked through it), written as files with their provenance. The one implementation behind
// `deformkit uvwarp`, the UV-warp stage of scenes (`deformkit eval`, farm tasks), the Python module's
// `uvwarp_shot` and the Blender add-on's bake.
//
// - Per tile one TileWarp is bound (rest mesh, rigidity map, mask map or a mask derived from the UVs,
//   orientation map) and solved frame after frame in ascending order. With the shot's options
//   (shotOptions(), the default of every host's shot) each frame is solved from the identity, so its maps
//   depend on that frame alone. With warm start (SolverOptions::warmStart) each frame starts from the
//   previous one's warp instead, and a job starts cold at its first frame (or at its warm-up frames,
//   ShotJob::warmUpFrames). Tiles are solved frame by frame together, so each frame's deformed positions
//   are asked for once; memory is one solver per tile of the job (a farm task bounds it with its tile
//   count).
// - Outputs per tile and frame: the redirect map as a 2-channel float EXR (the rigidity map's size) whose
//   header records how it was made and what it delivers (deformkit:version, deformkit:uvwarp:tile,
//   deformkit:uvwarp:frame, and as JSON deformkit:uvwarp:solver, deformkit:uvwarp:inputs and
//   deformkit:uvwarp:metrics, the log's figures of this map); with a texture, the bake (an EXR bake gets the
//   same attributes). Every file is written atomically.
// - Resuming (skipExisting): an output that exists is not written again. So that a resumed job writes the
//   bytes an uninterrupted one would have, the warm start is replayed: each tile solves every frame up to
//   its last missing output, frames whose outputs exist only to carry the warm start ("replayed"), and no
//   frame after it ("skipped"). A tile whose outputs all exist is not bound. Frames solved from the
//   identity (SolverOptions::warmStart false) need no replay and no warm-up: only the missing outputs are
//   solved.
// - Checks before anything is written: map patterns have a UDIM token; output folders exist; outputs have
//   names of their own (no two alike, none an input's or ShotJob::reservedFiles'); a bake's extension is one
//   OpenImageIO writes; per tile the
//   maps' sizes (square, equal, a power of two when the grid takes the map's size). A tile without a rigidity
//   map is left unwarped (no outputs) and reported, unless no tile has one (an error). A missing mask tile is
//   derived from the UVs, a missing orientation tile means the density heuristic's map where
//   orientationDensity turns it on (the shot's default) and 1 everywhere otherwise, a missing texture tile is
//   not baked; each is reported.
// - Animated maps: a rigidity, mask, orientation or texture pattern with a frame token in its file name as
//   well ("rig.<UDIM>.####.exr", io::ObjSequence tokens) has one file per frame, each checked to exist with
//   the first one's size before anything is written. The warp gets a frame's maps only when they differ
//   from the last ones (ShotTileReport::mapChanges), rebuilding its hierarchy and keeping the warm start.

// A per-tile map: a UDIM pattern of files ("rig.<UDIM>.exr", io/udim.h tokens) or images a host holds in
// memory (painted maps), by tile. Images are T x T (channel 0 used), rows from the top (io::Image).
struct TileMapSource {
    std::filesystem::path pattern;    // empty when the maps are `images`
    std::map<int, io::Image> images;  // tile -> map, used when there is no pattern
    // How messages name the source: an option ("--mask"), an argument, a scene's JSON path, a host's image
    // name. Headers record a file's path, or this name and the tile for an image in memory.
    std::string name;

    [[nodiscard]] bool given() const { return !pattern.empty() || !images.empty(); }
};

// The options a job over a shot starts from: TileWarpOptions{} but every frame solved from the identity
// (SolverOptions::warmStart false) and refined by the grid's size (kAutomaticRefinement: grids up to 1024
// cells end on a grid of twice the cells, UV-39) with the density heuristic's orientation preservation
// (kAutomaticDensity: a window of 1/16 of the map, UV-40). From the identity, the default schedule costs what
// a warm-started frame does and removes as much of the rigid stretch, and a frame's maps then depend on that
// frame alone: not on the frames before it, nor on where a farm chunk or a resumed job begins
// (docs/decisions.md, UV-20). Hosts that show a live preview, one iteration a frame, warm-start instead
// (the live preset, presetOptions).
[[nodiscard]] TileWarpOptions shotOptions();

struct ShotJob {
    const geom::Mesh* rest = nullptr;  // with UVs; must outlive the job
    std::string restName;              // names the rest mesh in messages and EXR headers
    std::vector<int> frames;           // ascending, at least one
    // The first this many of `frames` only warm-start the rest (a farm task's frames before its range):
    // solved, never written nor logged as outputs, whether or not their files exist.
    int32_t warmUpFrames = 0;
    std::vector<int> tiles;     // tiles of the rest mesh's UVs, ascending; empty: every tile of them
    TileMapSource rigidity;     // required; channel 0 in [0, 1], 1 = rigid
    TileMapSource mask;         // optional; channel 0 >= 0.5 may warp
    TileMapSource orientation;  // optional; channel 0 in [0, 1] scales the orientation preservation
    TileMapSource texture;      // optional; baked through each redirect map (needs bakePath)
    // Output files of a tile and frame; bakePath only with a texture. Their folders must exist.
    std::function<std::filesystem::path(int tile, int frame)> outPath, bakePath;
    TileWarpOptions options = shotOptions();  // cells: the grid resolution (0: the rigidity map's size)
    // A preset instead of `options` (options.h), resolved per tile for its grid (the live preset's schedule
    // depends on the grid's size); the options named in presetOwn keep their values from `options`, as the
    // caller set them. Without a preset, `options` as they are.
    std::optional<Preset> preset;
    std::vector<std::string> presetOwn;
    io::SampleFilter filter = io::SampleFilter::Bilinear;  // of the bake
    // Keep existing outputs and replay the warm start (a resumed job writes an uninterrupted job's bytes);
    // false writes every output again.
    bool skipExisting = true;
    // JSON lines, one per tile and frame: {"tile", "frame", "status" (written, replayed, skipped, unwarped),
    // "redirect", "bake", "metrics" (a written frame's redirect map's figures, then the grid's, named
    // grid_*, and the solver's), "seconds"}; with "task" when logTask >= 0 and "object" when logObject is
    // not empty.
    std::ostream* log = nullptr;
    int logTask = -1;
    std::string logObject;
    // The caller's own files, each with what it is ("the log (--log)"): those it writes (a log, a report)
    // and those it reads (the deformed frames' files). Checked before anything is written with the job's
    // outputs and inputs (the rest mesh when restName is a file, every map file at every frame): two
    // outputs with one name, or an output named as an input, is InvalidInput naming both. Names are
    // compared with symbolic links resolved.
    using CallerFile = io::FileUse;
    std::vector<CallerFile> callerFiles;
    // runShotJob calls it once the job is planned and checked, before any frame is solved or any output
    // written: a caller opens its log there, so that a job refused leaves the file as it was.
    std::function<void()> planned;
};

struct ShotTileReport {
    int tile = 0;
    bool warped = true;                        // false: no rigidity map, no outputs
    std::vector<std::string> notes;            // why unwarped, a derived mask, a texture not baked
    int32_t written = 0;                       // frames whose redirect or bake was written
    int32_t baked = 0;                         // bakes written
    int32_t replayed = 0;                      // outputs existed; solved to carry the warm start
    int32_t skipped = 0;                       // outputs existed; not solved
    int32_t warmedUp = 0;                      // warm-up frames solved (ShotJob::warmUpFrames)
    int32_t mapChanges = 0;                    // frames whose animated maps differed from the last (rebuilt)
    int lastFrame = 0;                         // the last frame solved (replayed or written)
    WarpMetrics lastMetrics;                   // of lastFrame: the solver's grid (diagnostics)
    int lastWrittenFrame = 0;                  // the last frame whose redirect map was written
    DeliveredMetrics lastDelivered;            // of lastWrittenFrame: its redirect map
    FoldRepair lastRepair;                     // of lastWrittenFrame: what made its map fold-free
    int32_t scaledBack = 0;                    // written frames whose fold repair scaled a region back
    std::vector<std::filesystem::path> files;  // written, in order
};

struct ShotReport {
    std::vector<ShotTileReport> tiles;  // ascending
};

// A shot job fed frame by frame, for a caller that makes the deformed positions itself (a scene evaluated
// once per frame for its meshes and every tile). Not thread-safe; each tile's solve runs in parallel inside.
class ShotSolver {
  public:
    // Plans the job and checks every input it can before anything is written. Throws InvalidInput for an
    // incomplete job, a tile the rest mesh's UVs do not touch or a map of the wrong size; IoError for a
    // missing output folder or when no tile has a rigidity map; ParseError for an unreadable map header.
    explicit ShotSolver(ShotJob job);
    ~ShotSolver();
    ShotSolver(ShotSolver&&) noexcept;
    ShotSolver& operator=(ShotSolver&&) noexcept;

    // Progress units of the job: tiles x frames.
    [[nodiscard]] int64_t units() const;
    // What planning found to say, one line per note as the report prints it ("tile 1002: left unwarped: no
    // rigidity map 'rig.1002.exr'"): a host that only plans (a farm plan) shows them.
    [[nodiscard]] std::vector<std::string> plannedNotes() const;
    // The last frame whose deformed positions some tile needs; frames after it need no evaluation. None
    // when every output exists.
    [[nodiscard]] std::optional<int> lastNeededFrame() const;
    // Whether the job's next frame is solved by some tile, so solveFrame needs its deformed positions (a
    // frame solved from the identity whose outputs exist, or a warm-up frame, is not): callers skip
    // evaluating the others and pass no positions.
    [[nodiscard]] bool needsPositions() const;
    // Frame `frame`, the job's next frame in order: solves every tile that needs it from `deformed` (#V
    // positions of the rest mesh's vertices; may be empty when needsPositions() is false) and writes its
    // outputs. `inputName` is what the headers record as the frame's input ("anim.0007.obj"). After each
    // tile the interrupter, when given, is told and may cancel (Cancelled). Throws InvalidInput for a frame
    // out of order or a vertex count that differs.
    void solveFrame(int frame, std::span<const glm::vec3> deformed, const std::string& inputName,
                    Interrupter* interrupter = nullptr);
    // Logs the frames not given (after lastNeededFrame) and returns the report.
    [[nodiscard]] ShotReport finish();

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The deformed positions of the rest mesh's vertices at `frame`; sets `name` to what the headers record as
// the frame's input. The span must stay valid until the next call.
using DeformedFrames = std::function<std::span<const glm::vec3>(int frame, std::string& name)>;

// The files of a deformed shot as ShotJob::callerFiles, inputs the job must not write: an OBJ sequence's file
// at each of `frames`, or the one file (a point cache). Each is "the deformed frame 7" or "the deformed
// shot", then `named` (" (--deformed)").
[[nodiscard]] std::vector<ShotJob::CallerFile> deformedShotFiles(const std::filesystem::path& deformed,
                                                                 const std::vector<int>& frames,
                                                                 const std::string& named = {});

// The whole job: ShotSolver fed by `deformed`, asked once per frame up to the last needed one. The
// interrupter, when given, is started with the job's units, told after each tile and frame, and ended.
ShotReport runShotJob(const ShotJob& job, const DeformedFrames& deformed, Interrupter* interrupter = nullptr);

// The file of `tile` and `frame` for a pattern with a UDIM token and a frame token in its file name
// ("out/redirect.<UDIM>.####.exr"; frame tokens as io::ObjSequence).
[[nodiscard]] std::filesystem::path tileFramePath(const std::filesystem::path& pattern, int tile, int frame);

// Sets job.outPath (and job.bakePath when `bake` is not empty) from such patterns, checked: each has a UDIM
// token and a frame token in its file name, `out` is an OpenEXR file (the redirect map is 2 float channels
// with header attributes) and `bake` another pattern. `outName` and `bakeName` name them in messages (an
// option, an argument). Throws InvalidInput.
void setOutputPatterns(ShotJob& job, const std::filesystem::path& out, const std::filesystem::path& bake,
                       const std::string& outName, const std::string& bakeName);

// The tiles a job on `rest` warps: `tiles`, or every tile of the rest mesh's UVs when it is empty. Throws
// InvalidInput when the mesh has no UVs (naming `restName`) or a tile has no UV face of it (naming
// `tilesName`: an option, an argument). ShotSolver checks its job with it; a host may check first.
[[nodiscard]] std::vector<int> shotTiles(const geom::Mesh& rest, const std::string& restName,
                                         const std::vector<int>& tiles, const std::string& tilesName);

// The deformed frames of an OBJ sequence ("anim.####.obj") or a point cache ("anim.pc2", "anim.mdd"), read
// through io::AnimatedPositions: checks now that `path` is either (InvalidInput naming `name`), that a cache
// has the vertex count of `rest` (read from `restName`) and that every one of `frames` is there (IoError
// naming a sequence's first missing file, InvalidInput naming a cache's missing frame); then reads each
// frame when asked, named by its file or as "anim.pc2 frame 7". `cacheFirstFrame` as io::PointCache.
[[nodiscard]] DeformedFrames animatedFrames(const std::filesystem::path& path, const std::vector<int>& frames,
                                            const std::string& name, const geom::Mesh& rest,
                                            const std::string& restName,
                                            std::optional<double> cacheFirstFrame = std::nullopt);

// One line per warped tile ("tile 1001: 24 frames written (24 baked), 0 replayed, 0 skipped (outputs exist);
// frame 24: rigid stretch removed 84.3% (error 0.041, identity 0.262), 0 inverted triangles, 0 off-chart
// texels in the redirect map") and one per note ("tile 1002: left
// unwarped: no rigidity map 'rig.1002.exr'").
[[nodiscard]] std::vector<std::string> shotSummary(const ShotReport& report);

}  // namespace deformkit::uvwarp
