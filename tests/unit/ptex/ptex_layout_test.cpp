#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>

#include "deformkit/ptex/ptex_file.h"
#include "ptex_test_util.h"

using namespace deformkit::ptex;
namespace tp = deformkit::test::ptex;

namespace {

// Channel c of texel (u, v) in the hand-made 4 × 2, 2-channel face.
uint8_t handValue(int c, int u, int v) {
    return static_cast<uint8_t>(100 * c + 10 * v + u);
}

// Two faces: face 0 is 4 × 2 with two u8 channels, one zipped (encoding 1) block in channel planes; face 1
// is a constant 2 × 2 face, flagged, with its value in ConstData and a zero header.
tp::HandStream handStream() {
    tp::HandStream s;
    s.channels = 2;
    tp::HandFace f0;
    f0.ulog2 = 2;
    f0.vlog2 = 1;
    f0.adjFaces[1] = 1;     // right neighbour: face 1 ...
    f0.adjEdges = 3u << 2;  // ... across its edge 3 (left)
    tp::HandFace f1;
    f1.ulog2 = 1;
    f1.vlog2 = 1;
    f1.flags = 1 | 8;  // constant, subface
    f1.adjFaces[3] = 0;
    f1.adjEdges = 1u << 6;  // edge 3 meets face 0's edge 1
    s.faces = {f0, f1};
    s.constData = {7, 8, 42, 43};  // face 0's average (not checked by readers), face 1's value
    std::vector<uint8_t> planes;
    for (int c = 0; c < 2; ++c) {
        for (int v = 0; v < 2; ++v) {
            for (int u = 0; u < 4; ++u)
                planes.push_back(handValue(c, u, v));
        }
    }
    const std::vector<uint8_t> block = tp::zlibCompress(planes);
    s.blocks = {block, {}};
    s.headers = {(1u << 30) | static_cast<uint32_t>(block.size()), 0};
    return s;
}

}  // namespace

TEST_CASE("a Ptex stream assembled by hand from the notes reads as expected", "[ptex][layout]") {
    // Texel values are small integers placed by hand: exact comparison.
    const tp::HandStream s = handStream();
    const PtexFile file = readPtex(s.bytes(), "hand.ptx");
    REQUIRE(file.faces.size() == 2);
    CHECK(file.dataType == DataType::UInt8);
    CHECK(file.meshType == MeshType::Quad);
    CHECK(file.channels == 2);
    CHECK(file.faces[0].ulog2 == 2);
    CHECK(file.faces[0].vlog2 == 1);
    CHECK(file.faces[0].adjFaces == std::array<int32_t, 4>{-1, 1, -1, -1});
    CHECK(file.faces[0].adjEdges == std::array<uint8_t, 4>{0, 3, 0, 0});
    CHECK(file.faces[1].constant);
    CHECK(file.faces[1].subface);
    CHECK(file.faces[1].adjEdges == std::array<uint8_t, 4>{0, 0, 0, 1});
    REQUIRE(file.texels[0].size() == 16);
    int wrong = 0;
    for (int v = 0; v < 2; ++v) {
        for (int u = 0; u < 4; ++u) {
            for (int c = 0; c < 2; ++c) {
                if (file.texels[0][(v * 4 + u) * 2 + c] != handValue(c, u, v)) ++wrong;
            }
        }
    }
    CHECK(wrong == 0);
    CHECK(file.texels[1].empty());
    CHECK(expandedTexels(file, 1) == std::vector<uint8_t>{42, 43, 42, 43, 42, 43, 42, 43});
}

