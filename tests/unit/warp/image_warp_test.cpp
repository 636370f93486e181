#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/warp/image_warp.h"
#include "image_support.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

using deformkit::test::makeImage;

}  // namespace

TEST_CASE("image warp: multichannel layout through a flip map", "[warp][beier_neely][image_warp]") {
    const int w = 13, h = 5, c = 4;
    auto f = [](int k, double i, double j) { return 100 * k + 10 * j + i; };
    const io::Image image = makeImage(w, h, c, f);
    std::vector<glm::vec2> map(w * h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x)
            map[y * w + x] = {w - x - 0.5f, y + 0.5f};  // mirror in x
    }
    for (auto interp : {io::SampleFilter::Bilinear, io::SampleFilter::Bicubic}) {
        const io::Image out = resampleImage(image, map, w, h, interp);
        REQUIRE(out.width == w);
        REQUIRE(out.height == h);
        REQUIRE(out.channels == c);
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                for (int k = 0; k < c; ++k)
                    CHECK(out.at(x, y, k) == Approx(f(k, w - 1 - x, y)).margin(1e-4));
            }
        }
    }
    // A destination of another size: 1 x 1 taking the pixel (2, 3).
    const std::vector<glm::vec2> one{{2.5f, 3.5f}};
    const io::Image single = resampleImage(image, one, 1, 1);
    CHECK(single.pixels == std::vector<float>{32, 132, 232, 332});
}

TEST_CASE("image warp: bit-identical for 1 and 2 threads", "[warp][beier_neely][image_warp][determinism]") {
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> uni(-5.0f, 105.0f);
    const io::Image image =
        makeImage(100, 80, 3, [](int k, double i, double j) { return std::cos(i * 0.1 * (k + 1)) * j; });
    std::vector<glm::vec2> map(120 * 90);
    for (auto& p : map)
        p = {uni(rng), uni(rng)};
    for (auto interp : {io::SampleFilter::Bilinear, io::SampleFilter::Bicubic}) {
        const int saved = omp_get_max_threads();
        omp_set_num_threads(1);
        const io::Image one = resampleImage(image, map, 120, 90, interp);
        omp_set_num_threads(2);
        const io::Image two = resampleImage(image, map, 120, 90, interp);
        omp_set_num_threads(saved);
        CHECK(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(float)) == 0);
    }
}

TEST_CASE("image warp: bad input", "[warp][beier_neely][image_warp][errors]") {
    const io::Image image(4, 3, 2, 0.5f);
    std::vector<glm::vec2> map(12, glm::vec2(1.0f));
    CHECK_THROWS_WITH(resampleImage(io::Image(), map, 4, 3),
                      Catch::Contains("source image") && Catch::Contains("0 x 0"));
    CHECK_THROWS_WITH(resampleImage(image, std::span(map).first(11), 4, 3),
                      Catch::Contains("map") && Catch::Contains("has 11 entries") && Catch::Contains("12"));
    map[6].y = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(resampleImage(image, map, 4, 3),
                      Catch::Contains("pixel (2, 1)") && Catch::Contains("not finite"));
    CHECK_THROWS_AS(resampleImage(image, map, 0, 3), InvalidInput);
    io::Image broken(4, 3, 2);
    broken.pixels.pop_back();
    CHECK_THROWS_WITH(resampleImage(broken, map, 4, 3), Catch::Contains("has 23 values"));
    // A non-finite source pixel spread into every pixel sampled next to it: named with the image.
    io::Image holed(4, 3, 2, 0.5f);
    holed.at(3, 2, 1) = std::numeric_limits<float>::infinity();
    map[6].y = 1.0f;
    CHECK_THROWS_WITH(resampleImage(holed, map, 4, 3, io::SampleFilter::Bilinear, "photo.exr"),
                      Catch::Contains("photo.exr: pixel (3, 2) channel 1: is inf (expected finite values"));
}
