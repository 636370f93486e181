#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

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
