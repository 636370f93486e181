#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

// `deformkit eval SCENE [--frames A-B] [--out DIR]`: evaluates a DeformKit scene (docs/scene.md) frame by
// frame, as a DCC plays it back, and writes every object's deformed mesh per frame:
//
//   DIR/<object>.<frame>.obj   frame zero padded to 4 digits (-0001 for frame -1), rest UVs and groups kept
//
// Every file is written atomically; DIR is created when missing. Frames are evaluated in ascending order
// through one host::SceneEvaluator, so each deformer binds once and animated parameters only change its
// controls.
namespace deformkit::harness {

struct EvalCommand {
    std::filesystem::path scene;
    // Frames to evaluate, ascending (parseFrames("1-24")); empty: the scene's "frames" range.
    std::vector<int> frames;
    std::filesystem::path outDir = "eval-out";
};

struct EvalReport {
    std::vector<int> frames;                   // evaluated, ascending
    std::vector<std::filesystem::path> files;  // written, frame by frame, objects in scene order
    std::vector<int64_t> binds;                // per object: binds done by its stack over the run
};

// Runs the command; writes one progress line per frame to `progress` when not null. Throws Error: bad
// scene input is InvalidInput (ParseError for text that is not JSON) naming the scene file and JSON path.
EvalReport evalCommand(const EvalCommand& command, std::ostream* progress = nullptr);

// "<object>.<frame>.obj" with the frame zero padded to 4 digits, a sign before the padding.
[[nodiscard]] std::string evalFileName(const std::string& object, int frame);

}  // namespace deformkit::harness
