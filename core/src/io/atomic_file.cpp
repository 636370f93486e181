#include "deformkit/io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

#include "deformkit/error.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

fs::path temporaryPathFor(const fs::path& path) {
    // ".name.tmp-<token>.ext": hidden, extension kept for OpenImageIO.
    return path.parent_path() /
           ("." + path.stem().string() + ".tmp-" + uniqueToken() + path.extension().string());
}

// Flushes `file` to the storage before it is renamed into place: shared storage (NFS) often reports a full
// disk or a quota only here, and a file it did not keep must not take the output's name. `path` names it.
void flushToDisk(const fs::path& file, const fs::path& path) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;  // written by another handle just now; nothing of ours to flush
    const int synced = ::fsync(fd);
    const int syncError = errno;
    const int closed = ::close(fd);
    const int closeError = errno;
    // EINVAL: a file system without fsync (a pipe-like special file); nothing was lost.
    if ((synced != 0 && syncError != EINVAL) || closed != 0) {
        throw StorageError(formatError(path.string(), "",
                                       std::string("the storage did not keep the written file: ") +
                                           std::strerror(synced != 0 ? syncError : closeError),
                                       "enough space to write"));
    }
}

// What a path is, for messages: "a folder", "a FIFO", ... (not a regular file).
const char* kindOf(fs::file_type type) {
    switch (type) {
        case fs::file_type::directory:
            return "a folder";
        case fs::file_type::fifo:
            return "a FIFO (named pipe)";
        case fs::file_type::character:
            return "a character device";
        case fs::file_type::block:
            return "a block device";
        case fs::file_type::socket:
            return "a socket";
        default:
            return "not a regular file";
    }
}

// The file a write to `path` must replace: `path` itself, or, through symbolic links, the file they lead
// to (the links stay links). Throws IoError naming `path` for a loop of links.
fs::path writeTarget(const fs::path& path) {
    fs::path target = path;
    std::error_code ec;
    for (int hops = 0; fs::is_symlink(fs::symlink_status(target, ec)); ++hops) {
        if (hops == 40) {
            throw IoError(formatError(path.string(), "", "cannot write: its symbolic links loop",
                                      "a link that leads to a file"));
        }
        const fs::path next = fs::read_symlink(target, ec);
        if (ec) break;
        target = next.is_absolute() ? next : target.parent_path() / next;
    }
    return target;
}

// The nearest existing ancestor of `folder` when it is not a folder (a regular file in the way), else empty.
fs::path fileInTheWay(const fs::path& folder) {
    std::error_code ec;
    for (fs::path p = folder; !p.empty(); p = p.parent_path()) {
        const fs::file_status status = fs::status(p, ec);
        if (fs::exists(status)) return fs::is_directory(status) ? fs::path() : p;
        if (p == p.parent_path()) break;
    }
    return {};
}

}  // namespace

std::string uniqueToken() {
    // The process id alone repeats across hosts and containers that share a folder (two farm runs of one
    // task): a random number drawn once per process tells them apart, the counter tells calls apart.
    static const std::string process = [] {
        std::random_device device;
        const uint64_t bits = (static_cast<uint64_t>(device()) << 32) ^ device();
        char hex[17];
        std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(bits));
        return std::to_string(::getpid()) + "-" + hex;
    }();
    static std::atomic<unsigned> counter{0};
    return process + "-" + std::to_string(counter.fetch_add(1));
}