TEST_CASE("a hand-made difference-zipped u16 face and small metadata read as expected", "[ptex][layout]") {
    tp::HandStream s;
    s.dataType = 1;  // u16
    tp::HandFace f;
    f.ulog2 = 1;
    f.vlog2 = 1;
    s.faces = {f};
    s.constData = {0, 0};
    const uint16_t values[4] = {1000, 65535, 3, 40000};  // (0,0) (1,0) (0,1) (1,1)
    tp::Bytes diffs;
    uint16_t previous = 0;
    for (uint16_t v : values) {
        diffs.u16(static_cast<uint16_t>(v - previous));  // wrapping difference from the previous value
        previous = v;
    }
    const std::vector<uint8_t> block = tp::zlibCompress(diffs.v);
    s.blocks = {block};
    s.headers = {(2u << 30) | static_cast<uint32_t>(block.size())};
    tp::Bytes meta;
    meta.u8(5).str("name").u8(0).u8(0).u32(3).str("ab").u8(0);    // string "ab"
    meta.u8(4).str("ids").u8(0).u8(3).u32(8).i32(-5).i32(70000);  // i32 {-5, 70000}
    meta.u8(2).str("d").u8(0).u8(5).u32(8).append(std::vector<uint8_t>{0, 0, 0, 0, 0, 0, 0xf0, 0x3f});  // 1.0
    s.metadata = meta.v;
    const PtexFile file = readPtex(s.bytes(), "hand16.ptx");
    REQUIRE(file.texels[0].size() == 8);
    for (int i = 0; i < 4; ++i)
        CHECK(tp::rd16(file.texels[0], 2 * i) == values[i]);
    REQUIRE(file.metadata.size() == 3);
    CHECK(file.metadata[0].key == "name");
    CHECK(file.metadata[0].string == "ab");
    CHECK(file.metadata[1].int32s == std::vector<int32_t>{-5, 70000});
    CHECK(file.metadata[2].doubles == std::vector<double>{1.0});
}

