#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace deformkit::io {

// A file a command or job writes or reads, with what it is there ("the output (--out)", "the rest mesh").
struct FileUse {
    std::filesystem::path path;
    std::string what;
    bool written = false;  // an output; else an input
};

// A path as outputs and inputs are compared: absolute, with the symbolic links of its existing part resolved
// (a folder reached through a link is the same folder), lexically normal.
[[nodiscard]] std::string pathKey(const std::filesystem::path& path);

// A path made absolute as a command names a file it keeps (a scene, a plan's folders): "." parts and
// trailing separators dropped, each ".." taking its parent, where the part before it is a symbolic link
// the parent of the link's target (as the system opens it). No other link is resolved: "link/.." dropped
// as text would name another file than the system opens, and resolving every link would write a
// machine's mount points into a plan other machines read.
[[nodiscard]] std::filesystem::path absolutePath(const std::filesystem::path& path);

// Names written and read, checked as they are added: no two outputs alike, no output the name of an input.
// Otherwise an output is written over another one or over an input (and a resumed job takes the damaged
// file for a finished output). Add every output before the inputs; each refusal is InvalidInput naming the
// file and both uses.
class FileNames {
  public:
    void output(const std::filesystem::path& path, const std::string& what);
    void input(const std::filesystem::path& path, const std::string& what) const;

  private:
    std::map<std::string, std::string> outputs_;  // path key -> what is written there
};

// Every file of `files` checked with FileNames, the outputs first.
void requireFilesApart(const std::vector<FileUse>& files);

}  // namespace deformkit::io
