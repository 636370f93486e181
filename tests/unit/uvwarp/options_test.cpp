// The UV warp's options declared once (uvwarp/options.h): names in every case, the checks of setOption
// against a range predicate written here, the constructors that check every option, the generated reference.
#include <catch2/catch.hpp>

#include <cctype>
#include <cmath>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/shot_job.h"
#include "test_support.h"

using namespace deformkit;
using uvwarp::OptionSpec;
using uvwarp::OptionType;
using uvwarp::OptionValue;

namespace {

// camelCase to words joined by `separator`, written apart from the library's: split before each capital.
std::string joined(const std::string& camel, char separator) {
    std::vector<std::string> words(1);
    for (char c : camel) {
        if (std::isupper(static_cast<unsigned char>(c))) words.emplace_back();
        words.back() += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    std::string out;
    for (const std::string& w : words)
        out += (out.empty() ? "" : std::string(1, separator)) + w;
    return out;
}

// The test's own reading of a declared range: may `given` be a value (an element, for a list) of `spec`? A
// number option holds a float, and the range is of what it holds (1e-60 above an open 0 is 0 as a float).
bool allowed(const OptionSpec& spec, double given) {
    const bool whole = spec.type != OptionType::Number;
    const double v = whole ? given : static_cast<double>(static_cast<float>(given));
    if (!std::isfinite(v) || (whole && std::floor(v) != v) || v > spec.high) return false;
    if (spec.lowOpen ? v <= spec.low : v < spec.low) return false;
    if (spec.powerOfTwo && v != 0) {
        if (v < 2) return false;
        auto n = static_cast<int64_t>(v);
        while (n % 2 == 0)
            n /= 2;
        if (n != 1) return false;
    }
    return true;
}

OptionValue number(double v) {
    return {OptionValue::Kind::Number, {v}, {}};
}
OptionValue flag(bool v) {
    return {OptionValue::Kind::Boolean, {v ? 1.0 : 0.0}, {}};
}
OptionValue list(std::vector<double> v) {
    return {OptionValue::Kind::List, std::move(v), {}};
}

}  // namespace

TEST_CASE("uv warp options: one camelCase name each, spelled by rule in the CLI and Python",
          "[uvwarp][options]") {
    std::set<std::string> names, cli, python;
    for (const OptionSpec& spec : uvwarp::optionSpecs()) {
        const std::string name(spec.name);
        CAPTURE(name);
        CHECK(std::islower(static_cast<unsigned char>(name[0])));
        CHECK(name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ") ==
              std::string::npos);
        CHECK(uvwarp::cliName(spec) == "--" + joined(name, '-'));
        CHECK(uvwarp::pythonName(spec) == joined(name, '_'));
        CHECK(uvwarp::findOption(name) == &spec);
        CHECK_FALSE(spec.meaning.empty());
        CHECK(spec.get != nullptr);
        CHECK(spec.put != nullptr);
        names.insert(name);
        cli.insert(uvwarp::cliName(spec));
        python.insert(uvwarp::pythonName(spec));
    }
    CHECK(names.size() == uvwarp::optionSpecs().size());
    CHECK(cli.size() == names.size());
    CHECK(python.size() == names.size());
    CHECK(uvwarp::findOption("borderWidth") == nullptr);
    CHECK(uvwarp::cliName(*uvwarp::findOption("coarseRelaxation")) == "--coarse-relaxation");
    CHECK(uvwarp::pythonName(*uvwarp::findOption("maskBorderWidth")) == "mask_border_width");
}

TEST_CASE("uv warp options: each writes the member it reads, and no other", "[uvwarp][options]") {
    // Each option's put writes the member its get reads, and no other: a new value through one option
    // leaves every other option as it was.
    const uvwarp::TileWarpOptions base;
    for (const OptionSpec& spec : uvwarp::optionSpecs()) {
        CAPTURE(spec.name);
        uvwarp::TileWarpOptions o = base;
        std::vector<double> v = spec.get(o);
        if (spec.type == OptionType::IntegerList && v.empty()) v = {2.0};  // empty: the library's schedule
        REQUIRE_FALSE(v.empty());
        v.front() = spec.type == OptionType::Flag ? 1.0 - v.front() : v.front() + 1.0;
        if (spec.type == OptionType::Number) v.front() = static_cast<float>(v.front());  // kept as float32
        spec.put(o, v);
        CHECK(spec.get(o) == v);
        for (const OptionSpec& other : uvwarp::optionSpecs()) {
            if (&other != &spec) CHECK(other.get(o) == other.get(base));
        }
    }
}

TEST_CASE("uv warp options: setOption takes what the declared range allows and nothing else",
          "[uvwarp][options]") {
    std::mt19937 random(20261204);
    for (const OptionSpec& spec : uvwarp::optionSpecs()) {
        const std::string name(spec.name);
        CAPTURE(name);
        // Candidates: the bounds and their neighbours, fractions, powers of two, non-finite values, and
        // random numbers over and around the range.
        std::vector<double> candidates = {spec.low,
                                          spec.high,
                                          spec.low - 1,
                                          spec.high + 1,
                                          spec.low + 0.5,
                                          spec.high - 0.5,
                                          spec.low - 0.5,
                                          0,
                                          1,
                                          2,
                                          3,
                                          64,
                                          48,
                                          spec.low + 1e-60,  // the low bound as a float
                                          spec.high + 1e-9,  // the high bound as a float, when it is large
                                          spec.high * 1e30,  // beyond float's range for the largest highs
                                          NAN,
                                          INFINITY,
                                          -INFINITY};
        std::uniform_real_distribution<double> around(spec.low - 2, spec.high + 2);
        for (int k = 0; k < 200; ++k) {
            const double x = around(random);
            candidates.push_back(x);
            candidates.push_back(std::round(x));
        }
        for (double x : candidates) {
            CAPTURE(x);
            uvwarp::TileWarpOptions o;
            OptionValue value = spec.type == OptionType::IntegerList ? list({x, 1}) : number(x);
            if (spec.type == OptionType::Flag) {
                CHECK_THROWS_AS(uvwarp::setOption(o, spec, value, "src", "elem"), InvalidInput);
                continue;
            }
            if (allowed(spec, x)) {
                uvwarp::setOption(o, spec, value, "src", "elem");
                const double stored = spec.get(o).front();
                CHECK(stored == (spec.type == OptionType::Number ? double(float(x)) : x));
            } else {
                CHECK_THROWS_WITH(uvwarp::setOption(o, spec, value, "src", "elem"),
                                  Catch::StartsWith("src: elem: is ") &&
                                      Catch::EndsWith("(expected " + uvwarp::expectedValue(spec) + ")"));
                CHECK(spec.get(o) == spec.get(uvwarp::TileWarpOptions{}));  // unchanged
            }
        }
        // Values of another kind are refused whatever they hold.
        uvwarp::TileWarpOptions o;
        const OptionValue other{OptionValue::Kind::Other, {}, "a string"};
        CHECK_THROWS_WITH(uvwarp::setOption(o, spec, other, "src", "elem"), Catch::Contains("is a string"));
        if (spec.type == OptionType::Flag) {
            CHECK_THROWS_AS(uvwarp::setOption(o, spec, list({1}), "", "elem"), InvalidInput);
            uvwarp::setOption(o, spec, flag(true), "", "elem");
            CHECK(spec.get(o) == std::vector<double>{1});
            uvwarp::setOption(o, spec, flag(false), "", "elem");
            CHECK(spec.get(o) == std::vector<double>{0});
        } else if (spec.type == OptionType::IntegerList) {
            CHECK_THROWS_AS(uvwarp::setOption(o, spec, number(4), "", "elem"), InvalidInput);
            uvwarp::setOption(o, spec, list({}), "", "elem");  // the library's choice
            CHECK(spec.get(o).empty());
            CHECK_THROWS_WITH(uvwarp::setOption(o, spec, list({0, 0, 0}), "", "elem"),
                              Catch::Contains("is [0, 0, 0]") && Catch::Contains("not all 0"));
            uvwarp::setOption(o, spec, list({0, 3}), "", "elem");
            CHECK(spec.get(o) == std::vector<double>{0, 3});
        } else {
            CHECK_THROWS_AS(uvwarp::setOption(o, spec, flag(true), "", "elem"), InvalidInput);
            CHECK_THROWS_AS(uvwarp::setOption(o, spec, list({spec.high}), "", "elem"), InvalidInput);
        }
    }
}

TEST_CASE("uv warp options: the presets and defaults are valid; zero iterations or no sweeps are not",
          "[uvwarp][options]") {
    uvwarp::checkOptions(uvwarp::TileWarpOptions{}, "defaults");
    uvwarp::checkOptions(uvwarp::shotOptions(), "shot");
    for (int32_t cells : {2, 64, 128, 256, 512, 1024, 2048, 4096, 32768})
        uvwarp::checkOptions(uvwarp::liveOptions(cells), "live");
    uvwarp::SolverOptions zero;
    zero.iterations = 0;
    CHECK_THROWS_WITH(uvwarp::checkOptions(zero, "tile 1001"),
                      "tile 1001: option iterations: is 0 (expected a whole number from 1 to 100000)");
    uvwarp::SolverOptions idle;
    idle.sweepsPerLevel = {0, 0};
    CHECK_THROWS_WITH(
        uvwarp::checkOptions(idle, "tile 1001"),
        "tile 1001: option sweepsPerLevel: is [0, 0] (expected a list of whole numbers from 0 to 1000, not "
        "all 0; empty: by the grid's size, 4 8 16 up to 1024 cells, 4 8 16 32 64 from 2048; where a "
        "refinement follows, the finest level 2 from 1024 cells, and 2 8 64 16 at 1024)");
}

TEST_CASE("uv warp options: the solver and the tile warp refuse each option out of range by its name",
          "[uvwarp][options]") {
    const geom::Mesh mesh = geom::makeGrid({4, 4, 1.0f, 1.0f});
    const io::Image rigidity(16, 16, 1, 0.5f);
    for (const OptionSpec& spec : uvwarp::optionSpecs()) {
        if (spec.type == OptionType::Flag) continue;  // every value of a flag is valid
        const std::string name(spec.name);
        CAPTURE(name);
        uvwarp::TileWarpOptions o;
        std::vector<double> bad = spec.get(o);
        if (bad.empty()) bad.push_back(0.0);  // an empty list: the library's choice
        bad.front() = spec.high + 1;
        spec.put(o, bad);
        const std::string message = test::errorOf<InvalidInput>(
            [&] { uvwarp::TileWarp warp(mesh, 1001, rigidity, {}, o, {}, "plane"); });
        CHECK_THAT(message, Catch::StartsWith("plane: option " + name + ": is "));
        if (spec.solver) {
            uvwarp::PointField rest;
            rest.cells = 16;
            rest.channels = 3;
            rest.values.assign(17 * 17 * 3, 0.0f);
            uvwarp::PointField one;
            one.cells = 16;
            one.channels = 1;
            one.values.assign(17 * 17, 1.0f);
            CHECK_THROWS_WITH(uvwarp::Solver(rest, one, one, o.solver, {}, "grid"),
                              Catch::StartsWith("grid: option " + name + ": is "));
        }
    }
}

TEST_CASE("uv warp options: the reference lists every option in every interface's spelling",
          "[uvwarp][options]") {
    std::istringstream table(uvwarp::optionReference(true));
    std::string line;
    std::vector<std::string> rows;
    while (std::getline(table, line))
        rows.push_back(line);
    const auto specs = uvwarp::optionSpecs();
    REQUIRE(rows.size() == specs.size() + 2);  // the header and its rule
    for (size_t i = 0; i < specs.size(); ++i) {
        const std::string& row = rows[i + 2];
        CAPTURE(row);
        CHECK_THAT(
            row, Catch::StartsWith("| `" + std::string(specs[i].name) + "` | `" + uvwarp::cliName(specs[i]) +
                                   "` | `" + uvwarp::pythonName(specs[i]) + "` | "));
        CHECK_THAT(row, Catch::Contains(uvwarp::expectedValue(specs[i])));
        CHECK(std::count(row.begin(), row.end(), '|') == 7);
    }
    CHECK_THAT(uvwarp::optionReference(true),
               Catch::Contains("| `warmStart` | `--warm-start` | `warm_start` | "
                               "true; in a shot: false |"));
    const std::string text = uvwarp::optionReference(false);
    for (const OptionSpec& spec : specs)
        CHECK_THAT(text, Catch::Contains(std::string(spec.name) + " (CLI " + uvwarp::cliName(spec) +
                                         ", Python " + uvwarp::pythonName(spec) + "): "));
}

TEST_CASE("uv warp options: presets by name, resolved for a grid, the caller's own options kept",
          "[uvwarp][options]") {
    CHECK(uvwarp::presetNamed("shot", "s", "e") == uvwarp::Preset::Shot);
    CHECK(uvwarp::presetNamed("live", "s", "e") == uvwarp::Preset::Live);
    CHECK(uvwarp::presetName(uvwarp::Preset::Live) == "live");
    CHECK_THROWS_WITH(uvwarp::presetNamed("fast", "cli", "--preset"),
                      "cli: --preset: is 'fast' (expected shot or live)");
    // shot: the shot job's options; live: the live schedule of the grid's size, warm-started.
    CHECK(uvwarp::presetOptions(uvwarp::Preset::Shot, 512).solver == uvwarp::shotOptions().solver);
    for (int32_t cells : {64, 256, 512, 1024, 2048}) {
        const uvwarp::TileWarpOptions live = uvwarp::presetOptions(uvwarp::Preset::Live, cells);
        CHECK(live.solver == uvwarp::liveOptions(cells));
        CHECK(live.solver.warmStart);
        CHECK(live.solver.iterations == 1);
        CHECK(live.cells == cells);
        uvwarp::checkOptions(live, "live");
    }
    // The options the caller set itself keep their values; every other one is the preset's.
    uvwarp::TileWarpOptions mine = uvwarp::shotOptions();
    mine.solver.iterations = 3;
    mine.solver.smoothing = 0.25f;
    mine.derivedMask.borderWidth = 2;
    const std::vector<std::string> own = {"iterations", "maskBorderWidth"};
    const uvwarp::TileWarpOptions o = uvwarp::withPreset(uvwarp::Preset::Live, 1024, mine, own);
    CHECK(o.solver.iterations == 3);
    CHECK(o.derivedMask.borderWidth == 2);
    CHECK(o.solver.smoothing == uvwarp::liveOptions(1024).smoothing);  // not named: the preset's
    CHECK(o.solver.sweepsPerLevel == uvwarp::liveOptions(1024).sweepsPerLevel);
    CHECK(o.solver.warmStart);
    const std::vector<std::string> bogus = {"borderWidth"};
    CHECK_THROWS_AS(uvwarp::withPreset(uvwarp::Preset::Live, 1024, mine, bogus), InvalidInput);
}
