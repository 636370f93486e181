#include <catch2/catch.hpp>

#include <string>

#include "deformkit/error.h"
#include "deformkit/scene/feature_lines_file.h"
#include "test_support.h"

using namespace deformkit;

TEST_CASE("feature lines file: parses with defaults and per-line overrides", "[scene][feature_lines]") {
    const auto pairs = scene::parseFeatureLines(
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

TEST_CASE("feature lines file: bad JSON names the JSON path", "[scene][feature_lines][errors]") {
    auto fails = [](const char* text) {
        try {
            (void)scene::parseFeatureLines(text, "lines.json");
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
    // Distinct ends 1e-7 apart: too short for a direction, named with its path and length.
    CHECK_THAT(fails(R"({"lines": [{"src": [[0, 0], [1, 0]], "dst": [[0, 0], [1e-7, 0]]}]})"),
               Catch::Contains("lines.json: lines[0].dst: is 1e-07 long (from [0, 0] to [1e-07, 0])") &&
                   Catch::Contains("longer than 1e-06 pixels"));
    CHECK_THAT(fails(R"({"a": 0, "lines": []})"),
               Catch::Contains("lines.json: a: is 0") && Catch::Contains("a > 0"));
    // Positive, but 0 as the float the warp keeps: said so, not "is 1e-300 (expected a > 0)".
    CHECK_THAT(fails(R"({"a": 1e-300, "lines": []})"),
               Catch::Contains("lines.json: a: is 1e-300, 0 as a float (expected a > 0)"));
    CHECK_THAT(fails(R"({"lines": [{"src": [[1, 2], [3, 4]], "dst": [[5, 6], [7, 8]], "b": -1}]})"),
               Catch::Contains("lines[0].b") && Catch::Contains("b >= 0"));
    CHECK_THAT(fails(R"({"lines": [{"dst": [[5, 6], [7, 8]]}]})"),
               Catch::Contains("lines[0].src") && Catch::Contains("missing"));
    CHECK_THAT(fails(R"({"a": 1})"), Catch::Contains("lines: is missing"));
    // Unknown keys are refused, as scenes refuse theirs (a typo would otherwise be ignored).
    CHECK_THAT(fails(R"({"lines": [], "P": 0.5})"), Catch::Contains("lines.json: P: is not a known key") &&
                                                        Catch::Contains("one of: a, b, p, lines"));
    CHECK_THAT(
        fails(R"({"lines": [{"src": [[1, 2], [3, 4]], "dst": [[5, 6], [7, 8]], "weight": 2}]})"),
        Catch::Contains("lines[0].weight: is not a known key") && Catch::Contains("src, dst, a, b, p"));
    CHECK_THAT(fails(R"({"lines": [1e999]})"), Catch::Contains("lines.json"));
    CHECK_THAT(fails(R"({"lines": [}")"),
               Catch::Contains("lines.json") && Catch::Contains("parse error at line 1"));
    CHECK_THROWS_AS(scene::parseFeatureLines("[1, 2", "x.json"), ParseError);
    CHECK_THROWS_AS(scene::parseFeatureLines(R"({"lines": 3})", "x.json"), InvalidInput);
}

TEST_CASE("feature lines file: read from disk, missing file is an IoError naming it",
          "[scene][feature_lines]") {
    test::TempDir dir;
    test::writeText(dir / "l.json", R"({"lines": [{"src": [[1, 2], [3, 4]], "dst": [[5, 6], [7, 8]]}]})");
    CHECK(scene::readFeatureLines(dir / "l.json").size() == 1);
    CHECK_THAT(test::errorOf<IoError>([&] { (void)scene::readFeatureLines(dir / "none.json"); }),
               Catch::Contains("none.json"));
}
