#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/preview.h"
#include "deformkit/scene/uvwarp_stage.h"
#include "eval_command.h"
#include "mesh_support.h"
#include "point_cache_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;

namespace {

// 6 rings of 10 vertices, UVs u around and v along.
const test::TubeOptions kTube{.rings = 6, .sides = 10, .uvs = test::TubeUVs::Wrapped};

const char* kScene = R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [
  {"name": "tube", "mesh": "tube.obj", "stack": [
    {"type": "twist", "label": "twist1", "params": {"handleY": [0, 1, 0],
       "endAngle": {"keys": [{"frame": 1, "value": 0, "interpolation": "linear"}, {"frame": 3, "value": 1.5}]}}},
    {"type": "bend", "label": "bend1", "envelope": {"keys": [{"frame": 1, "value": 0}, {"frame": 3, "value": 1}]},
       "params": {"curvature": 0.8}}]},
  {"name": "still", "mesh": "tube.obj", "stack": []}]})";

// Writes the tube and kScene into `dir`: a command evaluating them into dir/<out>.
harness::EvalCommand shotIn(const test::TempDir& dir, const std::string& out = "out") {
    io::writeObj(dir / "tube.obj", test::tube(kTube));
    test::writeText(dir / "shot.json", kScene);
    harness::EvalCommand command;
    command.scene = dir / "shot.json";
    command.outDir = dir / out;
    return command;
}

}  // namespace

TEST_CASE("eval command: file names pad the frame to 4 digits after the sign", "[harness][eval]") {
    CHECK(scene::frameFileName("tube", 7) == "tube.0007.obj");
    CHECK(scene::frameFileName("tube", 12345) == "tube.12345.obj");
    CHECK(scene::frameFileName("tube", -3) == "tube.-0003.obj");
    CHECK(scene::frameFileName("tube", -3, ".png") == "tube.-0003.png");
}

TEST_CASE("eval command: writes every object at every frame, equal to the stack evaluated directly",
          "[harness][eval]") {
    test::TempDir dir;
    const geom::Mesh tube = test::tube(kTube);
    io::writeObj(dir / "tube.obj", tube);
    test::writeText(dir / "shot.json", kScene);

    harness::EvalCommand command;
    command.scene = dir / "shot.json";
    command.outDir = dir / "out" / "frames";  // created when missing
    command.previews = false;                 // previews are checked below
    std::ostringstream progress;
    const harness::EvalReport report = harness::evalCommand(command, &progress);
    CHECK(report.frames == std::vector<int>{1, 2, 3});
    REQUIRE(report.files.size() == 6);
    for (int frame = 1; frame <= 3; ++frame) {
        CHECK(std::filesystem::is_regular_file(command.outDir / scene::frameFileName("tube", frame)));
        CHECK(std::filesystem::is_regular_file(command.outDir / scene::frameFileName("still", frame)));
    }
    // No temporaries left behind by the atomic writes.
    CHECK(std::distance(std::filesystem::directory_iterator(command.outDir), {}) == 6);
    CHECK_THAT(progress.str(), Contains("eval: frame 1 (1/3)") && Contains("eval: frame 3 (3/3)"));
    CHECK(report.binds == std::vector<int64_t>{2, 0});  // each deformer once; the bend skipped at envelope 0
                                                        // on frame 1 binds on frame 2

    // Reference: the same stack built by hand, at frame 2 (endAngle 0.75 exactly; the bend's envelope
    // Bezier between two auto keys at the midpoint is 0.5).
    host::DeformerStack stack;
    stack.setRest(tube);
    stack.add(host::makeDeformer("twist", "twist1"));
    stack.add(host::makeDeformer("bend", "bend1"));
    stack.set(0, "handleY", std::vector<double>{0, 1, 0});
    stack.set(0, "endAngle", 0.75);
    stack.set(1, "curvature", 0.8);
    stack.setEnvelope(1, 0.5);
    std::vector<glm::vec3> expected(tube.points().begin(), tube.points().end());
    stack.evaluate(expected);

    const io::ObjContent written = io::readObj(command.outDir / "tube.0002.obj");
    REQUIRE(written.mesh.numVertices() == tube.numVertices());
    CHECK(std::equal(written.mesh.faceIndices().begin(), written.mesh.faceIndices().end(),
                     tube.faceIndices().begin()));
    CHECK(written.mesh.hasUVs());
    // The writer's default 9 significant digits round-trip float32 exactly, so the tolerance is 0.
    float maxError = 0.0f, maxMove = 0.0f;
    for (int32_t v = 0; v < tube.numVertices(); ++v) {
        maxError = std::max(maxError, glm::length(written.mesh.points()[v] - expected[v]));
        maxMove = std::max(maxMove, glm::length(expected[v] - tube.points()[v]));
    }
    CHECK(maxError == 0.0f);
    CHECK(maxMove > 0.1f);  // the reference really deforms
    // The object with an empty stack is its rest mesh at every frame.
    const io::ObjContent still = io::readObj(command.outDir / "still.0003.obj");
    CHECK(std::equal(still.mesh.points().begin(), still.mesh.points().end(), tube.points().begin()));

    // --frames overrides the scene's range.
    command.frames = {5};
    command.outDir = dir / "five";
    CHECK(harness::evalCommand(command).files.size() == 2);
    CHECK(std::filesystem::is_regular_file(dir / "five" / "tube.0005.obj"));
}

