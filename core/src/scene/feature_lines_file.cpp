#include "deformkit/scene/feature_lines_file.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/io/read_file.h"
#include "deformkit/warp/beier_neely.h"
#include "scene/json_reading.h"

namespace deformkit::scene {
namespace {

using detail::json;

// Each reader names the JSON path of what it reads: `lines[2].dst[1][0]`.
float number(const json& v, const std::string& source, const std::string& path) {
    if (!v.is_number())
        throw InvalidInput(formatError(source, path, "is " + detail::jsonKind(v), "a number"));
    const double d = v.get<double>();
    if (!std::isfinite(d) || std::abs(d) > 3.0e38) {
        throw InvalidInput(formatError(source, path, "is " + v.dump(), "a finite float"));
    }
    return static_cast<float>(d);
}

glm::vec2 point(const json& v, const std::string& source, const std::string& path) {
    if (!v.is_array() || v.size() != 2)
        throw InvalidInput(formatError(source, path, "is " + detail::jsonKind(v), "[x, y]"));
    return {number(v[0], source, path + "[0]"), number(v[1], source, path + "[1]")};
}

void segment(const json& line, const char* key, const std::string& source, const std::string& path,
             glm::vec2& p, glm::vec2& q) {
    const std::string here = path + "." + key;
    if (!line.contains(key)) throw InvalidInput(formatError(source, here, "is missing", "[[x, y], [x, y]]"));
    const json& v = line.at(key);
    if (!v.is_array() || v.size() != 2) {
        throw InvalidInput(formatError(source, here, "is " + detail::jsonKind(v), "[[x, y], [x, y]]"));
    }
    p = point(v[0], source, here + "[0]");
    q = point(v[1], source, here + "[1]");
    if (const float length = glm::length(q - p); !(length > warp::kMinSegmentLength)) {
        const std::string ends = "[" + numberText(p.x) + ", " + numberText(p.y) + "]";
        const std::string what = length == 0.0f
                                     ? "has zero length (both ends at " + ends + ")"
                                     : "is " + numberText(length) + " long (from " + ends + " to [" +
                                           numberText(q.x) + ", " + numberText(q.y) + "])";
        throw InvalidInput(formatError(
            source, here, what, "a segment longer than " + numberText(warp::kMinSegmentLength) + " pixels"));
    }
}

// a, b, p at `object` (top level or one line), keeping `fallback` when absent.
void parameters(const json& object, const std::string& source, const std::string& prefix, float& a, float& b,
                float& p) {
    auto read = [&](const char* key, float& value, bool strictlyPositive) {
        if (!object.contains(key)) return;
        const std::string path = prefix + key;
        value = number(object.at(key), source, path);
        if (strictlyPositive ? !(value > 0.0f) : !(value >= 0.0f)) {
            // A positive number below float's least (1e-300) is 0 as the float the warp keeps: said so.
            const std::string shown =
                object.at(key).dump() +
                (value == 0.0f && object.at(key).get<double>() != 0.0 ? ", 0 as a float" : "");
            throw InvalidInput(formatError(source, path, "is " + shown,
                                           std::string(key) + (strictlyPositive ? " > 0" : " >= 0")));
        }
    };
    read("a", a, true);
    read("b", b, false);
    read("p", p, false);
}

}  // namespace

std::vector<warp::SegmentPair> parseFeatureLines(std::string_view text, const std::string& source) {
    const json root =
        detail::parseJson(text, source, "JSON {\"a\", \"b\", \"p\", \"lines\": [{\"src\", \"dst\"}, ...]}");
    if (!root.is_object())
        throw InvalidInput(formatError(source, "(top level)", "is " + detail::jsonKind(root), "an object"));
    detail::requireKnownKeys(root, source, "", {"a", "b", "p", "lines"});
    float a = 1.0f, b = 2.0f, p = 0.5f;
    parameters(root, source, "", a, b, p);
    if (!root.contains("lines"))
        throw InvalidInput(formatError(source, "lines", "is missing", "an array of lines"));
    const json& lines = root.at("lines");
    if (!lines.is_array())
        throw InvalidInput(
            formatError(source, "lines", "is " + detail::jsonKind(lines), "an array of lines"));
    std::vector<warp::SegmentPair> pairs;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::string path = "lines[" + std::to_string(i) + "]";
        const json& line = lines[i];
        if (!line.is_object()) {
            throw InvalidInput(
                formatError(source, path, "is " + detail::jsonKind(line), "{\"src\": ..., \"dst\": ...}"));
        }
        detail::requireKnownKeys(line, source, path, {"src", "dst", "a", "b", "p"});
        warp::SegmentPair s;
        s.a = a;
        s.b = b;
        s.p = p;
        parameters(line, source, path + ".", s.a, s.b, s.p);
        segment(line, "src", source, path, s.srcP, s.srcQ);
        segment(line, "dst", source, path, s.dstP, s.dstQ);
        pairs.push_back(s);
    }
    warp::validateSegmentPairs(pairs, source);  // backstop: "segment pair i" is lines[i]
    return pairs;
}

std::vector<warp::SegmentPair> readFeatureLines(const std::filesystem::path& path) {
    return parseFeatureLines(io::readFile(path, "JSON lines file"), path.string());
}

}  // namespace deformkit::scene
