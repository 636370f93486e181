#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <tuple>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "test_support.h"
#include "warp_command.h"

using namespace deformkit;

TEST_CASE("warp command: warps an image file and writes atomically", "[harness][beier_neely]") {
    test::TempDir dir;
    io::Image image(24, 16, 3);
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 24; ++x) {
            image.at(x, y, 0) = x / 23.0f;
            image.at(x, y, 1) = y / 15.0f;
            image.at(x, y, 2) = 0.5f;
        }
    }
    io::writeImage(dir / "in.exr", image);
    // One pair moving the content 3 pixels right: the destination pixel x reads the source at x - 3.
    test::writeText(dir / "shift.json",
                    R"({"lines": [{"src": [[2, 8], [20, 8]], "dst": [[5, 8], [23, 8]]}]})");
    harness::WarpImageCommand command;
    command.image = dir / "in.exr";
    command.lines = dir / "shift.json";
    command.out = dir / "out.exr";
    harness::warpImageCommand(command);
    const io::Image out = io::readImage(dir / "out.exr");
    REQUIRE(out.width == 24);
    REQUIRE(out.channels == 3);
    for (int x = 3; x < 24; ++x)
        CHECK(out.at(x, 5, 0) == Approx(image.at(x - 3, 5, 0)).margin(2e-3));  // half floats
    CHECK(out.at(1, 5, 0) == Approx(image.at(0, 5, 0)).margin(2e-3));          // clamp-to-edge

    // Bad lines: error, and no output written.
    test::writeText(dir / "bad.json", R"({"lines": [{"src": [[2, 8], [20, 8]], "dst": [[5, 8], [5, 8]]}]})");
    command.lines = dir / "bad.json";
    command.out = dir / "never.exr";
    CHECK_THROWS_WITH(harness::warpImageCommand(command), Catch::Contains("lines[0].dst"));
    CHECK_FALSE(std::filesystem::exists(dir / "never.exr"));
}

TEST_CASE("warp command: an empty set of lines copies the image, stored as the source is",
          "[harness][beier_neely]") {
    // A 16-bit PNG came back 8-bit and a float EXR half: the copy lost up to half an 8-bit step. With the
    // source's format the output keeps its pixel type, so no lines give the same pixels.
    test::TempDir dir;
    io::Image image(40, 33, 3);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] = static_cast<float>((i * 7919) % 65536) / 65535.0f;
    test::writeText(dir / "none.json", R"({"lines": []})");
    for (const auto& [name, type, stored] : {std::tuple{"in.png", io::PixelType::UInt16, "uint16"},
                                             std::tuple{"in.exr", io::PixelType::Float, "float"},
                                             std::tuple{"in.tif", io::PixelType::UInt16, "uint16"}}) {
        CAPTURE(name);
        io::writeImage(dir / name, image, {type, {}});
        harness::WarpImageCommand command;
        command.image = dir / name;
        command.lines = dir / "none.json";
        command.out = dir / ("copy" + std::filesystem::path(name).extension().string());
        harness::warpImageCommand(command);
        CHECK(io::readImageInfo(command.out).pixelType == stored);
        CHECK(io::readImage(command.out).pixels == io::readImage(dir / name).pixels);
    }
    // Another format takes its own default: a 16-bit PNG warped into an EXR is half.
    harness::WarpImageCommand command;
    command.image = dir / "in.png";
    command.lines = dir / "none.json";
    command.out = dir / "other.exr";
    harness::warpImageCommand(command);
    CHECK(io::readImageInfo(command.out).pixelType == "half");
}