TEST_CASE(
    "eval command: one point cache per object holds the OBJs' positions bit for bit, beside or instead "
    "of them",
    "[harness][eval][point_cache]") {
    test::TempDir dir;
    harness::EvalCommand command = shotIn(dir, "objs");
    command.previews = false;
    (void)harness::evalCommand(command);

    // The caches the test expects: the written OBJs' positions (which round-trip float32), encoded by the
    // test's own writer: PC2 starting at the first frame, MDD timed (frame - first) / fps.
    std::vector<std::vector<glm::vec3>> tube, still;
    for (int frame = 1; frame <= 3; ++frame) {
        for (auto* frames : {&tube, &still}) {
            const io::ObjContent obj =
                io::readObj(command.outDir / scene::frameFileName(frames == &tube ? "tube" : "still", frame));
            frames->emplace_back(obj.mesh.points().begin(), obj.mesh.points().end());
        }
    }
    command.cache = "pc2";
    command.outDir = dir / "pc2";
    harness::EvalReport report = harness::evalCommand(command);
    CHECK(test::readText(command.outDir / "tube.pc2") == test::pc2Bytes(1.0f, 1.0f, tube));
    CHECK(test::readText(command.outDir / "still.pc2") == test::pc2Bytes(1.0f, 1.0f, still));
    CHECK(report.files.size() == 8);  // six OBJs and two caches
    CHECK(std::filesystem::is_regular_file(command.outDir / "tube.0002.obj"));

    command.cache = "mdd";
    command.objs = false;
    command.movieFrameRate = 25;
    command.outDir = dir / "mdd";
    report = harness::evalCommand(command);
    CHECK(test::readText(command.outDir / "tube.mdd") == test::mddBytes({0.0f, 1.0f / 25, 2.0f / 25}, tube));
    CHECK(test::filesIn(command.outDir) == std::vector<std::filesystem::path>{"still.mdd", "tube.mdd"});
    CHECK(report.files.size() == 2);

    // Refused before anything is written: frames with a gap, --no-objs without a cache, another format.
    command.outDir = dir / "refused";
    command.frames = {1, 3};
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::evalCommand(command); }),
               Contains("--cache: mdd: cannot hold the frames 1 and 3 with a gap"));
    command.frames = {};
    command.cache = "";
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::evalCommand(command); }),
               Contains("--no-objs: is given without --cache"));
    command.cache = "abc";
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::evalCommand(command); }),
               Contains("--cache: abc: is not a point cache format (expected pc2 or mdd)"));
    CHECK_FALSE(std::filesystem::exists(dir / "refused"));
}

TEST_CASE("eval command: a bad scene names the file and JSON path and writes nothing",
          "[harness][eval][errors]") {
    test::TempDir dir;
    io::writeObj(dir / "tube.obj", test::tube(kTube));
    std::string text = kScene;
    text.replace(text.find("\"curvature\""), std::strlen("\"curvature\""), "\"curvatur\"");
    test::writeText(dir / "shot.json", text);
    harness::EvalCommand command;
    command.scene = dir / "shot.json";
    command.outDir = dir / "out";
    try {
        (void)harness::evalCommand(command);
        FAIL("no error");
    } catch (const InvalidInput& e) {
        CHECK_THAT(e.what(),
                   Contains((dir / "shot.json").string() + ": objects[0].stack[1].params.curvatur"));
    }
    CHECK_FALSE(std::filesystem::exists(dir / "out"));
}

