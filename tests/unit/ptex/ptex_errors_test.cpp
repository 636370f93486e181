#include <catch2/catch.hpp>

#include "deformkit/error.h"
#include "deformkit/ptex/ptex_file.h"
#include "ptex_test_util.h"

using namespace deformkit::ptex;
using Catch::Matchers::Contains;
using deformkit::ParseError;
namespace tp = deformkit::test::ptex;

namespace {

// Face 0: 4 × 2, 2 channels u8, zipped; face 1: 2 × 2 constant.
tp::HandStream validStream() {
    tp::HandStream s;
    s.channels = 2;
    tp::HandFace f0;
    f0.ulog2 = 2;
    f0.vlog2 = 1;
    tp::HandFace f1;
    f1.ulog2 = 1;
    f1.vlog2 = 1;
    f1.flags = 1;
    s.faces = {f0, f1};
    s.constData = {1, 2, 3, 4};
    std::vector<uint8_t> planes(16);
    for (size_t i = 0; i < planes.size(); ++i)
        planes[i] = static_cast<uint8_t>(i * 3);
    const std::vector<uint8_t> block = tp::zlibCompress(planes);
    s.blocks = {block, {}};
    s.headers = {(1u << 30) | static_cast<uint32_t>(block.size()), 0};
    s.metadata = tp::Bytes().u8(2).str("k").u8(0).u8(3).u32(4).i32(9).v;
    return s;
}

std::string at(size_t offset) {
    return " at byte " + std::to_string(offset);
}

// Reads bytes expecting a ParseError whose message contains every part.
void expectError(const std::vector<uint8_t>& bytes, std::initializer_list<std::string> parts) {
    try {
        (void)readPtex(bytes, "bad.ptx");
        FAIL("no error for a file that should fail");
    } catch (const ParseError& e) {
        const std::string message = e.what();
        INFO(message);
        CHECK(message.rfind("bad.ptx: ", 0) == 0);
        for (const std::string& part : parts)
            CHECK_THAT(message, Contains(part));
    }
}

}  // namespace

TEST_CASE("the valid hand stream used by the error tests reads", "[ptex][errors]") {
    const PtexFile file = readPtex(validStream().bytes(), "good.ptx");
    CHECK(file.faces.size() == 2);
    CHECK(file.metadata.size() == 1);
}

TEST_CASE("header errors name the header field's byte offset", "[ptex][errors]") {
    const std::vector<uint8_t> good = validStream().bytes();
    auto b = good;
    b[0] = 'X';
    expectError(b, {"header" + at(0), "magic is 'Xtex'", "expected 'Ptex'"});
    b = good;
    tp::wr32(b, 4, 2);
    expectError(b, {"header" + at(4), "version is 2", "version 1"});
    expectError(std::vector<uint8_t>(good.begin(), good.begin() + 50),
                {"header" + at(0), "file is 50 bytes"});
    b = good;
    tp::wr16(b, 20, 0);
    expectError(b, {"header" + at(20), "channel count is 0", "1..64"});
    tp::wr16(b, 20, 65);
    expectError(b, {"header" + at(20), "channel count is 65"});
    b = good;
    tp::wr32(b, 16, 2);
    expectError(b, {"header" + at(16), "alpha channel is 2", "-1 (none) or 0..1"});
    b = good;
    tp::wr32(b, 12, 4);
    expectError(b, {"header" + at(12), "data type is 4"});
}

TEST_CASE("truncated files and sizes pointing past the end name the section", "[ptex][errors]") {
    const tp::HandStream s = validStream();
    const std::vector<uint8_t> good = s.bytes();
    const auto layout = s.layout();
    auto b = good;
    tp::wr32(b, 32, 1000000);  // face info size
    expectError(b, {"face info" + at(104), "file ends at byte " + std::to_string(good.size())});
    expectError(std::vector<uint8_t>(good.begin(),
                                     good.begin() + static_cast<std::ptrdiff_t>(layout.levelBlocks + 3)),
                {"level data" + at(layout.levelData), "file ends"});
    expectError(std::vector<uint8_t>(good.begin(), good.begin() + 120), {"face info" + at(104)});
    b = good;
    tp::wr32(b, 28, 5000);  // extended header size
    expectError(b, {"extended header" + at(64)});
    // Every prefix of a valid file that cuts a section fails with a ParseError; none reads out of bounds or
    // throws anything else. (The final 8 bytes are the barrier after the metadata, which a reader only needs
    // when large metadata follows.)
    int otherErrors = 0;
    for (size_t n = 0; n + 8 < good.size(); ++n) {
        try {
            (void)readPtex(std::span(good.data(), n), "prefix.ptx");
            ++otherErrors;  // a prefix cannot be a whole file
        } catch (const ParseError&) {
        } catch (...) {
            ++otherErrors;
        }
    }
    CHECK(otherErrors == 0);
}

