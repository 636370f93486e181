#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/interrupter.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/tile_warp.h"
#include "test_support.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

constexpr int kTexels = 32;
constexpr int kFrames = 4;

struct Shot {
    test::TempDir dir;
    geom::Mesh rest = test::twoTileCharts();
    uvwarp::ShotJob job;
    int asked = 0;  // deformed-frame requests
    std::vector<glm::vec3> frame;

    // warm: frames warm-started (the replay of a resumed job); false: the shot's default, from the identity.
    explicit Shot(bool warm = true) {
        job.options.solver.warmStart = warm;
        job.rest = &rest;
        job.restName = "two tiles";
        job.frames = {1, 2, 3, 4};
        job.rigidity.images = {{1001, test::twoDisks(kTexels)}, {1002, test::twoDisks(kTexels)}};
        job.rigidity.name = "painted rigidity";
        job.outPath = [this](int tile, int f) {
            return dir / ("redirect." + std::to_string(tile) + "." + std::to_string(f) + ".exr");
        };
    }
    [[nodiscard]] uvwarp::DeformedFrames frames() {
        return [this](int f, std::string& name) -> std::span<const glm::vec3> {
            ++asked;
            name = "frame " + std::to_string(f);
            frame = test::stretchedAndBent(rest, f);
            return frame;
        };
    }
    [[nodiscard]] fs::path out(int tile, int f) const { return job.outPath(tile, f); }
};

// Cancels after `after` units; records what the job reported.
class CancelAfter final : public Interrupter {
  public:
    explicit CancelAfter(int64_t after) : after_(after) {}
    void start(std::string_view name, int64_t total) override {
        started = std::string(name);
        this->total = total;
    }
    void end() override { ++ends; }
    bool wasInterrupted(int64_t done, int64_t total, std::string_view unit) override {
        CHECK(total == this->total);
        CHECK(done == last + 1);
        last = done;
        units.emplace_back(unit);
        return done >= after_;
    }
    std::string started;
    int64_t total = -1, last = 0;
    int ends = 0;
    std::vector<std::string> units;

  private:
    int64_t after_;
};

}  // namespace

TEST_CASE("shot job: each tile equals a TileWarp solved frame by frame; each frame is asked for once",
          "[uvwarp][shot_job]") {
    Shot shot;
    std::ostringstream log;
    shot.job.log = &log;
    const uvwarp::ShotReport report = uvwarp::runShotJob(shot.job, shot.frames());
    CHECK(shot.asked == kFrames);  // not frames x tiles
    REQUIRE(report.tiles.size() == 2);
    for (const int tile : {1001, 1002}) {
        uvwarp::TileWarp reference(shot.rest, tile, test::twoDisks(kTexels), {}, shot.job.options);
        for (int f = 1; f <= kFrames; ++f) {
            reference.solve(test::stretchedAndBent(shot.rest, f));
            const io::Image written = io::readImage(shot.out(tile, f));
            CHECK(test::sameBits(written.pixels, reference.redirect().pixels));
        }
    }
    for (const uvwarp::ShotTileReport& t : report.tiles) {
        CHECK(t.written == kFrames);
        CHECK(t.files.size() == static_cast<size_t>(kFrames));
        CHECK(t.lastFrame == kFrames);
        CHECK(t.lastMetrics.foldOvers == 0);
    }
    // Provenance of a map from memory names the source it was given.
    const io::ImageInfo info = io::readImageInfo(shot.out(1002, 3));
    std::map<std::string, std::string> attributes(info.attributes.begin(), info.attributes.end());
    CHECK(attributes["deformkit:uvwarp:tile"] == "1002");
    CHECK(attributes["deformkit:uvwarp:frame"] == "3");
    CHECK_THAT(attributes["deformkit:uvwarp:inputs"],
               Contains("painted rigidity tile 1002") && Contains("\"deformed\":\"frame 3\""));
    // Frame-major log: frame 1 of both tiles first.
    std::istringstream lines(log.str());
    std::string first, second;
    std::getline(lines, first);
    std::getline(lines, second);
    CHECK_THAT(first, Contains("\"tile\":1001") && Contains("\"frame\":1"));
    CHECK_THAT(second, Contains("\"tile\":1002") && Contains("\"frame\":1"));
}

