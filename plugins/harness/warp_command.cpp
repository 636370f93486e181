#include "warp_command.h"
#include <iostream>
#include "cli.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/image.h"

namespace deformkit::harness {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string typeName(const json& v) {
    if (v.is_null()) return "null";
    if (v.is_boolean()) return "a boolean";
    if (v.is_number()) return "a number";
    if (v.is_string()) return "a string";
    if (v.is_array()) return "an array of " + std::to_string(v.size());
    return "an object";
}

// Each reader names the JSON path of what it reads: `lines[2].dst[1][0]`.
float number(const json& v, const std::string& source, const std::string& path) {
    if (!v.is_number()) throw InvalidInput(formatError(source, path, "is " + typeName(v), "a number"));
    const double d = v.get<double>();
    if (!std::isfinite(d) || std::abs(d) > 3.0e38) {
        throw InvalidInput(formatError(source, path, "is " + v.dump(), "a finite float"));
    }
    return static_cast<float>(d);
}

glm::vec2 point(const json& v, const std::string& source, const std::string& path) {
    if (!v.is_array() || v.size() != 2)
        throw InvalidInput(formatError(source, path, "is " + typeName(v), "[x, y]"));
    return {number(v[0], source, path + "[0]"), number(v[1], source, path + "[1]")};
}

void segment(const json& line, const char* key, const std::string& source, const std::string& path,
             glm::vec2& p, glm::vec2& q) {
    const std::string here = path + "." + key;
    if (!line.contains(key)) throw InvalidInput(formatError(source, here, "is missing", "[[x, y], [x, y]]"));
    const json& v = line.at(key);
    if (!v.is_array() || v.size() != 2) {
        throw InvalidInput(formatError(source, here, "is " + typeName(v), "[[x, y], [x, y]]"));
    }
    p = point(v[0], source, here + "[0]");
    q = point(v[1], source, here + "[1]");
    if (p == q) {
        throw InvalidInput(formatError(
            source, here,
            "has zero length (both ends at [" + std::to_string(p.x) + ", " + std::to_string(p.y) + "])",
            "two distinct points"));
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
            throw InvalidInput(formatError(source, path, "is " + object.at(key).dump(),
                                           std::string(key) + (strictlyPositive ? " > 0" : " >= 0")));
        }
    };
    read("a", a, true);
    read("b", b, false);
    read("p", p, false);
}

}  // namespace

std::vector<warp::SegmentPair> parseSegmentPairs(std::string_view text, const std::string& source) {
    json root;
    try {
        root = json::parse(text.begin(), text.end());
    } catch (const json::exception& e) {
        // nlohmann reports "[json.exception.parse_error.101] parse error at line L, column C: ..." (or
        // out_of_range for a number too large): keep the part after the bracketed id.
        std::string what = e.what();
        const size_t at = what.find("] ");
        throw ParseError(formatError(source, "", at == std::string::npos ? what : what.substr(at + 2),
                                     "JSON {\"a\", \"b\", \"p\", \"lines\": [{\"src\", \"dst\"}, ...]}"));
    }
    if (!root.is_object())
        throw InvalidInput(formatError(source, "(top level)", "is " + typeName(root), "an object"));
    float a = 1.0f, b = 2.0f, p = 0.5f;
    parameters(root, source, "", a, b, p);
    if (!root.contains("lines"))
        throw InvalidInput(formatError(source, "lines", "is missing", "an array of lines"));
    const json& lines = root.at("lines");
    if (!lines.is_array())
        throw InvalidInput(formatError(source, "lines", "is " + typeName(lines), "an array of lines"));
    std::vector<warp::SegmentPair> pairs;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::string path = "lines[" + std::to_string(i) + "]";
        const json& line = lines[i];
        if (!line.is_object()) {
            throw InvalidInput(
                formatError(source, path, "is " + typeName(line), "{\"src\": ..., \"dst\": ...}"));
        }
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

std::vector<warp::SegmentPair> readSegmentPairs(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw IoError(formatError(path.string(), "", "cannot open the lines file", "a readable JSON file"));
    std::ostringstream text;
    text << in.rdbuf();
    return parseSegmentPairs(text.str(), path.string());
}

void warpImageCommand(const WarpImageCommand& command) {
    const std::vector<warp::SegmentPair> pairs = readSegmentPairs(command.lines);
    const io::Image source = io::readImage(command.image);
    if (source.width <= 0 || source.height <= 0) {
        throw InvalidInput(formatError(command.image.string(), "", "has 0 pixels", "a non-empty image"));
    }
    const warp::BeierNeelyWarp warp(pairs, {command.variant});
    std::vector<glm::vec2> map(static_cast<size_t>(source.width) * source.height);
    warp.mapPixelCentres(source.width, source.height, map);
    const io::Image out =
        warp::resampleImage(source, map, source.width, source.height, command.interpolation);
    io::writeImage(command.out, out);
}

void addWarpCommand(CommandLine& cli) {
    struct Options {
        WarpImageCommand command;
        std::string image, lines, out, variant = "original", filter = "bilinear";
    };
    auto o = std::make_shared<Options>();
    CLI::App* warp =
        cli.add(cli.app(), "warp", "Warp an image with Beier-Neely segment pairs (inverse mapping)", [o] {
            WarpImageCommand& c = o->command;
            c.image = o->image;
            c.lines = o->lines;
            c.out = o->out;
            c.variant =
                o->variant == "global" ? warp::BeierNeelyVariant::Global : warp::BeierNeelyVariant::Original;
            c.interpolation = o->filter == "bicubic" ? io::SampleFilter::Bicubic : io::SampleFilter::Bilinear;
            warpImageCommand(c);
            std::cout << "wrote " << o->out << "\n";
            return 0;
        });
    warp->add_option("IMAGE", o->image, "source image")->required();
    warp->add_option("--lines", o->lines, "segment pairs, JSON (docs/warps/beier_neely.md)")->required();
    warp->add_option("--out", o->out, "output image, same size and channels")->required();
    warp->add_option("--variant", o->variant, "original or global (no fold-over, paper 5.2)")
        ->check(CLI::IsMember({"original", "global"}))
        ->capture_default_str();
    warp->add_option("--interp", o->filter, "bilinear or bicubic")
        ->check(CLI::IsMember({"bilinear", "bicubic"}))
        ->capture_default_str();
}

}  // namespace deformkit::harness
