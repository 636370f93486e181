#pragma once

#include <filesystem>
#include <string>

namespace deformkit::io {

// The whole content of `path` (a regular file, a pipe or a device read to its end). Throws IoError naming
// the file when it cannot be opened or read or is a folder; `kind` says what it should be in the message
// ("OBJ file": "... (expected an existing, readable OBJ file)").
[[nodiscard]] std::string readFile(const std::filesystem::path& path, const std::string& kind);

}  // namespace deformkit::io
