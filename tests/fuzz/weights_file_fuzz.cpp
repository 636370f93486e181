// libFuzzer target for weights files (a JSON array of one number per vertex, or {"weights": [...]}). Any
// input may be rejected with deformkit::Error; anything else is a bug. The expected count is the array's
// size as nlohmann's own parser reads it (when it does), so inputs reach the per-value checks; weights that
// parse must survive formatWeightsFile and a second parse to the bit.
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/scene/weights_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    size_t count = 0;
    const nlohmann::json root = nlohmann::json::parse(text, nullptr, false);
    if (root.is_array()) count = root.size();
    if (root.is_object() && root.contains("weights") && root["weights"].is_array())
        count = root["weights"].size();
    std::vector<float> weights;
    try {
        weights = deformkit::scene::parseWeightsFile(text, count, "fuzz.json");
    } catch (const deformkit::Error&) {
        return 0;
    }
    const std::vector<float> again =
        deformkit::scene::parseWeightsFile(deformkit::scene::formatWeightsFile(weights), count, "again.json");
    for (size_t i = 0; i < count; ++i) {
        if (std::bit_cast<uint32_t>(weights[i]) != std::bit_cast<uint32_t>(again[i])) std::abort();
    }
    return 0;
}
