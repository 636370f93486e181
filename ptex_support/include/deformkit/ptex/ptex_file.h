#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace deformkit::ptex {

// Values as stored in the file header (Ptex format version 1).
enum class DataType : uint32_t { UInt8 = 0, UInt16 = 1, Half = 2, Float = 3 };
enum class MeshType : uint32_t { Triangle = 0, Quad = 1 };
enum class BorderMode : uint16_t { Clamp = 0, Black = 1, Periodic = 2 };
enum class EdgeFilterMode : uint16_t { None = 0, TangentVectors = 1 };
enum class MetaType : uint8_t { String = 0, Int8 = 1, Int16 = 2, Int32 = 3, Float = 4, Double = 5 };

// Bytes of one channel value: 1, 2, 2, 4.
[[nodiscard]] constexpr size_t bytesPerChannel(DataType type) {
    switch (type) {
        case DataType::UInt8:
            return 1;
        case DataType::UInt16:
            return 2;
        case DataType::Half:
            return 2;
        case DataType::Float:
            return 4;
    }
    return 0;
}

// One face's resolution, neighbours and flags. Edges are numbered bottom (v = 0), right (u = 1), top, left.
struct FaceInfo {
    int8_t ulog2 = 0;  // resolution 2^ulog2 × 2^vlog2 texels, each log2 in [0, 15]
    int8_t vlog2 = 0;
    std::array<int32_t, 4> adjFaces{-1, -1, -1, -1};  // neighbour face id across each edge, -1 = none
    std::array<uint8_t, 4> adjEdges{0, 0, 0, 0};      // the neighbour's edge (0..3) that meets each edge
    bool constant = false;                            // all texels equal; the value is in PtexFile::constData
    bool subface = false;                             // one of the N sub-faces of an N-gon (N != 4)
    bool hasEdits = false;                            // set by the reader when an edit replaced the face
    bool neighbourhoodConstant = false;  // constant, and every neighbour constant with the same value

    [[nodiscard]] int32_t ures() const { return int32_t{1} << ulog2; }
    [[nodiscard]] int32_t vres() const { return int32_t{1} << vlog2; }
    [[nodiscard]] size_t texelCount() const { return size_t{1} << (ulog2 + vlog2); }
};

// One metadata entry. Only the member matching `type` is used; the others stay empty.
struct MetaValue {
    std::string key;  // 1..254 bytes, no NUL
    MetaType type = MetaType::String;
    std::string string;  // String: the text, stored with a terminating NUL that is not part of it
    std::vector<int8_t> int8s;
    std::vector<int16_t> int16s;
    std::vector<int32_t> int32s;
    std::vector<float> floats;
    std::vector<double> doubles;

    [[nodiscard]] static MetaValue ofString(std::string key, std::string value);
    [[nodiscard]] static MetaValue ofInt8(std::string key, std::vector<int8_t> values);
    [[nodiscard]] static MetaValue ofInt16(std::string key, std::vector<int16_t> values);
    [[nodiscard]] static MetaValue ofInt32(std::string key, std::vector<int32_t> values);
    [[nodiscard]] static MetaValue ofFloat(std::string key, std::vector<float> values);
    [[nodiscard]] static MetaValue ofDouble(std::string key, std::vector<double> values);

    // The value as stored in the file: little-endian elements (a String with its NUL).
    [[nodiscard]] std::vector<uint8_t> bytes() const;
};

// A face of a reduction level (read only with ReadOptions::readReductions).
struct ReducedFace {
    int32_t faceId = 0;
    int8_t ulog2 = 0;  // the level-0 log2 minus the level
    int8_t vlog2 = 0;
    std::vector<uint8_t> texels;  // same layout as PtexFile::texels; empty for a constant face
};

