#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/uvwarp/tile_warp.h"
#include "image_support.h"
#include "point_cache_support.h"
#include "progress_bar.h"
#include "test_support.h"
#include "uvwarp_command.h"

using namespace deformkit;
namespace fs = std::filesystem;

namespace {

constexpr int kTexels = 32;  // maps and grid: 32 x 32
constexpr int kQuads = 16;   // mesh quads per side and chart

// One n x n quad chart per entry of `tileU` (chart c covers u in [tileU[c], tileU[c] + 1], v in [0, 1]), as
// OBJ text. Vertex (i, j) of a chart sits at (stretch * i / n, j / n, 0) plus 2 along z per chart, so rest
// positions equal tile-local UVs when stretch = 1. Without `uvs` no vt lines are written.
std::string planeObj(double stretch, const std::vector<int>& tileU = {0}, bool uvs = true, int n = kQuads) {
    std::ostringstream out;
    out.precision(9);
    for (size_t c = 0; c < tileU.size(); ++c)
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i)
                out << "v " << stretch * i / n << " " << static_cast<double>(j) / n << " " << 2.0 * c << "\n";
    if (uvs) {
        for (int u0 : tileU)
            for (int j = 0; j <= n; ++j)
                for (int i = 0; i <= n; ++i)
                    out << "vt " << u0 + static_cast<double>(i) / n << " " << static_cast<double>(j) / n
                        << "\n";
    }
    for (size_t c = 0; c < tileU.size(); ++c) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const int a = static_cast<int>(c) * (n + 1) * (n + 1) + j * (n + 1) + i + 1;  // 1-based
                out << "f";
                for (int k : {a, a + 1, a + n + 2, a + n + 1}) {
                    out << " " << k;
                    if (uvs) out << "/" << k;
                }
                out << "\n";
            }
        }
    }
    return out.str();
}

// Rigidity 1 in disks of radius 0.1 on a 3 x 3 lattice, 0 elsewhere, at texel centres (grid.h).
io::Image disks(int t = kTexels) {
    io::Image image(t, t, 1);
    for (int y = 0; y < t; ++y)
        for (int x = 0; x < t; ++x)
            for (double cu : {0.25, 0.5, 0.75})
                for (double cv : {0.25, 0.5, 0.75})
                    if (std::hypot((x + 0.5) / t - cu, 1.0 - (y + 0.5) / t - cv) < 0.1)
                        image.at(x, y, 0) = 1.0f;
    return image;
}

// The scene: rest.obj, anim.0001-0003.obj (undeformed, 1.25x and 1.5x along u), rig.1001.exr, col.1001.exr
// and an out folder.
// An uncompressed scanline OpenEXR file of float channels named `names` (stored sorted by name, as the
// format requires), channel k holding planes[k] (width x height, top row first); spelled out from the
// OpenEXR file layout: magic, version, header attributes, the offset table, then one chunk per scanline.
std::string layeredExr(int32_t width, int32_t height,
                       const std::vector<std::pair<std::string, io::Image>>& planes) {
    std::vector<std::pair<std::string, io::Image>> sorted = planes;
    std::ranges::sort(sorted, {}, &std::pair<std::string, io::Image>::first);
    std::string out;
    const auto i32 = [&](int32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    const auto attribute = [&](const std::string& name, const std::string& type, const std::string& value) {
        out += name + '\0' + type + '\0';
        i32(static_cast<int32_t>(value.size()));
        out += value;
    };
    const auto ints = [](std::initializer_list<int32_t> values) {
        std::string v;
        for (int32_t x : values)
            v.append(reinterpret_cast<const char*>(&x), 4);
        return v;
    };
    out += "\x76\x2f\x31\x01";
    i32(2);
    std::string list;
    for (const auto& [name, plane] : sorted)
        list += name + '\0' + ints({2, 0, 1, 1});  // float, pLinear 0 + reserved, sampling 1 x 1
    attribute("channels", "chlist", list + '\0');
    attribute("compression", "compression", std::string(1, '\0'));
    attribute("dataWindow", "box2i", ints({0, 0, width - 1, height - 1}));
    attribute("displayWindow", "box2i", ints({0, 0, width - 1, height - 1}));
    attribute("lineOrder", "lineOrder", std::string(1, '\0'));
    attribute("pixelAspectRatio", "float", ints({0x3f800000}));
    attribute("screenWindowCenter", "v2f", ints({0, 0}));
    attribute("screenWindowWidth", "float", ints({0x3f800000}));
    out += '\0';
    const auto lineBytes = static_cast<int64_t>(width) * 4 * static_cast<int64_t>(sorted.size());
    const auto first = static_cast<int64_t>(out.size()) + 8 * static_cast<int64_t>(height);
    for (int32_t y = 0; y < height; ++y) {
        const int64_t offset = first + y * (8 + lineBytes);
        out.append(reinterpret_cast<const char*>(&offset), 8);
    }
    for (int32_t y = 0; y < height; ++y) {
        i32(y);
        i32(static_cast<int32_t>(lineBytes));
        for (const auto& [name, plane] : sorted)
            for (int32_t x = 0; x < width; ++x) {
                const float v = plane.at(x, y, 0);
                out.append(reinterpret_cast<const char*>(&v), 4);
            }
    }
    return out;
}

struct Scene {
    test::TempDir dir;
    harness::UvWarpCommand command;

    explicit Scene(const std::vector<int>& tileU = {0}) {
        test::writeText(dir / "rest.obj", planeObj(1.0, tileU));
        const double stretch[3] = {1.0, 1.25, 1.5};
        for (int f = 1; f <= 3; ++f)
            test::writeText(dir / ("anim.000" + std::to_string(f) + ".obj"), planeObj(stretch[f - 1], tileU));
        io::writeImage(dir / "rig.1001.exr", disks(), {io::PixelType::Float, {}});
        io::writeImage(dir / "col.1001.exr", test::exactHalfTexture(kTexels), {io::PixelType::Float, {}});
        fs::create_directories(dir / "out");
        command.rest = dir / "rest.obj";
        command.deformed = dir / "anim.####.obj";
        command.frames = {1, 2, 3};
        command.rigidity = dir / "rig.<UDIM>.exr";
        command.out = dir / "out/redirect.<UDIM>.####.exr";
    }
    [[nodiscard]] fs::path redirect(int frame, int tile = 1001) const {
        return dir / ("out/redirect." + std::to_string(tile) + ".000" + std::to_string(frame) + ".exr");
    }
    [[nodiscard]] fs::path baked(int frame) const {
        return dir / ("out/col.1001.000" + std::to_string(frame) + ".exr");
    }
};

// Largest |redirect - texel centre| over the texels: 0 for the identity, whose texel (x, y) holds its own
// centre ((x + 0.5) / T, 1 - (y + 0.5) / T).
double distanceFromIdentity(const io::Image& redirect) {
    double worst = 0.0;
    for (int y = 0; y < redirect.height; ++y) {
        for (int x = 0; x < redirect.width; ++x) {
            const double u = (x + 0.5) / redirect.width, v = 1.0 - (y + 0.5) / redirect.height;
            worst = std::max({worst, std::abs(redirect.at(x, y, 0) - u), std::abs(redirect.at(x, y, 1) - v)});
        }
    }
    return worst;
}

std::string attribute(const io::ImageInfo& info, const std::string& name) {
    for (const auto& [key, value] : info.attributes)
        if (key == name) return value;
    return "(missing)";
}

std::vector<nlohmann::json> logLines(const fs::path& path) {
    std::vector<nlohmann::json> lines;
    std::istringstream in(test::readText(path));
    for (std::string line; std::getline(in, line);)
        lines.push_back(nlohmann::json::parse(line));
    return lines;
}

}  // namespace

