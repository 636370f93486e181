// Ptex reader. Every size field is checked against the bytes that remain before it is used, and every
// zipped block against zlib's largest ratio before its output is allocated.
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "deformkit/error.h"
#include "deformkit/io/read_file.h"
#include "deformkit/ptex/ptex_file.h"
#include "format.h"

namespace deformkit::ptex {
namespace {

using namespace detail;

// zlib cannot inflate more than 1032 bytes per input byte (a deflate block of maximal matches), plus the
// few bytes of a stream's header and trailer.
constexpr uint64_t kMaxZipRatio = 1032;
constexpr uint64_t kZipSlack = 64;

std::string hex(uint32_t v) {
    static const char* digits = "0123456789abcdef";
    std::string s = "0x";
    for (int i = 28; i >= 0; i -= 4)
        s.push_back(digits[(v >> i) & 0xf]);
    return s;
}

class Reader {
  public:
    Reader(std::span<const uint8_t> bytes, std::string source, const ReadOptions& options)
        : bytes_(bytes), source_(std::move(source)), options_(options) {}

    PtexFile read() {
        readHeader();
        readFaceInfo();
        readConstData();
        readLevels();
        readMetadata();
        readEdits();
        return std::move(file_);
    }

  private:
    [[noreturn]] void fail(const std::string& section, uint64_t offset, const std::string& problem,
                           const std::string& expected) const {
        throw ParseError(
            formatError(source_, section + " at byte " + std::to_string(offset), problem, expected));
    }

    // Fails unless [offset, offset + size) lies inside the file.
    void need(const std::string& section, uint64_t offset, uint64_t size, const std::string& what) const {
        const uint64_t fileSize = bytes_.size();
        if (offset > fileSize || size > fileSize - offset) {
            fail(section, offset,
                 "needs " + std::to_string(size) + " bytes but the file ends at byte " +
                     std::to_string(fileSize) + " (truncated, or a size that points past the end)",
                 what);
        }
    }

    // Counts memory that grows with declared sizes (texels, face records, tiles, metadata entries), before it
    // is allocated or inflated.
    void charge(const std::string& section, uint64_t offset, uint64_t bytes) {
        decoded_ += bytes;
        if (decoded_ > options_.maxDecodedBytes) {
            fail(section, offset, "decoded data would reach " + std::to_string(decoded_) + " bytes",
                 "at most " + std::to_string(options_.maxDecodedBytes) + " (ReadOptions::maxDecodedBytes)");
        }
    }
    // Gives back what a charge counted for a buffer that has been freed (an inflated section once parsed).
    void release(uint64_t bytes) { decoded_ -= bytes; }

    void checkInflatable(const std::string& section, uint64_t offset, uint64_t zipSize,
                         uint64_t expected) const {
        if (expected > zipSize * kMaxZipRatio + kZipSlack) {
            fail(section, offset,
                 std::to_string(zipSize) + " zipped bytes are declared to inflate to " +
                     std::to_string(expected),
                 "at most " + std::to_string(kMaxZipRatio) + " times the zipped size (zlib's limit)");
        }
    }

    // Inflates the zlib stream at [offset, offset + zipSize), which must hold exactly `expected` bytes.
    std::vector<uint8_t> unzip(const std::string& section, uint64_t offset, uint64_t zipSize,
                               uint64_t expected) {
        need(section, offset, zipSize, std::to_string(zipSize) + " zipped bytes");
        checkInflatable(section, offset, zipSize, expected);
        if (zipSize == 0 && expected == 0) return {};
        std::vector<uint8_t> out(expected);
        z_stream z{};
        if (inflateInit(&z) != Z_OK) fail(section, offset, "zlib could not start", "");
        struct End {
            z_stream* z;
            ~End() { inflateEnd(z); }
        } end{&z};
        constexpr uint64_t kChunk = uint64_t{1} << 30;
        const uint8_t* in = bytes_.data() + offset;
        uint64_t inLeft = zipSize;
        uint64_t outGiven = 0;
        uint8_t spare = 0;
        bool spareGiven = false;
        while (true) {
            if (z.avail_in == 0 && inLeft > 0) {
                const auto chunk = static_cast<uInt>(std::min(inLeft, kChunk));
                z.next_in = const_cast<Bytef*>(in);
                z.avail_in = chunk;
                in += chunk;
                inLeft -= chunk;
            }
            if (z.avail_out == 0) {
                if (outGiven < expected) {
                    const auto chunk = static_cast<uInt>(std::min(expected - outGiven, kChunk));
                    z.next_out = out.data() + outGiven;
                    z.avail_out = chunk;
                    outGiven += chunk;
                } else {
                    z.next_out = &spare;
                    z.avail_out = 1;
                    spareGiven = true;
                }
            }
            const int rc = inflate(&z, Z_NO_FLUSH);
            if (spareGiven && z.avail_out == 0) {
                fail(section, offset,
                     "zlib data inflates to more than " + std::to_string(expected) + " bytes",
                     std::to_string(expected) + " bytes");
            }
            if (rc == Z_STREAM_END) break;
            if (rc == Z_BUF_ERROR && z.avail_in == 0 && inLeft == 0) {
                fail(section, offset,
                     "zlib stream is truncated after " + std::to_string(z.total_out) + " inflated bytes",
                     "a complete zlib stream of " + std::to_string(zipSize) + " bytes");
            }
            if (rc != Z_OK) {
                fail(section, offset,
                     std::string("zlib error: ") + (z.msg != nullptr ? z.msg : std::to_string(rc)),
                     "a valid zlib stream");
            }
        }
        if (z.total_out != expected) {
            fail(section, offset, "zlib data inflates to " + std::to_string(z.total_out) + " bytes",
                 std::to_string(expected) + " bytes");
        }
        const uint64_t consumed = zipSize - inLeft - z.avail_in;
        if (consumed != zipSize) {
            fail(section, offset, "zlib stream ends after " + std::to_string(consumed) + " bytes",
                 "a stream filling its " + std::to_string(zipSize) + " bytes");
        }
        return out;
    }

