#include <catch2/catch.hpp>

#include <filesystem>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/obj_sequence.h"
#include "test_support.h"

using deformkit::InvalidInput;
using deformkit::IoError;
using deformkit::geom::Mesh;
using namespace deformkit::io;
namespace fs = std::filesystem;
namespace test = deformkit::test;

namespace {

// The grid with every point moved up by `lift`: same topology, new positions.
Mesh liftedGrid(float lift) {
    const Mesh grid = deformkit::geom::makeGrid({3, 2});
    Mesh::Data d;
    for (const auto& p : grid.points())
        d.points.emplace_back(p.x, p.y, p.z + lift);
    d.faceCounts.assign(grid.faceCounts().begin(), grid.faceCounts().end());
    d.faceIndices.assign(grid.faceIndices().begin(), grid.faceIndices().end());
    return Mesh(std::move(d));
}

}  // namespace

TEST_CASE("obj sequence: frame paths for # and printf tokens", "[io][obj_sequence]") {
    const ObjSequence hashes(fs::path("/shots/a") / "body.####.obj");
    CHECK(hashes.framePath(7) == fs::path("/shots/a/body.0007.obj"));
    CHECK(hashes.framePath(0) == fs::path("/shots/a/body.0000.obj"));
    CHECK(hashes.framePath(12345) == fs::path("/shots/a/body.12345.obj"));
    CHECK(hashes.framePath(-12) == fs::path("/shots/a/body.-0012.obj"));
    CHECK(hashes.pattern() == fs::path("/shots/a/body.####.obj"));

    const ObjSequence printf4("cache/body_%04d.obj");
    CHECK(printf4.framePath(42) == fs::path("cache/body_0042.obj"));
    const ObjSequence printf0("body.%d.obj");
    CHECK(printf0.framePath(42) == fs::path("body.42.obj"));
    CHECK(printf0.framePath(-3) == fs::path("body.-3.obj"));
    const ObjSequence one("f#.obj");
    CHECK(one.framePath(5) == fs::path("f5.obj"));
    CHECK(one.framePath(15) == fs::path("f15.obj"));
}

TEST_CASE("obj sequence: patterns need exactly one frame token", "[io][obj_sequence][errors]") {
    CHECK(ObjSequence::isPattern("a/body.####.obj"));
    CHECK(ObjSequence::isPattern("body.%04d.obj"));
    CHECK(ObjSequence::isPattern("body.%d.obj"));
    CHECK(ObjSequence::isPattern("shot#12/body.#.obj"));  // only the file name counts
    CHECK_FALSE(ObjSequence::isPattern("body.0001.obj"));
    CHECK_FALSE(ObjSequence::isPattern("body.%4d.obj"));
    CHECK_FALSE(ObjSequence::isPattern("body.%s.obj"));
    CHECK_FALSE(ObjSequence::isPattern("shot#12/body.obj"));
    CHECK_FALSE(ObjSequence::isPattern("body.##.%02d.obj"));

    CHECK_THROWS_AS(ObjSequence("cache/body.obj"), InvalidInput);
    CHECK_THROWS_WITH(ObjSequence("cache/body.obj"),
                      Catch::Contains("cache/body.obj: has no frame token") &&
                          Catch::Contains("expected one frame token in the file name"));
    CHECK_THROWS_WITH(ObjSequence("body.##.%02d.obj"), Catch::Contains("has 2 frame tokens"));
    CHECK_THROWS_WITH(ObjSequence("body.%099d.obj"), Catch::Contains("padding"));
}

TEST_CASE("obj sequence: frames() lists existing frames, strictly parsed and sorted", "[io][obj_sequence]") {
    test::TempDir dir;
    for (const char* name :
         {"body.0010.obj", "body.0001.obj", "body.-0003.obj", "body.12345.obj", "body.0002.obj",
          // not frames of body.####.obj:
          "body.01.obj", "body.00001.obj", "body.-0000.obj", "body.+0004.obj", "body.abcd.obj",
          "body.0005.obj.bak", "body.0006.abc", "head.0007.obj", "body..obj", "body.0x10.obj"}) {
        test::writeText(dir / name, "");
    }
    fs::create_directory(dir / "body.0008.obj");
    CHECK(ObjSequence(dir / "body.####.obj").frames() == std::vector<int>{-3, 1, 2, 10, 12345});
    CHECK(ObjSequence(dir / "body.%04d.obj").frames() == std::vector<int>{-3, 1, 2, 10, 12345});
    CHECK(ObjSequence(dir / "body.%02d.obj").frames() == std::vector<int>{1, 12345});
    CHECK(ObjSequence(dir / "head.%d.obj").frames().empty());
    CHECK(ObjSequence(dir / "none.####.obj").frames().empty());

    CHECK_THROWS_AS(ObjSequence(dir / "missing" / "body.####.obj").frames(), IoError);
    CHECK_THROWS_WITH(
        ObjSequence(dir / "missing" / "body.####.obj").frames(),
        Catch::Contains("body.####.obj: folder '" + (dir / "missing").string() + "' does not exist"));
}