// A whole Ptex file in memory.
//
// Texel layout of PtexFile::texels[f] (and ReducedFace::texels): bytes in the file's data type,
// little-endian, u fastest then v, from (u, v) = (0, 0) at the face's bottom-left; the channels of a texel
// interleaved: byte offset ((v * ures + u) * channels + c) * bytesPerChannel(dataType). A constant face has
// empty texels and its value in constData.
struct PtexFile {
    MeshType meshType = MeshType::Quad;
    DataType dataType = DataType::UInt8;
    int32_t alphaChannel = -1;  // -1 none, else in [0, channels)
    int32_t channels = 1;       // 1..64
    BorderMode uBorderMode = BorderMode::Clamp;
    BorderMode vBorderMode = BorderMode::Clamp;
    EdgeFilterMode edgeFilterMode = EdgeFilterMode::None;
    std::vector<FaceInfo> faces;
    std::vector<std::vector<uint8_t>> texels;  // per face, level 0
    std::vector<uint8_t> constData;  // faces.size() × pixelSize(): constant value or average per face
    std::vector<MetaValue> metadata;
    // reductions[i - 1] is level i, faces in the format's reduction order (descending min(ulog2, vlog2), a
    // constant face counted as 1, then face id); a level may list only the first faces of that order.
    // Texels are as stored: colour premultiplied by alpha when the file has an alpha channel. Filled by
    // readPtex with ReadOptions::readReductions; writePtex ignores it and computes its own.
    std::vector<std::vector<ReducedFace>> reductions;

    [[nodiscard]] size_t pixelSize() const {
        return bytesPerChannel(dataType) * static_cast<size_t>(channels);
    }
};

struct ReadOptions {
    // Decode the reduction levels into PtexFile::reductions. Their sizes are validated either way.
    bool readReductions = false;
    // Cap on the memory a file's declared sizes may claim: decoded texels (all levels read), face records,
    // tile tables and metadata entries. Every zipped block is also bounded by zlib's largest ratio (1032:1)
    // before its output is allocated, so only constant faces and tiles can approach the cap from a small
    // file.
    uint64_t maxDecodedBytes = uint64_t{2} << 30;
};

// The standard mesh metadata (keys PtexFaceVertCounts, PtexFaceVertIndices, PtexVertPositions).
struct MeshData {
    std::vector<int32_t> faceVertCounts;   // #polygons, each >= 3
    std::vector<int32_t> faceVertIndices;  // sum of faceVertCounts, each in [0, #vertices)
    std::vector<float> vertPositions;      // #vertices × 3, xyz
};

struct WriteOptions {
    // Write the reduction levels as the reference library does: each face halved down to 4 texels on its
    // smaller side (2×2 box filter, or the triangle reduction in a triangle file), alpha-premultiplied.
    bool reductions = true;
    int compressionLevel = 6;                // zlib, 0..9
    size_t tileThresholdBytes = 128 * 1024;  // faces (and reduced faces) of this many bytes or more are tiled
    size_t tileBytes = 64 * 1024;  // a tiled face has 2^floor(log2(bytes / tileBytes)) tiles, near square
    std::optional<MeshData> mesh;  // written as the standard mesh metadata when given
};

// Reads a Ptex file: header, extended header, face info, constant data, level 0 (every block encoding:
// constant, zipped, difference-zipped, tiled), reductions (validated; decoded on request), small and large
// metadata, and edit data (face and metadata edits applied in order). Throws IoError when the file cannot be
// read and ParseError naming the file, section and byte offset for any malformed content.
[[nodiscard]] PtexFile readPtex(const std::filesystem::path& path, const ReadOptions& options = {});

// Reads Ptex bytes already in memory; `source` names them in errors.
[[nodiscard]] PtexFile readPtex(std::span<const uint8_t> bytes, const std::string& source,
                                const ReadOptions& options = {});

// Writes a Ptex file atomically (temporary file + rename). The writer decides the flags `constant` (all
// texels equal, or texels empty: the value is taken from constData) and `neighbourhoodConstant`, and
// writes `hasEdits` false; constData of non-constant faces is recomputed (the mean of the smallest stored
// reduction, alpha-premultiplied, then divided by its alpha). A triangle file (meshType Triangle) takes
// square faces and writes no sub-face flag or fourth edge. Files read back through the reference Ptex
// library with the texels, reductions, constant values and flags its own writer gives the same faces.
// Throws InvalidInput naming the face or entry for a file that cannot be written (bad resolution, a
// non-square triangle face, channel count, alpha channel, adjacency, texel buffer size, metadata key, an
// entry without values, mesh data).
void writePtex(const std::filesystem::path& path, const PtexFile& file, const WriteOptions& options = {});
[[nodiscard]] std::vector<uint8_t> writePtexBytes(const PtexFile& file, const WriteOptions& options = {});

// Face `face`'s level-0 texels, a constant face expanded from constData.
[[nodiscard]] std::vector<uint8_t> expandedTexels(const PtexFile& file, size_t face);

}  // namespace deformkit::ptex
