#pragma once

// Helpers for the Ptex tests, written from the format notes and independent of the library's own
// encoder and decoder: little-endian byte building, zlib through its one-shot API, and a minimal
// hand-assembled Ptex stream.

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace deformkit::test::ptex {

struct Bytes {
    std::vector<uint8_t> v;
    Bytes& u8(uint8_t x) {
        v.push_back(x);
        return *this;
    }
    Bytes& u16(uint16_t x) { return u8(x & 0xff).u8(x >> 8); }
    Bytes& u32(uint32_t x) { return u16(x & 0xffff).u16(x >> 16); }
    Bytes& i32(int32_t x) { return u32(static_cast<uint32_t>(x)); }
    Bytes& u64(uint64_t x) { return u32(static_cast<uint32_t>(x)).u32(static_cast<uint32_t>(x >> 32)); }
    Bytes& f32(float x) {
        uint32_t b;
        std::memcpy(&b, &x, 4);
        return u32(b);
    }
    Bytes& append(std::span<const uint8_t> b) {
        v.insert(v.end(), b.begin(), b.end());
        return *this;
    }
    Bytes& str(const std::string& s) {
        v.insert(v.end(), s.begin(), s.end());
        return *this;
    }
};

inline uint16_t rd16(std::span<const uint8_t> b, size_t o) {
    return static_cast<uint16_t>(b[o] | (b[o + 1] << 8));
}
inline uint32_t rd32(std::span<const uint8_t> b, size_t o) {
    return rd16(b, o) | (uint32_t{rd16(b, o + 2)} << 16);
}
inline uint64_t rd64(std::span<const uint8_t> b, size_t o) {
    return rd32(b, o) | (uint64_t{rd32(b, o + 4)} << 32);
}
inline void wr32(std::vector<uint8_t>& b, size_t o, uint32_t x) {
    for (int i = 0; i < 4; ++i)
        b[o + i] = static_cast<uint8_t>(x >> (8 * i));
}
inline void wr16(std::vector<uint8_t>& b, size_t o, uint16_t x) {
    b[o] = static_cast<uint8_t>(x);
    b[o + 1] = static_cast<uint8_t>(x >> 8);
}

inline std::vector<uint8_t> zlibCompress(std::span<const uint8_t> data) {
    uLongf size = compressBound(static_cast<uLong>(data.size()));
    std::vector<uint8_t> out(size);
    if (compress(out.data(), &size, data.data(), static_cast<uLong>(data.size())) != Z_OK) {
        throw std::runtime_error("compress failed");
    }
    out.resize(size);
    return out;
}

inline std::vector<uint8_t> zlibUncompress(std::span<const uint8_t> data, size_t expected) {
    std::vector<uint8_t> out(expected + 1);
    uLongf size = static_cast<uLongf>(out.size());
    if (uncompress(out.data(), &size, data.data(), static_cast<uLong>(data.size())) != Z_OK) {
        throw std::runtime_error("uncompress failed");
    }
    out.resize(size);
    return out;
}

// The fields of the 64-byte header and the 40-byte extended header, by their byte offsets in the notes.
struct Header {
    uint32_t magic, version, meshType, dataType;
    int32_t alphaChannel;
    uint16_t channels, levels;
    uint32_t faces, extHeaderSize, faceInfoSize, constDataSize, levelInfoSize, minorVersion;
    uint64_t levelDataSize;
    uint32_t metaZipSize, metaMemSize;
    uint16_t uBorder, pad, vBorder, edgeFilter;
    uint32_t lmdHeaderZipSize, lmdHeaderMemSize;
    uint64_t lmdDataSize, editDataSize, editDataPos;
};

inline Header parseHeader(std::span<const uint8_t> b) {
    Header h{};
    h.magic = rd32(b, 0);
    h.version = rd32(b, 4);
    h.meshType = rd32(b, 8);
    h.dataType = rd32(b, 12);
    h.alphaChannel = static_cast<int32_t>(rd32(b, 16));
    h.channels = rd16(b, 20);
    h.levels = rd16(b, 22);
    h.faces = rd32(b, 24);
    h.extHeaderSize = rd32(b, 28);
    h.faceInfoSize = rd32(b, 32);
    h.constDataSize = rd32(b, 36);
    h.levelInfoSize = rd32(b, 40);
    h.minorVersion = rd32(b, 44);
    h.levelDataSize = rd64(b, 48);
    h.metaZipSize = rd32(b, 56);
    h.metaMemSize = rd32(b, 60);
    h.uBorder = rd16(b, 64);
    h.pad = rd16(b, 66);
    h.vBorder = rd16(b, 68);
    h.edgeFilter = rd16(b, 70);
    h.lmdHeaderZipSize = rd32(b, 72);
    h.lmdHeaderMemSize = rd32(b, 76);
    h.lmdDataSize = rd64(b, 80);
    h.editDataSize = rd64(b, 88);
    h.editDataPos = rd64(b, 96);
    return h;
}

// A face as the notes lay out a FaceInfo record.
struct HandFace {
    int8_t ulog2 = 0, vlog2 = 0;
    uint8_t adjEdges = 0;  // 2 bits per edge, edge 0 lowest
    uint8_t flags = 0;     // 1 constant, 2 edits, 4 neighbourhood-constant, 8 subface
    int32_t adjFaces[4] = {-1, -1, -1, -1};
};

// A one-level Ptex stream assembled byte by byte from the notes. `blocks[f]` is face f's level-0 block
// (empty for a constant face) and `headers[f]` its face-data header. `metadata` is the raw (unzipped)
// small-metadata entry bytes; when non-empty it is zipped and followed by the 8-byte barrier.
struct HandStream {
    uint32_t dataType = 0;
    int32_t alphaChannel = -1;
    uint16_t channels = 1;
    std::vector<HandFace> faces;
    std::vector<uint8_t> constData;
    std::vector<uint32_t> headers;
    std::vector<std::vector<uint8_t>> blocks;
    std::vector<uint8_t> metadata;

    // Byte offset of the face-info section: 64-byte header + 40-byte extended header.
    static constexpr size_t kFaceInfoOffset = 104;

    [[nodiscard]] std::vector<uint8_t> bytes() const {
        Bytes faceInfo;
        for (const HandFace& f : faces) {
            faceInfo.u8(static_cast<uint8_t>(f.ulog2))
                .u8(static_cast<uint8_t>(f.vlog2))
                .u8(f.adjEdges)
                .u8(f.flags);
            for (int32_t a : f.adjFaces)
                faceInfo.i32(a);
        }
        const std::vector<uint8_t> faceInfoZip = zlibCompress(faceInfo.v);
        const std::vector<uint8_t> constZip = zlibCompress(constData);
        Bytes headerArray;
        for (uint32_t h : headers)
            headerArray.u32(h);
        const std::vector<uint8_t> headerZip = zlibCompress(headerArray.v);
        Bytes levelData;
        levelData.append(headerZip);
        for (const auto& b : blocks)
            levelData.append(b);
        Bytes levelInfo;
        levelInfo.u64(levelData.v.size())
            .u32(static_cast<uint32_t>(headerZip.size()))
            .u32(static_cast<uint32_t>(faces.size()));
        const std::vector<uint8_t> metaZip =
            metadata.empty() ? std::vector<uint8_t>{} : zlibCompress(metadata);
        const uint64_t total = 104 + faceInfoZip.size() + constZip.size() + levelInfo.v.size() +
                               levelData.v.size() + metaZip.size() + (metadata.empty() ? 0 : 8);
        Bytes out;
        out.str("Ptex").u32(1).u32(1).u32(dataType).i32(alphaChannel).u16(channels).u16(1);
        out.u32(static_cast<uint32_t>(faces.size())).u32(40).u32(static_cast<uint32_t>(faceInfoZip.size()));
        out.u32(static_cast<uint32_t>(constZip.size())).u32(static_cast<uint32_t>(levelInfo.v.size())).u32(4);
        out.u64(levelData.v.size())
            .u32(static_cast<uint32_t>(metaZip.size()))
            .u32(static_cast<uint32_t>(metadata.size()));
        // Extended header: border modes, large metadata (none), edit data (none, at the end of the file).
        out.u16(0).u16(0).u16(0).u16(0).u32(0).u32(0).u64(0).u64(0).u64(total);
        out.append(faceInfoZip).append(constZip).append(levelInfo.v).append(levelData.v).append(metaZip);
        if (!metadata.empty()) out.u64(0);
        return out.v;
    }

    // Byte offsets of the sections of bytes(), for tests that corrupt one of them.
    struct Layout {
        size_t constData, levelInfo, levelData, levelBlocks, metadata;
    };
    [[nodiscard]] Layout layout() const {
        const std::vector<uint8_t> b = bytes();
        const Header h = parseHeader(b);
        Layout l{};
        l.constData = kFaceInfoOffset + h.faceInfoSize;
        l.levelInfo = l.constData + h.constDataSize;
        l.levelData = l.levelInfo + h.levelInfoSize;
        l.levelBlocks = l.levelData + rd32(b, l.levelInfo + 8);
        l.metadata = l.levelData + h.levelDataSize;
        return l;
    }
};

}  // namespace deformkit::test::ptex