TEST_CASE("the writer's header fields and section sizes follow the notes", "[ptex][layout]") {
    PtexFile file;
    file.dataType = DataType::Float;
    file.channels = 2;
    file.alphaChannel = 1;
    file.vBorderMode = BorderMode::Periodic;
    file.faces.resize(3);
    file.faces[0].ulog2 = 5;
    file.faces[0].vlog2 = 4;  // 32 × 16: levels 0..2 (reductions down to 4 texels on the smaller side)
    file.faces[1].ulog2 = 1;
    file.faces[1].vlog2 = 1;  // 2 × 2: level 0 only
    file.faces[2].ulog2 = 0;
    file.faces[2].vlog2 = 5;  // 1 × 32: level 0 only
    file.faces[0].adjFaces = {2, -1, 1, -1};
    file.faces[0].adjEdges = {1, 0, 3, 0};
    file.texels.resize(3);
    for (size_t f = 0; f < 3; ++f) {
        file.texels[f].resize(file.faces[f].texelCount() * 8);
        for (size_t i = 0; i < file.texels[f].size() / 4; ++i) {
            const float x = static_cast<float>(f * 1000 + i) * 0.25f;
            std::memcpy(file.texels[f].data() + 4 * i, &x, 4);
        }
    }
    file.metadata.push_back(MetaValue::ofString("small", "s"));
    file.metadata.push_back(MetaValue::ofFloat("big", std::vector<float>(400, 2.0f)));  // 1600 bytes: large
    const std::vector<uint8_t> b = writePtexBytes(file);
    const tp::Header h = tp::parseHeader(b);
    CHECK(h.magic == 0x78657450u);  // "Ptex"
    CHECK(std::memcmp(b.data(), "Ptex", 4) == 0);
    CHECK(h.version == 1);
    CHECK(h.meshType == 1);
    CHECK(h.dataType == 3);
    CHECK(h.alphaChannel == 1);
    CHECK(h.channels == 2);
    CHECK(h.levels == 3);
    CHECK(h.faces == 3);
    CHECK(h.extHeaderSize == 40);
    CHECK(h.levelInfoSize == 3 * 16);
    CHECK(h.vBorder == 2);
    CHECK(h.uBorder == 0);
    CHECK(h.editDataSize == 0);
    // Sections back to back, with the 8-byte barrier after the metadata, ending where edit data would start.
    const uint64_t end = 64 + 40 + h.faceInfoSize + h.constDataSize + h.levelInfoSize + h.levelDataSize +
                         h.metaZipSize + 8 + h.lmdHeaderZipSize + h.lmdDataSize;
    CHECK(end == b.size());
    CHECK(h.editDataPos == b.size());
    size_t at = 104;
    const std::vector<uint8_t> faceInfo = tp::zlibUncompress(std::span(b).subspan(at, h.faceInfoSize), 60);
    REQUIRE(faceInfo.size() == 60);
    CHECK(static_cast<int8_t>(faceInfo[0]) == 5);
    CHECK(static_cast<int8_t>(faceInfo[1]) == 4);
    CHECK(faceInfo[2] == (1 | (0 << 2) | (3 << 4)));  // adjedges, 2 bits per edge
    CHECK(faceInfo[3] == 0);                          // flags: not constant
    CHECK(static_cast<int32_t>(tp::rd32(faceInfo, 4)) == 2);
    CHECK(static_cast<int32_t>(tp::rd32(faceInfo, 8)) == -1);
    CHECK(static_cast<int32_t>(tp::rd32(faceInfo, 12)) == 1);
    CHECK(static_cast<int8_t>(faceInfo[41]) == 5);
    at += h.faceInfoSize;
    const std::vector<uint8_t> constData = tp::zlibUncompress(std::span(b).subspan(at, h.constDataSize), 24);
    CHECK(constData.size() == 3 * 8);
    at += h.constDataSize;
    // Level info: level 0 lists every face, level i the faces with min(ulog2, vlog2) >= i + 2: 3, 1, 1.
    const uint32_t expectedFaces[3] = {3, 1, 1};
    uint64_t levelSum = 0;
    const size_t levelInfoAt = at;
    for (int i = 0; i < 3; ++i) {
        levelSum += tp::rd64(b, at + 16 * i);
        CHECK(tp::rd32(b, at + 16 * i + 12) == expectedFaces[i]);
    }
    CHECK(levelSum == h.levelDataSize);
    at += h.levelInfoSize;
    // Level 0: zipped u32 headers, then face blocks; float data is zipped as is (encoding 1).
    const uint32_t headerZip = tp::rd32(b, levelInfoAt + 8);
    const std::vector<uint8_t> headers = tp::zlibUncompress(std::span(b).subspan(at, headerZip), 12);
    REQUIRE(headers.size() == 12);
    uint64_t blocks = 0;
    for (int f = 0; f < 3; ++f) {
        CHECK(tp::rd32(headers, 4 * f) >> 30 == 1);
        blocks += tp::rd32(headers, 4 * f) & 0x3fffffffu;
    }
    CHECK(headerZip + blocks == tp::rd64(b, levelInfoAt));
    // Face 0's block, decoded here: channel planes of 32 × 16 floats, v-major.
    const std::vector<uint8_t> planes =
        tp::zlibUncompress(std::span(b).subspan(at + headerZip, tp::rd32(headers, 0) & 0x3fffffffu), 4096);
    REQUIRE(planes.size() == 4096);
    int wrong = 0;
    for (int c = 0; c < 2; ++c) {
        for (int t = 0; t < 512; ++t) {
            if (std::memcmp(planes.data() + 4 * (c * 512 + t), file.texels[0].data() + 4 * (t * 2 + c), 4) !=
                0)
                ++wrong;
        }
    }
    CHECK(wrong == 0);
    // Metadata: the small entry in the zipped block, the large one in the large-metadata section.
    const size_t metaAt = at + h.levelDataSize;
    const std::vector<uint8_t> meta =
        tp::zlibUncompress(std::span(b).subspan(metaAt, h.metaZipSize), h.metaMemSize);
    CHECK(meta == tp::Bytes().u8(6).str("small").u8(0).u8(0).u32(2).str("s").u8(0).v);
    for (size_t i = 0; i < 8; ++i)
        CHECK(b[metaAt + h.metaZipSize + i] == 0);
    const size_t lmdAt = metaAt + h.metaZipSize + 8;
    const std::vector<uint8_t> lmd =
        tp::zlibUncompress(std::span(b).subspan(lmdAt, h.lmdHeaderZipSize), h.lmdHeaderMemSize);
    REQUIRE(lmd.size() == 1 + 4 + 1 + 4 + 4);
    CHECK(lmd[0] == 4);
    CHECK(std::memcmp(lmd.data() + 1, "big", 4) == 0);
    CHECK(lmd[5] == 4);                         // float
    CHECK(tp::rd32(lmd, 6) == 1600);            // value bytes
    CHECK(tp::rd32(lmd, 10) == h.lmdDataSize);  // its zip block fills the data section
    const std::vector<uint8_t> value =
        tp::zlibUncompress(std::span(b).subspan(lmdAt + h.lmdHeaderZipSize, h.lmdDataSize), 1600);
    CHECK(value.size() == 1600);
}

