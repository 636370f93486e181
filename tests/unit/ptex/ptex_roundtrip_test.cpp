#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <random>

#include "deformkit/error.h"
#include "deformkit/ptex/ptex_file.h"
#include "ptex_test_util.h"
#include "test_support.h"

using namespace deformkit::ptex;
namespace tp = deformkit::test::ptex;

namespace {

struct Layout {
    int channels;
    int alpha;
};

std::vector<uint8_t> randomBytes(std::mt19937& rng, size_t n) {
    std::vector<uint8_t> out(n);
    for (uint8_t& b : out)
        b = static_cast<uint8_t>(rng());
    return out;
}

// Faces: 1×1, 4×4, 8×2, 1×16, a constant 4×4, a constant 2×2 given only by its ConstData value, and one
// face of at least 128 KiB (tiled) whose left half is constant (constant tiles) and right half random.
PtexFile sampleFile(DataType type, Layout layout, uint32_t seed) {
    std::mt19937 rng(seed);
    PtexFile file;
    file.dataType = type;
    file.channels = layout.channels;
    file.alphaChannel = layout.alpha;
    file.uBorderMode = BorderMode::Periodic;
    file.vBorderMode = BorderMode::Black;
    file.edgeFilterMode = EdgeFilterMode::TangentVectors;
    const size_t pixel = file.pixelSize();
    int largeLog2 = 0;
    while ((size_t{1} << largeLog2) * pixel < 128 * 1024)
        ++largeLog2;
    const std::vector<std::pair<int, int>> res = {
        {0, 0}, {2, 2}, {3, 1}, {0, 4}, {2, 2}, {1, 1}, {(largeLog2 + 1) / 2, largeLog2 / 2}};
    const size_t n = res.size();
    file.faces.resize(n);
    file.texels.resize(n);
    file.constData.assign(n * pixel, 0);
    for (size_t f = 0; f < n; ++f) {
        FaceInfo& info = file.faces[f];
        info.ulog2 = static_cast<int8_t>(res[f].first);
        info.vlog2 = static_cast<int8_t>(res[f].second);
        for (int e = 0; e < 4; ++e) {
            info.adjFaces[e] = static_cast<int32_t>(rng() % (n + 1)) - 1;
            info.adjEdges[e] = static_cast<uint8_t>(rng() % 4);
        }
        info.subface = f == 2;
        file.texels[f] = randomBytes(rng, info.texelCount() * pixel);
    }
    const std::vector<uint8_t> value = randomBytes(rng, pixel);
    for (size_t t = 0; t < file.faces[4].texelCount(); ++t) {
        std::memcpy(file.texels[4].data() + t * pixel, value.data(), pixel);
    }
    file.texels[5].clear();
    std::memcpy(file.constData.data() + 5 * pixel, value.data(), pixel);
    file.faces[4].adjFaces = {5, -1, -1, -1};  // constant next to an equal constant: neighbourhood constant
    file.faces[5].adjFaces = {-1, 4, -1, -1};
    FaceInfo& large = file.faces[6];
    const std::vector<uint8_t> fill = randomBytes(rng, pixel);
    for (int v = 0; v < large.vres(); ++v) {
        for (int u = 0; u < large.ures() / 2; ++u) {
            std::memcpy(file.texels[6].data() + (static_cast<size_t>(v) * large.ures() + u) * pixel,
                        fill.data(), pixel);
        }
    }
    return file;
}

std::vector<MetaValue> sampleMetadata() {
    std::vector<MetaValue> m;
    m.push_back(MetaValue::ofString("name", "hello"));
    m.push_back(MetaValue::ofString("long text", std::string(2000, 'x') + "end"));
    m.push_back(MetaValue::ofInt8("i8", {-128, 0, 127}));
    m.push_back(MetaValue::ofInt8("i8 large", std::vector<int8_t>(1500, -3)));
    m.push_back(MetaValue::ofInt16("i16", {-32768, 1, 32767}));
    std::vector<int16_t> i16(700);
    for (size_t i = 0; i < i16.size(); ++i)
        i16[i] = static_cast<int16_t>(i * 97 - 30000);
    m.push_back(MetaValue::ofInt16("i16 large", i16));
    m.push_back(MetaValue::ofInt32("i32", {-2147483647 - 1, 7, 2147483647}));
    std::vector<int32_t> i32(400);
    for (size_t i = 0; i < i32.size(); ++i)
        i32[i] = static_cast<int32_t>(i * 2654435761u);
    m.push_back(MetaValue::ofInt32("i32 large", i32));
    m.push_back(MetaValue::ofFloat("f32", {1.5f, -0.0f, 3.4e38f}));
    std::vector<float> f32(300);
    for (size_t i = 0; i < f32.size(); ++i)
        f32[i] = static_cast<float>(i) * 0.1f;
    m.push_back(MetaValue::ofFloat("f32 large", f32));
    m.push_back(MetaValue::ofDouble("f64", {0.1, -1e300}));
    std::vector<double> f64(200);
    for (size_t i = 0; i < f64.size(); ++i)
        f64[i] = 1.0 / (1.0 + static_cast<double>(i));
    m.push_back(MetaValue::ofDouble("f64 large", f64));
    return m;
}

bool allTexelsEqual(const std::vector<uint8_t>& t, size_t pixel) {
    for (size_t i = pixel; i < t.size(); i += pixel) {
        if (std::memcmp(t.data(), t.data() + i, pixel) != 0) return false;
    }
    return true;
}

// Compares what was read with what was written, to the bit. Returns the number of differences.
int compareFiles(const PtexFile& in, const PtexFile& out) {
    int diffs = 0;
    const size_t pixel = in.pixelSize();
    if (out.dataType != in.dataType || out.channels != in.channels || out.alphaChannel != in.alphaChannel)
        ++diffs;
    if (out.uBorderMode != in.uBorderMode || out.vBorderMode != in.vBorderMode) ++diffs;
    if (out.edgeFilterMode != in.edgeFilterMode || out.meshType != in.meshType) ++diffs;
    if (out.faces.size() != in.faces.size()) return diffs + 1;
    for (size_t f = 0; f < in.faces.size(); ++f) {
        const FaceInfo& a = in.faces[f];
        const FaceInfo& b = out.faces[f];
        if (a.ulog2 != b.ulog2 || a.vlog2 != b.vlog2 || a.adjFaces != b.adjFaces ||
            a.adjEdges != b.adjEdges || a.subface != b.subface || b.hasEdits) {
            ++diffs;
        }
        const std::vector<uint8_t> expected = expandedTexels(in, f);
        if (expandedTexels(out, f) != expected) ++diffs;
        const bool constant = allTexelsEqual(expected, pixel);
        if (b.constant != constant) ++diffs;
        if (constant && std::memcmp(out.constData.data() + f * pixel, expected.data(), pixel) != 0) ++diffs;
    }
    // Values over 1024 bytes live in the large-metadata section, read after the small ones: the read order is
    // the small entries, then the large ones, each in written order.
    std::vector<MetaValue> expected = in.metadata;
    std::stable_partition(expected.begin(), expected.end(),
                          [](const MetaValue& m) { return m.bytes().size() <= 1024; });
    if (out.metadata.size() != expected.size()) return diffs + 1;
    for (size_t i = 0; i < expected.size(); ++i) {
        if (out.metadata[i].key != expected[i].key || out.metadata[i].type != expected[i].type ||
            out.metadata[i].bytes() != expected[i].bytes()) {
            ++diffs;
        }
    }
    return diffs;
}

}  // namespace

