#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/interrupter.h"
#include "deformkit/io/sampling.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/tile_warp.h"

// `deformkit uvwarp`: the content-aware UV warp (Koniaris et al.) over a shot, for every UDIM tile, through
// the library's shot job (uvwarp/shot_job.h: warm start, resume by replay, provenance, atomic writes, bakes):
//
//   deformkit uvwarp --rest rest.obj --deformed 'anim.####.obj' --frames 1-24 --rigidity 'rig.<UDIM>.exr'
//       [--mask 'mask.<UDIM>.exr'] [--texture 'col.<UDIM>.exr' --bake 'out/col.<UDIM>.####.exr']
//       --out 'out/redirect.<UDIM>.####.exr' [--tiles 1001,1002] [--resolution N] [--log log.jsonl]
//       [--report report.html]
//       [every UV-warp option of uvwarp/options.h as --kebab-case: --iterations 4 --sweeps-per-level 4,8,8]
//
// Frame tokens: #### (one # per digit, zero padded) or %04d (io::ObjSequence); UDIM tokens: <UDIM>,
// <UVTILE>, %(UDIM)d, _MAPID_ (io/udim.h). Output folders must exist. Besides the shot job's own checks,
// the command checks before anything is written that the patterns have their tokens, the rest mesh has UVs
// and every frame is there (a file of the sequence, a sample of the cache). Reading a frame whose vertex
// count differs from the rest mesh's is an error naming the file; outputs of earlier frames stay complete.
namespace deformkit::harness {

struct UvWarpCommand {
    std::filesystem::path rest;  // OBJ with UVs (UDIM tiles 1001 + floor(u) + 10 floor(v))
    // The deformed frames: an OBJ sequence ('anim.####.obj') or a point cache ('anim.pc2', 'anim.mdd') with
    // the rest mesh's vertex count (io::AnimatedPositions).
    std::filesystem::path deformed;
    std::optional<double> cacheStart;           // the frame of a point cache's first sample (io::PointCache)
    std::vector<int> frames;                    // ascending, e.g. parseFrames("1-24")
    std::filesystem::path rigidity;             // UDIM pattern; channel 0 in [0, 1]
    std::optional<std::filesystem::path> mask;  // UDIM pattern; channel 0 >= 0.5 may warp
    std::optional<std::filesystem::path> orientation;  // UDIM pattern; channel 0 in [0, 1] scales the
                                                       // orientation preservation per texel
    std::optional<std::filesystem::path> texture;      // UDIM pattern, baked when `bake` is set
    std::filesystem::path out;                         // UDIM + frame pattern, .exr
    std::optional<std::filesystem::path> bake;         // UDIM + frame pattern, any writable format
    std::vector<int> tiles;                            // empty: every tile the rest mesh's UVs touch
    // The grid (cells: --resolution), solver, derived mask and dilation: every option of uvwarp/options.h.
    uvwarp::TileWarpOptions options = uvwarp::shotOptions();
    // --preset: the library's preset instead of `options`, but for the options named in presetOwn (given on
    // the command line), which keep their values from `options`.
    std::optional<uvwarp::Preset> preset;
    std::vector<std::string> presetOwn;
    io::SampleFilter filter = io::SampleFilter::Bilinear;  // bake filter
    std::optional<std::filesystem::path> log;              // JSON lines, appended: one per tile x frame
    // An HTML page of the shot (uvwarp/html_report.h) written at the end: from the log file when there is
    // one (every run it holds, merged), else from this run's lines.
    std::optional<std::filesystem::path> report;
};

// Runs the command. `interrupter`: progress (a progress bar on a terminal) and cancellation; may be null.
// Throws IoError / ParseError / InvalidInput (deformkit::Error) on bad input.
uvwarp::ShotReport uvwarpCommand(const UvWarpCommand& command, Interrupter* interrupter = nullptr);

// "1-24", "7", "1-10,15,20-22", "-5-5" (negative frames allowed): sorted, without repeats. InvalidInput
// naming `option` for anything else, a range whose end is before its start, or more than 1,000,000 frames.
[[nodiscard]] std::vector<int> parseFrames(std::string_view text, const std::string& option = "--frames");

// The values of a list option ("1 1 10" as three values, "1,1,10" as one, or both), each item a number;
// InvalidInput naming `option` for an empty item ("4,,8") or one that is not a number.
[[nodiscard]] std::vector<double> parseNumberList(const std::vector<std::string>& values,
                                                  const std::string& option);

// "1001,1002": UDIM tile numbers (1001..9999), sorted, without repeats. InvalidInput naming `option`.
[[nodiscard]] std::vector<int> parseTiles(std::string_view text, const std::string& option = "--tiles");

}  // namespace deformkit::harness
