#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <regex>
#include <string>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/file_uses.h"
#include "deformkit/io/obj.h"
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

TEST_CASE("a replaced file keeps its permissions; a write-protected one is refused and stays",
          "[io][atomic][errors]") {
    test::TempDir dir;
    const auto mode = [](const fs::path& file) {
        struct stat st {};
        ::stat(file.c_str(), &st);
        return st.st_mode & 0777;
    };
    for (const mode_t kept : {mode_t{0664}, mode_t{0600}, mode_t{0640}}) {
        const fs::path file = dir / "shared.txt";
        test::writeText(file, "old");
        ::chmod(file.c_str(), kept);
        io::writeFileAtomically(file, "new");
        CHECK(test::readText(file) == "new");
        CHECK(mode(file) == kept);
        fs::remove(file);
    }
    // A published file (0444) in a folder anyone may write: refused for a user who may not write it, as a
    // shell's `>` refuses it, and left as it was.
    ::chmod(dir.path().c_str(), 0777);
    const fs::path published = dir / "published.txt";
    test::writeText(published, "precious");
    ::chmod(published.c_str(), 0444);
    const bool refused = test::runUnprivileged([&] {
        try {
            io::writeFileAtomically(published, "clobbered");
            return false;
        } catch (const IoError& e) {
            const std::string msg = e.what();
            return msg.find("published.txt: cannot write: the file is write-protected") !=
                       std::string::npos &&
                   msg.find("(expected a file this user may write, or a new path)") != std::string::npos;
        }
    });
    CHECK(refused);
    CHECK(test::readText(published) == "precious");
    CHECK(mode(published) == 0444);
    CHECK(countEntries(dir.path()) == 1);
    ::chmod(dir.path().c_str(), 0755);
}

TEST_CASE("createFolder makes missing parents and names a path it cannot make", "[io][atomic][errors]") {
    test::TempDir dir;
    io::createFolder(dir / "a/b/c");
    CHECK(fs::is_directory(dir / "a/b/c"));
    io::createFolder(dir / "a/b/c");  // already there: nothing to do
    test::writeText(dir / "file", "x");
    const std::string message = test::errorOf<IoError>([&] { io::createFolder(dir / "file" / "sub"); });
    CHECK_THAT(message, Catch::Contains((dir / "file" / "sub").string()) &&
                            Catch::Contains("cannot be created") &&
                            Catch::Contains("file' is a file, not a folder"));
    CHECK_THAT(test::errorOf<IoError>([&] { io::createFolder(dir / "file"); }),
               Catch::Contains("cannot be created") && Catch::Contains("is a file, not a folder"));

    // A folder it may not write in: the system's reason, not that of the status check after it.
    fs::create_directory(dir / "locked");
    fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    const bool named = test::runUnprivileged([&] {
        try {
            io::createFolder(dir / "locked" / "sub");
        } catch (const IoError& e) {
            return std::string(e.what()).find("cannot be created: Permission denied") != std::string::npos;
        }
        return false;
    });
    fs::permissions(dir / "locked", fs::perms::owner_all);
    CHECK(named);
}

TEST_CASE("a write through a symbolic link replaces the link's target and keeps the link", "[io][atomic]") {
    test::TempDir dir;
    fs::create_directories(dir / "real");
    test::writeText(dir / "real" / "target.txt", "old");
    fs::create_symlink("real/target.txt", dir / "link.txt");  // relative link
    fs::create_symlink(dir / "link.txt", dir / "link2.txt");  // a link to the link
    io::writeFileAtomically(dir / "link2.txt", "new");
    CHECK(fs::is_symlink(fs::symlink_status(dir / "link.txt")));
    CHECK(fs::is_symlink(fs::symlink_status(dir / "link2.txt")));
    CHECK(test::readText(dir / "real" / "target.txt") == "new");
    CHECK(countEntries(dir / "real") == 1);  // no temporary left, none beside the links
    CHECK(countEntries(dir.path()) == 3);
    // A dangling link: its target is created.
    fs::create_symlink("real/made.txt", dir / "dangling.txt");
    io::writeFileAtomically(dir / "dangling.txt", "made");
    CHECK(test::readText(dir / "real" / "made.txt") == "made");
    CHECK(fs::is_symlink(fs::symlink_status(dir / "dangling.txt")));
    // A loop of links is an error, not a hang.
    fs::create_symlink("loop_b", dir / "loop_a");
    fs::create_symlink("loop_a", dir / "loop_b");
    CHECK_THROWS_WITH(io::writeFileAtomically(dir / "loop_a", "x"), Catch::Contains("symbolic links loop"));
}