    void readHeader() {
        const uint8_t* h = bytes_.data();
        if (bytes_.size() < kHeaderSize) {
            fail("header", 0, "file is " + std::to_string(bytes_.size()) + " bytes",
                 "at least the 64-byte Ptex header");
        }
        if (load<uint32_t>(h) != kMagic) {
            std::string magic;
            for (int i = 0; i < 4; ++i)
                magic += (h[i] >= 32 && h[i] < 127) ? static_cast<char>(h[i]) : '?';
            fail("header", 0, "magic is '" + magic + "'", "'Ptex'");
        }
        const auto version = load<uint32_t>(h + 4);
        if (version != kVersion) fail("header", 4, "version is " + std::to_string(version), "version 1");
        const auto meshType = load<uint32_t>(h + 8);
        if (meshType > 1)
            fail("header", 8, "mesh type is " + std::to_string(meshType), "0 (triangle) or 1 (quad)");
        const auto dataType = load<uint32_t>(h + 12);
        if (dataType > 3)
            fail("header", 12, "data type is " + std::to_string(dataType), "0..3 (u8, u16, half, float)");
        file_.meshType = static_cast<MeshType>(meshType);
        file_.dataType = static_cast<DataType>(dataType);
        const auto channels = load<uint16_t>(h + 20);
        if (channels == 0 || channels > kMaxChannels) {
            fail("header", 20, "channel count is " + std::to_string(channels), "1..64");
        }
        file_.channels = channels;
        const auto alpha = load<int32_t>(h + 16);
        if (alpha < -1 || alpha >= channels) {
            fail("header", 16, "alpha channel is " + std::to_string(alpha),
                 "-1 (none) or 0.." + std::to_string(channels - 1));
        }
        file_.alphaChannel = alpha;
        levels_ = load<uint16_t>(h + 22);
        faceCount_ = load<uint32_t>(h + 24);
        extHeaderSize_ = load<uint32_t>(h + 28);
        faceInfoSize_ = load<uint32_t>(h + 32);
        constDataSize_ = load<uint32_t>(h + 36);
        levelInfoSize_ = load<uint32_t>(h + 40);
        levelDataSize_ = load<uint64_t>(h + 48);
        metaZipSize_ = load<uint32_t>(h + 56);
        metaMemSize_ = load<uint32_t>(h + 60);
        if (faceCount_ > 0x7fffffffu) {
            fail("header", 24, "face count is " + std::to_string(faceCount_), "fewer than 2^31 faces");
        }
        if (faceCount_ > 0 && levels_ == 0) {
            fail("header", 22, "level count is 0 with " + std::to_string(faceCount_) + " faces",
                 "at least 1 level");
        }
        if (levels_ > kMaxLog2 + 1) {
            fail("header", 22, "level count is " + std::to_string(levels_),
                 "at most 16 (resolutions up to 2^15)");
        }
        need("extended header", kHeaderSize, extHeaderSize_, std::to_string(extHeaderSize_) + " bytes");
        uint8_t ext[kExtHeaderSize] = {};
        std::memcpy(ext, h + kHeaderSize, std::min<size_t>(kExtHeaderSize, extHeaderSize_));
        const auto uMode = load<uint16_t>(ext);
        const auto vMode = load<uint16_t>(ext + 4);
        const auto edgeMode = load<uint16_t>(ext + 6);
        if (uMode > 2)
            fail("extended header", kHeaderSize, "u border mode is " + std::to_string(uMode), "0..2");
        if (vMode > 2)
            fail("extended header", kHeaderSize + 4, "v border mode is " + std::to_string(vMode), "0..2");
        if (edgeMode > 1) {
            fail("extended header", kHeaderSize + 6, "edge filter mode is " + std::to_string(edgeMode),
                 "0 or 1");
        }
        file_.uBorderMode = static_cast<BorderMode>(uMode);
        file_.vBorderMode = static_cast<BorderMode>(vMode);
        file_.edgeFilterMode = static_cast<EdgeFilterMode>(edgeMode);
        lmdHeaderZipSize_ = load<uint32_t>(ext + 8);
        lmdHeaderMemSize_ = load<uint32_t>(ext + 12);
        lmdDataSize_ = load<uint64_t>(ext + 16);
        editDataSize_ = load<uint64_t>(ext + 24);
        editDataPos_ = load<uint64_t>(ext + 32);
        pos_ = kHeaderSize + extHeaderSize_;
    }

