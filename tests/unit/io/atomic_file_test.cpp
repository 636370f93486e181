#include <catch2/catch.hpp>

#include <sys/stat.h>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "test_support.h"

using namespace deformkit;
namespace fs = std::filesystem;

namespace {

size_t countEntries(const fs::path& dir) {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
        ++n;
    return n;
}

}  // namespace

TEST_CASE("atomic write replaces the file and leaves no temporary", "[io][atomic]") {
    test::TempDir dir;
    const fs::path file = dir / "out.txt";
    io::writeFileAtomically(file, "first");
    io::writeFileAtomically(file, "second version");
    CHECK(test::readText(file) == "second version");
    CHECK(countEntries(dir.path()) == 1);
}

TEST_CASE("a failing writer leaves the existing file intact and no temporary", "[io][atomic][errors]") {
    test::TempDir dir;
    const fs::path file = dir / "map.exr";
    test::writeText(file, "precious");
    fs::path seenTmp;
    CHECK_THROWS_WITH(io::writeAtomically(file,
                                          [&](const fs::path& tmp) {
                                              seenTmp = tmp;
                                              test::writeText(tmp, "half-writ");
                                              throw InvalidInput("writer gave up");
                                          }),
                      "writer gave up");
    CHECK(seenTmp.parent_path() == dir.path());
    CHECK(seenTmp.extension() == ".exr");  // format-by-extension writers still work
    CHECK(test::readText(file) == "precious");
    CHECK(countEntries(dir.path()) == 1);
    CHECK_THROWS_WITH(io::writeAtomically(file, [](const fs::path&) {}), Catch::Contains("produced no file"));
    CHECK(test::readText(file) == "precious");
}

TEST_CASE("an unwritable or missing folder is an IoError naming it; the existing file stays",
          "[io][atomic][errors]") {
    test::TempDir dir;
    const fs::path locked = dir / "locked";
    fs::create_directories(locked);
    test::writeText(locked / "out.txt", "precious");
    ::chmod(dir.path().c_str(), 0755);
    ::chmod(locked.c_str(), 0555);
    const bool ok = test::runUnprivileged([&] {
        try {
            io::writeFileAtomically(locked / "out.txt", "clobbered");
            return false;
        } catch (const IoError& e) {
            const std::string msg = e.what();
            return msg.find("not writable") != std::string::npos && msg.find("locked") != std::string::npos;
        }
    });
    CHECK(ok);
    CHECK(test::readText(locked / "out.txt") == "precious");
    CHECK(countEntries(locked) == 1);
    ::chmod(locked.c_str(), 0755);

    CHECK_THROWS_AS(io::writeFileAtomically(dir / "missing" / "out.txt", "x"), IoError);
    CHECK_THROWS_WITH(io::writeFileAtomically(dir / "missing" / "out.txt", "x"),
                      Catch::Contains("does not exist"));
    CHECK_THROWS_WITH(io::writeFileAtomically(locked, "x"), Catch::Contains("is a folder"));
}

TEST_CASE("createFolder makes missing parents and names a path it cannot make", "[io][atomic][errors]") {
    test::TempDir dir;
    io::createFolder(dir / "a/b/c");
    CHECK(fs::is_directory(dir / "a/b/c"));
    io::createFolder(dir / "a/b/c");  // already there: nothing to do
    test::writeText(dir / "file", "x");
    const std::string message = test::errorOf<IoError>([&] { io::createFolder(dir / "file" / "sub"); });
    CHECK_THAT(message, Catch::Contains((dir / "file" / "sub").string()) &&
                            Catch::Contains("cannot be created") && Catch::Contains("a writable folder"));
    CHECK_THAT(test::errorOf<IoError>([&] { io::createFolder(dir / "file"); }),
               Catch::Contains("cannot be created"));
}
