#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/scene/weights_file.h"
#include "test_support.h"

using namespace deformkit;

TEST_CASE("weights file: an array of one number per vertex; errors name the file and the element",
          "[scene][weights_file]") {
    CHECK(scene::parseWeightsFile("[0, 0.5, 1]", 3, "w.json") == std::vector<float>{0.0f, 0.5f, 1.0f});
    CHECK_THAT(test::errorOf<Error>([] { (void)scene::parseWeightsFile("[0, 0.5]", 3, "w.json"); }),
               Catch::Contains("w.json") && Catch::Contains("has 2 weights") &&
                   Catch::Contains("3, one per vertex"));
    CHECK_THAT(test::errorOf<Error>([] { (void)scene::parseWeightsFile("[0, \"a\", 1]", 3, "w.json"); }),
               Catch::Contains("w.json: [1]: is a string"));
    CHECK_THAT(test::errorOf<Error>([] { (void)scene::parseWeightsFile("{\"w\": 1}", 1, "w.json"); }),
               Catch::Contains("w.json: w: is not a known key (expected one of: weights)"));
    CHECK_THAT(test::errorOf<Error>([] { (void)scene::parseWeightsFile("{}", 1, "w.json"); }),
               Catch::Contains("w.json: weights: is missing"));
    CHECK_THAT(test::errorOf<Error>([] { (void)scene::parseWeightsFile("7", 1, "w.json"); }),
               Catch::Contains("w.json: (top level): is a number"));
    CHECK_THROWS_AS(scene::parseWeightsFile("[0, 1", 2, "w.json"), ParseError);
    CHECK_THAT(test::errorOf<Error>([] { (void)scene::parseWeightsFile("[0, 1e999]", 2, "w.json"); }),
               Catch::Contains("w.json"));
    // The scene's object form.
    CHECK(scene::parseWeightsFile(R"({"weights": [0.25, 1]})", 2, "w.json") ==
          std::vector<float>{0.25f, 1.0f});
    // Its errors name the key: a misspelt neighbour, a value that is not an array, an element.
    CHECK_THAT(test::errorOf<InvalidInput>([] {
                   (void)scene::parseWeightsFile(R"({"weights": [1], "wieghts_scale": 0})", 1, "w.json");
               }),
               Catch::Contains("w.json: wieghts_scale: is not a known key"));
    CHECK_THAT(
        test::errorOf<InvalidInput>([] { (void)scene::parseWeightsFile(R"({"weights": 5})", 1, "w.json"); }),
        Catch::Contains("w.json: weights: is a number"));
    CHECK_THAT(test::errorOf<InvalidInput>(
                   [] { (void)scene::parseWeightsFile(R"({"weights": [1, null]})", 2, "w.json"); }),
               Catch::Contains("w.json: weights[1]: is null"));
}

TEST_CASE("weights file: written weights read back bit for bit", "[scene][weights_file]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> any(-2.0f, 2.0f);
    std::vector<float> weights(500);
    for (float& w : weights)
        w = any(rng);
    weights[0] = 0.0f;
    weights[1] = 1.0f;
    weights[2] = std::numeric_limits<float>::denorm_min();
    weights[3] = std::numeric_limits<float>::max();
    weights[4] = -std::numeric_limits<float>::max();
    weights[5] = -0.0f;  // written "-0.0": "-0" reads back as the integer 0 (found by the fuzz target)
    test::TempDir dir;
    test::writeText(dir / "w.json", scene::formatWeightsFile(weights));
    CHECK(test::sameBits(scene::readWeightsFile(dir / "w.json", weights.size()), weights));
    CHECK(scene::formatWeightsFile(std::vector<float>{0.5f, 0.1f}) == "[0.5, 0.1]\n");
    // JSON has no NaN or infinity: refused, naming the index, rather than written as text no reader takes.
    CHECK_THROWS_WITH(scene::formatWeightsFile(std::vector<float>{0.5f, std::nanf("")}, "w.json"),
                      Catch::Contains("w.json: [1]: is nan"));
    CHECK_THROWS_WITH(
        scene::formatWeightsFile(std::vector<float>{std::numeric_limits<float>::infinity()}, "w.json"),
        Catch::Contains("w.json: [0]: is inf"));
    CHECK_THROWS_AS(scene::readWeightsFile(dir / "none.json", 1), IoError);
}

TEST_CASE("weights file: numbers beyond float range are refused", "[scene][weights_file][errors]") {
    CHECK_THAT(test::errorOf<InvalidInput>([] { (void)scene::parseWeightsFile("[0, 3.5e38]", 2, "w.json"); }),
               Catch::Contains("w.json: [1]: is 3.5e+38"));
    CHECK_THAT(test::errorOf<InvalidInput>([] { (void)scene::parseWeightsFile("[-1e300]", 1, "w.json"); }),
               Catch::Contains("[0]"));
}
