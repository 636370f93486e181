// The Ptex format's reduction levels, constant values and flags, checked two ways: against the rules
// written out here (which faces a level lists and in what order, premultiplied alpha, truncating integer
// arithmetic, the triangle reduction, the walk around corners for the neighbourhood flag), and against
// files written by the reference Ptex library (tests/data/ptex/README.txt), which the writer must
// reproduce byte for byte from the same texels.

#include <catch2/catch.hpp>

#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/ptex/ptex_file.h"
#include "ptex_test_util.h"

using namespace deformkit::ptex;
using deformkit::test::ptex::rd16;
using deformkit::test::ptex::rd32;

namespace {

// The face count of every level, from the header and level info records.
std::vector<uint32_t> levelFaceCounts(const std::vector<uint8_t>& b) {
    const uint16_t levels = rd16(b, 22);
    const size_t levelInfo = 64 + rd32(b, 28) + rd32(b, 32) + rd32(b, 36);
    std::vector<uint32_t> counts;
    for (uint16_t i = 0; i < levels; ++i)
        counts.push_back(rd32(b, levelInfo + 16 * i + 12));
    return counts;
}

float floatAt(const std::vector<uint8_t>& t, size_t i) {
    float v;
    std::memcpy(&v, t.data() + 4 * i, 4);
    return v;
}

std::vector<uint8_t> floats(const std::vector<float>& v) {
    std::vector<uint8_t> out(v.size() * 4);
    std::memcpy(out.data(), v.data(), out.size());
    return out;
}

PtexFile randomFloatFile(const std::vector<std::array<int, 2>>& res, const std::vector<bool>& constant,
                         uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> value(-1.0f, 3.0f);
    PtexFile file;
    file.dataType = DataType::Float;
    file.faces.resize(res.size());
    file.texels.resize(res.size());
    for (size_t f = 0; f < res.size(); ++f) {
        file.faces[f].ulog2 = static_cast<int8_t>(res[f][0]);
        file.faces[f].vlog2 = static_cast<int8_t>(res[f][1]);
        std::vector<float> t(file.faces[f].texelCount());
        const float c = value(rng);
        for (float& x : t)
            x = constant[f] ? c : value(rng);
        file.texels[f] = floats(t);
    }
    return file;
}

// The 2×2 box filter in float as the format computes it: 0.25 × (((a + b) + c) + d).
std::vector<float> halveQuad(const std::vector<float>& t, int w, int h) {
    std::vector<float> out(static_cast<size_t>(w / 2) * (h / 2));
    for (int y = 0; y < h / 2; ++y)
        for (int x = 0; x < w / 2; ++x)
            out[y * (w / 2) + x] = 0.25f * (t[2 * y * w + 2 * x] + t[2 * y * w + 2 * x + 1] +
                                            t[(2 * y + 1) * w + 2 * x] + t[(2 * y + 1) * w + 2 * x + 1]);
    return out;
}

std::vector<float> asFloats(const std::vector<uint8_t>& t) {
    std::vector<float> v(t.size() / 4);
    std::memcpy(v.data(), t.data(), t.size());
    return v;
}

std::vector<uint8_t> fileBytes(const std::string& name) {
    std::ifstream in(std::string(DEFORMKIT_TEST_DATA) + "/ptex/" + name, std::ios::binary);
    REQUIRE(in);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST_CASE("reduction levels list faces by descending smaller log2, a constant face as 1, down to 4 texels",
          "[ptex][reduction]") {
    // Faces (ulog2, vlog2): smaller log2 4 (constant: ranked 1), 3, 4, 1 (constant), 4, 2.
    PtexFile file = randomFloatFile({{4, 4}, {3, 3}, {5, 4}, {1, 1}, {4, 6}, {2, 3}},
                                    {true, false, false, true, false, false}, 3);
    const std::vector<uint8_t> bytes = writePtexBytes(file);
    // Level i lists the faces whose smaller side reduces to at least 4 texels: rank >= i + 2.
    CHECK(levelFaceCounts(bytes) == std::vector<uint32_t>{6, 3, 2});

    ReadOptions options;
    options.readReductions = true;
    const PtexFile back = readPtex(bytes, "levels.ptx", options);
    REQUIRE(back.reductions.size() == 2);
    const std::vector<int32_t> level1{2, 4, 1};
    const std::vector<int32_t> level2{2, 4};
    for (size_t l = 0; l < 2; ++l) {
        const std::vector<int32_t>& expected = l == 0 ? level1 : level2;
        REQUIRE(back.reductions[l].size() == expected.size());
        for (size_t k = 0; k < expected.size(); ++k) {
            const ReducedFace& r = back.reductions[l][k];
            CHECK(r.faceId == expected[k]);
            // The level's texels: the face halved l + 1 times.
            const FaceInfo& info = file.faces[r.faceId];
            std::vector<float> t = asFloats(file.texels[r.faceId]);
            int w = info.ures(), h = info.vres();
            for (size_t i = 0; i <= l; ++i) {
                t = halveQuad(t, w, h);
                w /= 2;
                h /= 2;
            }
            CHECK(asFloats(r.texels) == t);
        }
    }

    // A constant 8 × 8 face beside a 4 × 4 face: no reduction is stored (the reference orders the constant
    // face as 1 × 1; a 4 × 4 face is already at the smallest stored size).
    const PtexFile pair = randomFloatFile({{3, 3}, {2, 2}}, {true, false}, 4);
    CHECK(levelFaceCounts(writePtexBytes(pair)) == std::vector<uint32_t>{2});
}

TEST_CASE(
    "u8 RGBA reductions are premultiplied by alpha and truncated; ConstData is their mean unpremultiplied",
    "[ptex][reduction]") {
    std::mt19937 rng(11);
    PtexFile file;
    file.channels = 4;
    file.alphaChannel = 3;
    file.faces.resize(1);
    file.faces[0].ulog2 = 4;
    file.faces[0].vlog2 = 4;
    std::vector<uint8_t> t(256 * 4);
    for (uint8_t& b : t)
        b = static_cast<uint8_t>(rng());
    for (size_t i = 0; i < 256; i += 5)
        t[4 * i + 3] = 0;  // transparent
    for (size_t i = 1; i < 256; i += 7)
        t[4 * i + 3] = 255;  // opaque
    file.texels = {t};

    // The format's rules: colour × (alpha × (1/255)) in float, truncated; a reduction sums four values in
    // integers and shifts by 2.
    std::vector<uint8_t> level = t;
    for (size_t i = 0; i < 256; ++i)
        for (int c = 0; c < 3; ++c)
            level[4 * i + c] = static_cast<uint8_t>(static_cast<float>(t[4 * i + c]) *
                                                    ((1.0f / 255.0f) * static_cast<float>(t[4 * i + 3])));
    const auto halve = [](const std::vector<uint8_t>& in, int w) {
        std::vector<uint8_t> out(static_cast<size_t>(w / 2) * (w / 2) * 4);
        for (int y = 0; y < w / 2; ++y)
            for (int x = 0; x < w / 2; ++x)
                for (int c = 0; c < 4; ++c) {
                    const auto at = [&](int xx, int yy) { return int{in[(yy * w + xx) * 4 + c]}; };
                    out[(y * (w / 2) + x) * 4 + c] =
                        static_cast<uint8_t>((at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) +
                                              at(2 * x + 1, 2 * y + 1)) >>
                                             2);
                }
        return out;
    };
    const std::vector<uint8_t> level1 = halve(level, 16);
    const std::vector<uint8_t> level2 = halve(level1, 8);

    ReadOptions options;
    options.readReductions = true;
    const PtexFile back = readPtex(writePtexBytes(file), "rgba.ptx", options);
    CHECK(back.texels[0] == t);  // level 0 as given, not premultiplied
    REQUIRE(back.reductions.size() == 2);
    CHECK(back.reductions[0][0].texels == level1);
    CHECK(back.reductions[1][0].texels == level2);

    // ConstData: the float mean of the 4 × 4 level, truncated, then colour × (255 / alpha), truncated.
    float sums[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < 16; ++i)
        for (int c = 0; c < 4; ++c)
            sums[c] += static_cast<float>(level2[4 * i + c]);
    uint8_t mean[4];
    for (int c = 0; c < 4; ++c)
        mean[c] = static_cast<uint8_t>(sums[c] * (1.0f / 16.0f));
    REQUIRE(mean[3] != 0);
    for (int c = 0; c < 3; ++c)
        mean[c] = static_cast<uint8_t>(static_cast<float>(mean[c]) * (255.0f / static_cast<float>(mean[3])));
    CHECK(std::vector<uint8_t>(back.constData.begin(), back.constData.end()) ==
          std::vector<uint8_t>(mean, mean + 4));
}

TEST_CASE("a triangle file keeps its type, square faces and three edges; its reduction uses the packed texel",
          "[ptex][reduction]") {
    PtexFile file = randomFloatFile({{3, 3}, {2, 2}}, {false, false}, 5);
    file.meshType = MeshType::Triangle;
    file.faces[0].subface = true;
    file.faces[0].adjFaces = {1, -1, -1, 1};  // a fourth edge, which a triangle does not have
    file.faces[0].adjEdges = {0, 0, 0, 2};
    file.faces[1].adjFaces = {0, -1, -1, -1};

    ReadOptions options;
    options.readReductions = true;
    const PtexFile back = readPtex(writePtexBytes(file), "tri.ptx", options);
    CHECK(back.meshType == MeshType::Triangle);
    CHECK_FALSE(back.faces[0].subface);
    CHECK(back.faces[0].adjFaces[3] == -1);
    CHECK(back.faces[0].adjEdges[3] == 0);
    CHECK(back.faces[0].adjFaces[0] == 1);

    // A triangle of resolution w stores w² texels in a square: (u, v) with u + v < w upright, the rest the
    // inverted texels, the one between (i, j), (i + 1, j) and (i, j + 1) at (w − 1 − j, w − 1 − i). A coarse
    // texel (x, y) averages fine (2x, 2y), (2x + 1, 2y), (2x, 2y + 1) and the inverted texel at
    // (w − 1 − 2y, w − 1 − 2x); the format applies the same formula over the whole square.
    REQUIRE(back.reductions.size() == 1);
    REQUIRE(back.reductions[0].size() == 1);
    CHECK(back.reductions[0][0].faceId == 0);
    const std::vector<float> t = asFloats(file.texels[0]);
    const int w = 8;
    std::vector<float> expected(16);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x)
            expected[y * 4 + x] =
                0.25f * (t[2 * y * w + 2 * x] + t[2 * y * w + 2 * x + 1] + t[(2 * y + 1) * w + 2 * x] +
                         t[(w - 1 - 2 * x) * w + (w - 1 - 2 * y)]);
    CHECK(asFloats(back.reductions[0][0].texels) == expected);