TEST_CASE("shot job: maps from files give the pixels of the same maps in memory", "[uvwarp][shot_job]") {
    Shot memory, files;
    io::writeImage(files.dir / "rig.1001.exr", test::twoDisks(kTexels), {io::PixelType::Float, {}});
    io::writeImage(files.dir / "rig.1002.exr", test::twoDisks(kTexels), {io::PixelType::Float, {}});
    files.job.rigidity = {};
    files.job.rigidity.pattern = files.dir / "rig.<UDIM>.exr";
    (void)uvwarp::runShotJob(memory.job, memory.frames());
    (void)uvwarp::runShotJob(files.job, files.frames());
    for (const int tile : {1001, 1002}) {
        for (int f = 1; f <= kFrames; ++f) {
            CHECK(test::sameBits(io::readImage(memory.out(tile, f)).pixels,
                                 io::readImage(files.out(tile, f)).pixels));
        }
    }
}

TEST_CASE("shot job: animated maps are given to the warp when they change, and only then",
          "[uvwarp][shot_job]") {
    // rig.<UDIM>.####.exr: the disks for frames 1 and 2, none (rigidity 0) from frame 3. The reference is a
    // TileWarp solved frame by frame and given the new map at frame 3 (TileWarp::setMaps); frames 1-2 are
    // the static job's bytes; rigidity 0 warps nothing, so the new map's frames drift back towards the
    // identity instead of continuing the disks' warp.
    Shot animated, still;
    const io::Image none(kTexels, kTexels, 1);
    for (const int tile : {1001, 1002}) {
        for (int f = 1; f <= kFrames; ++f) {
            const fs::path file = animated.dir / ("rig." + std::to_string(tile) + "." +
                                                  std::to_string(f).insert(0, 4 - 1, '0') + ".exr");
            io::writeImage(file, f <= 2 ? test::twoDisks(kTexels) : none, {io::PixelType::Float, {}});
        }
    }
    animated.job.rigidity = {};
    animated.job.rigidity.pattern = animated.dir / "rig.<UDIM>.####.exr";
    const uvwarp::ShotReport report = uvwarp::runShotJob(animated.job, animated.frames());
    (void)uvwarp::runShotJob(still.job, still.frames());
    REQUIRE(report.tiles.size() == 2);
    for (const uvwarp::ShotTileReport& t : report.tiles)
        CHECK(t.mapChanges == 1);
    CHECK_THAT(uvwarp::shotSummary(report)[0], Contains("maps changed at 1 frame"));
    for (const int tile : {1001, 1002}) {
        uvwarp::TileWarp reference(animated.rest, tile, test::twoDisks(kTexels), {}, animated.job.options);
        for (int f = 1; f <= kFrames; ++f) {
            if (f == 3) reference.setMaps(none);
            reference.solve(test::stretchedAndBent(animated.rest, f));
            const io::Image written = io::readImage(animated.out(tile, f));
            CHECK(test::sameBits(written.pixels, reference.redirect().pixels));
            const bool same = test::sameBits(written.pixels, io::readImage(still.out(tile, f)).pixels);
            CHECK(same == (f <= 2));
        }
    }
    // The header names the frame's map.
    const io::ImageInfo info = io::readImageInfo(animated.out(1001, 3));
    std::map<std::string, std::string> attributes(info.attributes.begin(), info.attributes.end());
    CHECK_THAT(attributes["deformkit:uvwarp:inputs"], Contains("rig.1001.0003.exr"));

    // A frame without its map stops the job before anything is written, naming the file.
    Shot missing;
    for (const int tile : {1001, 1002})
        for (const int f : {1, 2, 4})
            io::writeImage(
                missing.dir / ("rig." + std::to_string(tile) + ".000" + std::to_string(f) + ".exr"),
                test::twoDisks(kTexels), {io::PixelType::Float, {}});
    missing.job.rigidity = {};
    missing.job.rigidity.pattern = missing.dir / "rig.<UDIM>.####.exr";
    CHECK_THAT(test::errorOf<Error>([&] { (void)uvwarp::runShotJob(missing.job, missing.frames()); }),
               Contains("rig.1001.0003.exr") && Contains("does not exist"));
    CHECK_FALSE(fs::exists(missing.out(1001, 1)));
}

