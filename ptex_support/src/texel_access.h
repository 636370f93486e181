#pragma once

// Private to the Ptex support over meshes (ptex_mesh.cpp, ptex_sampler.cpp, ptex_vertex_values.cpp,
// ptex_udim.cpp): texel values in a file's data type, and the checks of a file that texel look-ups rely on.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "deformkit/ptex/half.h"
#include "deformkit/ptex/ptex_file.h"

namespace deformkit::ptex::detail {

// Whether `value` is one a texel of `type` holds: u8 and u16 in [0, 1] (a rounding's 1e-5 beyond is taken
// as the bound), half within +-65504 (beyond it, inf); float any finite value. Empty when it is, else what
// a texel of the type holds, for a message.
inline std::string outsideTypeRange(double value, DataType type) {
    switch (type) {
        case DataType::UInt8:
        case DataType::UInt16:
            if (value >= -1e-5 && value <= 1.0 + 1e-5) return {};
            return std::string("values in [0, 1] for ") + (type == DataType::UInt8 ? "u8" : "u16") +
                   " texels (half or float hold others)";
        case DataType::Half:
            if (std::abs(value) <= 65504.0) return {};
            return "values within +-65504 for half texels (float holds larger ones)";
        case DataType::Float:
            return {};
    }
    return {};
}

// A float value in the file's data type, little-endian bytes.
inline void storeValue(float value, DataType type, uint8_t* out) {
    switch (type) {
        case DataType::UInt8:
            out[0] = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255.0f));
            return;
        case DataType::UInt16: {
            const auto q = static_cast<uint16_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 65535.0f));
            out[0] = static_cast<uint8_t>(q & 0xff);
            out[1] = static_cast<uint8_t>(q >> 8);
            return;
        }
        case DataType::Half: {
            const uint16_t h = floatToHalf(value);
            out[0] = static_cast<uint8_t>(h & 0xff);
            out[1] = static_cast<uint8_t>(h >> 8);
            return;
        }
        case DataType::Float: {
            uint32_t bits = 0;
            std::memcpy(&bits, &value, 4);
            for (int b = 0; b < 4; ++b)
                out[b] = static_cast<uint8_t>(bits >> (8 * b));
            return;
        }
    }
}

inline float loadValue(const uint8_t* in, DataType type) {
    switch (type) {
        case DataType::UInt8:
            return static_cast<float>(in[0]) / 255.0f;
        case DataType::UInt16:
            return static_cast<float>(static_cast<uint16_t>(in[0] | (in[1] << 8))) / 65535.0f;
        case DataType::Half:
            return halfToFloat(static_cast<uint16_t>(in[0] | (in[1] << 8)));
        case DataType::Float: {
            const uint32_t bits =
                uint32_t{in[0]} | (uint32_t{in[1]} << 8) | (uint32_t{in[2]} << 16) | (uint32_t{in[3]} << 24);
            float value = 0.0f;
            std::memcpy(&value, &bits, 4);
            return value;
        }
    }
    return 0.0f;
}

// Throws InvalidInput naming `source` when a face's adjacency points outside `faces`.
void requireAdjacency(std::span<const FaceInfo> faces, const std::string& source);

// The file's channel count and texel buffers as the look-ups read them (a file built in memory may be
// inconsistent; one read from disk never is).
void requireBuffers(const PtexFile& file, const std::string& source);

}  // namespace deformkit::ptex::detail
