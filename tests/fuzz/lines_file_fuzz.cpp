// libFuzzer target for Beier-Neely feature-line files. Any input may be rejected with deformkit::Error;
// anything else is a bug. Lines that parse hold finite coordinates and parameters in their ranges
// (a > 0, b >= 0, p >= 0), as the warp requires.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/scene/feature_lines_file.h"

namespace {

bool finite(glm::vec2 v) {
    return std::isfinite(v.x) && std::isfinite(v.y);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    std::vector<deformkit::warp::SegmentPair> lines;
    try {
        lines = deformkit::scene::parseFeatureLines(text, "fuzz.json");
    } catch (const deformkit::Error&) {
        return 0;
    }
    for (const auto& l : lines) {
        if (!finite(l.dstP) || !finite(l.dstQ) || !finite(l.srcP) || !finite(l.srcQ)) std::abort();
        if (!(l.a > 0.0f) || !(l.b >= 0.0f) || !(l.p >= 0.0f)) std::abort();
        if (!std::isfinite(l.a) || !std::isfinite(l.b) || !std::isfinite(l.p)) std::abort();
    }
    return 0;
}