    // Checks a face record; a triangle's has no fourth edge and no sub-face flag, so those bits read as none.
    void validateFaceInfo(FaceInfo& info, const std::string& section, uint64_t offset,
                          const std::string& face, const std::string& where = {}) {
        if (info.ulog2 < 0 || info.ulog2 > kMaxLog2 || info.vlog2 < 0 || info.vlog2 > kMaxLog2) {
            fail(section, offset,
                 face + " has resolution log2 " + std::to_string(info.ulog2) + " x " +
                     std::to_string(info.vlog2) + where,
                 "each log2 in 0..15");
        }
        if (file_.meshType == MeshType::Triangle) {
            if (info.ulog2 != info.vlog2) {
                fail(section, offset,
                     face + " has resolution log2 " + std::to_string(info.ulog2) + " x " +
                         std::to_string(info.vlog2) + " in a triangle file" + where,
                     "equal log2 resolutions (a triangle face is stored as a square)");
            }
            info.adjFaces[3] = -1;
            info.adjEdges[3] = 0;
            info.subface = false;
        }
        for (int e = 0; e < 4; ++e) {
            if (info.adjFaces[e] < -1 || info.adjFaces[e] >= static_cast<int64_t>(faceCount_)) {
                fail(section, offset,
                     face + " edge " + std::to_string(e) + " names neighbour face " +
                         std::to_string(info.adjFaces[e]) + where,
                     "-1 (none) or a face id below " + std::to_string(faceCount_));
            }
            // adjEdges are 2-bit fields: always 0..3.
        }
    }

    void readFaceInfo() {
        const uint64_t offset = pos_;
        const uint64_t inflated = uint64_t{faceCount_} * kFaceInfoSize;
        checkInflatable("face info", offset, faceInfoSize_, inflated);  // an impossible size, said as such
        charge("face info", offset,
               inflated + uint64_t{faceCount_} * (sizeof(FaceInfo) + sizeof(std::vector<uint8_t>)));
        std::vector<uint8_t> raw = unzip("face info", offset, faceInfoSize_, inflated);
        file_.faces.resize(faceCount_);
        for (size_t f = 0; f < faceCount_; ++f) {
            file_.faces[f] = loadFaceInfo(raw.data() + f * kFaceInfoSize);
            validateFaceInfo(file_.faces[f], "face info", offset, "face " + std::to_string(f),
                             " (record at inflated byte " + std::to_string(f * kFaceInfoSize) + ")");
        }
        std::vector<uint8_t>().swap(raw);
        release(inflated);
        pos_ += faceInfoSize_;
    }

    void readConstData() {
        const uint64_t bytes = uint64_t{faceCount_} * file_.pixelSize();
        checkInflatable("constant data", pos_, constDataSize_, bytes);
        charge("constant data", pos_, bytes);
        file_.constData = unzip("constant data", pos_, constDataSize_, bytes);
        pos_ += constDataSize_;
    }

    struct Level {
        uint64_t offset = 0;  // of the level's zipped headers in the file
        uint64_t size = 0;
        uint32_t headerZipSize = 0;
        uint32_t faces = 0;
        std::vector<uint32_t> headers;
        std::vector<uint64_t> blockOffsets;
    };