TEST_CASE("FIFOs, devices and folders at an output path are refused, never replaced",
          "[io][atomic][errors]") {
    test::TempDir dir;
    const fs::path fifo = dir / "pipe.obj";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    CHECK_THROWS_AS(io::writeFileAtomically(fifo, "x"), IoError);
    CHECK_THROWS_WITH(io::writeFileAtomically(fifo, "x"),
                      Catch::Contains("pipe.obj") && Catch::Contains("is a FIFO") &&
                          Catch::Contains("a regular file or a new path"));
    CHECK(fs::is_fifo(fs::status(fifo)));
    CHECK_THROWS_WITH(io::writeFileAtomically("/dev/null", "x"), Catch::Contains("is a character device"));
    CHECK(fs::is_character_file(fs::status("/dev/null")));
    fs::create_directories(dir / "folder.obj");
    CHECK_THROWS_WITH(io::writeFileAtomically(dir / "folder.obj", "x"), Catch::Contains("is a folder"));
    // Through a link to a FIFO: named as the link's target.
    fs::create_symlink(fifo, dir / "to_pipe.obj");
    CHECK_THROWS_WITH(io::writeFileAtomically(dir / "to_pipe.obj", "x"),
                      Catch::Contains("its link's target") && Catch::Contains("is a FIFO"));
    CHECK(countEntries(dir.path()) == 3);  // nothing written beside them
}

TEST_CASE("an output path inside a regular file says that it is a file", "[io][atomic][errors]") {
    test::TempDir dir;
    test::writeText(dir / "afile", "x");
    CHECK_THROWS_WITH(io::writeFileAtomically(dir / "afile" / "out.obj", "x"),
                      Catch::Contains("afile' is a file, not a folder"));
    CHECK_THROWS_WITH(io::writeFileAtomically(dir / "afile" / "sub" / "out.obj", "x"),
                      Catch::Contains("afile' is a file, not a folder"));
    CHECK_THROWS_WITH(io::writeFileAtomically(dir / "missing" / "out.obj", "x"),
                      Catch::Contains("folder '") && Catch::Contains("missing' does not exist"));
}

TEST_CASE("writers refuse a file name of another format", "[io][atomic][errors]") {
    CHECK_NOTHROW(io::requireExtension("a/mesh.obj", {".obj"}, "an OBJ mesh"));
    CHECK_NOTHROW(io::requireExtension("MESH.OBJ", {".obj"}, "an OBJ mesh"));  // case does not matter
    CHECK_THROWS_AS(io::requireExtension("o.png", {".obj"}, "an OBJ mesh"), InvalidInput);
    CHECK_THROWS_WITH(
        io::requireExtension("o.png", {".obj"}, "an OBJ mesh"),
        Catch::Contains("o.png: has the extension '.png' (expected a file name ending in .obj for an "
                        "OBJ mesh)"));
    CHECK_THROWS_WITH(io::requireExtension("plan", {".json"}, "a farm plan"),
                      Catch::Contains("has no extension"));
    CHECK_THROWS_WITH(io::requireExtension("x.y", {".tif", ".tiff"}, "a TIFF"),
                      Catch::Contains(".tif or .tiff"));
    // The OBJ writer checks it before writing anything.
    test::TempDir dir;
    const geom::Mesh mesh = geom::makeGrid({2, 2});
    CHECK_THROWS_WITH(io::writeObj(dir / "o.png", mesh), Catch::Contains("ending in .obj"));
    CHECK(countEntries(dir.path()) == 0);
}

TEST_CASE("temporary names carry the process, a random number drawn once and a call count", "[io][atomic]") {
    // Two processes with one process id (containers, two hosts) must still not share a temporary: the
    // token's middle part is 64 random bits drawn once per process; the last part counts calls.
    const std::string a = io::uniqueToken(), b = io::uniqueToken();
    const std::regex form(std::to_string(::getpid()) + "-([0-9a-f]{16})-([0-9]+)");
    std::smatch ma, mb;
    REQUIRE(std::regex_match(a, ma, form));
    REQUIRE(std::regex_match(b, mb, form));
    CHECK(ma[1] == mb[1]);
    CHECK(std::stoul(mb[2]) == std::stoul(ma[2]) + 1);
    CHECK(ma[1] != std::string(16, '0'));
}

TEST_CASE("absolutePath keeps '..' after a symbolic link: it names the file the system opens",
          "[io][atomic]") {
    const test::TempDir dir;
    fs::create_directories(dir / "real" / "shots");
    fs::create_directories(dir / "work");
    test::writeText(dir / "real" / "shot.json", "real");
    test::writeText(dir / "work" / "shot.json", "other");
    fs::create_directory_symlink(fs::path("..") / "real" / "shots", dir / "work" / "link");
    const fs::path through = dir / "work" / "link" / ".." / "shot.json";
    // The system opens real/shot.json; a text normalisation would name work/shot.json.
    CHECK(test::readText(through) == "real");
    CHECK(test::readText(io::absolutePath(through)) == "real");
    CHECK(io::absolutePath(through) == dir.path() / "real" / "shot.json");
    // Links not followed by ".." stay: a plan keeps the show's paths, not one machine's mount points.
    CHECK(io::absolutePath(dir / "work" / "link" / "x" / ".." / "y") == dir.path() / "work" / "link" / "y");
    CHECK(io::absolutePath(dir / "work" / ".." / "real" / "shot.json") == dir.path() / "real" / "shot.json");
    // "." parts and a trailing separator go; a relative path is made absolute from the working folder.
    CHECK(io::absolutePath(dir / "work" / "." / "shot.json") == dir.path() / "work" / "shot.json");
    CHECK(io::absolutePath(dir.path() / "work" / "") == dir.path() / "work");
    CHECK(io::absolutePath("a/./b") == fs::current_path() / "a" / "b");
}