namespace {

// 8-bit values of an image read from an 8-bit PNG (readImage gives n / 255; rounding recovers n exactly).
std::vector<int> bytesOf(const io::Image& image) {
    std::vector<int> out(image.pixels.size());
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = static_cast<int>(std::lround(image.pixels[i] * 255.0f));
    return out;
}

// Region [x0, x0 + w) x [y0, y0 + h) of an 8-bit RGB buffer `width` pixels wide.
std::vector<int> crop(const std::vector<int>& bytes, int width, int x0, int y0, int w, int h) {
    std::vector<int> out;
    for (int y = y0; y < y0 + h; ++y)
        for (int x = x0; x < x0 + w; ++x)
            for (int c = 0; c < 3; ++c)
                out.push_back(bytes[(static_cast<size_t>(y) * width + x) * 3 + c]);
    return out;
}

// Reference downscale: mean of each k x k block, rounded half up, computed in double then floored.
std::vector<int> boxDown(const std::vector<int>& bytes, int width, int height, int k) {
    std::vector<int> out;
    for (int y = 0; y < height / k; ++y)
        for (int x = 0; x < width / k; ++x)
            for (int c = 0; c < 3; ++c) {
                double sum = 0.0;
                for (int j = 0; j < k; ++j)
                    for (int i = 0; i < k; ++i)
                        sum += bytes[(static_cast<size_t>(y * k + j) * width + (x * k + i)) * 3 + c];
                out.push_back(static_cast<int>(std::floor(sum / (k * k) + 0.5)));
            }
    return out;
}

size_t countFiles(const std::filesystem::path& dir) {
    return static_cast<size_t>(std::distance(std::filesystem::directory_iterator(dir), {}));
}

bool onPath(const std::string& program) {
    return std::system(("command -v " + program + " >/dev/null 2>&1").c_str()) == 0;
}

// Sets PATH for the scope of a test.
struct ScopedPath {
    std::string saved;
    explicit ScopedPath(const std::string& value) : saved(std::getenv("PATH") ? std::getenv("PATH") : "") {
        ::setenv("PATH", value.c_str(), 1);
    }
    ~ScopedPath() { ::setenv("PATH", saved.c_str(), 1); }
};

}  // namespace

TEST_CASE("eval command: previews of the rest pose equal the renderer's view of the rest mesh",
          "[harness][eval][preview]") {
    test::TempDir dir;
    const geom::Mesh tube = test::tube(kTube);
    io::writeObj(dir / "tube.obj", tube);
    test::writeText(dir / "shot.json", kScene);
    harness::EvalCommand command;
    command.scene = dir / "shot.json";
    command.outDir = dir / "out";
    const harness::EvalReport report = harness::evalCommand(command);

    // 3 frames x 2 objects, an OBJ and a PNG each, and one contact sheet per object; no temporaries.
    CHECK(report.files.size() == 14);
    CHECK(countFiles(command.outDir) == 14);
    CHECK(report.notes.empty());
    for (const char* name : {"tube", "still"}) {
        for (int frame = 1; frame <= 3; ++frame) {
            const io::ImageInfo info =
                io::readImageInfo(command.outDir / scene::frameFileName(name, frame, ".png"));
            CHECK(info.width == 480);
            CHECK(info.height == 360);
            CHECK(info.channels == 3);
        }
    }

    // Reference: the renderer's default view of the rest mesh at the same size, written and read back the
    // same way. Exact: the same camera, triangles and shading must give the same 8-bit pixels.
    io::PreviewOptions view;
    view.width = 480;
    view.height = 360;
    io::writeImage(dir / "rest.png", io::renderPreview(tube, view));
    const std::vector<int> rest = bytesOf(io::readImage(dir / "rest.png"));
    // The object without deformers, at every frame.
    for (int frame = 1; frame <= 3; ++frame)
        CHECK(bytesOf(io::readImage(command.outDir / scene::frameFileName("still", frame, ".png"))) == rest);
    // Frame 1 of the deformed object: twist angle 0 and bend envelope 0 leave the rest positions exactly.
    const io::ObjContent first = io::readObj(command.outDir / "tube.0001.obj");
    REQUIRE(std::equal(first.mesh.points().begin(), first.mesh.points().end(), tube.points().begin()));
    CHECK(bytesOf(io::readImage(command.outDir / "tube.0001.png")) == rest);
    // Frame 3 is deformed: its preview differs from the rest view in many pixels (> 1% of the values).
    const std::vector<int> last = bytesOf(io::readImage(command.outDir / "tube.0003.png"));
    REQUIRE(last.size() == rest.size());
    size_t differing = 0;
    for (size_t i = 0; i < rest.size(); ++i)
        differing += last[i] != rest[i];
    CHECK(differing > rest.size() / 100);

    // Contact sheet: 3 tiles -> 3 columns, 1 row, factor max(1, ceil(3 * 480 / 2048)) = 1: the previews
    // side by side, exactly.
    const io::Image sheet = io::readImage(command.outDir / "tube.contact.png");
    REQUIRE(sheet.width == 1440);
    REQUIRE(sheet.height == 360);
    const std::vector<int> sheetBytes = bytesOf(sheet);
    CHECK(crop(sheetBytes, 1440, 0, 0, 480, 360) == rest);
    CHECK(crop(sheetBytes, 1440, 960, 0, 480, 360) == last);
}

