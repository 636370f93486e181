#include "deformkit/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "deformkit/error.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

fs::path temporaryPathFor(const fs::path& path) {
    static std::atomic<unsigned> counter{0};
    // ".name.tmp-<pid>-<n>.ext": hidden, unique per process and call, extension kept for OpenImageIO.
    const std::string stem = path.stem().string();
    const std::string name = "." + stem + ".tmp-" + std::to_string(::getpid()) + "-" +
                             std::to_string(counter.fetch_add(1)) + path.extension().string();
    return path.parent_path() / name;
}

void flushToDisk(const fs::path& file) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

}  // namespace

void writeAtomically(const fs::path& path, const std::function<void(const fs::path& tmp)>& write) {
    const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) {
        throw IoError(formatError(path.string(), "",
                                  "cannot write: folder '" + folder.string() + "' does not exist",
                                  "an existing, writable folder"));
    }
    if (::access(folder.c_str(), W_OK) != 0) {
        throw IoError(formatError(path.string(), "",
                                  "cannot write: folder '" + folder.string() + "' is not writable",
                                  "a writable folder"));
    }
    if (fs::is_directory(path, ec)) {
        throw IoError(formatError(path.string(), "", "cannot write: the path is a folder", "a file path"));
    }
    const fs::path tmp = temporaryPathFor(path);
    try {
        write(tmp);
        if (!fs::exists(tmp, ec)) {
            throw IoError(formatError(path.string(), "", "the writer produced no file", "a written file"));
        }
        flushToDisk(tmp);
        fs::rename(tmp, path, ec);
        if (ec) {
            throw IoError(formatError(path.string(), "", "cannot replace the file: " + ec.message(),
                                      "a writable destination"));
        }
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
}

void createFolder(const fs::path& path) {
    std::error_code ec;
    fs::create_directories(path, ec);
    if (!fs::is_directory(path)) {
        throw IoError(formatError(path.string(), "",
                                  "cannot be created" + (ec ? ": " + ec.message() : std::string()),
                                  "a writable folder"));
    }
}

void writeFileAtomically(const fs::path& path, std::string_view bytes) {
    writeAtomically(path, [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) {
            throw IoError(formatError(path.string(), "",
                                      std::string("cannot create file: ") + std::strerror(errno),
                                      "a writable folder"));
        }
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        out.flush();
        if (!out) {
            throw IoError(
                formatError(path.string(), "", "write failed (disk full?)", "enough space to write"));
        }
    });
}

}  // namespace deformkit::io
