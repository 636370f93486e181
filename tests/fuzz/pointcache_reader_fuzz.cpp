// libFuzzer target for point caches read back (io/point_cache.h). The first byte picks the format (bit 0:
// .mdd, else .pc2) and whether the reader is given a first frame (bit 1); the rest is the file. Any input may
// be refused with deformkit::Error; anything else is a bug. A cache that opens must account for every byte of
// the file (the header, MDD's times, whole frames and nothing after them), list its frames ascending, each
// the frame of its sample, and read a frame as vertexCount() finite points or refuse it naming the vertex.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/io/point_cache.h"

namespace {

// Frames read per input: the first, the last and a few between (a long cache costs no more than a short one).
constexpr size_t kReads = 4;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    namespace fs = std::filesystem;
    if (size == 0) return 0;
    const bool mdd = (data[0] & 1u) != 0;
    const bool firstGiven = (data[0] & 2u) != 0;
    const fs::path path = fs::temp_directory_path() /
                          ("deformkit_fuzz_" + std::to_string(::getpid()) + (mdd ? ".mdd" : ".pc2"));
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
        if (!out) std::abort();  // the fuzzer's own temporary file, not the input
    }
    const auto bytes = static_cast<uint64_t>(size - 1);
    try {
        deformkit::io::PointCache cache(path, firstGiven ? std::optional<double>(-3.0) : std::nullopt);
        const auto vertices = static_cast<uint64_t>(cache.vertexCount());
        const auto samples = static_cast<uint64_t>(cache.sampleCount());
        if (vertices == 0) std::abort();
        const uint64_t header = mdd ? 8 + 4 * samples : 32;
        if (header + 12 * vertices * samples != bytes) std::abort();  // no wrap: it fits in a real file
        const std::vector<int> frames = cache.frames();
        if (frames.size() > samples) std::abort();
        for (size_t k = 0; k < frames.size(); ++k) {
            if (k > 0 && frames[k] <= frames[k - 1]) std::abort();
            const std::optional<int32_t> sample = cache.sampleOf(frames[k]);
            if (!sample || *sample < 0 || static_cast<uint64_t>(*sample) >= samples) std::abort();
            if (std::abs(cache.sampleFrame(*sample) - frames[k]) > 1e-3) std::abort();
        }
        std::vector<glm::vec3> points;
        for (size_t r = 0; r < kReads && !frames.empty(); ++r) {
            const int frame = frames[r * (frames.size() - 1) / (kReads - 1)];
            try {
                cache.read(frame, points);
            } catch (const deformkit::InvalidInput&) {
                continue;  // a coordinate that is not finite, named
            }
            if (points.size() != vertices) std::abort();
            for (const glm::vec3& p : points)
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
        }
    } catch (const deformkit::Error&) {
    }
    std::error_code ec;
    fs::remove(path, ec);
    return 0;
}