    void readLevels() {
        if (levelInfoSize_ != uint64_t{levels_} * kLevelInfoSize) {
            fail("level info", pos_, "is " + std::to_string(levelInfoSize_) + " bytes",
                 std::to_string(uint64_t{levels_} * kLevelInfoSize) + " (16 per level, " +
                     std::to_string(levels_) + " levels)");
        }
        need("level info", pos_, levelInfoSize_, std::to_string(levelInfoSize_) + " bytes");
        const uint64_t dataStart = pos_ + levelInfoSize_;
        need("level data", dataStart, levelDataSize_,
             std::to_string(levelDataSize_) + " bytes of level data");
        std::vector<Level> levels(levels_);
        uint64_t offset = dataStart;
        for (size_t i = 0; i < levels_; ++i) {
            const uint8_t* p = bytes_.data() + pos_ + i * kLevelInfoSize;
            const uint64_t infoOffset = pos_ + i * kLevelInfoSize;
            Level& level = levels[i];
            level.size = load<uint64_t>(p);
            level.headerZipSize = load<uint32_t>(p + 8);
            level.faces = load<uint32_t>(p + 12);
            level.offset = offset;
            const std::string name = "level info (level " + std::to_string(i) + ")";
            if (i == 0 && level.faces != faceCount_) {
                fail(name, infoOffset, "lists " + std::to_string(level.faces) + " faces",
                     std::to_string(faceCount_) + " (every face at level 0)");
            }
            if (level.faces > faceCount_) {
                fail(name, infoOffset, "lists " + std::to_string(level.faces) + " faces",
                     "at most " + std::to_string(faceCount_));
            }
            if (level.size > dataStart + levelDataSize_ - offset) {
                fail(name, infoOffset,
                     "level size " + std::to_string(level.size) + " runs past the level data",
                     "levels within the " + std::to_string(levelDataSize_) + " bytes of level data");
            }
            if (level.headerZipSize > level.size) {
                fail(name, infoOffset,
                     "header size " + std::to_string(level.headerZipSize) + " exceeds the level size " +
                         std::to_string(level.size),
                     "a header inside its level");
            }
            offset += level.size;
        }
        if (offset != dataStart + levelDataSize_) {
            fail("level info", pos_, "levels add up to " + std::to_string(offset - dataStart) + " bytes",
                 std::to_string(levelDataSize_) + " (the header's level data size)");
        }
        for (size_t i = 0; i < levels_; ++i)
            readLevelHeaders(levels[i], i);
        readLevelZero(levels.empty() ? Level{} : levels[0]);
        if (options_.readReductions) {
            const std::vector<uint32_t> order = reductionOrder(file_.faces);
            for (size_t i = 1; i < levels_; ++i)
                readReduction(levels[i], static_cast<int>(i), order);
        }
        pos_ = dataStart + levelDataSize_;
    }

    void readLevelHeaders(Level& level, size_t index) {
        const std::string section = "level " + std::to_string(index) + " face-data headers";
        const uint64_t inflated = uint64_t{level.faces} * 4;
        checkInflatable(section, level.offset, level.headerZipSize, inflated);
        charge(section, level.offset,
               inflated + uint64_t{level.faces} * (sizeof(uint32_t) + sizeof(uint64_t)));
        std::vector<uint8_t> raw = unzip(section, level.offset, level.headerZipSize, inflated);
        level.headers.resize(level.faces);
        level.blockOffsets.resize(level.faces);
        uint64_t offset = level.offset + level.headerZipSize;
        const uint64_t end = level.offset + level.size;
        for (size_t f = 0; f < level.faces; ++f) {
            level.headers[f] = load<uint32_t>(raw.data() + 4 * f);
            level.blockOffsets[f] = offset;
            const uint32_t size = blockSize(level.headers[f]);
            if (size > end - offset) {
                fail("level " + std::to_string(index) + " data", offset,
                     "face entry " + std::to_string(f) + " block of " + std::to_string(size) +
                         " bytes runs past the level's end at byte " + std::to_string(end),
                     "face-data header sizes that add up to the level size");
            }
            offset += size;
        }
        if (offset != end) {
            fail("level " + std::to_string(index) + " data", level.offset,
                 "face blocks end at byte " + std::to_string(offset) + " but the level ends at byte " +
                     std::to_string(end),
                 "face-data header sizes that add up to the level size");
        }
        std::vector<uint8_t>().swap(raw);
        release(inflated);
    }