TEST_CASE("uvwarp command: frame lists, tile lists and output paths parse", "[harness][uvwarp]") {
    CHECK(harness::parseFrames("1-3") == std::vector<int>{1, 2, 3});
    CHECK(harness::parseFrames("7") == std::vector<int>{7});
    CHECK(harness::parseFrames("10,1-3,2") == std::vector<int>{1, 2, 3, 10});
    CHECK(harness::parseFrames("-2-1") == std::vector<int>{-2, -1, 0, 1});
    CHECK(harness::parseFrames("-3--2") == std::vector<int>{-3, -2});
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFrames("5-1"); }),
               Catch::Contains("--frames") && Catch::Contains("'5-1' ends before it starts"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFrames("1-x"); }),
               Catch::Contains("'1-x' is not a frame range"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFrames("1,,2"); }),
               Catch::Contains("'' is not a frame"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFrames("0-2000000"); }),
               Catch::Contains("more than 1000000"));
    CHECK(harness::parseFrames("999999999-1000000000") == std::vector<int>{999999999, 1000000000});
    for (const char* far :
         {"1000000001", "2147483647", "-1000000001", "-9223372036854775808", "1-2147483648"})
        CHECK_THAT(test::errorOf<Error>([far] { (void)harness::parseFrames(far); }),
                   Catch::Contains("is out of range (expected frames from -1000000000 to 1000000000)"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseFrames(""); }),
               Catch::Contains("'' is not a frame"));
    CHECK(harness::parseTiles("1012,1001,1002") == std::vector<int>{1001, 1002, 1012});
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseTiles("1002,1001,1002"); }),
               Catch::Contains("--tiles: lists tile 1002 twice (expected each tile once, comma separated)"));
    CHECK_THAT(test::errorOf<Error>([] { (void)harness::parseTiles("1001,1000"); }),
               Catch::Contains("--tiles") && Catch::Contains("'1000' is not a UDIM tile"));
    // A list option's values: spaces and commas alike; an empty item is refused, not dropped.
    CHECK(harness::parseNumberList({"1", "1", "10"}, "--sweeps") == std::vector<double>{1, 1, 10});
    CHECK(harness::parseNumberList({"4,8", "16"}, "--sweeps") == std::vector<double>{4, 8, 16});
    CHECK(harness::parseNumberList({"4, 8", " 16 32 ", "+2"}, "--sweeps") ==
          std::vector<double>{4, 8, 16, 32, 2});
    for (const char* bad : {"4,,8", "4,8,", ",4", ""})
        CHECK_THAT(test::errorOf<InvalidInput>([bad] { (void)harness::parseNumberList({bad}, "--sweeps"); }),
                   Catch::Contains(std::string("--sweeps: '") + bad + "' has an empty item"));
    CHECK_THAT(test::errorOf<InvalidInput>([] { (void)harness::parseNumberList({"4,x"}, "--sweeps"); }),
               Catch::Contains("'4,x' has 'x', not a number"));
    CHECK(uvwarp::tileFramePath("out/r.<UDIM>.####.exr", 1012, 7) == fs::path("out/r.1012.0007.exr"));
    CHECK(uvwarp::tileFramePath("r_<UVTILE>.%03d.exr", 1012, -4) == fs::path("r_u2_v2.-004.exr"));
}