    // A non-square face cannot be a triangle.
    file.faces[1].ulog2 = 3;
    file.texels[1].resize(32 * 4);
    try {
        (void)writePtexBytes(file);
        FAIL("a 8 x 4 triangle face was written");
    } catch (const deformkit::InvalidInput& e) {
        const std::string message = e.what();
        CHECK(message.find("face 1") != std::string::npos);
        CHECK(message.find("triangle") != std::string::npos);
    }
}

TEST_CASE("the neighbourhood-constant flag needs every face around every corner constant with the same value",
          "[ptex][reduction]") {
    // A 3 × 3 grid of quads (f = 3 row + column; edges bottom, right, top, left), constant value A on faces
    // 1, 3, 4, 5, 7, 8 and texture on the corners 0, 2, 6:
    //   6 7 8
    //   3 4 5
    //   0 1 2
    // Face 4's edge neighbours are all A but its corners touch 0, 2 and 6: not flagged. Face 8 meets only
    // 4, 5 and 7 and the border: flagged with clamp borders, not with periodic ones. Every other A face has
    // a textured edge neighbour.
    const std::vector<bool> isConstant{false, true, false, true, true, true, false, true, true};
    PtexFile file = randomFloatFile(std::vector<std::array<int, 2>>(9, {2, 2}), isConstant, 6);
    const std::vector<uint8_t> a = floats(std::vector<float>(16, 0.25f));
    for (int f = 0; f < 9; ++f) {
        if (isConstant[f]) file.texels[f] = a;
        const int x = f % 3, y = f / 3;
        file.faces[f].adjFaces = {y > 0 ? f - 3 : -1, x < 2 ? f + 1 : -1, y < 2 ? f + 3 : -1,
                                  x > 0 ? f - 1 : -1};
        file.faces[f].adjEdges = {2, 3, 0, 1};
    }
    const PtexFile clamped = readPtex(writePtexBytes(file), "grid.ptx");
    for (int f = 0; f < 9; ++f) {
        INFO("face " << f);
        CHECK(clamped.faces[f].constant == isConstant[f]);
        CHECK(clamped.faces[f].neighbourhoodConstant == (f == 8));
    }
    file.uBorderMode = BorderMode::Periodic;
    const PtexFile periodic = readPtex(writePtexBytes(file), "grid.ptx");
    for (int f = 0; f < 9; ++f)
        CHECK_FALSE(periodic.faces[f].neighbourhoodConstant);
}