    // Decodes a face (or a face edit) block into interleaved texels. `constPixel` is the face's ConstData.
    std::vector<uint8_t> decodeFace(const std::string& section, uint64_t offset, uint32_t header, int ulog2,
                                    int vlog2) {
        const uint32_t encoding = blockEncoding(header);
        const uint32_t size = blockSize(header);
        const size_t pixel = file_.pixelSize();
        const int w = 1 << ulog2;
        const int h = 1 << vlog2;
        const uint64_t bytes = (uint64_t{1} << (ulog2 + vlog2)) * pixel;
        if (encoding == kZipped || encoding == kDiffZipped) {
            checkEncoding(section, offset, encoding);
            checkInflatable(section, offset, size, bytes);
            charge(section, offset, bytes);
            std::vector<uint8_t> planar = unzip(section, offset, size, bytes);
            std::vector<uint8_t> out(bytes);
            finishRect(planar, encoding, w, h, out.data(), w, 0, 0);
            return out;
        }
        if (encoding != kTiled) {
            fail(
                section, offset,
                "face-data header " + hex(header) + " has encoding 0 with " + std::to_string(size) + " bytes",
                "a constant block of 0 bytes");
        }
        need(section, offset, 6, "a tiled face header");
        if (size < 6) {
            fail(section, offset, "tiled block is " + std::to_string(size) + " bytes",
                 "at least 6 (tile header)");
        }
        const int tileULog2 = static_cast<int8_t>(bytes_[offset]);
        const int tileVLog2 = static_cast<int8_t>(bytes_[offset + 1]);
        const uint32_t tileHeaderZipSize = load<uint32_t>(&bytes_[offset + 2]);
        if (tileULog2 < 0 || tileULog2 > ulog2 || tileVLog2 < 0 || tileVLog2 > vlog2) {
            fail(section, offset,
                 "tile resolution log2 " + std::to_string(tileULog2) + " x " + std::to_string(tileVLog2),
                 "0.." + std::to_string(ulog2) + " x 0.." + std::to_string(vlog2) + " (within the face)");
        }
        if (tileHeaderZipSize > size - 6) {
            fail(section, offset + 2,
                 "tile header size " + std::to_string(tileHeaderZipSize) + " exceeds the block",
                 "at most " + std::to_string(size - 6));
        }
        const uint64_t tilesU = uint64_t{1} << (ulog2 - tileULog2);
        const uint64_t tilesV = uint64_t{1} << (vlog2 - tileVLog2);
        if (tilesU * tilesV > size - 6 - tileHeaderZipSize) {
            fail(section, offset,
                 std::to_string(tilesU * tilesV) + " tiles cannot fit in " +
                     std::to_string(size - 6 - tileHeaderZipSize) + " bytes of tile data",
                 "at least one byte per tile");
        }
        charge(section, offset, tilesU * tilesV * sizeof(uint64_t));
        const std::vector<uint8_t> raw =
            unzip(section + " tile headers", offset + 6, tileHeaderZipSize, tilesU * tilesV * 4);
        // Validate every tile before allocating the face.
        const uint64_t tileBytes = (uint64_t{1} << (tileULog2 + tileVLog2)) * pixel;
        uint64_t tileOffset = offset + 6 + tileHeaderZipSize;
        const uint64_t end = offset + size;
        std::vector<uint64_t> tileOffsets(tilesU * tilesV);
        for (size_t t = 0; t < tileOffsets.size(); ++t) {
            const uint32_t th = load<uint32_t>(raw.data() + 4 * t);
            const uint32_t ts = blockSize(th);
            const uint32_t te = blockEncoding(th);
            const std::string tile = "tile " + std::to_string(t);
            if (ts > end - tileOffset) {
                fail(section, tileOffset,
                     tile + " of " + std::to_string(ts) + " bytes runs past the face block",
                     "tile sizes that add up to the face block");
            }
            if (te == kConstant && ts != pixel) {
                fail(section, tileOffset, tile + " is constant with " + std::to_string(ts) + " bytes",
                     std::to_string(pixel) + " (one pixel)");
            }
            if (te == kTiled)
                fail(section, tileOffset, tile + " header " + hex(th) + " is tiled", "encoding 0, 1 or 2");
            if (te != kConstant) {
                if (ts == 0) fail(section, tileOffset, tile + " is zipped with 0 bytes", "a zlib stream");
                checkEncoding(section, tileOffset, te);
                checkInflatable(section, tileOffset, ts, tileBytes);
            }
            tileOffsets[t] = tileOffset;
            tileOffset += ts;
        }
        if (tileOffset != end) {
            fail(section, offset,
                 "tiles end at byte " + std::to_string(tileOffset) + " but the block ends at byte " +
                     std::to_string(end),
                 "tile sizes that add up to the face block");
        }
        charge(section, offset, bytes);
        std::vector<uint8_t> out(bytes);
        const int tw = 1 << tileULog2;
        const int th = 1 << tileVLog2;
        for (size_t t = 0; t < tileOffsets.size(); ++t) {
            const uint32_t header = load<uint32_t>(raw.data() + 4 * t);
            const int x0 = static_cast<int>(t % tilesU) * tw;
            const int y0 = static_cast<int>(t / tilesU) * th;
            if (blockEncoding(header) == kConstant) {
                const uint8_t* value = &bytes_[tileOffsets[t]];
                for (int y = 0; y < th; ++y) {
                    uint8_t* row = out.data() + (static_cast<size_t>(y0 + y) * w + x0) * pixel;
                    for (int x = 0; x < tw; ++x)
                        std::memcpy(row + x * pixel, value, pixel);
                }
                continue;
            }
            std::vector<uint8_t> planar =
                unzip(section + " tile " + std::to_string(t), tileOffsets[t], blockSize(header), tileBytes);
            finishRect(planar, blockEncoding(header), tw, th, out.data(), w, x0, y0);
        }
        return out;
    }

    void checkEncoding(const std::string& section, uint64_t offset, uint32_t encoding) const {
        const bool integer = file_.dataType == DataType::UInt8 || file_.dataType == DataType::UInt16;
        if (encoding == kDiffZipped && !integer) {
            fail(section, offset, "block is difference-zipped (encoding 2) for half or float data",
                 "encoding 1 (zipped) for half and float");
        }
    }