TEST_CASE("uvwarp command: redirect maps and bakes per frame, identity for the undeformed frame",
          "[harness][uvwarp]") {
    Scene s;
    s.command.texture = s.dir / "col.<UDIM>.exr";
    s.command.bake = s.dir / "out/col.<UDIM>.####.exr";
    s.command.log = s.dir / "log.jsonl";
    std::ostringstream progress;
    harness::ProgressBar bar(progress);
    const uvwarp::ShotReport report = harness::uvwarpCommand(s.command, &bar);
    REQUIRE(report.tiles.size() == 1);
    CHECK(report.tiles[0].tile == 1001);
    CHECK(report.tiles[0].warped);
    CHECK(report.tiles[0].written == 3);
    CHECK(report.tiles[0].baked == 3);
    CHECK(report.tiles[0].notes.empty());
    CHECK_THAT(progress.str(), Catch::Contains("3/3") && Catch::Contains("ETA"));

    // Frame 1 is the rest pose: its redirect is the identity. Float32 uv after barycentric interpolation
    // of grid corners: a few ulps of 1 (6e-8 each).
    const io::Image first = io::readImage(s.redirect(1));
    REQUIRE(first.width == kTexels);
    REQUIRE(first.channels == 2);
    CHECK(distanceFromIdentity(first) < 1e-5);
    // Baked through the identity, the texture comes back: bilinear weights (1, 0) at texel centres, up to
    // the float rounding of the redirect's uv (a few ulps of 1, 2.4e-7, times 32 texels times a step of up to
    // 1 between neighbours: 8e-6), stored as float like the float texture (half storage used to round the
    // texture's multiples of 1/256 back exactly).
    const io::Image tex = test::exactHalfTexture(kTexels), bakedFirst = io::readImage(s.baked(1));
    REQUIRE(bakedFirst.pixels.size() == tex.pixels.size());
    double worst = 0.0;
    for (size_t k = 0; k < tex.pixels.size(); ++k)
        worst = std::max(worst, static_cast<double>(std::abs(bakedFirst.pixels[k] - tex.pixels[k])));
    CHECK(worst < 1e-5);
    CHECK(io::readImageInfo(s.baked(1)).pixelType == "float");

    // Frame 3 (1.5x) warps, and is what a TileWarp solving frame 3 from the identity gives, bit for bit
    // (a shot's frames are solved from the identity by default).
    const io::Image third = io::readImage(s.redirect(3));
    CHECK(distanceFromIdentity(third) > 0.5 / kTexels);
    uvwarp::TileWarp reference(io::readObj(s.command.rest).mesh, 1001, disks(), {}, uvwarp::shotOptions());
    reference.solve(io::readObj(s.dir / "anim.0003.obj").mesh.points());
    CHECK(reference.redirect().pixels == third.pixels);

    const io::ImageInfo info = io::readImageInfo(s.redirect(3));
    CHECK(info.pixelType == "float");
    CHECK(attribute(info, "deformkit:uvwarp:tile") == "1001");
    CHECK(attribute(info, "deformkit:uvwarp:frame") == "3");
    CHECK(attribute(info, "deformkit:version") != "(missing)");
    const auto solver = nlohmann::json::parse(attribute(info, "deformkit:uvwarp:solver"));
    CHECK(solver.at("cells") == kTexels);
    CHECK(solver.at("iterations") == uvwarp::SolverOptions{}.iterations);
    CHECK(solver.at("smoothing") == 0.1);  // written as the float's shortest decimal
    CHECK(nlohmann::json::parse(attribute(info, "deformkit:uvwarp:inputs")).at("mask") == "derived");
    // The map carries what it delivers, the log line's figures.
    const auto delivered = nlohmann::json::parse(attribute(info, "deformkit:uvwarp:metrics"));
    CHECK(delivered.at("inverted_triangles") == 0);
    CHECK(delivered.at("chart_texels") == kTexels * kTexels);

    // One log line per frame with the metrics: the undeformed frame has no stretch to remove, the 1.5x
    // frame has some and the warp removes most of it.
    const std::vector<nlohmann::json> lines = logLines(*s.command.log);
    REQUIRE(lines.size() == 3);
    for (int f = 0; f < 3; ++f) {
        CHECK(lines[f].at("tile") == 1001);
        CHECK(lines[f].at("frame") == f + 1);
        CHECK(lines[f].at("status") == "written");
        CHECK(lines[f].at("metrics").at("inverted_triangles") == 0);  // the delivered map's
        CHECK(lines[f].at("metrics").at("off_chart_texels") == 0);
        CHECK(lines[f].at("metrics").at("grid_fold_overs") == 0);  // the solver's grid, a diagnostic
        CHECK(lines[f].at("seconds").at("solve").get<double>() >= 0.0);
    }
    CHECK(lines[0].at("metrics").at("identity_stretch_error").get<double>() < 1e-5);
    const double identity = lines[2].at("metrics").at("identity_stretch_error").get<double>();
    CHECK(identity > 0.2);  // disks stretched 1.5x along u: horizontal rigid edges alone are 0.5 off
    CHECK(lines[2].at("metrics").at("rigid_stretch_error").get<double>() < 0.5 * identity);
}