TEST_CASE("write then read gives every texel and field back bit for bit", "[ptex][roundtrip]") {
    // Lossless format: any difference, even one bit of a NaN payload, is a failure (no tolerance).
    const DataType types[] = {DataType::UInt8, DataType::UInt16, DataType::Half, DataType::Float};
    const Layout layouts[] = {{1, -1}, {3, -1}, {4, 3}};
    uint32_t seed = 1;
    for (const DataType type : types) {
        for (const Layout layout : layouts) {
            INFO("data type " << static_cast<int>(type) << ", channels " << layout.channels);
            PtexFile file = sampleFile(type, layout, seed++);
            file.metadata = sampleMetadata();
            const std::vector<uint8_t> bytes = writePtexBytes(file);
            const PtexFile back = readPtex(bytes, "roundtrip.ptx");
            CHECK(compareFiles(file, back) == 0);
            // Faces 4 and 5 are equal constants side by side, but walking around their corners reaches the
            // border, and the format flags a neighbourhood constant there only with clamp borders (these are
            // periodic and black): no face is flagged (the flag's rule: ptex_reduction_test.cpp).
            for (const FaceInfo& info : back.faces)
                CHECK_FALSE(info.neighbourhoodConstant);
            // The large face really was tiled: its level-0 face-data header has encoding 3.
            const tp::Header h = tp::parseHeader(bytes);
            const size_t levelInfo = 104 + h.faceInfoSize + h.constDataSize;
            const size_t levelData = levelInfo + h.levelInfoSize;
            const std::vector<uint8_t> headers = tp::zlibUncompress(
                std::span(bytes).subspan(levelData, tp::rd32(bytes, levelInfo + 8)), 4 * file.faces.size());
            CHECK(tp::rd32(headers, 4 * 6) >> 30 == 3);
            CHECK(tp::rd32(headers, 4 * 4) == 0);  // constant face: zero header
        }
    }
}