    void finishRect(std::vector<uint8_t>& planar, uint32_t encoding, int w, int h, uint8_t* face,
                    int faceWidth, int x0, int y0) const {
        const int bpc = static_cast<int>(bytesPerChannel(file_.dataType));
        if (encoding == kDiffZipped) diffDecode(planar, bpc);
        planarToInterleaved(planar.data(), w, h, file_.channels, bpc, face, faceWidth, x0, y0);
    }

    // The texels of a level-0 face (or a face edit): empty for a constant face.
    std::vector<uint8_t> faceTexels(FaceInfo& info, size_t face, uint32_t header, uint64_t offset,
                                    const std::string& section) {
        const size_t pixel = file_.pixelSize();
        const uint32_t encoding = blockEncoding(header);
        const uint32_t size = blockSize(header);
        if (info.constant) {
            if (header != 0) {
                fail(section, offset,
                     "face " + std::to_string(face) + " is flagged constant but its face-data header is " +
                         hex(header),
                     "0 (no data block)");
            }
            return {};
        }
        if (encoding == kConstant && size == 0) {
            info.constant = true;  // no data: the value is in ConstData
            return {};
        }
        if (encoding == kConstant && size == pixel) {
            // One raw pixel.
            info.constant = true;
            std::memcpy(file_.constData.data() + face * pixel, &bytes_[offset], pixel);
            return {};
        }
        if (info.ulog2 == 0 && info.vlog2 == 0) {
            if (encoding == kConstant) decodeFace(section, offset, header, 0, 0);  // reports the bad header
            // A 1 × 1 face is always read from ConstData.
            charge(section, offset, pixel);
            return {file_.constData.begin() + static_cast<std::ptrdiff_t>(face * pixel),
                    file_.constData.begin() + static_cast<std::ptrdiff_t>((face + 1) * pixel)};
        }
        return decodeFace(section, offset, header, info.ulog2, info.vlog2);
    }

    void readLevelZero(const Level& level) {
        file_.texels.assign(faceCount_, {});
        for (size_t f = 0; f < faceCount_; ++f) {
            const std::string section = "level 0 data, face " + std::to_string(f);
            file_.texels[f] = faceTexels(file_.faces[f], f, level.headers[f], level.blockOffsets[f], section);
        }
    }

    // Level `index` lists a prefix of `order`, the faces in reduction order (constant faces ranked 1), each
    // at (ulog2 − index, vlog2 − index); the reference writer stops at 4 texels on the smaller side, so a
    // level may list fewer faces than could be reduced to it.
    void readReduction(const Level& level, int index, const std::vector<uint32_t>& order) {
        size_t reducible = 0;
        while (reducible < order.size() && reductionRank(file_.faces[order[reducible]]) >= index)
            ++reducible;
        const std::string section = "level " + std::to_string(index) + " data";
        if (level.faces > reducible) {
            fail(section, level.offset, "lists " + std::to_string(level.faces) + " faces",
                 "at most " + std::to_string(reducible) + " (the faces with min(ulog2, vlog2) >= " +
                     std::to_string(index) + ", a constant face counted as 1)");
        }
        std::vector<ReducedFace> faces(level.faces);
        for (size_t k = 0; k < level.faces; ++k) {
            const uint32_t f = order[k];
            ReducedFace& r = faces[k];
            r.faceId = static_cast<int32_t>(f);
            r.ulog2 = static_cast<int8_t>(std::max(0, file_.faces[f].ulog2 - index));
            r.vlog2 = static_cast<int8_t>(std::max(0, file_.faces[f].vlog2 - index));
            const uint32_t header = level.headers[k];
            if (header == 0 || file_.faces[f].constant) continue;  // the face's ConstData
            r.texels = decodeFace(section + ", face " + std::to_string(f), level.blockOffsets[k], header,
                                  r.ulog2, r.vlog2);
        }
        file_.reductions.push_back(std::move(faces));
    }

