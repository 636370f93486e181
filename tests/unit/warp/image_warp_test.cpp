#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/warp/image_warp.h"

using namespace deformkit;
using namespace deformkit::warp;

namespace {

// An image whose channel k at pixel (i, j) is f(k, i, j).
template <class F>
io::Image makeImage(int w, int h, int c, F f) {
    io::Image image(w, h, c);
    for (int j = 0; j < h; ++j) {
        for (int i = 0; i < w; ++i) {
            for (int k = 0; k < c; ++k)
                image.at(i, j, k) = static_cast<float>(f(k, double(i), double(j)));
        }
    }
    return image;
}

std::vector<float> sampleAt(const io::Image& image, glm::vec2 position, Interpolation interpolation) {
    std::vector<float> out(image.channels);
    sampleImage(image, position, interpolation, out);
    return out;
}

}  // namespace

TEST_CASE("image warp: bilinear reproduces a linear image exactly", "[warp][beier_neely][image_warp]") {
    auto f = [](int k, double i, double j) { return 0.3 + 0.02 * i * (k + 1) - 0.05 * j + 0.1 * k; };
    const io::Image image = makeImage(23, 17, 3, f);
    std::mt19937 rng(1);
    // Anywhere between the first and last pixel centres: continuous index x - 0.5 in [0, w - 1].
    std::uniform_real_distribution<float> ux(0.5f, 22.5f), uy(0.5f, 16.5f);
    double worst = 0.0;
    for (int n = 0; n < 2000; ++n) {
        const glm::vec2 p(ux(rng), uy(rng));
        const std::vector<float> got = sampleAt(image, p, Interpolation::Bilinear);
        for (int k = 0; k < 3; ++k)
            worst = std::max(worst, std::abs(got[k] - f(k, p.x - 0.5, p.y - 0.5)));
    }
    CHECK(worst <= 2e-6);
}

TEST_CASE("image warp: bicubic (Keys a = -0.5) reproduces a quadratic image in the interior",
          "[warp][beier_neely][image_warp]") {
    auto f = [](int k, double i, double j) {
        return 0.1 + 0.01 * i - 0.02 * j + 0.002 * i * i - 0.003 * i * j + 0.0015 * j * j + 0.05 * k;
    };
    const io::Image image = makeImage(20, 18, 2, f);
    std::mt19937 rng(2);
    // All 4 x 4 taps inside the image: continuous index in [1, size - 3].
    std::uniform_real_distribution<float> ux(1.5f, 17.5f), uy(1.5f, 15.5f);
    double worst = 0.0;
    for (int n = 0; n < 2000; ++n) {
        const glm::vec2 p(ux(rng), uy(rng));
        const std::vector<float> got = sampleAt(image, p, Interpolation::Bicubic);
        for (int k = 0; k < 2; ++k)
            worst = std::max(worst, std::abs(got[k] - f(k, p.x - 0.5, p.y - 0.5)));
    }
    CHECK(worst <= 1e-5);
    // Bilinear does not reproduce the curvature: the reference above can fail.
    const glm::vec2 mid(10.0f, 9.0f);  // halfway between centres in x and y
    CHECK(std::abs(sampleAt(image, mid, Interpolation::Bilinear)[0] - f(0, 9.5, 8.5)) > 1e-4);
}

TEST_CASE("image warp: clamp-to-edge and exact pixel centres", "[warp][beier_neely][image_warp]") {
    auto f = [](int k, double i, double j) { return std::sin(i + 2 * j) + k; };
    const io::Image image = makeImage(9, 7, 2, f);
    for (auto interp : {Interpolation::Bilinear, Interpolation::Bicubic}) {
        // At a pixel centre every kernel returns that pixel.
        for (int j = 0; j < 7; ++j) {
            for (int i = 0; i < 9; ++i) {
                const std::vector<float> got = sampleAt(image, {i + 0.5f, j + 0.5f}, interp);
                CHECK(got[1] == Approx(image.at(i, j, 1)).margin(1e-6));
            }
        }
        // Far outside: the nearest edge pixel, whatever the kernel.
        CHECK(sampleAt(image, {-50.0f, -3.0f}, interp)[0] == Approx(image.at(0, 0, 0)).margin(1e-6));
        CHECK(sampleAt(image, {1e30f, 3.5f}, interp)[1] == Approx(image.at(8, 3, 1)).margin(1e-6));
        CHECK(sampleAt(image, {4.5f, 100.0f}, interp)[0] == Approx(image.at(4, 6, 0)).margin(1e-6));
    }
}

TEST_CASE("image warp: multichannel layout through a flip map", "[warp][beier_neely][image_warp]") {
    const int w = 13, h = 5, c = 4;
    auto f = [](int k, double i, double j) { return 100 * k + 10 * j + i; };
    const io::Image image = makeImage(w, h, c, f);
    std::vector<glm::vec2> map(w * h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x)
            map[y * w + x] = {w - x - 0.5f, y + 0.5f};  // mirror in x
    }
    for (auto interp : {Interpolation::Bilinear, Interpolation::Bicubic}) {
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
    for (auto interp : {Interpolation::Bilinear, Interpolation::Bicubic}) {
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
}
