#include "deformkit/scene/weights_file.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>

#include "deformkit/error.h"
#include "deformkit/io/read_file.h"
#include "scene/json_reading.h"

namespace deformkit::scene {

using detail::json;

// The doubles that round to a finite float: below FLT_MAX plus half its last place (2^103), where rounding
// to nearest goes to infinity. FLT_MAX's shortest decimal, 3.4028235e38, is above FLT_MAX itself.
constexpr double kFloatLimit = static_cast<double>(std::numeric_limits<float>::max()) + 0x1p103;

std::vector<float> parseWeightsFile(std::string_view text, size_t count, const std::string& source) {
    constexpr const char* kExpected = "a JSON array of one number per vertex, or {\"weights\": [...]}";
    const json root = detail::parseJson(text, source, kExpected);
    const json* array = &root;
    std::string path;  // of the array: "" at the top level, "weights" in the object form
    if (root.is_object()) {
        // The object form holds "weights" and nothing else: a misspelt key is an error, not ignored.
        detail::requireKnownKeys(root, source, "", {"weights"});
        if (!root.contains("weights"))
            throw InvalidInput(formatError(source, "weights", "is missing", kExpected));
        array = &root.at("weights");
        path = "weights";
    }
    if (!array->is_array()) {
        throw InvalidInput(formatError(source, path.empty() ? "(top level)" : path,
                                       "is " + detail::jsonKind(*array), kExpected));
    }
    if (array->size() != count) {
        throw InvalidInput(formatError(source, "", "has " + std::to_string(array->size()) + " weights",
                                       std::to_string(count) + ", one per vertex of the rest mesh"));
    }
    std::vector<float> weights(count);
    for (size_t i = 0; i < count; ++i) {
        const json& v = (*array)[i];
        const std::string element = detail::jsonIndex(path, i);
        if (!v.is_number())
            throw InvalidInput(formatError(source, element, "is " + detail::jsonKind(v), "a number"));
        const double d = v.get<double>();
        if (!(std::abs(d) < kFloatLimit)) {
            throw InvalidInput(
                formatError(source, element, "is " + v.dump(), "a finite number, normally in [0, 1]"));
        }
        weights[i] = static_cast<float>(d);
    }
    return weights;
}

std::vector<float> readWeightsFile(const std::filesystem::path& path, size_t count) {
    return parseWeightsFile(io::readFile(path, "JSON weights file"), count, path.string());
}

std::string formatWeightsFile(std::span<const float> weights, const std::string& source) {
    std::string text = "[";
    char number[32];
    for (size_t v = 0; v < weights.size(); ++v) {
        if (!std::isfinite(weights[v])) {
            throw InvalidInput(formatError(source, "[" + std::to_string(v) + "]",
                                           "is " + numberText(weights[v]),
                                           "a finite number (JSON has no NaN or infinity)"));
        }
        if (v > 0) text += ", ";
        if (weights[v] == 0.0f && std::signbit(weights[v])) {
            text += "-0.0";  // "-0" would read back as the integer 0, losing the sign
            continue;
        }
        const auto [end, ec] = std::to_chars(number, number + sizeof(number), weights[v]);
        text.append(number, ec == std::errc() ? end : number);
    }
    return text + "]\n";
}

}  // namespace deformkit::scene