    // Parses metadata entries from an inflated block; large entries take their values from `largeData`.
    void parseMetadata(const std::vector<uint8_t>& raw, const std::string& section, uint64_t offset,
                       bool large, uint64_t largeDataOffset, uint64_t largeDataSize,
                       std::vector<MetaValue>& out) {
        size_t p = 0;
        uint64_t largeUsed = 0;
        while (p < raw.size()) {
            const size_t entryStart = p;
            const auto bad = [&](const std::string& problem, const std::string& expected) {
                fail(section, offset, "entry at inflated byte " + std::to_string(entryStart) + ": " + problem,
                     expected);
            };
            const size_t keySize = raw[p];
            if (keySize < 2)
                bad("key size is " + std::to_string(keySize), "a key of at least 1 byte plus its NUL");
            const size_t fixed = 1 + keySize + 1 + 4 + (large ? 4 : 0);
            if (fixed > raw.size() - p) bad("runs past the end of the block", "a complete entry");
            const char* key = reinterpret_cast<const char*>(&raw[p + 1]);
            if (key[keySize - 1] != '\0' || std::memchr(key, 0, keySize - 1) != nullptr) {
                bad("key is not NUL-terminated where its size says", "a key of keysize - 1 bytes then a NUL");
            }
            MetaValue m;
            m.key.assign(key, keySize - 1);
            const uint8_t type = raw[p + 1 + keySize];
            if (type > 5)
                bad("type is " + std::to_string(type), "0..5 (string, i8, i16, i32, float, double)");
            m.type = static_cast<MetaType>(type);
            const uint32_t size = load<uint32_t>(&raw[p + 2 + keySize]);
            std::vector<uint8_t> largeValue;
            const uint8_t* value = nullptr;
            if (large) {
                const uint32_t zipSize = load<uint32_t>(&raw[p + 6 + keySize]);
                if (zipSize > largeDataSize - largeUsed) {
                    bad("value of " + std::to_string(zipSize) +
                            " zipped bytes runs past the large-metadata data",
                        "values within its " + std::to_string(largeDataSize) + " bytes");
                }
                largeValue =
                    unzip("large metadata value '" + m.key + "'", largeDataOffset + largeUsed, zipSize, size);
                largeUsed += zipSize;
                value = largeValue.data();
                p += fixed;
            } else {
                if (size > raw.size() - p - fixed)
                    bad("value of " + std::to_string(size) + " bytes runs past the block",
                        "a complete entry");
                value = &raw[p + fixed];
                p += fixed + size;
            }
            static constexpr size_t kElementSize[6] = {1, 1, 2, 4, 4, 8};
            if (size % kElementSize[type] != 0) {
                bad("value of " + std::to_string(size) + " bytes",
                    "a multiple of " + std::to_string(kElementSize[type]));
            }
            const size_t n = size / kElementSize[type];
            switch (m.type) {
                case MetaType::String: {
                    size_t len = size;
                    if (len > 0 && value[len - 1] == 0) --len;
                    m.string.assign(reinterpret_cast<const char*>(value), len);
                    break;
                }
                case MetaType::Int8:
                    for (size_t i = 0; i < n; ++i)
                        m.int8s.push_back(static_cast<int8_t>(value[i]));
                    break;
                case MetaType::Int16:
                    for (size_t i = 0; i < n; ++i)
                        m.int16s.push_back(load<int16_t>(value + 2 * i));
                    break;
                case MetaType::Int32:
                    for (size_t i = 0; i < n; ++i)
                        m.int32s.push_back(load<int32_t>(value + 4 * i));
                    break;
                case MetaType::Float:
                    for (size_t i = 0; i < n; ++i)
                        m.floats.push_back(load<float>(value + 4 * i));
                    break;
                case MetaType::Double:
                    for (size_t i = 0; i < n; ++i)
                        m.doubles.push_back(load<double>(value + 8 * i));
                    break;
            }
            charge(section, offset, sizeof(MetaValue) + size);
            out.push_back(std::move(m));
        }
    }

    void readMetadata() {
        const uint64_t metaOffset = pos_;
        const std::vector<uint8_t> raw = unzip("metadata", metaOffset, metaZipSize_, metaMemSize_);
        parseMetadata(raw, "metadata", metaOffset, false, 0, 0, file_.metadata);
        pos_ += metaZipSize_;
        if (lmdHeaderZipSize_ == 0 && lmdHeaderMemSize_ == 0 && lmdDataSize_ == 0) return;
        need("metadata barrier", pos_, kBarrierSize, "8 zero bytes before the large metadata");
        pos_ += kBarrierSize;
        const uint64_t headerOffset = pos_;
        const std::vector<uint8_t> header =
            unzip("large metadata", headerOffset, lmdHeaderZipSize_, lmdHeaderMemSize_);
        const uint64_t dataOffset = headerOffset + lmdHeaderZipSize_;
        need("large metadata data", dataOffset, lmdDataSize_, std::to_string(lmdDataSize_) + " bytes");
        parseMetadata(header, "large metadata", headerOffset, true, dataOffset, lmdDataSize_, file_.metadata);
        pos_ = dataOffset + lmdDataSize_;
    }