TEST_CASE("zlib errors and inconsistent inflated sizes name the section", "[ptex][errors]") {
    const tp::HandStream s = validStream();
    const std::vector<uint8_t> good = s.bytes();
    auto b = good;
    b[104] = 0;  // the face info stream's zlib header byte
    expectError(b, {"face info" + at(104), "zlib error", "a valid zlib stream"});
    b = good;
    tp::wr32(b, 24, 3);  // 3 faces: face info should inflate to 60 bytes, it holds 40
    expectError(b, {"face info" + at(104), "inflates to 40 bytes", "expected 60 bytes"});
    b = good;
    tp::wr32(b, 24, 100000000);  // more face records than zlib could inflate from these bytes
    expectError(b, {"face info" + at(104), "declared to inflate", "zlib's limit"});
    b = good;
    tp::wr32(b, 36, tp::rd32(good, 36) - 1);  // constant data one byte short: a truncated stream
    expectError(b, {"constant data" + at(s.layout().constData), "zlib"});
}

TEST_CASE("impossible resolutions and adjacency name the face info section", "[ptex][errors]") {
    tp::HandStream s = validStream();
    s.faces[1].ulog2 = 16;
    expectError(s.bytes(), {"face info" + at(104), "face 1", "resolution log2 16 x 1", "0..15"});
    s = validStream();
    s.faces[0].vlog2 = -1;
    expectError(s.bytes(), {"face info" + at(104), "face 0", "log2 2 x -1"});
    s = validStream();
    s.faces[0].adjFaces[2] = 2;  // only faces 0 and 1 exist
    expectError(s.bytes(), {"face info" + at(104), "face 0 edge 2 names neighbour face 2", "below 2"});
    s = validStream();
    s.faces[1].adjFaces[0] = -2;
    expectError(s.bytes(), {"face info" + at(104), "neighbour face -2"});
}

TEST_CASE("inconsistent face-data headers and level info name the level and offset", "[ptex][errors]") {
    tp::HandStream s = validStream();
    const auto layout = s.layout();
    s.headers[0] += 5;  // a block longer than the level
    expectError(s.bytes(), {"level 0 data" + at(layout.levelBlocks), "runs past the level's end"});
    s = validStream();
    s.headers[0] -= 1;  // blocks shorter than the level
    expectError(s.bytes(), {"level 0 data" + at(layout.levelData), "face blocks end at byte"});
    s = validStream();
    s.headers[1] = 1u << 30;  // a constant face with a (zero-length) zipped block
    expectError(s.bytes(), {"level 0 data, face 1", "flagged constant", "0x40000000"});
    s = validStream();
    s.blocks[0].push_back(0);  // a zip block with one byte after the stream's end
    s.headers[0] += 1;
    expectError(s.bytes(), {"level 0 data, face 0" + at(layout.levelBlocks), "zlib stream ends after"});
    s = validStream();
    s.headers[0] = (2u << 30) | (s.headers[0] & 0x3fffffffu);
    s.dataType = 3;  // float data may not be difference-zipped
    s.constData.resize(16);
    expectError(s.bytes(), {"level 0 data, face 0", "difference-zipped"});
    auto b = validStream().bytes();
    tp::wr32(b, layout.levelInfo + 12, 3);  // level 0 lists 3 faces of 2
    expectError(b, {"level info (level 0)" + at(layout.levelInfo), "lists 3 faces", "every face at level 0"});
    b = validStream().bytes();
    tp::wr32(b, 40, 32);  // level info size for 2 levels with 1 level declared
    expectError(b, {"level info" + at(layout.levelInfo), "is 32 bytes"});
}

