#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/warp/beier_neely.h"
#include "deformkit/warp/image_warp.h"

// `deformkit warp IMAGE --lines FILE.json --out OUT [--variant global] [--interp bicubic]`: the Beier-Neely
// image warp (paper §4.2, §5.2) as a CLI command. The lines file (docs/warps/beier_neely.md):
//   {"a": 1.0, "b": 2.0, "p": 0.5,
//    "lines": [{"src": [[x, y], [x, y]], "dst": [[x, y], [x, y]]}, ...]}
// a, b, p are optional (defaults 1, 2, 0.5) and may be overridden per line; positions are pixels with the
// origin at the top-left corner; src lines are in IMAGE, dst lines in OUT.
namespace deformkit::harness {

struct WarpImageCommand {
    std::filesystem::path image;  // source image, any format OpenImageIO reads
    std::filesystem::path lines;  // segment pairs, JSON as above
    std::filesystem::path out;    // written atomically, same size and channels as image
    warp::BeierNeelyVariant variant = warp::BeierNeelyVariant::Original;
    io::SampleFilter interpolation = io::SampleFilter::Bilinear;
};

// Reads IMAGE and the lines file, warps, writes OUT atomically. Throws IoError / ParseError / InvalidInput
// (deformkit::Error) before anything is written.
void warpImageCommand(const WarpImageCommand& command);

// The segment pairs of a lines file. ParseError for malformed JSON (naming the file, line and column);
// InvalidInput naming the JSON path of a bad value, e.g. "lines[2].dst[1][0]: is a string (expected a
// number)" or "lines[0].a: is 0 (expected a > 0)".
[[nodiscard]] std::vector<warp::SegmentPair> readSegmentPairs(const std::filesystem::path& path);
// The same from text; `source` names it in errors.
[[nodiscard]] std::vector<warp::SegmentPair> parseSegmentPairs(std::string_view json,
                                                               const std::string& source);

}  // namespace deformkit::harness
