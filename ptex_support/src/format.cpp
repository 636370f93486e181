#include "format.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <optional>
#include <utility>

#include "deformkit/ptex/half.h"

namespace deformkit::ptex::detail {

void interleavedToPlanar(const uint8_t* face, int faceWidth, int x0, int y0, int w, int h, int channels,
                         int bpc, uint8_t* planar) {
    const size_t pixel = static_cast<size_t>(channels) * bpc;
    for (int c = 0; c < channels; ++c) {
        for (int y = 0; y < h; ++y) {
            const uint8_t* row = face + (static_cast<size_t>(y0 + y) * faceWidth + x0) * pixel + c * bpc;
            for (int x = 0; x < w; ++x) {
                std::memcpy(planar, row + x * pixel, bpc);
                planar += bpc;
            }
        }
    }
}

void planarToInterleaved(const uint8_t* planar, int w, int h, int channels, int bpc, uint8_t* face,
                         int faceWidth, int x0, int y0) {
    const size_t pixel = static_cast<size_t>(channels) * bpc;
    for (int c = 0; c < channels; ++c) {
        for (int y = 0; y < h; ++y) {
            uint8_t* row = face + (static_cast<size_t>(y0 + y) * faceWidth + x0) * pixel + c * bpc;
            for (int x = 0; x < w; ++x) {
                std::memcpy(row + x * pixel, planar, bpc);
                planar += bpc;
            }
        }
    }
}

void diffEncode(std::span<uint8_t> data, int bpc) {
    if (bpc == 1) {
        uint8_t previous = 0;
        for (uint8_t& v : data) {
            const uint8_t current = v;
            v = static_cast<uint8_t>(current - previous);
            previous = current;
        }
        return;
    }
    uint16_t previous = 0;
    for (size_t i = 0; i + 1 < data.size(); i += 2) {
        const uint16_t current = load<uint16_t>(&data[i]);
        const auto d = static_cast<uint16_t>(current - previous);
        data[i] = static_cast<uint8_t>(d);
        data[i + 1] = static_cast<uint8_t>(d >> 8);
        previous = current;
    }
}

void diffDecode(std::span<uint8_t> data, int bpc) {
    if (bpc == 1) {
        uint8_t running = 0;
        for (uint8_t& v : data) {
            running = static_cast<uint8_t>(running + v);
            v = running;
        }
        return;
    }
    uint16_t running = 0;
    for (size_t i = 0; i + 1 < data.size(); i += 2) {
        running = static_cast<uint16_t>(running + load<uint16_t>(&data[i]));
        data[i] = static_cast<uint8_t>(running);
        data[i + 1] = static_cast<uint8_t>(running >> 8);
    }
}

namespace {

// The reference library's float to binary16 conversion: half an ulp added to the magnitude, then truncated
// (ties away from zero), zero of either sign to +0, subnormals rounded the same way, overflow to infinity,
// NaN keeping its top payload bits. floatToHalf rounds ties to even; a reduction must round as the files
// renderers read were written, so it uses this one (docs/decisions.md PTX-2).
uint16_t referenceHalf(float value) {
    if (value == 0.0f) return 0;
    const uint32_t bits = std::bit_cast<uint32_t>(value);
    const auto sign = static_cast<uint16_t>((bits >> 16) & 0x8000u);
    const int32_t exponent = static_cast<int32_t>((bits >> 23) & 0xffu) - 127 + 15;
    if (exponent >= 1 && exponent <= 30) {
        const uint32_t normal = sign | (static_cast<uint32_t>(exponent) << 10);
        return static_cast<uint16_t>(normal + (((bits & 0x7fffffu) + 0x1000u) >> 13));
    }
    if (exponent <= 0) {
        const double magnitude = std::fabs(static_cast<double>(value)) * 16777216.0 + 0.5;
        return static_cast<uint16_t>(sign | static_cast<uint32_t>(magnitude));
    }
    if (exponent == 128 + 15) return static_cast<uint16_t>(sign | 0x7c00u | ((bits & 0x7fffffu) >> 13));
    return static_cast<uint16_t>(sign | 0x7c00u);
}

// float to an unsigned integer channel by truncation, as a C++ conversion does inside the range (the clamp
// only keeps values the arithmetic never produces from stored data defined).
template <typename U>
U truncateTo(float value) {
    constexpr float kMax = static_cast<float>(std::numeric_limits<U>::max());
    if (!(value > 0.0f)) return 0;
    if (value >= kMax) return std::numeric_limits<U>::max();
    return static_cast<U>(value);
}

// One channel type and the arithmetic the format's reductions use on it.
template <DataType Type>
struct Channel;

// u8 and u16: four values summed in integers and shifted by 2; from float by truncation.
template <typename U>
struct IntegerChannel {
    using Stored = U;
    static constexpr float kOne = static_cast<float>(std::numeric_limits<U>::max());  // 255, 65535
    static float value(Stored v) { return v; }
    static Stored from(float v) { return truncateTo<U>(v); }
    static Stored quarter(Stored a, Stored b, Stored c, Stored d) {
        return static_cast<Stored>((uint32_t{a} + b + c + d) >> 2);
    }
};

template <>
struct Channel<DataType::UInt8> : IntegerChannel<uint8_t> {};

template <>
struct Channel<DataType::UInt16> : IntegerChannel<uint16_t> {};

template <>
struct Channel<DataType::Half> {
    using Stored = uint16_t;  // the binary16 bits
    static constexpr float kOne = 1.0f;
    static float value(Stored v) { return halfToFloat(v); }
    static Stored from(float v) { return referenceHalf(v); }
    static Stored quarter(Stored a, Stored b, Stored c, Stored d) {
        return from(0.25f * (value(a) + value(b) + value(c) + value(d)));
    }
};

template <>
struct Channel<DataType::Float> {
    using Stored = float;
    static constexpr float kOne = 1.0f;
    static float value(Stored v) { return v; }
    static Stored from(float v) { return v; }
    static Stored quarter(Stored a, Stored b, Stored c, Stored d) { return 0.25f * (a + b + c + d); }
};

// Calls f(Channel<T>{}) for the file's data type.
template <typename F>
decltype(auto) withChannel(DataType type, F&& f) {
    switch (type) {
        case DataType::UInt8:
            return f(Channel<DataType::UInt8>{});
        case DataType::UInt16:
            return f(Channel<DataType::UInt16>{});
        case DataType::Half:
            return f(Channel<DataType::Half>{});
        case DataType::Float:
            break;
    }
    return f(Channel<DataType::Float>{});
}

// The channels alpha scales: those before it, or all after it when it is channel 0.
std::pair<int, int> colourChannels(int channels, int alphaChannel) {
    return alphaChannel == 0 ? std::pair{1, channels} : std::pair{0, alphaChannel};
}

}  // namespace

namespace {

// Multiplies the colour channels of every texel by factor(C, alpha), a float; a texel whose factor is
// not set keeps its colour.
template <typename Factor>
void scaleColour(std::span<uint8_t> texels, DataType type, int channels, int alphaChannel, Factor factor) {
    if (alphaChannel < 0) return;
    withChannel(type, [&]<typename C>(C) {
        using T = typename C::Stored;
        const size_t pixel = sizeof(T) * channels;
        const auto [first, last] = colourChannels(channels, alphaChannel);
        for (size_t p = 0; p + pixel <= texels.size(); p += pixel) {
            uint8_t* texel = texels.data() + p;
            const std::optional<float> f = factor(C{}, C::value(load<T>(texel + alphaChannel * sizeof(T))));
            if (!f) continue;
            for (int c = first; c < last; ++c) {
                uint8_t* v = texel + c * sizeof(T);
                store(v, C::from(C::value(load<T>(v)) * *f));
            }
        }
    });
}

// The 2 × 2 reduction of a quad face, or with `triangle` of a packed triangle face (w = h), whose fourth
// texel is the inverted one packed opposite the block.
std::vector<uint8_t> reduce(std::span<const uint8_t> texels, int w, int h, DataType type, int channels,
                            bool triangle) {
    return withChannel(type, [&]<typename C>(C) {
        using T = typename C::Stored;
        const size_t pixel = sizeof(T) * channels;
        const int rw = w / 2;
        const int rh = h / 2;
        std::vector<uint8_t> out(static_cast<size_t>(rw) * rh * pixel);
        const auto at = [&](int x, int y, int c) {
            return load<T>(texels.data() + (static_cast<size_t>(y) * w + x) * pixel + c * sizeof(T));
        };
        for (int y = 0; y < rh; ++y) {
            for (int x = 0; x < rw; ++x) {
                uint8_t* o = out.data() + (static_cast<size_t>(y) * rw + x) * pixel;
                const int fourthX = triangle ? w - 1 - 2 * y : 2 * x + 1;
                const int fourthY = triangle ? w - 1 - 2 * x : 2 * y + 1;
                for (int c = 0; c < channels; ++c) {
                    store(o + c * sizeof(T), C::quarter(at(2 * x, 2 * y, c), at(2 * x + 1, 2 * y, c),
                                                        at(2 * x, 2 * y + 1, c), at(fourthX, fourthY, c)));
                }
            }
        }
        return out;
    });
}

}  // namespace

void premultiplyAlpha(std::span<uint8_t> texels, DataType type, int channels, int alphaChannel) {
    scaleColour(texels, type, channels, alphaChannel,
                []<typename C>(C, float alpha) -> std::optional<float> { return (1.0f / C::kOne) * alpha; });
}

void unpremultiplyAlpha(std::span<uint8_t> texels, DataType type, int channels, int alphaChannel) {
    scaleColour(texels, type, channels, alphaChannel, []<typename C>(C, float alpha) -> std::optional<float> {
        if (alpha == 0.0f) return std::nullopt;  // transparent: the colour stays as it is
        return C::kOne / alpha;
    });
}

std::vector<uint8_t> reduceQuadFace(std::span<const uint8_t> texels, int w, int h, DataType type,
                                    int channels) {
    return reduce(texels, w, h, type, channels, false);
}

std::vector<uint8_t> reduceTriangleFace(std::span<const uint8_t> texels, int w, DataType type, int channels) {
    return reduce(texels, w, w, type, channels, true);
}

void averageTexels(std::span<const uint8_t> texels, size_t count, DataType type, int channels, uint8_t* out) {
    withChannel(type, [&]<typename C>(C) {
        using T = typename C::Stored;
        const size_t pixel = sizeof(T) * channels;
        std::array<float, kMaxChannels> sums{};
        for (size_t k = 0; k < count; ++k) {
            for (int c = 0; c < channels; ++c)
                sums[c] += C::value(load<T>(texels.data() + k * pixel + c * sizeof(T)));
        }
        const float scale = 1.0f / static_cast<float>(count);
        for (int c = 0; c < channels; ++c)
            store(out + c * sizeof(T), C::from(sums[c] * scale));
    });
}

int reductionRank(const FaceInfo& info) {
    return info.constant ? 1 : std::min(info.ulog2, info.vlog2);
}

std::vector<uint32_t> reductionOrder(std::span<const FaceInfo> faces) {
    std::vector<uint32_t> order(faces.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return reductionRank(faces[a]) > reductionRank(faces[b]);
    });
    return order;
}

