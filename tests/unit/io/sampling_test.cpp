#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/io/sampling.h"
#include "image_support.h"

using namespace deformkit;

namespace {

using deformkit::test::makeImage;

std::vector<float> sampleAt(const io::Image& image, glm::vec2 position, io::SampleFilter filter) {
    std::vector<float> out(image.channels);
    io::sampleImage(image, position, filter, out);
    return out;
}

}  // namespace

TEST_CASE("sampling: bilinear reproduces a linear image exactly", "[io][sampling]") {
    auto f = [](int k, double i, double j) { return 0.3 + 0.02 * i * (k + 1) - 0.05 * j + 0.1 * k; };
    const io::Image image = makeImage(23, 17, 3, f);
    std::mt19937 rng(1);
    // Anywhere between the first and last pixel centres: continuous index x - 0.5 in [0, w - 1].
    std::uniform_real_distribution<float> ux(0.5f, 22.5f), uy(0.5f, 16.5f);
    double worst = 0.0;
    for (int n = 0; n < 2000; ++n) {
        const glm::vec2 p(ux(rng), uy(rng));
        const std::vector<float> got = sampleAt(image, p, io::SampleFilter::Bilinear);
        for (int k = 0; k < 3; ++k)
            worst = std::max(worst, std::abs(got[k] - f(k, p.x - 0.5, p.y - 0.5)));
    }
    CHECK(worst <= 2e-6);
}

TEST_CASE("sampling: bicubic (Keys a = -0.5) reproduces a quadratic image in the interior",
          "[io][sampling]") {
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
        const std::vector<float> got = sampleAt(image, p, io::SampleFilter::Bicubic);
        for (int k = 0; k < 2; ++k)
            worst = std::max(worst, std::abs(got[k] - f(k, p.x - 0.5, p.y - 0.5)));
    }
    CHECK(worst <= 1e-5);
    // Bilinear does not reproduce the curvature: the reference above can fail.
    const glm::vec2 mid(10.0f, 9.0f);  // halfway between centres in x and y
    CHECK(std::abs(sampleAt(image, mid, io::SampleFilter::Bilinear)[0] - f(0, 9.5, 8.5)) > 1e-4);
}

TEST_CASE("sampling: clamp-to-edge and exact pixel centres", "[io][sampling]") {
    auto f = [](int k, double i, double j) { return std::sin(i + 2 * j) + k; };
    const io::Image image = makeImage(9, 7, 2, f);
    for (auto interp : {io::SampleFilter::Bilinear, io::SampleFilter::Bicubic}) {
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

TEST_CASE("sampling: bad input names what is wrong", "[io][sampling][errors]") {
    io::Image image(4, 3, 2, 0.5f);
    std::vector<float> out(2);
    CHECK_THROWS_WITH(io::sampleImage(io::Image(), {1.0f, 1.0f}, io::SampleFilter::Bilinear, out),
                      Catch::Contains("image") && Catch::Contains("0 x 0"));
    std::vector<float> three(3);
    CHECK_THROWS_WITH(
        io::sampleImage(image, {1.0f, 1.0f}, io::SampleFilter::Bicubic, three),
        Catch::Contains("output") && Catch::Contains("has 3 values") && Catch::Contains("2 (one"));
    CHECK_THROWS_WITH(io::sampleImage(image, {std::nanf(""), 1.0f}, io::SampleFilter::Bilinear, out),
                      Catch::Contains("position") && Catch::Contains("not finite"));
    io::Image broken = image;
    broken.pixels.pop_back();
    CHECK_THROWS_AS(io::sampleImage(broken, {1.0f, 1.0f}, io::SampleFilter::Bilinear, out), InvalidInput);
}
