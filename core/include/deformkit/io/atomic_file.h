#pragma once

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>
#include <string_view>

namespace deformkit::io {

// Writes `path` atomically. `write` is called with a temporary path in the same folder (same file
// extension, so format-by-extension writers work) and must create that file; only when it returns
// normally is the temporary flushed to disk and renamed over `path`. If `write` throws, or the folder is
// not writable, the temporary is removed, an existing file at `path` is left intact, and the error
// propagates (IoError names the folder and what was expected).
void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& tmp)>& write);

// Throws IoError, as writeAtomically would before writing, when `path` cannot be written (its folder missing
// or not writable, a folder or FIFO there, a write-protected file): for a command that writes several files
// to check them all before the first.
void requireWritable(const std::filesystem::path& path);

// Creates folder `path` and its parents when missing. Throws IoError naming it (and the system's reason)
// when it cannot be created or exists as something else.
void createFolder(const std::filesystem::path& path);

// Throws InvalidInput naming `path` when its extension (compared without case) is none of `extensions`
// (".obj"): a writer refuses to put one format behind another's name. `format` names it ("an OBJ mesh").
void requireExtension(const std::filesystem::path& path, std::initializer_list<std::string_view> extensions,
                      std::string_view format);

// A token no other call in any process uses ("<pid>-<random>-<n>"), for temporary names beside outputs
// that several processes, on one host or several, may write at once.
[[nodiscard]] std::string uniqueToken();

// Writes `bytes` to `path` atomically.
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace deformkit::io
