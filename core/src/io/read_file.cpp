#include "deformkit/io/read_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "deformkit/error.h"

namespace deformkit::io {
namespace fs = std::filesystem;

std::string readFile(const fs::path& path, const std::string& kind) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        const int err = errno;
        throw IoError(formatError(path.string(), "", "cannot open: " + std::system_category().message(err),
                                  "an existing, readable " + kind));
    }
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat info {};
    if (::fstat(fd, &info) != 0 || S_ISDIR(info.st_mode)) {
        throw IoError(
            formatError(path.string(), "", "is a folder or cannot be examined", "a readable " + kind));
    }
    std::string bytes;
    size_t size = 0;
    const auto grow = [&](size_t to) {
        try {
            bytes.resize(to);
        } catch (const std::bad_alloc&) {
            throw OutOfMemory(formatError(path.string(), "",
                                          "cannot be read into memory (" + std::to_string(to) + " bytes)",
                                          "the " + kind + " to fit in this machine's memory"));
        }
    };
    grow(S_ISREG(info.st_mode) ? static_cast<size_t>(info.st_size) + 1 : 65536);
    while (true) {
        if (size == bytes.size()) grow(bytes.size() * 2);
        const ssize_t got = ::read(fd, bytes.data() + size, bytes.size() - size);
        if (got == 0) break;
        if (got < 0) {
            if (errno == EINTR) continue;
            const int err = errno;
            throw IoError(formatError(path.string(), "",
                                      "cannot read: " + std::system_category().message(err),
                                      "a readable " + kind));
        }
        size += static_cast<size_t>(got);
    }
    bytes.resize(size);
    return bytes;
}

}  // namespace deformkit::io