TEST_CASE("eval command: contact sheet tiles are the previews box filtered by a whole factor",
          "[harness][eval][preview]") {
    test::TempDir dir;
    harness::EvalCommand command = shotIn(dir);
    command.frames = {-1, 0, 1, 2, 3, 5, 8};  // negative frames and gaps
    command.previewWidth = 481;  // odd sizes: the last column and row of each preview are dropped
    command.previewHeight = 361;
    command.contactMaxWidth = 1000;
    const harness::EvalReport report = harness::evalCommand(command);
    CHECK(report.files.size() == 7 * 2 * 2 + 2);

    // The grid, written out: 7 tiles, at most 6 columns -> 6 x 2; factor ceil(6 * 481 / 1000) = 3;
    // tile floor(481 / 3) x floor(361 / 3) = 160 x 120; sheet 960 x 240 (<= 1000 wide).
    const int columns = std::min(7, 6), rows = (7 + columns - 1) / columns;
    const int factor = std::max(1, (columns * 481 + 1000 - 1) / 1000);
    const int tileW = 481 / factor, tileH = 361 / factor;
    CHECK(columns == 6);
    CHECK(rows == 2);
    CHECK(factor == 3);
    const harness::ContactSheetLayout layout = harness::contactSheetLayout(7, 481, 361, 6, 1000);
    CHECK(layout.columns == columns);
    CHECK(layout.rows == rows);
    CHECK(layout.factor == factor);
    CHECK(layout.tileWidth == tileW);
    CHECK(layout.tileHeight == tileH);

    const io::Image sheet = io::readImage(command.outDir / "tube.contact.png");
    REQUIRE(sheet.width == columns * tileW);
    REQUIRE(sheet.height == rows * tileH);
    const std::vector<int> sheetBytes = bytesOf(sheet);
    // Every tile equals the reference box filter of its preview file, exactly (integer arithmetic on
    // 8-bit values both ways).
    for (size_t t = 0; t < command.frames.size(); ++t) {
        const std::vector<int> preview =
            bytesOf(io::readImage(command.outDir / scene::frameFileName("tube", command.frames[t], ".png")));
        const int x0 = static_cast<int>(t % columns) * tileW, y0 = static_cast<int>(t / columns) * tileH;
        CHECK(crop(sheetBytes, sheet.width, x0, y0, tileW, tileH) == boxDown(preview, 481, 361, factor));
    }
    // The 5 empty cells hold the background colour, the preview default's 8-bit value.
    const glm::vec3 bg = io::PreviewOptions{}.background;
    const std::vector<int> empty = crop(sheetBytes, sheet.width, tileW, tileH, 5 * tileW, tileH);
    for (size_t i = 0; i < empty.size(); ++i) {
        const int expected = static_cast<int>(std::lround(bg[static_cast<int>(i % 3)] * 255.0f));
        if (empty[i] != expected) {
            FAIL("empty cell value " << empty[i] << " at " << i << ", expected " << expected);
        }
    }
}