TEST_CASE("files written by the reference Ptex library read back whole and are written again byte for byte",
          "[ptex][reduction]") {
    const auto name = GENERATE(as<std::string>{}, "ref_quad_u8_rgba.ptx", "ref_quad_half_a0.ptx",
                               "ref_tri_float.ptx", "ref_quad_u16_tiled.ptx");
    INFO(name);
    const std::vector<uint8_t> bytes = fileBytes(name);
    ReadOptions options;
    options.readReductions = true;
    const PtexFile file = readPtex(bytes, name, options);
    const std::vector<uint32_t> counts = levelFaceCounts(bytes);
    REQUIRE(file.reductions.size() + 1 == counts.size());
    for (size_t l = 0; l < file.reductions.size(); ++l)
        CHECK(file.reductions[l].size() == counts[l + 1]);
    // The reader's level 0 and metadata, written again: the reference writer's bytes (reductions, their
    // order and premultiplication, ConstData, flags, tiling, zlib blocks, metadata).
    const std::vector<uint8_t> again = writePtexBytes(file);
    CHECK(again.size() == bytes.size());
    CHECK(again == bytes);
}

TEST_CASE("a metadata entry without values is refused, as the format has none", "[ptex][reduction]") {
    PtexFile file = randomFloatFile({{1, 1}}, {false}, 7);
    file.metadata.push_back(MetaValue::ofInt32("empty", {}));
    CHECK_THROWS_WITH(writePtexBytes(file),
                      Catch::Contains("metadata entry 0") && Catch::Contains("'empty' has no values"));
}