TEST_CASE("obj sequence: read checks every frame against the first frame read", "[io][obj_sequence]") {
    test::TempDir dir;
    ObjSequence sequence(dir / "grid.####.obj");
    for (int frame = 1; frame <= 3; ++frame)
        writeObj(sequence.framePath(frame), liftedGrid(0.5f * frame));

    const ObjContent second = sequence.read(2);
    CHECK(second.mesh.points()[0].z == 1.0f);
    const ObjContent first = sequence.read(1);
    CHECK(first.mesh.points()[5].z == 0.5f);
    CHECK(sequence.read(3).mesh.points()[11].z == 1.5f);

    SECTION("missing frame") {
        CHECK_THROWS_AS(sequence.read(4), IoError);
        CHECK_THROWS_WITH(sequence.read(4),
                          Catch::Contains((dir / "grid.0004.obj").string() + ": frame 4: is missing") &&
                              Catch::Contains("grid.####.obj"));
    }
    SECTION("a face with other vertices") {
        test::writeText(dir / "grid.0004.obj",
                        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 3 1 0\n"
                        "v 0 2 0\nv 1 2 0\nv 2 2 0\nv 3 2 0\n"
                        "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 5 6 10 9\nf 6 7 11 12\nf 7 8 12 11\n");
        CHECK_THROWS_AS(sequence.read(4), InvalidInput);
        CHECK_THROWS_WITH(sequence.read(4),
                          Catch::Contains((dir / "grid.0004.obj").string() + ": face 4: has 4 "
                                                                             "vertices (5 6 10 11)") &&
                              Catch::Contains("the first frame has 4 vertices (5 6 10 9)") &&
                              Catch::Contains("grid.0002.obj"));
    }
    SECTION("fewer faces") {
        const Mesh grid = liftedGrid(0.0f);
        Mesh::Data d;
        d.points.assign(grid.points().begin(), grid.points().end());
        d.faceCounts.assign(grid.faceCounts().begin(), grid.faceCounts().end() - 1);
        d.faceIndices.assign(grid.faceIndices().begin(), grid.faceIndices().end() - 4);
        writeObj(sequence.framePath(5), Mesh(std::move(d)));
        CHECK_THROWS_WITH(sequence.read(5),
                          Catch::Contains("grid.0005.obj: has 5 faces instead of 6 (expected the topology"));
    }
    SECTION("a triangle where the quad was") {
        const Mesh grid = liftedGrid(0.0f);
        Mesh::Data d;
        d.points.assign(grid.points().begin(), grid.points().end());
        d.faceCounts = {4, 3, 4, 4, 4, 4};
        d.faceIndices.assign(grid.faceIndices().begin(), grid.faceIndices().end());
        d.faceIndices.erase(d.faceIndices.begin() + 7);
        writeObj(sequence.framePath(6), Mesh(std::move(d)));
        CHECK_THROWS_WITH(sequence.read(6), Catch::Contains("grid.0006.obj: face 1: has 3 vertices"));
    }
    SECTION("an extra vertex") {
        const Mesh grid = liftedGrid(0.0f);
        Mesh::Data d;
        d.points.assign(grid.points().begin(), grid.points().end());
        d.points.emplace_back(9.0f, 9.0f, 9.0f);
        d.faceCounts.assign(grid.faceCounts().begin(), grid.faceCounts().end());
        d.faceIndices.assign(grid.faceIndices().begin(), grid.faceIndices().end());
        writeObj(sequence.framePath(7), Mesh(std::move(d)));
        CHECK_THROWS_WITH(sequence.read(7), Catch::Contains("grid.0007.obj: has 13 vertices instead of 12"));
    }
    SECTION("a frame that fails to parse names its file and line") {
        test::writeText(dir / "grid.0008.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
        CHECK_THROWS_WITH(sequence.read(8), Catch::Contains("grid.0008.obj: line 4"));
    }
}

TEST_CASE("obj sequence: the first frame read sets the reference, whichever it is", "[io][obj_sequence]") {
    test::TempDir dir;
    ObjSequence sequence(dir / "s.%d.obj");
    writeObj(sequence.framePath(10), deformkit::geom::makeGrid({2, 2}));
    writeObj(sequence.framePath(11), deformkit::geom::makeGrid({2, 3}));
    CHECK_THROWS_AS(sequence.read(12), IoError);  // a failed read sets no reference
    CHECK(sequence.read(11).mesh.numFaces() == 6);
    CHECK_THROWS_WITH(sequence.read(10), Catch::Contains("s.10.obj: has 9 vertices instead of 12") &&
                                             Catch::Contains("s.11.obj"));
    CHECK(sequence.frames() == std::vector<int>{10, 11});
}
