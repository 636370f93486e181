#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/sampling.h"
#include "deformkit/uvwarp/tile_warp.h"

// `deformkit uvwarp`: the content-aware UV warp (Koniaris et al.) over a shot, for every UDIM tile:
//
//   deformkit uvwarp --rest rest.obj --deformed 'anim.####.obj' --frames 1-24 --rigidity 'rig.<UDIM>.exr'
//       [--mask 'mask.<UDIM>.exr'] [--texture 'col.<UDIM>.exr' --bake 'out/col.<UDIM>.####.exr']
//       --out 'out/redirect.<UDIM>.####.exr' [--tiles 1001,1002] [--resolution N] [--log log.jsonl]
//
// Frame tokens: #### (one # per digit, zero padded) or %04d (io::ObjSequence); UDIM tokens: <UDIM>,
// <UVTILE>, %(UDIM)d, _MAPID_ (io/udim.h). Output folders must exist.
//
// Per tile, one TileWarp is bound (rest mesh, rigidity map, mask map or a mask derived from the UVs) and
// the frames are solved in ascending order, each warm-started from the previous one. Per frame the
// redirect map W^-1 is written as a 2-channel float EXR (the rigidity map's size) whose header records
// the library version, tile, frame, solver parameters and inputs (deformkit:version,
// deformkit:uvwarp:tile, deformkit:uvwarp:frame, deformkit:uvwarp:solver, deformkit:uvwarp:inputs, the
// last two JSON); with --bake the tile's texture baked through it is written too. Every file is written
// atomically.
//
// Resuming: an output that already exists is not written again. So that a resumed run writes the same
// bytes an uninterrupted one would have, the warm start is replayed: every frame up to the tile's last
// missing output is solved in order, frames whose outputs exist only to carry the warm start ("replayed"),
// and frames after the last missing output are not solved ("skipped"). A tile whose outputs all exist is
// not bound. Frames of another run are not part of the warm start: a run starts cold at its first frame.
//
// Inputs are checked before anything is written: the rest mesh has UVs, every frame file exists, the
// output folders exist, and per tile the maps' sizes (square, equal, a power of two when the grid takes the
// map's size). A tile without a rigidity map is left unwarped (no outputs) and reported, unless no tile
// has one (an error). A missing mask tile is derived from the UVs, a missing orientation tile means 1
// everywhere, a missing texture tile is not baked; each is reported. Reading a frame whose vertex count
// differs from the rest mesh's is an error naming the file; outputs of earlier frames stay complete.
namespace deformkit::harness {

struct UvWarpCommand {
    std::filesystem::path rest;                 // OBJ with UVs (UDIM tiles 1001 + floor(u) + 10 floor(v))
    std::filesystem::path deformed;             // frame pattern of OBJs with the rest mesh's vertex count
    std::vector<int> frames;                    // ascending, e.g. parseFrames("1-24")
    std::filesystem::path rigidity;             // UDIM pattern; channel 0 in [0, 1]
    std::optional<std::filesystem::path> mask;  // UDIM pattern; channel 0 >= 0.5 may warp
    std::optional<std::filesystem::path> orientation;  // UDIM pattern; channel 0 in [0, 1] scales the
                                                       // orientation preservation per texel
    std::optional<std::filesystem::path> texture;      // UDIM pattern, baked when `bake` is set
    std::filesystem::path out;                         // UDIM + frame pattern, .exr
    std::optional<std::filesystem::path> bake;         // UDIM + frame pattern, any writable format
    std::vector<int> tiles;                            // empty: every tile the rest mesh's UVs touch
    int32_t resolution = 0;                            // grid cells per side, a power of two; 0: map size
    uvwarp::TileWarpOptions options;                   // solver, derived mask, dilation (cells: resolution)
    io::SampleFilter filter = io::SampleFilter::Bilinear;  // bake filter
    std::optional<std::filesystem::path> log;              // JSON lines, appended: one per tile x frame
};

struct UvWarpTileReport {
    int tile = 0;
    bool warped = true;                        // false: no rigidity map, no outputs
    std::vector<std::string> notes;            // why unwarped, a derived mask, a texture not baked
    int32_t written = 0;                       // frames whose redirect or bake was written
    int32_t baked = 0;                         // bakes written
    int32_t replayed = 0;                      // outputs existed; solved to carry the warm start
    int32_t skipped = 0;                       // outputs existed; not solved
    int lastFrame = 0;                         // the last frame solved (replayed or written)
    uvwarp::WarpMetrics lastMetrics;           // of lastFrame
    std::vector<std::filesystem::path> files;  // written, in order
};

struct UvWarpReport {
    std::vector<UvWarpTileReport> tiles;
};

// Runs the command. `progress`: where to draw a progress bar (frames x tiles, with an ETA), normally
// std::cerr when it is a terminal; nullptr draws nothing. Throws IoError / ParseError / InvalidInput
// (deformkit::Error) on bad input.
UvWarpReport uvwarpCommand(const UvWarpCommand& command, std::ostream* progress = nullptr);

// The engine under `deformkit uvwarp` and under the UV-warp stage of scenes (deformkit eval, farm tasks):
// per tile one TileWarp, the frames solved in ascending order with warm start, a redirect EXR (and a bake)
// written per tile and frame, atomically, resuming as uvwarpCommand describes when skipExisting is set.
// Tiles run one after the other, so memory is bounded by one tile's solver. The deformed positions come
// from `deformed`, asked once per solved frame and tile.
struct UvWarpJob {
    const geom::Mesh* rest = nullptr;  // with UVs; must outlive the run
    std::string restName;              // names the rest mesh in messages and EXR headers
    std::vector<int> frames;           // ascending, at least one
    std::vector<int> tiles;            // tiles of the rest mesh's UVs, ascending
    std::filesystem::path rigidity;    // UDIM pattern
    std::optional<std::filesystem::path> mask, orientation, texture;  // UDIM patterns
    // How messages name the rigidity pattern ("--rigidity", or a scene's JSON path).
    std::string rigidityOption = "--rigidity";
    // Output files of a tile and frame; bakePath only with a texture. Their folders must exist.
    std::function<std::filesystem::path(int tile, int frame)> outPath, bakePath;
    uvwarp::TileWarpOptions options;  // cells: grid resolution (0: the rigidity map's size)
    io::SampleFilter filter = io::SampleFilter::Bilinear;
    // Existing outputs are kept and the warm start replayed (a resumed run writes an uninterrupted run's
    // bytes); false writes every output again.
    bool skipExisting = true;
    // The deformed positions of the rest mesh's vertices at `frame`; sets `name` to what the EXR header
    // records as the frame's input ("anim.0007.obj"). The span must stay valid until the next call.
    std::function<std::span<const glm::vec3>(int frame, std::string& name)> deformed;
    std::ostream* log = nullptr;  // JSON lines, one per tile x frame
    int logTask = -1;             // >= 0: every log line carries "task": logTask
    std::string logObject;        // not empty: every log line carries "object": logObject
};

// Runs the job. Throws as uvwarpCommand (maps checked per tile before anything is written).
UvWarpReport runUvWarpJob(const UvWarpJob& job, std::ostream* progress = nullptr);

// The lines the CLI prints: one per warped tile ("tile 1001: 24 frames written (24 baked), 0 replayed, 0
// skipped (outputs exist); frame 24: rigid stretch error 0.041 (identity 0.262), 0 fold-overs") and one per
// note ("tile 1002: left unwarped: no rigidity map 'rig.1002.exr'").
[[nodiscard]] std::vector<std::string> uvwarpSummary(const UvWarpReport& report);

// "1-24", "7", "1-10,15,20-22", "-5-5" (negative frames allowed): sorted, without repeats. InvalidInput
// naming `option` for anything else, a range whose end is before its start, or more than 1,000,000 frames.
[[nodiscard]] std::vector<int> parseFrames(std::string_view text, const std::string& option = "--frames");

// "1001,1002": UDIM tile numbers (1001..9999), sorted, without repeats. InvalidInput naming `option`.
[[nodiscard]] std::vector<int> parseTiles(std::string_view text, const std::string& option = "--tiles");

// The file of `tile` and `frame` for a pattern with a UDIM token and a frame token in its file name.
[[nodiscard]] std::filesystem::path tileFramePath(const std::filesystem::path& pattern, int tile, int frame);

}  // namespace deformkit::harness
