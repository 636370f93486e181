#include <catch2/catch.hpp>

#include "deformkit/error.h"
#include "deformkit/ptex/ptex_file.h"
#include "ptex_test_util.h"

using namespace deformkit::ptex;
namespace tp = deformkit::test::ptex;

namespace {

// A two-face single-channel u8 file from the writer, with metadata "name" = "old".
std::vector<uint8_t> baseFile() {
    PtexFile file;
    file.faces.resize(2);
    file.faces[0].ulog2 = 1;
    file.faces[0].vlog2 = 1;
    file.faces[1].ulog2 = 1;
    file.faces[1].vlog2 = 0;
    file.texels = {{1, 2, 3, 4}, {5, 6}};
    file.metadata.push_back(MetaValue::ofString("name", "old"));
    return writePtexBytes(file);
}

// Appends edit records to `bytes` and points the extended header at them.
std::vector<uint8_t> withEdits(std::vector<uint8_t> bytes, const std::vector<uint8_t>& edits) {
    const uint64_t pos = bytes.size();
    bytes.insert(bytes.end(), edits.begin(), edits.end());
    for (int i = 0; i < 8; ++i) {
        bytes[88 + i] = static_cast<uint8_t>(static_cast<uint64_t>(edits.size()) >> (8 * i));
        bytes[96 + i] = static_cast<uint8_t>(pos >> (8 * i));
    }
    return bytes;
}

}  // namespace

TEST_CASE("face and metadata edits are applied in order", "[ptex][edits]") {
    // Face edit: face 1 becomes 4 × 1 with texels 10, 20, 30, 40 (one zipped block, encoding 1).
    const std::vector<uint8_t> block = tp::zlibCompress(std::vector<uint8_t>{10, 20, 30, 40});
    tp::Bytes face;
    face.i32(1);                                                  // face id
    face.u8(2).u8(0).u8(0).u8(0).i32(0).i32(-1).i32(-1).i32(-1);  // FaceInfo: 4 × 1, bottom neighbour face 0
    face.u32((1u << 30) | static_cast<uint32_t>(block.size()));   // face-data header
    face.u8(25);                                                  // constant value (the average)
    face.append(block);
    // Metadata edit: "name" replaced, "extra" added.
    const std::vector<uint8_t> entries = tp::Bytes()
                                             .u8(5)
                                             .str("name")
                                             .u8(0)
                                             .u8(0)
                                             .u32(4)
                                             .str("new")
                                             .u8(0)
                                             .u8(6)
                                             .str("extra")
                                             .u8(0)
                                             .u8(1)
                                             .u32(2)
                                             .u8(0xff)
                                             .u8(7)
                                             .v;
    const std::vector<uint8_t> zipped = tp::zlibCompress(entries);
    tp::Bytes meta;
    meta.u32(static_cast<uint32_t>(zipped.size())).u32(static_cast<uint32_t>(entries.size())).append(zipped);
    tp::Bytes edits;
    edits.u8(0).u32(static_cast<uint32_t>(face.v.size())).append(face.v);
    edits.u8(1).u32(static_cast<uint32_t>(meta.v.size())).append(meta.v);
    const PtexFile file = readPtex(withEdits(baseFile(), edits.v), "edited.ptx");
    REQUIRE(file.faces.size() == 2);
    CHECK(file.texels[0] == std::vector<uint8_t>{1, 2, 3, 4});
    CHECK(file.faces[1].ulog2 == 2);
    CHECK(file.faces[1].vlog2 == 0);
    CHECK(file.faces[1].adjFaces[0] == 0);
    CHECK(file.faces[1].hasEdits);
    CHECK_FALSE(file.faces[0].hasEdits);
    CHECK(file.texels[1] == std::vector<uint8_t>{10, 20, 30, 40});
    CHECK(file.constData[1] == 25);
    REQUIRE(file.metadata.size() == 2);
    CHECK(file.metadata[0].string == "new");
    CHECK(file.metadata[1].key == "extra");
    CHECK(file.metadata[1].int8s == std::vector<int8_t>{-1, 7});
}

TEST_CASE("a face edit naming a missing face or with inconsistent sizes is a ParseError",
          "[ptex][edits][errors]") {
    const std::vector<uint8_t> base = baseFile();
    tp::Bytes face;
    face.i32(2).u8(0).u8(0).u8(1).u8(0).i32(-1).i32(-1).i32(-1).i32(-1).u32(0).u8(9);  // face 2 of 2
    tp::Bytes edits;
    edits.u8(0).u32(static_cast<uint32_t>(face.v.size())).append(face.v);
    CHECK_THROWS_AS(readPtex(withEdits(base, edits.v), "bad.ptx"), deformkit::ParseError);
    CHECK_THROWS_WITH(readPtex(withEdits(base, edits.v), "bad.ptx"),
                      Catch::Matchers::Contains("face edit at byte " + std::to_string(base.size() + 5)) &&
                          Catch::Matchers::Contains("names face 2"));
    face = tp::Bytes();
    face.i32(0).u8(0).u8(0).u8(1).u8(0).i32(-1).i32(-1).i32(-1).i32(-1).u32((1u << 30) | 50).u8(9);
    edits = tp::Bytes();
    edits.u8(0).u32(static_cast<uint32_t>(face.v.size())).append(face.v);
    CHECK_THROWS_WITH(readPtex(withEdits(base, edits.v), "bad.ptx"),
                      Catch::Matchers::Contains("face edit") && Catch::Matchers::Contains("50-byte block"));
}