TEST_CASE("a tiled block with an impossible tile layout names the face", "[ptex][errors]") {
    tp::HandStream s = validStream();
    const std::vector<uint8_t> tileHeaders = tp::zlibCompress(tp::Bytes().u32(2).v);
    tp::Bytes block;
    block.u8(3).u8(1).u32(static_cast<uint32_t>(tileHeaders.size())).append(tileHeaders).u8(1).u8(2);
    s.blocks[0] = block.v;
    s.headers[0] = (3u << 30) | static_cast<uint32_t>(block.v.size());
    const auto layout = s.layout();
    expectError(s.bytes(), {"level 0 data, face 0" + at(layout.levelBlocks), "tile resolution log2 3 x 1"});
    // A valid layout (one 4 × 2 tile) whose tile is "constant" with 2 bytes (one 2-channel pixel) reads.
    block = tp::Bytes();
    block.u8(2).u8(1).u32(static_cast<uint32_t>(tileHeaders.size())).append(tileHeaders).u8(5).u8(6);
    s.blocks[0] = block.v;
    s.headers[0] = (3u << 30) | static_cast<uint32_t>(block.v.size());
    const PtexFile file = readPtex(s.bytes(), "tiled.ptx");
    CHECK(file.texels[0] == std::vector<uint8_t>{5, 6, 5, 6, 5, 6, 5, 6, 5, 6, 5, 6, 5, 6, 5, 6});
    // The same tile declared as 3 bytes does not match the pixel size.
    const std::vector<uint8_t> badHeaders = tp::zlibCompress(tp::Bytes().u32(3).v);
    block = tp::Bytes();
    block.u8(2).u8(1).u32(static_cast<uint32_t>(badHeaders.size())).append(badHeaders).u8(5).u8(6).u8(7);
    s.blocks[0] = block.v;
    s.headers[0] = (3u << 30) | static_cast<uint32_t>(block.v.size());
    expectError(s.bytes(), {"level 0 data, face 0", "tile 0 is constant with 3 bytes", "2 (one pixel)"});
}

TEST_CASE("malformed metadata, large metadata and edit data name their section", "[ptex][errors]") {
    tp::HandStream s = validStream();
    s.metadata = tp::Bytes().u8(3).str("abc").u8(3).u32(0).v;  // key without its NUL
    const auto layout = s.layout();
    expectError(s.bytes(), {"metadata" + at(layout.metadata), "entry at inflated byte 0", "NUL"});
    s.metadata = tp::Bytes().u8(2).str("k").u8(0).u8(3).u32(6).u32(1).u16(2).v;  // 6 bytes of i32
    expectError(s.bytes(), {"metadata" + at(layout.metadata), "a multiple of 4"});
    s.metadata = tp::Bytes().u8(2).str("k").u8(0).u8(9).u32(0).v;
    expectError(s.bytes(), {"metadata" + at(layout.metadata), "type is 9"});

    // Large metadata whose value claims more zipped bytes than the section holds.
    PtexFile file;
    file.faces.resize(1);
    file.texels.resize(1);
    file.texels[0] = {1};
    file.metadata.push_back(MetaValue::ofDouble("big", std::vector<double>(200, 0.5)));
    std::vector<uint8_t> b = writePtexBytes(file);
    const tp::Header h = tp::parseHeader(b);
    const size_t lmd = b.size() - h.lmdDataSize - h.lmdHeaderZipSize;
    auto cut = b;
    tp::wr32(cut, 80, static_cast<uint32_t>(h.lmdDataSize - 1));
    expectError(cut, {"large metadata" + at(lmd), "runs past the large-metadata data"});
    cut = b;
    cut.back() ^= 0xff;  // damages the value's zlib stream (its Adler-32 trailer)
    expectError(cut, {"large metadata value 'big'" + at(lmd + h.lmdHeaderZipSize), "zlib"});
    cut = b;
    tp::wr32(cut, 88, 100);  // edit data size 100 at the end of the file
    expectError(cut, {"edit data" + at(b.size()), "needs 100 bytes"});
}

