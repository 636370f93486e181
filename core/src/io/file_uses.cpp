#include "deformkit/io/file_uses.h"

#include "deformkit/error.h"

namespace deformkit::io {

namespace fs = std::filesystem;

std::string pathKey(const fs::path& path) {
    std::error_code error;
    fs::path key = fs::weakly_canonical(path, error);
    if (error) key = fs::absolute(path, error);
    return (error ? path : key).lexically_normal().string();
}

namespace {

// `path` (absolute) with "." parts and trailing separators dropped and each ".." taking its parent: a
// symbolic link followed by ".." is replaced by its target first (up to 40 links deep, as the system gives
// up), no other link is resolved.
fs::path normalPath(const fs::path& path, int depth) {
    fs::path out;
    for (const fs::path& part : path) {
        if (part.empty() || part == ".") continue;
        if (part != "..") {
            out /= part;
            continue;
        }
        std::error_code error;
        if (depth < 40 && fs::is_symlink(out, error)) {
            const fs::path target = fs::read_symlink(out, error);
            if (!error)
                out = normalPath(target.is_absolute() ? target : out.parent_path() / target, depth + 1);
        }
        out = out.parent_path();
    }
    return out;
}

}  // namespace

fs::path absolutePath(const fs::path& path) {
    return normalPath(fs::absolute(path), 0);
}

void FileNames::output(const fs::path& path, const std::string& what) {
    if (const auto [it, added] = outputs_.emplace(pathKey(path), what); !added) {
        throw InvalidInput(formatError(path.string(), "", "is both " + it->second + " and " + what,
                                       "a file of its own for each output"));
    }
}

void FileNames::input(const fs::path& path, const std::string& what) const {
    if (const auto it = outputs_.find(pathKey(path)); it != outputs_.end()) {
        throw InvalidInput(formatError(path.string(), "", "is " + what + ", and " + it->second,
                                       "outputs apart from the job's inputs and the caller's files"));
    }
}

void requireFilesApart(const std::vector<FileUse>& files) {
    FileNames names;
    for (const FileUse& file : files)
        if (file.written) names.output(file.path, file.what);
    for (const FileUse& file : files)
        if (!file.written) names.input(file.path, file.what);
}

}  // namespace deformkit::io
