#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <tuple>

#include "deformkit/error.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/inversion.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using namespace deformkit::uvwarp;

namespace {

// Channel c of the ramp texture at tile-local (u, v).
double ramp(double u, double v, int c) {
    return (2.0 + c) * u + 3.0 * v + 1.0 - 0.5 * c;
}

io::Image rampTexture(int32_t size, int32_t channels) {
    io::Image image(size, size, channels);
    for (int32_t y = 0; y < size; ++y) {
        for (int32_t x = 0; x < size; ++x) {
            for (int c = 0; c < channels; ++c)
                image.at(x, y, c) = static_cast<float>(ramp((x + 0.5) / size, 1.0 - (y + 0.5) / size, c));
        }
    }
    return image;
}

}  // namespace

TEST_CASE("baking through the identity redirect reproduces the texture", "[uvwarp][bake]") {
    const int32_t size = 64;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> value(-1.0f, 2.0f);
    io::Image texture(size, size, 5);
    for (float& p : texture.pixels)
        p = value(rng);
    const io::Image redirect = invertWarp(WarpGrid::identity(size), size);
    for (const auto filter : {io::SampleFilter::Bilinear, io::SampleFilter::Bicubic}) {
        BakeOptions options;
        options.filter = filter;
        const io::Image baked = bakeTexture(texture, redirect, options);
        REQUIRE(baked.width == size);
        REQUIRE(baked.channels == 5);
        // Texel centres map to exact texel coordinates (power-of-two sizes), where both filters return the
        // texel itself: bitwise equal.
        CHECK(baked.pixels == texture.pixels);
    }
    // Any channel count: 70 channels (more than io::sampleImage takes).
    io::Image wide(8, 8, 70);
    for (float& p : wide.pixels)
        p = value(rng);
    CHECK(bakeTexture(wide, invertWarp(WarpGrid::identity(8), 8)).pixels == wide.pixels);
}

TEST_CASE("baking a ramp through a shifted redirect gives the shifted ramp", "[uvwarp][bake]") {
    const int32_t size = 32;
    const io::Image texture = rampTexture(size, 3);
    // uv' = uv + (1.5, -0.75) texels.
    const double du = 1.5 / size, dv = -0.75 / size;
    io::Image redirect(size, size, 2);
    for (int32_t y = 0; y < size; ++y) {
        for (int32_t x = 0; x < size; ++x) {
            redirect.at(x, y, 0) = static_cast<float>((x + 0.5) / size + du);
            redirect.at(x, y, 1) = static_cast<float>(1.0 - (y + 0.5) / size + dv);
        }
    }
    const double lo = 0.5 / size, hi = 1.0 - 0.5 / size;
    const io::Image bilinear = bakeTexture(texture, redirect);
    BakeOptions cubic;
    cubic.filter = io::SampleFilter::Bicubic;
    const io::Image bicubic = bakeTexture(texture, redirect, cubic);
    int cubicChecked = 0;
    for (int32_t y = 0; y < size; ++y) {
        for (int32_t x = 0; x < size; ++x) {
            const double u = (x + 0.5) / size + du, v = 1.0 - (y + 0.5) / size + dv;
            for (int c = 0; c < 3; ++c) {
                // Bilinear reproduces the ramp; past the outer texel centres clamp-to-edge holds the edge
                // value. float32 texels of size ~10.
                CHECK(bilinear.at(x, y, c) ==
                      Approx(ramp(std::clamp(u, lo, hi), std::clamp(v, lo, hi), c)).margin(2e-5));
                // Catmull-Rom reproduces linear data where its 4 x 4 taps lie inside the tile.
                const double fx = u * size - 0.5, fy = (1.0 - v) * size - 0.5;
                if (fx >= 1.0 && fx <= size - 3.0 && fy >= 1.0 && fy <= size - 3.0) {
                    CHECK(bicubic.at(x, y, c) == Approx(ramp(u, v, c)).margin(2e-5));
                    ++cubicChecked;
                }
            }
        }
    }
    CHECK(cubicChecked > 3 * 20 * 20);
}

TEST_CASE("a redirect of another size is sampled bilinearly", "[uvwarp][bake]") {
    // A 16-texel identity redirect read for a 64-texel texture: inside the redirect's centre hull the
    // bilinear look-up reproduces uv exactly; outside it clamps to [0.5 / 16, 1 - 0.5 / 16].
    const int32_t size = 64, small = 16;
    const io::Image texture = rampTexture(size, 2);
    const io::Image redirect = invertWarp(WarpGrid::identity(small), small);
    const io::Image baked = bakeTexture(texture, redirect);
    REQUIRE(baked.width == size);
    const double lo = 0.5 / small, hi = 1.0 - 0.5 / small;
    for (int32_t y = 0; y < size; ++y) {
        for (int32_t x = 0; x < size; ++x) {
            const double u = std::clamp((x + 0.5) / size, lo, hi),
                         v = std::clamp(1.0 - (y + 0.5) / size, lo, hi);
            for (int c = 0; c < 2; ++c)
                CHECK(baked.at(x, y, c) == Approx(ramp(u, v, c)).margin(2e-5));
        }
    }
    // An explicit output size: 16 x 16 output through the 16-texel redirect samples the 64-texel texture at
    // the 16-texel centres.
    BakeOptions options;
    options.width = small;
    options.height = small;
    const io::Image reduced = bakeTexture(texture, redirect, options);
    REQUIRE(reduced.width == small);
    CHECK(reduced.at(3, 9, 1) == Approx(ramp(3.5 / small, 1.0 - 9.5 / small, 1)).margin(2e-5));
}

