#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "test_support.h"
#include "warp_command.h"

using namespace deformkit;

TEST_CASE("warp command: lines JSON parses with defaults and per-line overrides", "[harness][beier_neely]") {
    const auto pairs = harness::parseSegmentPairs(
        R"({"a": 2, "lines": [{"src": [[1, 2], [3, 4]], "dst": [[5, 6], [7, 8]]},
                              {"src": [[0, 0], [0, 9]], "dst": [[1, 0], [1, 9]], "b": 1.5, "p": 0}]})",
        "lines.json");
    REQUIRE(pairs.size() == 2);
    CHECK(pairs[0].srcP == glm::vec2(1, 2));
    CHECK(pairs[0].srcQ == glm::vec2(3, 4));
    CHECK(pairs[0].dstP == glm::vec2(5, 6));
    CHECK(pairs[0].dstQ == glm::vec2(7, 8));
    CHECK(pairs[0].a == 2.0f);
    CHECK(pairs[0].b == 2.0f);  // default
    CHECK(pairs[0].p == 0.5f);  // default
    CHECK(pairs[1].b == 1.5f);
    CHECK(pairs[1].p == 0.0f);
}

TEST_CASE("warp command: bad lines JSON names the JSON path", "[harness][beier_neely][errors]") {
    auto fails = [](const char* text) {
        try {
            (void)harness::parseSegmentPairs(text, "lines.json");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK_THAT(fails(R"({"lines": [{"src": [[1, 2], [3, 4]], "dst": [[5, 6], ["x", 8]]}]})"),
               Catch::Contains("lines.json") && Catch::Contains("lines[0].dst[1][0]") &&
                   Catch::Contains("a string"));
    CHECK_THAT(fails(R"({"lines": [{"src": [[1, 2], [3, 4]], "dst": [[5, 6], [7, 8]]}, {"src": [[1, 2]]}]})"),
               Catch::Contains("lines[1].src") && Catch::Contains("an array of 1"));
    CHECK_THAT(fails(R"({"lines": [{"src": [[1, 2], [1, 2]], "dst": [[5, 6], [7, 8]]}]})"),
               Catch::Contains("lines[0].src") && Catch::Contains("zero length"));
    CHECK_THAT(fails(R"({"a": 0, "lines": []})"),
               Catch::Contains("lines.json: a: is 0") && Catch::Contains("a > 0"));
    CHECK_THAT(fails(R"({"lines": [{"src": [[1, 2], [3, 4]], "dst": [[5, 6], [7, 8]], "b": -1}]})"),
               Catch::Contains("lines[0].b") && Catch::Contains("b >= 0"));
    CHECK_THAT(fails(R"({"lines": [{"dst": [[5, 6], [7, 8]]}]})"),
               Catch::Contains("lines[0].src") && Catch::Contains("missing"));
    CHECK_THAT(fails(R"({"a": 1})"), Catch::Contains("lines: is missing"));
    CHECK_THAT(fails(R"({"lines": [1e999]})"), Catch::Contains("lines.json"));
    CHECK_THAT(fails(R"({"lines": [}")"),
               Catch::Contains("lines.json") && Catch::Contains("parse error at line 1"));
    CHECK_THROWS_AS(harness::parseSegmentPairs("[1, 2", "x.json"), ParseError);
    CHECK_THROWS_AS(harness::parseSegmentPairs(R"({"lines": 3})", "x.json"), InvalidInput);
}

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