TEST_CASE("uvwarp command: a rerun solves only the missing outputs, each from the identity",
          "[harness][uvwarp]") {
    Scene s;
    s.command.log = s.dir / "log.jsonl";
    (void)harness::uvwarpCommand(s.command);
    const std::string frame2 = test::readText(s.redirect(2)), frame3 = test::readText(s.redirect(3));
    fs::remove(s.redirect(2));
    const uvwarp::ShotReport again = harness::uvwarpCommand(s.command);
    CHECK(again.tiles[0].written == 1);
    CHECK(again.tiles[0].replayed == 0);  // frame 1 is not solved again: frame 2 does not depend on it
    CHECK(again.tiles[0].skipped == 2);
    CHECK(test::readText(s.redirect(2)) == frame2);
    CHECK(test::readText(s.redirect(3)) == frame3);
}

TEST_CASE("uvwarp command: warm-started, a rerun skips existing outputs and replays the warm start",
          "[harness][uvwarp]") {
    Scene s;
    s.command.options.solver.warmStart = true;
    s.command.log = s.dir / "log.jsonl";
    (void)harness::uvwarpCommand(s.command);
    const std::string frame2 = test::readText(s.redirect(2)), frame3 = test::readText(s.redirect(3));
    const auto stamp = fs::last_write_time(s.redirect(3));

    uvwarp::ShotReport again = harness::uvwarpCommand(s.command);
    CHECK(again.tiles[0].written == 0);
    CHECK(again.tiles[0].replayed == 0);
    CHECK(again.tiles[0].skipped == 3);
    CHECK(fs::last_write_time(s.redirect(3)) == stamp);

    // A job killed before frame 2 was written: frame 1 is solved again (not written) to warm-start frame 2,
    // which comes out byte for byte as in the uninterrupted run; frame 3 is not touched.
    fs::remove(s.redirect(2));
    again = harness::uvwarpCommand(s.command);
    CHECK(again.tiles[0].written == 1);
    CHECK(again.tiles[0].replayed == 1);
    CHECK(again.tiles[0].skipped == 1);
    CHECK(test::readText(s.redirect(2)) == frame2);
    CHECK(test::readText(s.redirect(3)) == frame3);
    CHECK(fs::last_write_time(s.redirect(3)) == stamp);

    // The log is appended: 3 lines per run, the last run's statuses in frame order.
    const std::vector<nlohmann::json> lines = logLines(*s.command.log);
    REQUIRE(lines.size() == 9);
    CHECK(lines[3].at("status") == "skipped");
    CHECK(lines[6].at("status") == "replayed");
    CHECK(lines[7].at("status") == "written");
    CHECK(lines[8].at("status") == "skipped");
}

