#pragma once

// Private: the Ptex file layout (sizes, encodings), little-endian byte access, texel layout conversions and
// the reduction filter shared by the reader and the writer.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "deformkit/ptex/ptex_file.h"

namespace deformkit::ptex::detail {

constexpr uint32_t kMagic = 0x78657450u;  // "Ptex" read as a little-endian u32
constexpr uint32_t kVersion = 1;
constexpr uint32_t kMinorVersion = 4;
constexpr size_t kHeaderSize = 64;
constexpr size_t kExtHeaderSize = 40;
constexpr size_t kFaceInfoSize = 20;
constexpr size_t kLevelInfoSize = 16;
constexpr size_t kBarrierSize = 8;
constexpr size_t kLargeMetaThreshold = 1024;  // values over this many bytes go to the large-metadata section
constexpr int kMaxLog2 = 15;
constexpr int kMaxChannels = 64;

enum Encoding : uint32_t { kConstant = 0, kZipped = 1, kDiffZipped = 2, kTiled = 3 };
constexpr uint32_t kBlockSizeMask = (1u << 30) - 1;

constexpr uint8_t kFlagConstant = 1, kFlagHasEdits = 2, kFlagNeighbourhoodConstant = 4, kFlagSubface = 8;

[[nodiscard]] inline uint32_t blockEncoding(uint32_t header) {
    return header >> 30;
}
[[nodiscard]] inline uint32_t blockSize(uint32_t header) {
    return header & kBlockSizeMask;
}
[[nodiscard]] inline uint32_t blockHeader(uint32_t encoding, uint32_t size) {
    return (encoding << 30) | size;
}

template <size_t N>
using UIntOfSize =
    std::conditional_t<N == 1, uint8_t,
                       std::conditional_t<N == 2, uint16_t, std::conditional_t<N == 4, uint32_t, uint64_t>>>;

// Little-endian load from a buffer the caller has bounds-checked.
template <typename T>
[[nodiscard]] T load(const uint8_t* p) {
    using U = UIntOfSize<sizeof(T)>;
    U bits = 0;
    for (size_t i = 0; i < sizeof(T); ++i)
        bits = static_cast<U>(bits | (static_cast<U>(p[i]) << (8 * i)));
    return std::bit_cast<T>(bits);
}

// Little-endian store into a buffer the caller has sized.
template <typename T>
void store(uint8_t* p, T value) {
    const auto bits = std::bit_cast<UIntOfSize<sizeof(T)>>(value);
    for (size_t i = 0; i < sizeof(T); ++i)
        p[i] = static_cast<uint8_t>(bits >> (8 * i));
}

// Little-endian appends.
class ByteWriter {
  public:
    explicit ByteWriter(std::vector<uint8_t>& out) : out_(out) {}
    template <typename T>
    void put(T value) {
        const auto bits = std::bit_cast<UIntOfSize<sizeof(T)>>(value);
        for (size_t i = 0; i < sizeof(T); ++i)
            out_.push_back(static_cast<uint8_t>(bits >> (8 * i)));
    }
    void bytes(std::span<const uint8_t> data) { out_.insert(out_.end(), data.begin(), data.end()); }

  private:
    std::vector<uint8_t>& out_;
};

// Copies the (x0, y0, w, h) rectangle of an interleaved face buffer `faceWidth` texels wide into a planar
// buffer (all of channel 0 row by row, then channel 1, ...), and back.
void interleavedToPlanar(const uint8_t* face, int faceWidth, int x0, int y0, int w, int h, int channels,
                         int bpc, uint8_t* planar);
void planarToInterleaved(const uint8_t* planar, int w, int h, int channels, int bpc, uint8_t* face,
                         int faceWidth, int x0, int y0);

// Difference coding of u8/u16 values: one running value over the whole buffer, wrapping.
void diffEncode(std::span<uint8_t> data, int bpc);
void diffDecode(std::span<uint8_t> data, int bpc);

// The format's reductions as the reference library writes them and renderers read them (docs/decisions.md
// PTX-2): level i holds a prefix of the faces in reduction order, each at (ulog2 - i, vlog2 - i), with its
// colour premultiplied by alpha; integer channels are summed in integers and truncated, half and float
// channels summed in float.
constexpr int kMinReductionLog2 = 2;  // the writer stores reductions down to 4 texels on the smaller side

// The size that orders faces in the reduction levels: min(ulog2, vlog2), a constant face counted as 1.
[[nodiscard]] int reductionRank(const FaceInfo& info);

// Face ids in reduction order: descending reductionRank, equal ranks by face id.
[[nodiscard]] std::vector<uint32_t> reductionOrder(std::span<const FaceInfo> faces);

// Multiplies (divides) the colour channels of interleaved texels by alpha: the channels before the alpha
// channel, or all after it when it is channel 0; integer alpha scaled by 1/255 or 1/65535. Dividing skips
// texels whose alpha is 0. No-ops without alpha (alphaChannel < 0).
void premultiplyAlpha(std::span<uint8_t> texels, DataType type, int channels, int alphaChannel);
void unpremultiplyAlpha(std::span<uint8_t> texels, DataType type, int channels, int alphaChannel);

// 2×2 box filter of an interleaved w × h quad face (both even) into (w/2) × (h/2).
[[nodiscard]] std::vector<uint8_t> reduceQuadFace(std::span<const uint8_t> texels, int w, int h,
                                                  DataType type, int channels);

// The triangle reduction of a packed w × w triangle face (w even) into (w/2) × (w/2): each texel the mean of
// three texels of its 2×2 block and the inverted texel packed opposite, at (w − 1 − 2y, w − 1 − 2x).
[[nodiscard]] std::vector<uint8_t> reduceTriangleFace(std::span<const uint8_t> texels, int w, DataType type,
                                                      int channels);

// The mean of `count` interleaved texels, summed in float, into one pixel at `out`.
void averageTexels(std::span<const uint8_t> texels, size_t count, DataType type, int channels, uint8_t* out);

// Decodes a FaceInfo record (20 bytes) and encodes one.
[[nodiscard]] FaceInfo loadFaceInfo(const uint8_t* p);
void storeFaceInfo(ByteWriter& out, const FaceInfo& info);

}  // namespace deformkit::ptex::detail