TEST_CASE("tile warp: new maps keep the warm start; a map of another size is refused", "[uvwarp]") {
    // setMaps with the same maps changes nothing: the next solve gives the bytes of a warp never given them
    // (the warp and its velocities are kept, not reset).
    const geom::Mesh rest = test::twoTileCharts();
    uvwarp::TileWarp a(rest, 1001, test::twoDisks(kTexels)), b(rest, 1001, test::twoDisks(kTexels));
    a.solve(test::stretchedAndBent(rest, 2));
    b.solve(test::stretchedAndBent(rest, 2));
    b.setMaps(test::twoDisks(kTexels));
    CHECK(test::sameBits(a.solve(test::stretchedAndBent(rest, 3)).u,
                         b.solve(test::stretchedAndBent(rest, 3)).u));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { b.setMaps(io::Image(16, 16, 1)); }),
               Contains("rigidity map") && Contains("16 texels per side") && Contains("32"));
    io::Image outOfRange = test::twoDisks(kTexels);
    outOfRange.at(3, 4, 0) = 2.0f;
    CHECK_THROWS_AS(b.setMaps(outOfRange), InvalidInput);
    CHECK(test::sameBits(a.solve(test::stretchedAndBent(rest, 4)).u,
                         b.solve(test::stretchedAndBent(rest, 4)).u));  // unchanged
}

TEST_CASE("shot job: a cancelled job leaves complete files and a rerun writes an uninterrupted job's bytes",
          "[uvwarp][shot_job]") {
    Shot whole;
    (void)uvwarp::runShotJob(whole.job, whole.frames());

    Shot cut;
    CancelAfter cancel(3);  // frame 1 of both tiles, frame 2 of tile 1001
    CHECK_THROWS_AS(uvwarp::runShotJob(cut.job, cut.frames(), &cancel), Cancelled);
    CHECK(cancel.started == "uvwarp");
    CHECK(cancel.total == 2 * kFrames);
    CHECK(cancel.ends == 1);
    CHECK(cancel.units.front() == "tile 1001 frame 1 written");
    CHECK(test::filesIn(cut.dir.path()).size() == 3);
    for (const auto& [tile, f] : std::vector<std::pair<int, int>>{{1001, 1}, {1002, 1}, {1001, 2}})
        CHECK(test::readText(cut.out(tile, f)) == test::readText(whole.out(tile, f)));

    // The rerun replays the warm start where outputs exist and writes the rest.
    CancelAfter never(1000);
    const uvwarp::ShotReport again = uvwarp::runShotJob(cut.job, cut.frames(), &never);
    CHECK(never.last == 2 * kFrames);
    CHECK(again.tiles[0].replayed == 2);
    CHECK(again.tiles[0].written == 2);
    CHECK(again.tiles[1].replayed == 1);
    CHECK(again.tiles[1].written == 3);
    for (const int tile : {1001, 1002})
        for (int f = 1; f <= kFrames; ++f)
            CHECK(test::readText(cut.out(tile, f)) == test::readText(whole.out(tile, f)));

    // Everything exists: nothing is asked for, every frame skipped.
    cut.asked = 0;
    const uvwarp::ShotReport done = uvwarp::runShotJob(cut.job, cut.frames());
    CHECK(cut.asked == 0);
    CHECK(done.tiles[0].skipped == kFrames);
    CHECK(uvwarp::shotSummary(done)[0] ==
          "tile 1001: 0 frames written, 0 replayed, 4 skipped (outputs exist)");
}