TEST_CASE("eval command: bad preview sizes are rejected before anything is written",
          "[harness][eval][errors]") {
    test::TempDir dir;
    harness::EvalCommand command = shotIn(dir);
    command.previewWidth = 0;
    CHECK_THROWS_WITH(harness::evalCommand(command), Contains("preview width") && Contains("is 0"));
    command.previewWidth = 480;
    command.contactMaxWidth = 2;  // 3 columns cannot fit in 2 pixels
    CHECK_THROWS_AS(harness::evalCommand(command), InvalidInput);
    CHECK_FALSE(std::filesystem::exists(command.outDir));
    command.previews = false;  // sizes do not matter without previews
    CHECK(harness::evalCommand(command).files.size() == 6);
}

TEST_CASE("eval command: movies through ffmpeg, a note without it, an error naming a failing ffmpeg",
          "[harness][eval][movie]") {
    test::TempDir dir;
    io::writeObj(dir / "tube.obj", test::tube(kTube));
    test::writeText(dir / "shot.json", kScene);
    harness::EvalCommand command;
    command.scene = dir / "shot.json";
    command.frames = {1, 2, 3, 5, 8};
    command.movie = true;

    std::filesystem::create_directories(dir / "bin");
    {
        // No ffmpeg on PATH: not an error, a note, no movie.
        ScopedPath path((dir / "bin").string());
        command.outDir = dir / "none";
        const harness::EvalReport report = harness::evalCommand(command);
        REQUIRE(report.notes.size() == 1);
        CHECK_THAT(report.notes[0], Contains("ffmpeg"));
        CHECK_FALSE(std::filesystem::exists(command.outDir / "tube.mp4"));
        CHECK(countFiles(command.outDir) == 5 * 2 * 2 + 2);
    }
    {
        // An ffmpeg that fails: IoError naming the command and its status; no movie, no scratch files.
        test::writeText(dir / "bin" / "ffmpeg", "#!/bin/sh\nexit 3\n");
        std::filesystem::permissions(dir / "bin" / "ffmpeg", std::filesystem::perms::owner_all);
        ScopedPath path((dir / "bin").string());
        command.outDir = dir / "failing";
        try {
            (void)harness::evalCommand(command);
            FAIL("no error");
        } catch (const IoError& e) {
            CHECK_THAT(e.what(),
                       Contains((dir / "bin" / "ffmpeg").string()) && Contains("exited with status 3"));
        }
        CHECK_FALSE(std::filesystem::exists(command.outDir / "tube.mp4"));
        CHECK(countFiles(command.outDir) == 5 * 2 * 2 + 2);
    }
    if (!onPath("ffmpeg")) {
        WARN("ffmpeg not on PATH: movie encoding not tested");
        return;
    }
    command.outDir = dir / "movie";
    const harness::EvalReport report = harness::evalCommand(command);
    CHECK(report.notes.empty());
    CHECK(countFiles(command.outDir) == 5 * 2 * 2 + 2 + 2);  // no scratch folder or temporary left
    for (const char* name : {"tube", "still"}) {
        const std::filesystem::path movie = command.outDir / (std::string(name) + ".mp4");
        REQUIRE(std::filesystem::is_regular_file(movie));
        CHECK(std::filesystem::file_size(movie) > 0);
        if (!onPath("ffprobe")) {
            WARN("ffprobe not on PATH: movie frame count not checked");
            continue;
        }
        // Decoded frame count and size: exactly one frame per evaluated frame, at the preview size.
        const std::string probe =
            "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
            "stream=nb_read_frames,width,height -of csv=p=0 '" +
            movie.string() + "'";
        FILE* pipe = ::popen(probe.c_str(), "r");
        REQUIRE(pipe != nullptr);
        char line[256] = {};
        const bool read = std::fgets(line, sizeof(line), pipe) != nullptr;
        ::pclose(pipe);
        REQUIRE(read);
        CHECK(std::string(line).substr(0, std::string(line).find_last_not_of("\r\n") + 1) == "480,360,5");
    }
}