TEST_CASE("uvwarp command: bad input names the file and writes nothing", "[harness][uvwarp]") {
    SECTION("a missing frame") {
        Scene s;
        fs::remove(s.dir / "anim.0002.obj");
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("anim.0002.obj") && Catch::Contains("frame 2: is missing"));
        CHECK(fs::is_empty(s.dir / "out"));
    }
    SECTION("a frame with another vertex count") {
        Scene s;
        test::writeText(s.dir / "anim.0002.obj", planeObj(1.25, {0}, true, kQuads / 2));
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("anim.0002.obj") && Catch::Contains("has 81 vertices"));
        CHECK(fs::exists(s.redirect(1)));  // frames before it are complete
        CHECK_FALSE(fs::exists(s.redirect(2)));
    }
    SECTION("a sequence whose faces list the rest mesh's vertices in another order") {
        // Each face starts at its second corner: the same positions, another topology. The first frame read
        // is held to the rest mesh, as a scene holds it, not taken as the sequence's own reference.
        Scene s;
        const double stretch[3] = {1.0, 1.25, 1.5};
        for (int f = 1; f <= 3; ++f) {
            std::istringstream in(planeObj(stretch[f - 1]));
            std::string rotated;
            for (std::string line; std::getline(in, line);) {
                if (line.rfind("f ", 0) == 0) {
                    const size_t second = line.find(' ', 2);
                    line = "f" + line.substr(second) + " " + line.substr(2, second - 2);
                }
                rotated += line + "\n";
            }
            test::writeText(s.dir / ("anim.000" + std::to_string(f) + ".obj"), rotated);
        }
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("anim.0001.obj: face 0: has 4 vertices (1 18 17 0) where rest.obj has "
                                   "4 vertices (0 1 18 17)"));
        CHECK(fs::is_empty(s.dir / "out"));
    }
    SECTION("a texture pattern that matches no file for any tile") {
        Scene s;
        s.command.texture = s.dir / "colr.<UDIM>.exr";  // col.1001.exr is there
        s.command.bake = s.dir / "out/col.<UDIM>.####.exr";
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("colr.<UDIM>.exr: matches no file for any of the mesh's tiles (1001) "
                                   "(expected textures for some tiles, or none given)"));
        CHECK(fs::is_empty(s.dir / "out"));
    }
    SECTION("a layered EXR: the channel read is named as the file names it") {
        // Channels are stored sorted by name: "mask.Y" is channel 0, not the rigidity layer. The note said
        // "channel 0 (red) is read" of it; it names the layer, so the mistake shows.
        Scene s;
        test::writeText(
            s.dir / "layers.1001.exr",
            layeredExr(kTexels, kTexels,
                       {{"rigidity.Y", disks()}, {"mask.Y", io::Image(kTexels, kTexels, 1, 1.0f)}}));
        REQUIRE(io::readImageInfo(s.dir / "layers.1001.exr").channelNames ==
                std::vector<std::string>{"mask.Y", "rigidity.Y"});
        CHECK(io::readImage(s.dir / "layers.1001.exr").at(3, 5, 1) == disks().at(3, 5, 0));
        s.command.rigidity = s.dir / "layers.<UDIM>.exr";
        s.command.frames = {1};
        const uvwarp::ShotReport report = harness::uvwarpCommand(s.command);
        REQUIRE(report.tiles.size() == 1);
        CHECK_THAT(report.tiles[0].notes.at(0), Catch::Contains("layers.1001.exr' has 2 channels: channel 0 "
                                                                "('mask.Y') is read"));
    }
    SECTION("a rigidity map that is 0 everywhere") {
        // Identity maps were written with "0 fold-overs" and nothing else said.
        Scene s;
        io::writeImage(s.dir / "rig.1001.exr", io::Image(kTexels, kTexels, 1, 0.0f),
                       {io::PixelType::Float, {}});
        s.command.frames = {2};
        const uvwarp::ShotReport report = harness::uvwarpCommand(s.command);
        REQUIRE(report.tiles.size() == 1);
        REQUIRE(report.tiles[0].notes.size() == 1);
        CHECK_THAT(report.tiles[0].notes[0],
                   Catch::Contains("rig.1001.exr' is 0 at every texel: nothing is held "
                                   "rigid, the redirect maps are the identity"));
        CHECK(distanceFromIdentity(io::readImage(s.redirect(2))) < 1e-5);
    }
    SECTION("a texture with a texel that is not finite") {
        // One NaN texel became a patch of NaN in every bake: refused naming the file and the texel, before
        // the frame's outputs are written.
        Scene s;
        io::Image texture = io::readImage(s.dir / "col.1001.exr");
        texture.at(5, 9, 2) = std::nanf("");
        io::writeImage(s.dir / "col.1001.exr", texture, {io::PixelType::Float, {}});
        s.command.texture = s.dir / "col.<UDIM>.exr";
        s.command.bake = s.dir / "out/col.<UDIM>.####.exr";
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains((s.dir / "col.1001.exr").string() +
                                   ": pixel (5, 9) channel 2: is nan (expected finite values"));
        CHECK(fs::is_empty(s.dir / "out"));
    }
    SECTION("a rest mesh without UVs") {
        Scene s;
        test::writeText(s.dir / "rest.obj", planeObj(1.0, {0}, false));
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("rest.obj") && Catch::Contains("has no UVs"));
        CHECK(fs::is_empty(s.dir / "out"));
    }
    SECTION("a resolution that is not a power of two") {
        Scene s;
        s.command.options.cells = 24;
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("option resolution: is 24") && Catch::Contains("power of two"));
    }
    SECTION("a mask of another size than the rigidity map") {
        Scene s;
        io::writeImage(s.dir / "mask.1001.exr", io::Image(16, 16, 1, 1.0f));
        s.command.mask = s.dir / "mask.<UDIM>.exr";
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("mask.1001.exr") && Catch::Contains("16 x 16 texels") &&
                       Catch::Contains("32 x 32, the size of"));
        CHECK(fs::is_empty(s.dir / "out"));
    }
    SECTION("a rigidity map whose size is not a power of two") {
        Scene s;
        io::writeImage(s.dir / "rig.1001.exr", disks(48), {io::PixelType::Float, {}});
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("rig.1001.exr") && Catch::Contains("48 texels per side"));
        // With the grid's size given, the map is resampled and the redirect keeps the map's size.
        s.command.options.cells = 32;
        s.command.frames = {1};
        (void)harness::uvwarpCommand(s.command);
        const io::Image redirect = io::readImage(s.redirect(1));
        CHECK(redirect.width == 48);
        CHECK(distanceFromIdentity(redirect) < 1e-5);  // the rest pose, as above
    }
    SECTION("rigidity values outside [0, 1]") {
        Scene s;
        io::Image bad = disks();
        bad.at(5, 6, 0) = 1.5f;
        io::writeImage(s.dir / "rig.1001.exr", bad, {io::PixelType::Float, {}});
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("rig.1001.exr") && Catch::Contains("texel (5, 6)"));
        CHECK(fs::is_empty(s.dir / "out"));
    }
    SECTION("an output pattern without a frame token, a tile the mesh does not have") {
        Scene s;
        s.command.out = s.dir / "out/redirect.<UDIM>.exr";
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("--out") && Catch::Contains("no frame token"));
        // Two tokens were said to be none.
        s.command.out = s.dir / "out/redirect.<UDIM>.####.v###.exr";
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("--out") && Catch::Contains("has 2 frame tokens in its file name"));
        s.command.out = s.dir / "out/redirect.<UDIM>.####.exr";
        s.command.tiles = {1001, 1005};
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("tile 1005") && Catch::Contains("no UV face"));
        s.command.tiles = {};
        test::writeText(s.dir / "afile", "x");
        s.command.out = s.dir / "afile/redirect.<UDIM>.####.exr";
        CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains("afile' is a file, not a folder"));
    }
}