TEST_CASE("shot job: bad input names the input and what was expected", "[uvwarp][shot_job][errors]") {
    Shot shot;
    uvwarp::ShotSolver solver(shot.job);
    CHECK(solver.units() == 2 * kFrames);
    CHECK(solver.lastNeededFrame() == kFrames);
    const std::vector<glm::vec3> second = test::stretchedAndBent(shot.rest, 2);
    CHECK_THAT(test::errorOf<InvalidInput>([&] { solver.solveFrame(2, second, "f2"); }),
               Contains("frame 2") && Contains("out of order") && Contains("frame 1"));
    const std::vector<glm::vec3> few(10);
    CHECK_THAT(test::errorOf<InvalidInput>([&] { solver.solveFrame(1, few, "anim.0001.obj"); }),
               Contains("anim.0001.obj") && Contains("has 10 vertices") && Contains("'two tiles'"));

    Shot mask;
    mask.job.mask.images = {{1001, io::Image(16, 16, 1, 1.0f)}};
    mask.job.mask.name = "painted mask";
    CHECK_THAT(test::errorOf<InvalidInput>([&] { uvwarp::ShotSolver s(mask.job); }),
               Contains("painted mask tile 1001") && Contains("16 x 16") && Contains("32 x 32"));
    CHECK(test::filesIn(mask.dir.path()).empty());

    Shot none;
    none.job.rigidity.images.clear();
    none.job.rigidity.pattern = none.dir / "rig.<UDIM>.exr";
    none.job.rigidity.name = "--rigidity";
    CHECK_THAT(test::errorOf<IoError>([&] { uvwarp::ShotSolver s(none.job); }),
               Contains("--rigidity") && Contains("no tile has a rigidity map"));

    // A missing output folder is made (before any work); one behind a regular file cannot be, named.
    Shot folder;
    folder.job.outPath = [&](int tile, int f) {
        return folder.dir / "missing" / ("r." + std::to_string(tile) + "." + std::to_string(f) + ".exr");
    };
    { uvwarp::ShotSolver made(folder.job); }
    CHECK(fs::is_directory(folder.dir / "missing"));
    test::writeText(folder.dir / "afile", "x");
    folder.job.outPath = [&](int tile, int f) {
        return folder.dir / "afile" / ("r." + std::to_string(tile) + "." + std::to_string(f) + ".exr");
    };
    CHECK_THAT(test::errorOf<IoError>([&] { uvwarp::ShotSolver s(folder.job); }),
               Contains("afile' is a file, not a folder"));

    Shot tiles;
    tiles.job.tiles = {1003};
    CHECK_THAT(test::errorOf<InvalidInput>([&] { uvwarp::ShotSolver s(tiles.job); }),
               Contains("tile 1003") && Contains("1001 1002"));
}

TEST_CASE("shot job: shotTiles gives the asked tiles or every tile of the UVs, and names what is wrong",
          "[uvwarp][shot_job][errors]") {
    const geom::Mesh rest = test::twoTileCharts();
    CHECK(uvwarp::shotTiles(rest, "rest.obj", {}, "--tiles") == std::vector<int>{1001, 1002});
    CHECK(uvwarp::shotTiles(rest, "rest.obj", {1002}, "--tiles") == std::vector<int>{1002});
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)uvwarp::shotTiles(rest, "rest.obj", {1001, 1011}, "--tiles");
               }),
               Contains("--tiles: tile 1011") && Contains("'rest.obj' has no UV face in it") &&
                   Contains("1001 1002"));
    geom::Mesh::Data bare;
    bare.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    bare.faceCounts = {3};
    bare.faceIndices = {0, 1, 2};
    const geom::Mesh noUvs(std::move(bare), "bare");
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)uvwarp::shotTiles(noUvs, "bare.obj", {}, "tiles"); }),
               Contains("bare.obj") && Contains("has no UVs"));
}

// A shot's default (uvwarp::shotOptions): every frame from the identity, so each map is a TileWarp's solve of
// that frame alone, a job over the last two frames writes the whole job's bytes for them, and a rerun that
// misses one output solves that frame only.
TEST_CASE("shot job: by default each frame's map depends on that frame alone", "[uvwarp][shot_job]") {
    CHECK_FALSE(uvwarp::ShotJob{}.options.solver.warmStart);
    Shot whole(false), last(false);
    last.job.frames = {3, 4};
    (void)uvwarp::runShotJob(whole.job, whole.frames());
    (void)uvwarp::runShotJob(last.job, last.frames());
    for (const int tile : {1001, 1002}) {
        for (int f = 3; f <= kFrames; ++f) {
            uvwarp::TileWarp alone(whole.rest, tile, test::twoDisks(kTexels), {}, uvwarp::shotOptions());
            alone.solve(test::stretchedAndBent(whole.rest, f));
            const io::Image written = io::readImage(whole.out(tile, f));
            CHECK(test::sameBits(written.pixels, alone.redirect().pixels));
            CHECK(test::readText(last.out(tile, f)) == test::readText(whole.out(tile, f)));
        }
    }
    fs::remove(whole.out(1001, 3));
    whole.asked = 0;
    const uvwarp::ShotReport again = uvwarp::runShotJob(whole.job, whole.frames());
    CHECK(again.tiles[0].written == 1);
    CHECK(again.tiles[0].replayed == 0);
    CHECK(again.tiles[0].skipped == kFrames - 1);
    CHECK(again.tiles[1].written == 0);
}