    void readEdits() {
        if (editDataSize_ == 0) return;
        need("edit data", editDataPos_, editDataSize_, std::to_string(editDataSize_) + " bytes of edits");
        uint64_t p = editDataPos_;
        const uint64_t end = editDataPos_ + editDataSize_;
        const size_t pixel = file_.pixelSize();
        while (p < end) {
            if (end - p < 5)
                fail("edit data", p, "edit header runs past the edit data", "type u8 and size u32");
            const uint8_t type = bytes_[p];
            const uint32_t size = load<uint32_t>(&bytes_[p + 1]);
            const uint64_t payload = p + 5;
            if (size > end - payload) {
                fail("edit data", p, "edit of " + std::to_string(size) + " bytes runs past the edit data",
                     "at most " + std::to_string(end - payload));
            }
            if (type == 0) {
                readFaceEdit(payload, size, pixel);
            } else if (type == 1) {
                readMetaEdit(payload, size);
            }  // other edit types are skipped
            p = payload + size;
        }
    }

    void readFaceEdit(uint64_t p, uint32_t size, size_t pixel) {
        const std::string section = "face edit";
        const uint64_t fixed = 4 + kFaceInfoSize + 4 + pixel;
        if (size < fixed)
            fail(section, p, "is " + std::to_string(size) + " bytes", "at least " + std::to_string(fixed));
        const int32_t face = load<int32_t>(&bytes_[p]);
        if (face < 0 || static_cast<uint32_t>(face) >= faceCount_) {
            fail(section, p, "names face " + std::to_string(face),
                 "0.." + std::to_string(int64_t{faceCount_} - 1));
        }
        FaceInfo info = loadFaceInfo(&bytes_[p + 4]);
        validateFaceInfo(info, section, p + 4, "face " + std::to_string(face));
        const uint32_t header = load<uint32_t>(&bytes_[p + 4 + kFaceInfoSize]);
        if (fixed + blockSize(header) != size) {
            fail(section, p,
                 "face-data header " + hex(header) + " gives a " + std::to_string(blockSize(header)) +
                     "-byte block in a " + std::to_string(size) + "-byte edit",
                 "edit size = " + std::to_string(fixed) + " + block size");
        }
        std::memcpy(file_.constData.data() + static_cast<size_t>(face) * pixel,
                    &bytes_[p + 4 + kFaceInfoSize + 4], pixel);
        std::vector<uint8_t> texels = faceTexels(info, static_cast<size_t>(face), header, p + fixed, section);
        info.hasEdits = true;
        file_.faces[face] = info;
        file_.texels[face] = std::move(texels);
        // Reductions stored in the file no longer describe the edited face.
        for (auto& level : file_.reductions) {
            std::erase_if(level, [&](const ReducedFace& r) { return r.faceId == face; });
        }
    }

    void readMetaEdit(uint64_t p, uint32_t size) {
        const std::string section = "metadata edit";
        if (size < 8)
            fail(section, p, "is " + std::to_string(size) + " bytes", "at least 8 (zip and memory sizes)");
        const uint32_t zipSize = load<uint32_t>(&bytes_[p]);
        const uint32_t memSize = load<uint32_t>(&bytes_[p + 4]);
        if (uint64_t{zipSize} + 8 != size) {
            fail(section, p,
                 "zipped size " + std::to_string(zipSize) + " in a " + std::to_string(size) + "-byte edit",
                 "edit size = 8 + zipped size");
        }
        const std::vector<uint8_t> raw = unzip(section, p + 8, zipSize, memSize);
        std::vector<MetaValue> entries;
        parseMetadata(raw, section, p + 8, false, 0, 0, entries);
        for (MetaValue& m : entries) {
            const auto same = std::find_if(file_.metadata.begin(), file_.metadata.end(),
                                           [&](const MetaValue& e) { return e.key == m.key; });
            if (same != file_.metadata.end()) {
                *same = std::move(m);
            } else {
                file_.metadata.push_back(std::move(m));
            }
        }
    }

    std::span<const uint8_t> bytes_;
    std::string source_;
    const ReadOptions& options_;
    PtexFile file_;
    uint64_t decoded_ = 0;
    uint64_t pos_ = 0;
    uint32_t levels_ = 0;
    uint32_t faceCount_ = 0;
    uint32_t extHeaderSize_ = 0;
    uint32_t faceInfoSize_ = 0;
    uint32_t constDataSize_ = 0;
    uint32_t levelInfoSize_ = 0;
    uint64_t levelDataSize_ = 0;
    uint32_t metaZipSize_ = 0;
    uint32_t metaMemSize_ = 0;
    uint32_t lmdHeaderZipSize_ = 0;
    uint32_t lmdHeaderMemSize_ = 0;
    uint64_t lmdDataSize_ = 0;
    uint64_t editDataSize_ = 0;
    uint64_t editDataPos_ = 0;
};

}  // namespace

PtexFile readPtex(std::span<const uint8_t> bytes, const std::string& source, const ReadOptions& options) {
    return Reader(bytes, source, options).read();
}

PtexFile readPtex(const std::filesystem::path& path, const ReadOptions& options) {
    const std::string bytes = io::readFile(path, "Ptex file");
    return readPtex(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), path.string(),
                    options);
}

}  // namespace deformkit::ptex