TEST_CASE("every single-byte corruption of a written file reads or fails with a library error",
          "[ptex][errors]") {
    PtexFile file;
    file.dataType = DataType::UInt16;
    file.channels = 2;
    file.alphaChannel = 1;
    const int res[3][2] = {{2, 3}, {0, 0}, {3, 3}};
    for (int f = 0; f < 3; ++f) {
        FaceInfo info;
        info.ulog2 = static_cast<int8_t>(res[f][0]);
        info.vlog2 = static_cast<int8_t>(res[f][1]);
        info.adjFaces = {(f + 1) % 3, -1, -1, (f + 2) % 3};
        file.faces.push_back(info);
        std::vector<uint8_t> t(info.texelCount() * 4);
        for (size_t i = 0; i < t.size(); ++i)
            t[i] = static_cast<uint8_t>(i * 31 + f);
        file.texels.push_back(t);
    }
    file.metadata.push_back(MetaValue::ofString("s", "text"));
    file.metadata.push_back(MetaValue::ofInt32("large", std::vector<int32_t>(300, 5)));
    WriteOptions options;
    options.tileThresholdBytes = 64;  // tile the 8 × 8 face into small tiles
    options.tileBytes = 32;
    const std::vector<uint8_t> good = writePtexBytes(file, options);
    REQUIRE(readPtex(good, "good.ptx").faces.size() == 3);
    int otherErrors = 0;
    int rejected = 0;
    for (size_t i = 0; i < good.size(); ++i) {
        for (const uint8_t mask : {uint8_t{0xff}, uint8_t{0x01}}) {
            std::vector<uint8_t> b = good;
            b[i] ^= mask;
            try {
                (void)readPtex(b, "flip.ptx", ReadOptions{true, uint64_t{1} << 24});
            } catch (const deformkit::Error&) {
                ++rejected;
            } catch (...) {
                ++otherErrors;
            }
        }
    }
    CHECK(otherErrors == 0);
    CHECK(rejected > static_cast<int>(good.size()));  // most flips land in zlib streams or size fields
}

TEST_CASE("decoded texels are capped by ReadOptions::maxDecodedBytes", "[ptex][errors]") {
    // One 2^15 × 2^15 u8 face as a single constant tile: a few bytes that expand to 1 GiB.
    tp::HandStream s;
    tp::HandFace f;
    f.ulog2 = 15;
    f.vlog2 = 15;
    s.faces = {f};
    s.constData = {0};
    const std::vector<uint8_t> tileHeaders = tp::zlibCompress(tp::Bytes().u32(1).v);
    tp::Bytes block;
    block.u8(15).u8(15).u32(static_cast<uint32_t>(tileHeaders.size())).append(tileHeaders).u8(200);
    s.blocks = {block.v};
    s.headers = {(3u << 30) | static_cast<uint32_t>(block.v.size())};
    ReadOptions options;
    options.maxDecodedBytes = uint64_t{1} << 20;
    CHECK_THROWS_WITH(readPtex(s.bytes(), "huge.ptx", options),
                      Contains("level 0 data, face 0 at byte " + std::to_string(s.layout().levelBlocks)) &&
                          Contains("maxDecodedBytes"));
}

TEST_CASE("face records and constant data are capped before they are inflated", "[ptex][errors]") {
    // 4096 constant 1 x 1 faces of 64 float channels: a few hundred zipped bytes declare 1 MiB of constant
    // data and 80 KiB of face records, counted before zlib is asked for them.
    tp::HandStream s;
    s.dataType = 3;  // float32
    s.channels = 64;
    tp::HandFace constant;
    constant.flags = 1;
    s.faces.assign(4096, constant);
    s.constData.assign(4096 * 64 * 4, 0);
    s.blocks.assign(4096, {});
    s.headers.assign(4096, 0);
    ReadOptions options;
    options.maxDecodedBytes = uint64_t{512} << 10;
    CHECK_THROWS_WITH(readPtex(s.bytes(), "consts.ptx", options), Contains("constant data") &&
                                                                      Contains("decoded data would reach") &&
                                                                      Contains("maxDecodedBytes"));
    options.maxDecodedBytes = uint64_t{64} << 10;
    CHECK_THROWS_WITH(
        readPtex(s.bytes(), "consts.ptx", options),
        Contains("face info" + at(tp::HandStream::kFaceInfoOffset)) && Contains("maxDecodedBytes"));
    options.maxDecodedBytes = uint64_t{4} << 20;
    CHECK(readPtex(s.bytes(), "consts.ptx", options).constData.size() == 4096u * 64 * 4);
}

TEST_CASE("a 1 x 1 face is read from ConstData whatever its block holds", "[ptex][errors]") {
    tp::HandStream s = validStream();
    s.faces[1].ulog2 = 0;
    s.faces[1].vlog2 = 0;
    s.faces[1].flags = 0;
    const std::vector<uint8_t> block = tp::zlibCompress(std::vector<uint8_t>{99, 98});
    s.blocks[1] = block;
    s.headers[1] = (1u << 30) | static_cast<uint32_t>(block.size());
    const PtexFile file = readPtex(s.bytes(), "one.ptx");
    CHECK(file.texels[1] == std::vector<uint8_t>{3, 4});
}
