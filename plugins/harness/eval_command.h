#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

// `deformkit eval SCENE [--frames A-B] [--out DIR]`: evaluates a DeformKit scene (docs/scene.md) frame by
// frame, as a DCC plays it back, and writes every object's deformed mesh per frame, with previews:
//
//   DIR/<object>.<frame>.obj   frame zero padded to 4 digits (-0001 for frame -1), rest UVs and groups kept
//   DIR/<object>.pc2 / .mdd    with `cache`: one point cache per object holding every evaluated frame
//                              (io/point_cache.h), beside the OBJs or, without `objs`, instead of them
//   DIR/<object>.<frame>.png   shaded preview (io::renderPreview), one camera per object: the default view
//                              framing the object's rest bounding box, so previews of a shot do not jump
//   DIR/<object>.contact.png   the object's previews tiled in frame order, each downscaled
//                              (contactSheetLayout)
//   DIR/<object>.mp4           with `movie`, when ffmpeg is on PATH: the previews at `movieFrameRate`
//   DIR/<object>.redirect.<tile>.<frame>.exr, DIR/<object>.bake.<tile>.<frame>.<ext>
//                              the UV-warp stage of an object that has one (scene/uvwarp_stage.h): every
//                              tile's frames solved in order, warm-started
//   DIR/uvwarp.jsonl, REPORT   with `report`: the stages' log and the shot's HTML page
//
// Every file is written atomically; DIR is created when missing. Frames are evaluated in ascending order
// through one scene::SceneEvaluator, so each deformer binds once and animated parameters only change its
// controls; each object is evaluated once per frame, and that mesh feeds its OBJ, its preview and every
// tile of its UV-warp stage.
namespace deformkit::harness {

struct EvalCommand {
    std::filesystem::path scene;
    // Frames to evaluate, ascending (parseFrames("1-24")); empty: the scene's "frames" range.
    std::vector<int> frames;
    std::filesystem::path outDir = "eval-out";

    // "pc2" or "mdd": also write each object's frames as one point cache, its first sample the first frame
    // (the frames must be consecutive: a cache holds one frame per sample). Empty: no cache.
    std::string cache;
    bool objs = true;                // write the per-frame OBJs (false needs `cache`)
    bool previews = true;            // write the PNG previews and contact sheets
    int32_t previewWidth = 480;      // pixels, 1 to 16384
    int32_t previewHeight = 360;     // pixels, 1 to 16384
    int32_t contactColumns = 6;      // at most this many tiles per contact sheet row, >= 1
    int32_t contactMaxWidth = 2048;  // contact sheet width limit in pixels (tiles shrink by a whole factor)
    // Encode DIR/<object>.mp4 from the previews with ffmpeg (its default MP4 codec, yuv420p); needs
    // `previews`. When no ffmpeg is on PATH the movies are skipped and EvalReport::notes says so.
    bool movie = false;
    int32_t movieFrameRate = 24;  // frames per second, >= 1: the movies', and an MDD cache's times
    // With UV-warp stages: their log as DIR/uvwarp.jsonl and an HTML page of the shot here
    // (uvwarp/html_report.h); relative to the working folder. Without a stage, a note.
    std::optional<std::filesystem::path> report;
};

struct EvalReport {
    std::vector<int> frames;  // evaluated, ascending
    // Written: per frame, per object in scene order, the OBJ then the preview; then per object with a UV
    // warp its maps, tile by tile, frame by frame; then per object its point cache, its contact sheet, then
    // per object its movie (OBJs, caches, previews, sheets and movies only when made).
    std::vector<std::filesystem::path> files;
    std::vector<int64_t> binds;        // per object: binds done by its stack over the run
    std::vector<int64_t> evaluations;  // per object: stack evaluations over the run (one per frame)
    std::vector<std::string> notes;    // things not done that are not errors (no ffmpeg on PATH)
    // Per object with a UV-warp stage, uvwarp::shotSummary's lines prefixed with the object's name.
    std::vector<std::string> uvwarpLines;
};

// Runs the command; writes one progress line per frame to `progress` when not null. Throws Error: bad
// scene input is InvalidInput (ParseError for text that is not JSON) naming the scene file and JSON path;
// bad preview or contact sheet sizes are InvalidInput, checked before anything is written; a failing
// ffmpeg is IoError naming the command.
EvalReport evalCommand(const EvalCommand& command, std::ostream* progress = nullptr);

// Contact sheet grid for `tiles` previews of previewWidth x previewHeight pixels:
//   columns = min(tiles, maxColumns), rows = ceil(tiles / columns);
//   factor  = max(1, ceil(columns * previewWidth / maxWidth)), the smallest whole shrink factor that keeps
//             the sheet at most maxWidth wide;
//   tile    = floor(previewWidth / factor) x floor(previewHeight / factor) (a preview's last columns and
//             rows that do not fill a whole block are dropped); sheet = columns * tile by rows * tile.
// A tile pixel is the box filter of its factor x factor block of the preview's 8-bit values, rounded half
// up: (sum + factor^2 / 2) / factor^2 in integers. Tiles touch, in frame order row by row; cells after the
// last tile have the preview background colour.
struct ContactSheetLayout {
    int32_t columns = 0;
    int32_t rows = 0;
    int32_t factor = 1;
    int32_t tileWidth = 0;
    int32_t tileHeight = 0;
};

// Throws InvalidInput when no whole factor fits (maxWidth < columns, or a tile would be empty).
[[nodiscard]] ContactSheetLayout contactSheetLayout(int32_t tiles, int32_t previewWidth,
                                                    int32_t previewHeight, int32_t maxColumns,
                                                    int32_t maxWidth);

}  // namespace deformkit::harness