TEST_CASE("uvwarp command: a tile without a rigidity map is left unwarped and reported",
          "[harness][uvwarp]") {
    Scene s({0, 1});  // charts in tiles 1001 and 1002, rigidity for 1001 only
    s.command.log = s.dir / "log.jsonl";
    const uvwarp::ShotReport report = harness::uvwarpCommand(s.command);
    REQUIRE(report.tiles.size() == 2);
    CHECK(report.tiles[0].written == 3);
    CHECK_FALSE(report.tiles[1].warped);
    CHECK(report.tiles[1].written == 0);
    REQUIRE(report.tiles[1].notes.size() == 1);
    CHECK_THAT(report.tiles[1].notes[0],
               Catch::Contains("no rigidity map") && Catch::Contains("rig.1002.exr"));
    CHECK(fs::exists(s.redirect(3, 1001)));
    CHECK_FALSE(fs::exists(s.redirect(1, 1002)));
    const std::vector<nlohmann::json> lines = logLines(*s.command.log);
    REQUIRE(lines.size() == 6);
    CHECK(lines[3].at("tile") == 1002);
    CHECK(lines[3].at("status") == "unwarped");
    const std::vector<std::string> summary = uvwarp::shotSummary(report);
    REQUIRE(summary.size() == 2);
    CHECK_THAT(summary[0], Catch::StartsWith("tile 1001: 3 frames written"));
    CHECK_THAT(summary[1], Catch::StartsWith("tile 1002: left unwarped: no rigidity map"));

    // Without any rigidity map the pattern itself is wrong: an error.
    fs::remove(s.dir / "rig.1001.exr");
    CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(s.command); }),
               Catch::Contains("--rigidity") && Catch::Contains("no tile has a rigidity map"));
}

TEST_CASE("uvwarp command: an orientation map scales the orientation preservation per texel",
          "[harness][uvwarp]") {
    // References that need no tolerance: the solver multiplies the global amount by the map, so a map of
    // ones must give the bytes of no map, and a map of zeros the bytes of a zero global amount. Without a
    // map the density heuristic is off here (a shot's default is on: orientationDensity), so that no map
    // means 1 everywhere.
    auto run = [](const io::Image* map, float preservation) {
        Scene s;
        s.command.options.orientationDensity = 0;
        s.command.options.solver.orientationPreservation = preservation;
        if (map != nullptr) {
            io::writeImage(s.dir / "orient.1001.exr", *map, {io::PixelType::Float, {}});
            s.command.orientation = s.dir / "orient.<UDIM>.exr";
        }
        const uvwarp::ShotReport report = harness::uvwarpCommand(s.command, nullptr);
        REQUIRE(report.tiles.size() == 1);
        CHECK(report.tiles[0].notes.empty());
        return io::readImage(s.redirect(3));
    };
    io::Image ones(kTexels, kTexels, 1), zeros(kTexels, kTexels, 1);
    std::fill(ones.pixels.begin(), ones.pixels.end(), 1.0f);
    const io::Image none = run(nullptr, 0.5f);
    CHECK(run(&ones, 0.5f).pixels == none.pixels);
    CHECK(run(&zeros, 0.5f).pixels == run(nullptr, 0.0f).pixels);
    // And the amount matters on this scene: 0.5 everywhere differs from 0.
    CHECK(none.pixels != run(nullptr, 0.0f).pixels);

    // A pattern that matches no tile's map is a typo, refused before anything is written (a tile without
    // one, where another tile has its map, means the density heuristic's map, with a note: test_uvwarp.py);
    // a wrong size or a value outside [0, 1] is an error naming the file.
    Scene missing;
    missing.command.orientation = missing.dir / "orient.<UDIM>.exr";
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(missing.command, nullptr); }),
               Catch::Contains("--orientation: " + (missing.dir / "orient.<UDIM>.exr").string() +
                               ": matches no file for any of the mesh's tiles (1001) (expected orientation "
                               "maps for some tiles, or none given)"));

    Scene wrongSize;
    io::writeImage(wrongSize.dir / "orient.1001.exr", io::Image(kTexels / 2, kTexels / 2, 1),
                   {io::PixelType::Float, {}});
    wrongSize.command.orientation = wrongSize.dir / "orient.<UDIM>.exr";
    CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(wrongSize.command, nullptr); }),
               Catch::Contains("orient.1001.exr") && Catch::Contains("orientation map") &&
                   Catch::Contains("16 x 16 texels"));
    CHECK_FALSE(fs::exists(wrongSize.redirect(1)));

    Scene outOfRange;
    io::Image bad(kTexels, kTexels, 1);
    bad.at(3, 5, 0) = 1.5f;
    io::writeImage(outOfRange.dir / "orient.1001.exr", bad, {io::PixelType::Float, {}});
    outOfRange.command.orientation = outOfRange.dir / "orient.<UDIM>.exr";
    CHECK_THAT(test::errorOf<Error>([&] { (void)harness::uvwarpCommand(outOfRange.command, nullptr); }),
               Catch::Contains("orient.1001.exr") && Catch::Contains("1.5"));
}

TEST_CASE("uvwarp command: faces without UVs are in no tile, left alone and reported once",
          "[harness][uvwarp]") {
    Scene plain({0, 1});
    Scene mixed({0, 1});  // the same files, each with one more face, without texture coordinates
    for (const char* name : {"rest.obj", "anim.0001.obj", "anim.0002.obj", "anim.0003.obj"}) {
        std::ofstream(mixed.dir / name, std::ios::app) << "f 1 3 2\n";
    }
    for (Scene* s : {&plain, &mixed})
        io::writeImage(s->dir / "rig.1002.exr", disks(), {io::PixelType::Float, {}});
    const uvwarp::ShotReport plainReport = harness::uvwarpCommand(plain.command);
    const uvwarp::ShotReport report = harness::uvwarpCommand(mixed.command);
    REQUIRE(report.tiles.size() == 2);
    int said = 0;
    for (const auto& tile : report.tiles)
        for (const std::string& note : tile.notes)
            said += note.find("no UVs") != std::string::npos ? 1 : 0;
    CHECK(said == 1);
    REQUIRE_FALSE(report.tiles[0].notes.empty());
    CHECK(report.tiles[0].notes[0] == "1 face has no UVs: in no tile, left unwarped");
    for (int tile : {1001, 1002}) {
        CHECK(io::readImage(mixed.redirect(3, tile)).pixels == io::readImage(plain.redirect(3, tile)).pixels);
    }
    CHECK(plainReport.tiles[0].notes.empty());
}

