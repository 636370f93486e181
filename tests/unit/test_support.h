#pragma once

// Helpers shared by the unit tests: a scratch folder that cleans up after itself, file and error helpers,
// bitwise comparison of positions.

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <unistd.h>

namespace deformkit::test {

// A fresh, empty folder under the system temp folder, removed (with its contents) on destruction.
class TempDir {
  public:
    TempDir() {
        static std::atomic<int> counter{0};
        path_ = std::filesystem::temp_directory_path() /
                ("deformkit-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::permissions(path_, std::filesystem::perms::owner_all, ec);
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

  private:
    std::filesystem::path path_;
};

inline void writeText(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

inline std::string readText(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The names of the entries of `dir`, sorted.
inline std::vector<std::filesystem::path> filesIn(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        files.push_back(entry.path().filename());
    std::sort(files.begin(), files.end());
    return files;
}

// The message of the E that `body` throws, or "no error" when it returns. Other exceptions propagate.
template <class E>
std::string errorOf(const std::function<void()>& body) {
    try {
        body();
    } catch (const E& e) {
        return e.what();
    }
    return "no error";
}

// True when `a` and `b` hold the same positions bit for bit (0.0f and -0.0f differ).
inline bool sameBits(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}
inline bool sameBits(std::span<const float> a, std::span<const float> b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// True when the process can bypass file permissions (root): permission tests are skipped then.
inline bool runningAsRoot() {
    return ::geteuid() == 0;
}

}  // namespace deformkit::test

#include <sys/wait.h>

#include <functional>

namespace deformkit::test {

// Runs `body` without the power to bypass file permissions and returns its result: as root it runs in a
// forked child that drops to uid/gid 65534 (nobody), otherwise in-process. Lets permission tests run
// the same way on a developer's machine and in CI (which runs as root). Catch assertions cannot be used
// inside `body`: report failure through the return value.
inline bool runUnprivileged(const std::function<bool()>& body) {
    if (::geteuid() != 0) return body();
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(3);
        ::_exit(body() ? 0 : 1);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace deformkit::test