TEST_CASE("a file written to disk reads back the same, with the standard mesh metadata",
          "[ptex][roundtrip]") {
    deformkit::test::TempDir dir;
    PtexFile file = sampleFile(DataType::Half, {4, 3}, 99);
    WriteOptions options;
    // A pentagon (5 Ptex faces) and two quads: the file's 7 faces.
    options.mesh = MeshData{{5, 4, 4},
                            {0, 1, 2, 3, 4, 1, 5, 6, 2, 2, 6, 7, 3},
                            {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 0, 0, 2, 0, 0, 2, 1, 0, 1, 2, 0}};
    REQUIRE(file.faces.size() == 7);
    writePtex(dir / "mesh.ptx", file, options);
    const PtexFile back = readPtex(dir / "mesh.ptx");
    REQUIRE(back.metadata.size() == 3);
    CHECK(back.metadata[0].key == "PtexFaceVertCounts");
    CHECK(back.metadata[0].int32s == options.mesh->faceVertCounts);
    CHECK(back.metadata[1].key == "PtexFaceVertIndices");
    CHECK(back.metadata[1].int32s == options.mesh->faceVertIndices);
    CHECK(back.metadata[2].key == "PtexVertPositions");
    CHECK(back.metadata[2].type == MetaType::Float);
    CHECK(back.metadata[2].floats == options.mesh->vertPositions);
    PtexFile withoutMesh = back;
    withoutMesh.metadata.clear();
    CHECK(compareFiles(file, withoutMesh) == 0);
}

TEST_CASE("writing without reductions still reads back; a file of no faces is refused", "[ptex][roundtrip]") {
    PtexFile file = sampleFile(DataType::UInt16, {3, -1}, 7);
    WriteOptions options;
    options.reductions = false;
    const std::vector<uint8_t> bytes = writePtexBytes(file, options);
    CHECK(tp::parseHeader(bytes).levels == 1);
    CHECK(compareFiles(file, readPtex(bytes, "flat.ptx")) == 0);

    // The reference library writes none and reads none ("unzip failed").
    PtexFile empty;
    empty.channels = 2;
    CHECK_THROWS_WITH(writePtexBytes(empty),
                      Catch::Matchers::Contains("faces: are none (expected at least one face)"));
}

TEST_CASE("the writer rejects what it cannot write, naming the face or entry", "[ptex][roundtrip][errors]") {
    using deformkit::InvalidInput;
    PtexFile file = sampleFile(DataType::UInt8, {1, -1}, 3);
    auto bad = file;
    bad.faces[1].adjEdges[2] = 4;
    CHECK_THROWS_WITH(writePtexBytes(bad),
                      Catch::Matchers::Contains("face 1") && Catch::Matchers::Contains("neighbour edge 4"));
    bad = file;
    bad.faces[2].adjFaces[0] = 7;
    CHECK_THROWS_AS(writePtexBytes(bad), InvalidInput);
    CHECK_THROWS_WITH(writePtexBytes(bad), Catch::Matchers::Contains("face 2"));
    bad = file;
    bad.faces[3].vlog2 = 16;
    CHECK_THROWS_WITH(writePtexBytes(bad), Catch::Matchers::Contains("face 3"));
    bad = file;
    bad.texels[1].pop_back();
    CHECK_THROWS_WITH(writePtexBytes(bad), Catch::Matchers::Contains("texel bytes"));
    bad = file;
    bad.channels = 65;
    CHECK_THROWS_AS(writePtexBytes(bad), InvalidInput);
    bad = file;
    bad.alphaChannel = 1;
    CHECK_THROWS_WITH(writePtexBytes(bad), Catch::Matchers::Contains("alpha"));
    bad = file;
    bad.metadata.push_back(MetaValue::ofInt8(std::string(255, 'k'), {1}));
    CHECK_THROWS_WITH(writePtexBytes(bad), Catch::Matchers::Contains("metadata entry 0"));
    WriteOptions options;
    options.mesh = MeshData{{4}, {0, 1, 2, 5}, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}};
    CHECK_THROWS_WITH(writePtexBytes(file, options), Catch::Matchers::Contains("vertex index 3"));
    // Mesh metadata must describe the file's faces: one per triangle in a triangle file, one per quad and N
    // per N-gon in a quad file.
    options.mesh = MeshData{{4}, {0, 1, 2, 3}, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}};
    CHECK_THROWS_WITH(
        writePtexBytes(file, options),
        Catch::Matchers::Contains("mesh: has 1 Ptex faces (expected " + std::to_string(file.faces.size()) +
                                  ", the file's faces (one per quad, N per N-gon))"));
    bad = file;
    bad.meshType = MeshType::Triangle;
    for (FaceInfo& info : bad.faces)
        info.vlog2 = info.ulog2;
    for (size_t f = 0; f < bad.faces.size(); ++f)
        bad.texels[f].resize(bad.faces[f].texelCount() * bad.pixelSize());
    CHECK_THROWS_WITH(writePtexBytes(bad, options),
                      Catch::Matchers::Contains("mesh polygon 0: has 4 vertices in a triangle-mesh file"));
    // Metadata text is stored NUL-terminated: a NUL inside would cut it short in every reader.
    bad = file;
    bad.metadata.push_back(MetaValue::ofString("note", std::string("ab\0cd", 5)));
    CHECK_THROWS_WITH(
        writePtexBytes(bad),
        Catch::Matchers::Contains("metadata entry 0: key 'note' has a NUL byte at 2 of its text"));
}