TEST_CASE("uvwarp command: maps of several channels are read from channel 0 and said once per map",
          "[harness][uvwarp]") {
    // A rigger's map exported as RGBA (the rigidity in red, other values in the other channels) and a
    // warp mask as RGB give the bytes of their one-channel forms, with one note each.
    Scene plain;
    plain.command.frames = {3};
    const uvwarp::ShotReport reference = harness::uvwarpCommand(plain.command);
    CHECK(reference.tiles[0].notes.empty());

    Scene colour;
    colour.command.frames = {3};
    const io::Image rigidity = disks();
    io::Image rgba(kTexels, kTexels, 4);
    io::Image rgbMask(kTexels, kTexels, 3);
    for (int y = 0; y < kTexels; ++y) {
        for (int x = 0; x < kTexels; ++x) {
            rgba.at(x, y, 0) = rigidity.at(x, y, 0);
            rgba.at(x, y, 1) = 0.25f;  // other channels hold anything: they are not read
            rgba.at(x, y, 2) = 1.0f - rigidity.at(x, y, 0);
            rgba.at(x, y, 3) = 1.0f;
            for (int c = 0; c < 3; ++c)
                rgbMask.at(x, y, c) = (c == 0) ? 1.0f : 0.0f;
        }
    }
    io::writeImage(colour.dir / "rig.1001.exr", rgba, {io::PixelType::Float, {}});
    io::writeImage(colour.dir / "mask.1001.exr", rgbMask, {io::PixelType::Float, {}});
    io::writeImage(plain.dir / "mask.1001.exr", io::Image(kTexels, kTexels, 1, 1.0f),
                   {io::PixelType::Float, {}});
    colour.command.mask = colour.dir / "mask.<UDIM>.exr";
    plain.command.mask = plain.dir / "mask.<UDIM>.exr";
    fs::remove(plain.redirect(3));
    (void)harness::uvwarpCommand(plain.command);
    const uvwarp::ShotReport report = harness::uvwarpCommand(colour.command);
    REQUIRE(report.tiles[0].notes.size() == 2);
    CHECK_THAT(report.tiles[0].notes[0],
               Catch::Contains("rigidity map '" + (colour.dir / "rig.1001.exr").string() +
                               "' has 4 channels: channel 0 (red) is read"));
    CHECK_THAT(report.tiles[0].notes[1], Catch::Contains("mask.1001.exr' has 3 channels: channel 0"));
    CHECK(test::sameBits(io::readImage(colour.redirect(3)).pixels, io::readImage(plain.redirect(3)).pixels));
    // Said once in the summary, not per frame.
    colour.command.frames = {1, 2, 3};
    fs::remove(colour.redirect(3));
    const std::vector<std::string> summary = uvwarp::shotSummary(harness::uvwarpCommand(colour.command));
    CHECK(std::count_if(summary.begin(), summary.end(), [](const std::string& line) {
              return line.find("4 channels") != std::string::npos;
          }) == 1);
}

TEST_CASE("uvwarp command: a PC2 or MDD cache of the shot writes the maps and bakes of its OBJ sequence",
          "[harness][uvwarp][point_cache]") {
    // The OBJ sequence's positions, as the OBJ reader gives them (float32), written into caches by the test's
    // own encoder; the caches' frames 1-3 are the sequence's.
    std::vector<std::vector<glm::vec3>> positions;
    Scene s;
    for (int f = 1; f <= 3; ++f) {
        const io::ObjContent obj = io::readObj(s.dir / ("anim.000" + std::to_string(f) + ".obj"));
        const auto p = obj.mesh.points();
        positions.emplace_back(p.begin(), p.end());
    }
    test::writeText(s.dir / "anim.pc2", test::pc2Bytes(1.0f, 1.0f, positions));
    // MDD starting at frame 0 as Blender's exporter times it; --cache-start 1 numbers it from 1.
    test::writeText(s.dir / "anim.mdd", test::mddBytes({0.0f, 1.0f / 24, 2.0f / 24}, positions));
    s.command.texture = s.dir / "col.<UDIM>.exr";
    s.command.bake = s.dir / "out/col.<UDIM>.####.exr";
    (void)harness::uvwarpCommand(s.command);

    for (const char* cache : {"anim.pc2", "anim.mdd"}) {
        CAPTURE(cache);
        Scene c;
        c.command.deformed = s.dir / cache;
        if (std::string(cache) == "anim.mdd") c.command.cacheStart = 1.0;
        c.command.texture = c.dir / "col.<UDIM>.exr";
        c.command.bake = c.dir / "out/col.<UDIM>.####.exr";
        const uvwarp::ShotReport report = harness::uvwarpCommand(c.command);
        CHECK(report.tiles.at(0).written == 3);
        for (int f = 1; f <= 3; ++f) {
            // The pixels bit for bit; the headers differ only where they name the frame's input.
            CHECK(io::readImage(c.redirect(f)).pixels == io::readImage(s.redirect(f)).pixels);
            CHECK(io::readImage(c.baked(f)).pixels == io::readImage(s.baked(f)).pixels);
            const io::ImageInfo mine = io::readImageInfo(c.redirect(f)),
                                theirs = io::readImageInfo(s.redirect(f));
            CHECK(attribute(mine, "deformkit:uvwarp:metrics") ==
                  attribute(theirs, "deformkit:uvwarp:metrics"));
            CHECK(attribute(mine, "deformkit:uvwarp:solver") == attribute(theirs, "deformkit:uvwarp:solver"));
            const auto inputs = nlohmann::json::parse(attribute(mine, "deformkit:uvwarp:inputs"));
            CHECK_THAT(inputs.dump(), Catch::Contains(std::string(cache) + " frame " + std::to_string(f)));
        }
    }

    // Bad caches stop the command before anything is written, naming the file and what is wrong.
    Scene bad;
    bad.command.deformed = s.dir / "anim.pc2";
    bad.command.frames = {2, 3, 4};
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(bad.command); }),
               Catch::Contains("anim.pc2: frame 4: is not in the cache (expected one of its frames 1 to 3)"));
    bad.command.frames = {1, 2, 3};
    bad.command.deformed = s.dir / "anim.mdd";  // frames 1-3 by default
    bad.command.cacheStart = 5.0;
    CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(bad.command); }),
               Catch::Contains("anim.mdd: frame 1: is not in the cache (expected one of its frames 5 to 7)"));
    std::vector<std::vector<glm::vec3>> fewer = positions;
    for (auto& frame : fewer)
        frame.pop_back();
    test::writeText(bad.dir / "short.pc2", test::pc2Bytes(1.0f, 1.0f, fewer));
    bad.command.deformed = bad.dir / "short.pc2";
    bad.command.cacheStart.reset();
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(bad.command); }),
        Catch::Contains("short.pc2: header: has 288 vertices per frame (expected 289 vertices, as the rest "
                        "mesh"));
    CHECK(test::filesIn(bad.dir / "out").empty());
}

