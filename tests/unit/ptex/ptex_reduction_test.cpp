#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <random>

#include "deformkit/ptex/ptex_file.h"

using namespace deformkit::ptex;

TEST_CASE("level 1 of a 4 x 4 RGBA u8 face is the alpha-premultiplied 2 x 2 box filter",
          "[ptex][reduction]") {
    std::mt19937 rng(11);
    PtexFile file;
    file.channels = 4;
    file.alphaChannel = 3;
    file.faces.resize(1);
    file.faces[0].ulog2 = 2;
    file.faces[0].vlog2 = 2;
    file.texels.resize(1);
    file.texels[0].resize(16 * 4);
    for (uint8_t& b : file.texels[0])
        b = static_cast<uint8_t>(rng());
    file.texels[0][3] = 0;  // one transparent texel in the first 2 × 2 block
    ReadOptions options;
    options.readReductions = true;
    const PtexFile back = readPtex(writePtexBytes(file), "reduce.ptx", options);
    REQUIRE(back.reductions.size() == 2);
    REQUIRE(back.reductions[0].size() == 1);
    const ReducedFace& r = back.reductions[0][0];
    CHECK(r.faceId == 0);
    CHECK(r.ulog2 == 1);
    CHECK(r.vlog2 == 1);
    REQUIRE(r.texels.size() == 4 * 4);
    // Reference, in integers: colour = Σ cᵢ aᵢ / Σ aᵢ, alpha = Σ aᵢ / 4, each rounded to nearest. The library
    // computes the same ratio in double with alpha scaled by 1/255, so it may land on the other side of an
    // exact .5 tie: tolerance 1 count, and the exact matches are counted too.
    int maxError = 0;
    int exact = 0;
    const auto& t = file.texels[0];
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 2; ++x) {
            int alphaSum = 0;
            for (int k = 0; k < 4; ++k)
                alphaSum += t[((2 * y + k / 2) * 4 + 2 * x + k % 2) * 4 + 3];
            for (int c = 0; c < 4; ++c) {
                double expected = 0;
                if (c == 3 || alphaSum == 0) {
                    int sum = 0;
                    for (int k = 0; k < 4; ++k)
                        sum += t[((2 * y + k / 2) * 4 + 2 * x + k % 2) * 4 + c];
                    expected = std::floor(sum / 4.0 + 0.5);
                } else {
                    int weighted = 0;
                    for (int k = 0; k < 4; ++k) {
                        const int texel = ((2 * y + k / 2) * 4 + 2 * x + k % 2) * 4;
                        weighted += t[texel + c] * t[texel + 3];
                    }
                    expected = std::floor(static_cast<double>(weighted) / alphaSum + 0.5);
                }
                const int got = r.texels[(y * 2 + x) * 4 + c];
                maxError = std::max(maxError, std::abs(got - static_cast<int>(expected)));
                exact += got == static_cast<int>(expected);
            }
        }
    }
    CHECK(maxError <= 1);
    CHECK(exact >= 15);
    // Level 2 (1 × 1) is the same filter applied to level 1.
    REQUIRE(back.reductions[1].size() == 1);
    CHECK(back.reductions[1][0].texels.size() == 4);
}

TEST_CASE("float reductions average 2 x 2 blocks, faces ordered by descending min log2",
          "[ptex][reduction]") {
    PtexFile file;
    file.dataType = DataType::Float;
    file.faces.resize(4);
    const int res[4][2] = {{1, 1}, {3, 2}, {2, 2}, {0, 3}};
    file.texels.resize(4);
    for (int f = 0; f < 4; ++f) {
        file.faces[f].ulog2 = static_cast<int8_t>(res[f][0]);
        file.faces[f].vlog2 = static_cast<int8_t>(res[f][1]);
        file.texels[f].resize(file.faces[f].texelCount() * 4);
        for (size_t i = 0; i < file.faces[f].texelCount(); ++i) {
            const float x = std::sin(static_cast<float>(f * 100 + i)) * 10.0f;
            std::memcpy(file.texels[f].data() + 4 * i, &x, 4);
        }
    }
    ReadOptions options;
    options.readReductions = true;
    const PtexFile back = readPtex(writePtexBytes(file), "reduce-float.ptx", options);
    // min(ulog2, vlog2): 1, 2, 2, 0. Level 1 holds faces 1, 2 (min 2) then 0 (min 1); level 2 faces 1, 2.
    REQUIRE(back.reductions.size() == 2);
    REQUIRE(back.reductions[0].size() == 3);
    CHECK(back.reductions[0][0].faceId == 1);
    CHECK(back.reductions[0][1].faceId == 2);
    CHECK(back.reductions[0][2].faceId == 0);
    REQUIRE(back.reductions[1].size() == 2);
    CHECK(back.reductions[1][0].faceId == 1);
    CHECK(back.reductions[1][1].faceId == 2);
    // Face 1 (8 × 4) at level 1 is 4 × 2: each texel the mean of a 2 × 2 block. The library sums in double
    // and rounds once to float; the reference sums the same floats in double: identical up to that one
    // rounding, so a relative tolerance of 1e-6 (above float's 6e-8 epsilon) is ample.
    const ReducedFace& r = back.reductions[0][0];
    REQUIRE(r.texels.size() == 8 * 4);
    const auto at = [&](const std::vector<uint8_t>& t, int w, int x, int y) {
        float v;
        std::memcpy(&v, t.data() + 4 * (y * w + x), 4);
        return static_cast<double>(v);
    };
    double worst = 0;
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 4; ++x) {
            const auto& t = file.texels[1];
            const double mean = (at(t, 8, 2 * x, 2 * y) + at(t, 8, 2 * x + 1, 2 * y) +
                                 at(t, 8, 2 * x, 2 * y + 1) + at(t, 8, 2 * x + 1, 2 * y + 1)) /
                                4;
            worst = std::max(worst, std::abs(at(r.texels, 4, x, y) - mean) / std::max(1.0, std::abs(mean)));
        }
    }
    CHECK(worst < 1e-6);
}
