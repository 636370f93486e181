#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

// Point cache bytes written by the tests themselves, from the formats' descriptions (io/point_cache.h), as
// the independent reference of the reader and the writer: values are copied in the machine's byte order
// (little-endian, checked) and reversed word by word for MDD's big-endian layout.
namespace deformkit::test {

static_assert(std::endian::native == std::endian::little, "these encoders assume a little-endian machine");

template <class T>
void appendWord(std::string& out, T value, bool bigEndian) {
    static_assert(sizeof(T) == 4);
    char bytes[4];
    std::memcpy(bytes, &value, 4);
    if (bigEndian) std::reverse(bytes, bytes + 4);
    out.append(bytes, 4);
}

inline void appendFrame(std::string& out, const std::vector<glm::vec3>& points, bool bigEndian) {
    for (const glm::vec3& p : points)
        for (int c = 0; c < 3; ++c)
            appendWord(out, p[c], bigEndian);
}

// A PC2 file: "POINTCACHE2\0", version 1, vertex count, start, sampling, sample count, then the samples.
inline std::string pc2Bytes(float start, float sampling, const std::vector<std::vector<glm::vec3>>& frames,
                            int32_t version = 1) {
    std::string out("POINTCACHE2", 11);
    out.push_back('\0');
    appendWord(out, version, false);
    appendWord(out, static_cast<int32_t>(frames.empty() ? 0 : frames[0].size()), false);
    appendWord(out, start, false);
    appendWord(out, sampling, false);
    appendWord(out, static_cast<int32_t>(frames.size()), false);
    for (const auto& frame : frames)
        appendFrame(out, frame, false);
    return out;
}

// An MDD file: frame count, vertex count, the times, then the frames, all big-endian.
inline std::string mddBytes(const std::vector<float>& times,
                            const std::vector<std::vector<glm::vec3>>& frames) {
    std::string out;
    appendWord(out, static_cast<int32_t>(frames.size()), true);
    appendWord(out, static_cast<int32_t>(frames.empty() ? 0 : frames[0].size()), true);
    for (float t : times)
        appendWord(out, t, true);
    for (const auto& frame : frames)
        appendFrame(out, frame, true);
    return out;
}

}  // namespace deformkit::test