TEST_CASE("baking samples as io::sampleImage does", "[uvwarp][bake]") {
    // Reference: one io::sampleImage call per texel at the redirected position, for a random texture and
    // a redirect that also reaches past the tile border (clamped).
    const int32_t size = 48, redirectSize = 32;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> value(-1.0f, 1.0f), shift(-0.1f, 0.1f);
    io::Image texture(size, size, 4);
    for (float& p : texture.pixels)
        p = value(rng);
    io::Image redirect(redirectSize, redirectSize, 2);
    for (int32_t y = 0; y < redirectSize; ++y) {
        for (int32_t x = 0; x < redirectSize; ++x) {
            redirect.at(x, y, 0) = (x + 0.5f) / redirectSize + shift(rng);
            redirect.at(x, y, 1) = 1.0f - (y + 0.5f) / redirectSize + shift(rng);
        }
    }
    for (const auto filter : {io::SampleFilter::Bilinear, io::SampleFilter::Bicubic}) {
        BakeOptions options;
        options.filter = filter;
        options.width = redirectSize;  // direct redirect look-ups
        options.height = redirectSize;
        const io::Image baked = bakeTexture(texture, redirect, options);
        double worst = 0.0;
        float expected[4];
        for (int32_t y = 0; y < redirectSize; ++y) {
            for (int32_t x = 0; x < redirectSize; ++x) {
                const glm::vec2 position(redirect.at(x, y, 0) * size, (1.0f - redirect.at(x, y, 1)) * size);
                io::sampleImage(texture, position, filter, expected);
                for (int c = 0; c < 4; ++c)
                    worst = std::max(worst, static_cast<double>(std::abs(baked.at(x, y, c) - expected[c])));
            }
        }
        // The same formulas in the same order: equal up to floating-point contraction (values ~1).
        CHECK(worst < 1e-6);
    }
}

TEST_CASE("baking is bit-identical for 1 and 2 threads", "[uvwarp][bake]") {
    const io::Image texture = rampTexture(128, 3);
    const WarpGrid warp = test::warpFrom(64, [](double u, double v) {
        return glm::dvec2(u + 0.05 * std::sin(M_PI * u) * std::sin(M_PI * v), v);
    });
    const io::Image redirect = invertWarp(warp, 64);
    BakeOptions options;
    options.filter = io::SampleFilter::Bicubic;
    const auto run = [&] { return bakeTexture(texture, redirect, options).pixels; };
    CHECK(test::withThreads(1, run) == test::withThreads(2, run));
}

TEST_CASE("baking bad input", "[uvwarp][bake]") {
    const io::Image texture = rampTexture(8, 1);
    io::Image redirect = invertWarp(WarpGrid::identity(8), 8);
    CHECK_THROWS_AS(bakeTexture(io::Image(), redirect), InvalidInput);
    CHECK_THROWS_WITH(bakeTexture(texture, io::Image(8, 4, 2)), Catch::Contains("redirect map"));
    CHECK_THROWS_WITH(bakeTexture(texture, io::Image(8, 8, 1)), Catch::Contains("redirect map"));
    redirect.at(6, 1, 0) = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(bakeTexture(texture, redirect), Catch::Contains("redirect texel (6, 1)"));
    // A non-finite texel of the texture: one NaN became 8 baked NaNs (its filter's neighbours). Named, for
    // every position in a texture larger than one scanned block.
    const io::Image identity = invertWarp(WarpGrid::identity(8), 8);
    io::Image holed = rampTexture(96, 3);
    for (const auto& [x, y, c] : {std::tuple{0, 0, 0}, std::tuple{95, 95, 2}, std::tuple{37, 60, 1}}) {
        CAPTURE(x, y, c);
        io::Image image = holed;
        image.at(x, y, c) = c == 1 ? -std::numeric_limits<float>::infinity() : std::nanf("");
        CHECK_THROWS_WITH(
            bakeTexture(image, identity),
            Catch::Contains("bake: texture: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") channel " + std::to_string(c) + ": is " + (c == 1 ? "-inf" : "nan")));
    }
    CHECK_NOTHROW(bakeTexture(holed, identity));
}