namespace {

// What writeAtomically checks before writing: the file it writes (a link's target), and whether it replaces
// one (with its mode in `before`).
struct WriteCheck {
    fs::path path;
    bool replacing = false;
    struct stat before {};
};

WriteCheck checkWritable(const fs::path& requested) {
    // Through a symbolic link the link's target is written (atomically, in the target's folder) and the link
    // stays; a FIFO, a device, a socket or a folder at the path is refused, never replaced.
    WriteCheck check;
    check.path = writeTarget(requested);
    const fs::path& path = check.path;
    const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code ec;
    const fs::file_status existing = fs::status(path, ec);
    if (fs::exists(existing) && !fs::is_regular_file(existing)) {
        throw IoError(
            formatError(requested.string(), "",
                        std::string("cannot write: ") +
                            (path == requested ? "the path" : "its link's target '" + path.string() + "'") +
                            " is " + kindOf(existing.type()),
                        "a regular file or a new path"));
    }
    if (!fs::is_directory(folder, ec)) {
        const fs::path blocker = fileInTheWay(folder);
        if (!blocker.empty()) {
            throw IoError(formatError(requested.string(), "",
                                      "cannot write: '" + blocker.string() + "' is a file, not a folder",
                                      "a path whose folders are folders"));
        }
        throw IoError(formatError(requested.string(), "",
                                  "cannot write: folder '" + folder.string() + "' does not exist",
                                  "an existing, writable folder"));
    }
    if (::access(folder.c_str(), W_OK) != 0) {
        throw IoError(formatError(requested.string(), "",
                                  "cannot write: folder '" + folder.string() + "' is not writable",
                                  "a writable folder"));
    }
    // An existing file is replaced only where it could be written in place: a write-protected one (a
    // published map) is refused, as a shell's redirection refuses it, and the one replaced keeps its
    // permissions (a group-writable file stays group-writable).
    check.replacing = fs::is_regular_file(existing) && ::stat(path.c_str(), &check.before) == 0;
    if (check.replacing && ::access(path.c_str(), W_OK) != 0) {
        throw IoError(
            formatError(requested.string(), "",
                        std::string("cannot write: ") +
                            (path == requested ? "the file" : "its link's target '" + path.string() + "'") +
                            " is write-protected (" + std::strerror(errno) + ")",
                        "a file this user may write, or a new path"));
    }
    return check;
}

}  // namespace

void requireWritable(const fs::path& path) {
    (void)checkWritable(path);
}

void writeAtomically(const fs::path& requested, const std::function<void(const fs::path& tmp)>& write) {
    const WriteCheck check = checkWritable(requested);
    const fs::path& path = check.path;
    const bool replacing = check.replacing;
    const struct stat& before = check.before;
    std::error_code ec;
    const fs::path tmp = temporaryPathFor(path);
    try {
        write(tmp);
        if (!fs::exists(tmp, ec)) {
            throw IoError(formatError(path.string(), "", "the writer produced no file", "a written file"));
        }
        if (replacing) ::chmod(tmp.c_str(), before.st_mode & 0777);
        flushToDisk(tmp, path);
        fs::rename(tmp, path, ec);
        if (ec) {
            // EIO: the storage failed (a retry may do); anything else is the destination's fault.
            const std::string problem = "cannot replace the file: " + ec.message();
            if (ec == std::errc::io_error)
                throw StorageError(formatError(path.string(), "", problem, "working storage"));
            throw IoError(formatError(path.string(), "", problem, "a writable destination"));
        }
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
}

void createFolder(const fs::path& path) {
    std::error_code ec;  // the reason creating failed (permission denied, a read-only file system)
    fs::create_directories(path, ec);
    std::error_code statusError;
    if (!fs::is_directory(fs::status(path, statusError))) {
        const fs::path blocker = fileInTheWay(path);
        if (!blocker.empty()) {
            throw IoError(formatError(path.string(), "",
                                      "cannot be created: '" + blocker.string() + "' is a file, not a folder",
                                      "a path whose folders are folders"));
        }
        throw IoError(formatError(path.string(), "",
                                  "cannot be created" + (ec ? ": " + ec.message() : std::string()),
                                  "a writable folder"));
    }
}

void requireExtension(const fs::path& path, std::initializer_list<std::string_view> extensions,
                      std::string_view format) {
    std::string extension = path.extension().string();
    for (char& c : extension)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    std::string expected;
    for (std::string_view e : extensions) {
        if (extension == e) return;
        expected += (expected.empty() ? "" : " or ") + std::string(e);
    }
    throw InvalidInput(formatError(
        path.string(), "",
        extension.empty() ? "has no extension" : "has the extension '" + path.extension().string() + "'",
        "a file name ending in " + expected + " for " + std::string(format)));
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
            throw StorageError(
                formatError(path.string(), "", "write failed (disk full?)", "enough space to write"));
        }
    });
}

}  // namespace deformkit::io