TEST_CASE(
    "uvwarp command: an output named as another output, an input or the log is refused, the file untouched",
    "[harness][uvwarp]") {
    // Each case would have overwritten a file, and a rerun would then have skipped the damaged output as
    // done.
    Scene s;
    const fs::path map1 = s.redirect(1);
    test::writeText(map1, "a finished map");  // the file an output's name points at, as before a rerun
    const auto refused = [&](const std::string& expected) {
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(s.command); }),
                   Catch::Contains(expected));
        CHECK(test::readText(map1) == "a finished map");
        CHECK_FALSE(fs::exists(s.redirect(2)));
    };
    SECTION("the report") {
        s.command.report = map1;
        refused(
            "redirect.1001.0001.exr: is both the redirect map of tile 1001, frame 1 and the report "
            "(--report)");
    }
    SECTION("the log, not opened") {
        s.command.log = map1;
        refused("redirect.1001.0001.exr: is both the redirect map of tile 1001, frame 1 and the log (--log)");
    }
    SECTION("the report over the log, an input or a map through a linked folder") {
        s.command.log = s.dir / "shot.jsonl";
        s.command.report = s.dir / "shot.jsonl";
        refused("shot.jsonl: is both the log (--log) and the report (--report)");
        s.command.log.reset();
        s.command.report = s.dir / "rig.1001.exr";
        refused("rig.1001.exr: is the rigidity map of tile 1001, and the report (--report)");
        s.command.report = s.dir / "anim.0002.obj";
        refused("anim.0002.obj: is the deformed frame 2 (--deformed), and the report (--report)");
        s.command.report.reset();
        s.command.log = s.dir / "rest.obj";
        refused("rest.obj: is the rest mesh, and the log (--log)");
        fs::create_directory_symlink(s.dir / "out", s.dir / "link");
        s.command.log = s.dir / "link/redirect.1001.0001.exr";
        refused("is both the redirect map of tile 1001, frame 1 and the log (--log)");
        CHECK(test::readText(s.dir / "rest.obj") == planeObj(1.0));
    }
    SECTION("a bake pattern spelled another way") {
        s.command.texture = s.dir / "col.<UDIM>.exr";
        s.command.bake = s.dir / "out/redirect.<UDIM>.%04d.exr";
        refused(
            "redirect.1001.0001.exr: is both the redirect map of tile 1001, frame 1 and the bake of tile "
            "1001, frame 1 (expected a file of its own for each output)");
    }
    SECTION("an animated rigidity map") {
        for (int f = 1; f <= 3; ++f)
            io::writeImage(s.dir / ("out/redirect.1001.000" + std::to_string(f) + ".exr"), disks(),
                           {io::PixelType::Float, {}});
        s.command.rigidity = s.command.out;
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(s.command); }),
            Catch::Contains("is the rigidity map of tile 1001 at frame 1, and the redirect map of tile "
                            "1001, frame 1"));
        CHECK(io::readImage(s.redirect(2)).pixels == disks().pixels);
    }
    SECTION("a deformed frame") {
        s.command.deformed = s.dir / "out/redirect.1001.####.exr";
        fs::remove(map1);
        for (int f = 1; f <= 3; ++f)
            fs::copy_file(s.dir / ("anim.000" + std::to_string(f) + ".obj"), s.redirect(f));
        s.command.out = s.dir / "out/redirect.<UDIM>.####.exr";
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { (void)harness::uvwarpCommand(s.command); }),
            Catch::Contains("is the deformed frame 1 (--deformed), and the redirect map of tile 1001"));
    }
    SECTION("a bake extension no writer takes, before any frame is solved") {
        s.command.texture = s.dir / "col.<UDIM>.exr";
        s.command.bake = s.dir / "out/col.<UDIM>.####.xyz";
        refused("col.1001.0001.xyz: no image format for the extension '.xyz'");
    }
}
