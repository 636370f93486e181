#include "format.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

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

double channelValue(const uint8_t* p, DataType type) {
    switch (type) {
        case DataType::UInt8:
            return *p;
        case DataType::UInt16:
            return load<uint16_t>(p);
        case DataType::Half:
            return halfToFloat(load<uint16_t>(p));
        case DataType::Float:
            return load<float>(p);
    }
    return 0;
}

// Alpha as a weight in [0, 1] for integer types, as stored for floating-point types.
double alphaWeight(double alpha, DataType type) {
    switch (type) {
        case DataType::UInt8:
            return alpha / 255.0;
        case DataType::UInt16:
            return alpha / 65535.0;
        default:
            return alpha;
    }
}

// double to float without the undefined behaviour of an out-of-range conversion: beyond the float range
// gives infinity, as the hardware conversion would.
float toFloat(double value) {
    constexpr double kMax = std::numeric_limits<float>::max();
    if (value > kMax) return std::numeric_limits<float>::infinity();
    if (value < -kMax) return -std::numeric_limits<float>::infinity();
    return static_cast<float>(value);
}

void storeChannel(double value, DataType type, uint8_t* p) {
    switch (type) {
        case DataType::UInt8: {
            const double r = std::floor(value + 0.5);
            *p = static_cast<uint8_t>(std::isnan(r) ? 0.0 : std::clamp(r, 0.0, 255.0));
            break;
        }
        case DataType::UInt16: {
            const double r = std::floor(value + 0.5);
            store(p, static_cast<uint16_t>(std::isnan(r) ? 0.0 : std::clamp(r, 0.0, 65535.0)));
            break;
        }
        case DataType::Half:
            store(p, floatToHalf(toFloat(value)));
            break;
        case DataType::Float:
            store(p, toFloat(value));
            break;
    }
}

// Filters `count` texels given by pointers into one pixel: colour = Σ cᵢ aᵢ / Σ aᵢ (plain mean when Σ aᵢ =
// 0), alpha and every channel without alpha = mean.
template <typename TexelAt>
void filterPixel(size_t count, const TexelAt& texelAt, DataType type, int channels, int alphaChannel,
                 uint8_t* out) {
    const size_t bpc = bytesPerChannel(type);
    double alphaSum = 0;
    if (alphaChannel >= 0) {
        for (size_t k = 0; k < count; ++k) {
            alphaSum += alphaWeight(channelValue(texelAt(k) + alphaChannel * bpc, type), type);
        }
    }
    for (int c = 0; c < channels; ++c) {
        double sum = 0;
        double weighted = 0;
        for (size_t k = 0; k < count; ++k) {
            const double v = channelValue(texelAt(k) + c * bpc, type);
            sum += v;
            if (alphaChannel >= 0 && c != alphaChannel) {
                weighted += v * alphaWeight(channelValue(texelAt(k) + alphaChannel * bpc, type), type);
            }
        }
        const bool premultiplied = alphaChannel >= 0 && c != alphaChannel && alphaSum != 0;
        const double value = premultiplied ? weighted / alphaSum : sum / static_cast<double>(count);
        storeChannel(value, type, out + c * bpc);
    }
}

}  // namespace

std::vector<uint8_t> reduceFace(std::span<const uint8_t> texels, int w, int h, DataType type, int channels,
                                int alphaChannel) {
    const size_t pixel = bytesPerChannel(type) * channels;
    const int rw = w / 2;
    const int rh = h / 2;
    std::vector<uint8_t> out(static_cast<size_t>(rw) * rh * pixel);
    for (int y = 0; y < rh; ++y) {
        for (int x = 0; x < rw; ++x) {
            // Order (2x, 2y), (2x+1, 2y), (2x, 2y+1), (2x+1, 2y+1).
            const auto texelAt = [&](size_t k) {
                const size_t sx = 2 * x + (k & 1);
                const size_t sy = 2 * y + (k >> 1);
                return texels.data() + (sy * w + sx) * pixel;
            };
            filterPixel(4, texelAt, type, channels, alphaChannel,
                        out.data() + (static_cast<size_t>(y) * rw + x) * pixel);
        }
    }
    return out;
}

std::vector<uint8_t> averagePixel(std::span<const uint8_t> texels, size_t count, DataType type, int channels,
                                  int alphaChannel) {
    const size_t pixel = bytesPerChannel(type) * channels;
    std::vector<uint8_t> out(pixel);
    filterPixel(
        count, [&](size_t k) { return texels.data() + k * pixel; }, type, channels, alphaChannel, out.data());
    return out;
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
