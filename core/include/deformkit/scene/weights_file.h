#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace deformkit::scene {

// Painted weights as a file (a scene's "weights", `deformkit slide --weights`, `deformkit preview --weights`,
// `deformkit ptex to-vertex`): JSON, an array of one number per vertex, or {"weights": [...]}.

// The weights of `text`, `count` of them; `source` names the file in messages. ParseError for text that is
// not JSON (naming line and column); InvalidInput for another shape, another count or a value that is not a
// finite number within float range (naming its index, "[12]").
[[nodiscard]] std::vector<float> parseWeightsFile(std::string_view text, size_t count,
                                                  const std::string& source);
// The same from a file; IoError when it cannot be read.
[[nodiscard]] std::vector<float> readWeightsFile(const std::filesystem::path& path, size_t count);
// The file's text: an array of the weights, each the shortest decimal that reads back as the float.
// InvalidInput naming `source` and the index for a NaN or infinite weight (JSON has no such number).
[[nodiscard]] std::string formatWeightsFile(std::span<const float> weights,
                                            const std::string& source = "weights file");

}  // namespace deformkit::scene
