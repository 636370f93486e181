#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/warp/beier_neely.h"

namespace deformkit::scene {

// Beier and Neely's segment pairs as a file (`deformkit warp --lines`, docs/warps/beier_neely.md):
//   {"a": 1.0, "b": 2.0, "p": 0.5,
//    "lines": [{"src": [[x, y], [x, y]], "dst": [[x, y], [x, y]]}, ...]}
// a, b, p are optional (defaults 1, 2, 0.5) and may be overridden per line; positions are pixels with the
// origin at the top-left corner; src lines are in the source image, dst lines in the warped one.

// The segment pairs of `text`; `source` names it in messages. ParseError for malformed JSON (naming the
// line and column); InvalidInput naming the JSON path of a bad value, e.g. "lines[2].dst[1][0]: is a string
// (expected a number)" or "lines[0].a: is 0 (expected a > 0)".
[[nodiscard]] std::vector<warp::SegmentPair> parseFeatureLines(std::string_view text,
                                                               const std::string& source);
// The same from a file; IoError when it cannot be read.
[[nodiscard]] std::vector<warp::SegmentPair> readFeatureLines(const std::filesystem::path& path);

}  // namespace deformkit::scene