FaceInfo loadFaceInfo(const uint8_t* p) {
    FaceInfo info;
    info.ulog2 = static_cast<int8_t>(p[0]);
    info.vlog2 = static_cast<int8_t>(p[1]);
    const uint8_t edges = p[2];
    const uint8_t flags = p[3];
    for (int e = 0; e < 4; ++e) {
        info.adjEdges[e] = static_cast<uint8_t>((edges >> (2 * e)) & 3u);
        info.adjFaces[e] = load<int32_t>(p + 4 + 4 * e);
    }
    info.constant = (flags & kFlagConstant) != 0;
    info.hasEdits = (flags & kFlagHasEdits) != 0;
    info.neighbourhoodConstant = (flags & kFlagNeighbourhoodConstant) != 0;
    info.subface = (flags & kFlagSubface) != 0;
    return info;
}

void storeFaceInfo(ByteWriter& out, const FaceInfo& info) {
    out.put(info.ulog2);
    out.put(info.vlog2);
    uint8_t edges = 0;
    for (int e = 0; e < 4; ++e)
        edges = static_cast<uint8_t>(edges | ((info.adjEdges[e] & 3u) << (2 * e)));
    out.put(edges);
    const uint8_t flags = static_cast<uint8_t>(
        (info.constant ? kFlagConstant : 0) | (info.hasEdits ? kFlagHasEdits : 0) |
        (info.neighbourhoodConstant ? kFlagNeighbourhoodConstant : 0) | (info.subface ? kFlagSubface : 0));
    out.put(flags);
    for (int e = 0; e < 4; ++e)
        out.put(info.adjFaces[e]);
}

}  // namespace deformkit::ptex::detail