TEST_CASE("tiled faces: tile resolution, zipped tile headers and constant tiles follow the notes",
          "[ptex][layout]") {
    // A u8 single-channel 512 × 256 face (128 KiB) is tiled; its left half is constant.
    PtexFile file;
    file.faces.resize(1);
    file.faces[0].ulog2 = 9;
    file.faces[0].vlog2 = 8;
    file.texels.resize(1);
    file.texels[0].resize(512 * 256);
    for (int v = 0; v < 256; ++v) {
        for (int u = 0; u < 512; ++u)
            file.texels[0][v * 512 + u] = u < 256 ? 9 : static_cast<uint8_t>(u * 7 + v * 13);
    }
    const std::vector<uint8_t> b = writePtexBytes(file);
    const tp::Header h = tp::parseHeader(b);
    const size_t levelInfo = 104 + h.faceInfoSize + h.constDataSize;
    const size_t level0 = levelInfo + h.levelInfoSize;
    const uint32_t headerZip = tp::rd32(b, levelInfo + 8);
    const uint32_t header = tp::rd32(tp::zlibUncompress(std::span(b).subspan(level0, headerZip), 4), 0);
    REQUIRE(header >> 30 == 3);
    const size_t face = level0 + headerZip;
    const int tileU = static_cast<int8_t>(b[face]);
    const int tileV = static_cast<int8_t>(b[face + 1]);
    CHECK(tileU + tileV <= 16);  // tiles of at most 64 KiB
    const uint32_t tileHeaderZip = tp::rd32(b, face + 2);
    const size_t tilesU = size_t{1} << (9 - tileU);
    const size_t tiles = tilesU << (8 - tileV);
    const std::vector<uint8_t> th =
        tp::zlibUncompress(std::span(b).subspan(face + 6, tileHeaderZip), 4 * tiles);
    REQUIRE(th.size() == 4 * tiles);
    uint64_t sum = 6 + tileHeaderZip;
    size_t at = face + 6 + tileHeaderZip;
    int wrong = 0;
    for (size_t t = 0; t < tiles; ++t) {
        const uint32_t e = tp::rd32(th, 4 * t) >> 30;
        const uint32_t size = tp::rd32(th, 4 * t) & 0x3fffffffu;
        const bool leftHalf = (t % tilesU) * (size_t{1} << tileU) < 256;
        if (leftHalf && !(e == 0 && size == 1 && b[at] == 9)) ++wrong;  // a constant tile is one raw pixel
        if (!leftHalf && e != 2) ++wrong;                               // u8 tiles are difference-zipped
        sum += size;
        at += size;
    }
    CHECK(wrong == 0);
    CHECK(sum == (header & 0x3fffffffu));
}
