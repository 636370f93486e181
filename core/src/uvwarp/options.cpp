#include "deformkit/uvwarp/options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <type_traits>

#include "deformkit/error.h"
#include "deformkit/uvwarp/shot_job.h"

namespace deformkit::uvwarp {
namespace {

// Accessors of a scalar member of SolverOptions or TileWarpOptions, as OptionSpec's get and put.
template <auto Member>
struct SolverMember {
    static std::vector<double> get(const TileWarpOptions& o) {
        return {static_cast<double>(o.solver.*Member)};
    }
    static void put(TileWarpOptions& o, std::span<const double> v) {
        o.solver.*Member = static_cast<std::remove_reference_t<decltype(o.solver.*Member)>>(v[0]);
    }
};
template <auto Member>
struct TileMember {
    static std::vector<double> get(const TileWarpOptions& o) { return {static_cast<double>(o.*Member)}; }
    static void put(TileWarpOptions& o, std::span<const double> v) {
        o.*Member = static_cast<std::remove_reference_t<decltype(o.*Member)>>(v[0]);
    }
};

// refinementSweeps' lowMeans spells the rule of refinementSweepsFor out.
static_assert(kAutomaticRefinementSweeps == 4 && kAutomaticRefinementCells == 1024,
              "refinementSweeps' lowMeans states 4 sweeps up to 1024 cells");

// sweepsPerLevel's zeroMeans spells the rule of defaultSweeps out.
static_assert(kHalvedFinestCells == 1024 && kRefinedThirdLevelSweeps == 64,
              "sweepsPerLevel's zeroMeans states the finest level 2 from 1024 cells, 2 8 64 16 at 1024");

// orientationDensity's lowMeans spells the rule of orientationDensityFor out.
static_assert(kAutomaticDensityShare == 16 && kAutomaticDensityCells == 8192,
              "orientationDensity's lowMeans states 1/16 of the map's texels on grids up to 8192 cells");

// geometryImageCells' zeroMeans spells the rule of geometryImageCellsFor out.
static_assert(kFullGeometryImageCells == 8192,
              "geometryImageCells' zeroMeans states the grid's cells up to 8192");

const OptionSpec kSpecs[] = {
    {.name = "resolution",
     .type = OptionType::Integer,
     .high = 32768,
     .powerOfTwo = true,
     .unit = "grid cells",
     .zeroMeans = "the rigidity map's size",
     .meaning = "Warp grid cells per side. A finer grid follows smaller rigid detail and costs more; the "
                "redirect map keeps the rigidity map's size. Twice the map's size took 1024^2 maps of rigged "
                "characters 1-7 points further, for about 4x the time (not every size and shot gains).",
     .recorded = false,
     .get = TileMember<&TileWarpOptions::cells>::get,
     .put = TileMember<&TileWarpOptions::cells>::put},
    {.name = "refinementSweeps",
     .type = OptionType::Integer,
     .low = kAutomaticRefinement,
     .high = 64,
     .zeroMeans = "none",
     .lowMeans = "by the grid's size: 4 up to 1024 cells, none from 2048",
     .meaning =
         "Sweeps of one last iteration on a grid of twice the cells, started from the solved warp, "
         "whose warp is delivered: its points follow the posed surface where it bends between the "
         "grid's points (a mesh bends at every edge). 4 sweeps took rigged characters at 1024^2 1.5-7.0 "
         "points further (rigged Spot 80.9 to 87.9% median); the shot preset runs them after a solve "
         "whose third level sweeps 64 times, at 1.34-1.37x Spot's unrefined frame; the live preset "
         "has none.",
     .get = TileMember<&TileWarpOptions::refinementSweeps>::get,
     .put = TileMember<&TileWarpOptions::refinementSweeps>::put},
    {.name = "iterations",
     .type = OptionType::Integer,
     .low = 1,
     .high = 100000,
     .meaning = "PBD iterations per solve (paper §4.1); with a tolerance, the most run.",
     .solver = true,
     .get = SolverMember<&SolverOptions::iterations>::get,
     .put = SolverMember<&SolverOptions::iterations>::put},
    {.name = "coldIterations",
     .type = OptionType::Integer,
     .high = 100000,
     .zeroMeans = "iterations",
     .meaning = "Iterations of a solve that starts from the identity: a solver's first, the first after a "
                "reset (a cut), every solve without warm start.",
     .solver = true,
     .get = SolverMember<&SolverOptions::coldIterations>::get,
     .put = SolverMember<&SolverOptions::coldIterations>::put},
    {.name = "tolerance",
     .type = OptionType::Number,
     .high = 1,
     .unit = "grid cells",
     .zeroMeans = "off",
     .meaning = "Convergence stop: a solve ends after the first iteration in which no grid point moved "
                "farther than this.",
     .solver = true,
     .get = SolverMember<&SolverOptions::tolerance>::get,
     .put = SolverMember<&SolverOptions::tolerance>::put},
    {.name = "sweepsPerLevel",
     .type = OptionType::IntegerList,
     .high = 1000,
     .zeroMeans = "by the grid's size, 4 8 16 up to 1024 cells, 4 8 16 32 64 from 2048; where a refinement "
                  "follows, the finest level 2 from 1024 cells, and 2 8 64 16 at 1024",
     .meaning = "Constraint-projection sweeps (all 8 parallel sets) per iteration at each hierarchy level, "
                "finest first; levels beyond the list use its last value.",
     .solver = true,
     .get =
         [](const TileWarpOptions& o) {
             return std::vector<double>(o.solver.sweepsPerLevel.begin(), o.solver.sweepsPerLevel.end());
         },
     .put =
         [](TileWarpOptions& o, std::span<const double> v) {
             o.solver.sweepsPerLevel.assign(v.size(), 0);
             std::transform(v.begin(), v.end(), o.solver.sweepsPerLevel.begin(),
                            [](double x) { return static_cast<int32_t>(x); });
         }},
    {.name = "levels",
     .type = OptionType::Integer,
     .high = 16,
     .zeroMeans = "automatic",
     .meaning = "Hierarchy levels, the finest included (paper §4.4). Automatic: down to an 8-cell grid, but "
                "no level whose points are farther apart than a third of the widest chart's half-width.",
     .solver = true,
     .get = SolverMember<&SolverOptions::levels>::get,
     .put = SolverMember<&SolverOptions::levels>::put},
    {.name = "maxLevels",
     .type = OptionType::Integer,
     .high = 16,
     .zeroMeans = "no cap",
     .meaning = "With automatic levels, at most this many. The live presets from 1024 cells keep the "
                "coarsest level at 128 cells: a warm-started frame follows the motion better without the "
                "coarsest levels.",
     .solver = true,
     .get = SolverMember<&SolverOptions::maxLevels>::get,
     .put = SolverMember<&SolverOptions::maxLevels>::put},
    {.name = "orientationPreservation",
     .type = OptionType::Number,
     .high = 1,
     .meaning = "How far a segment turns back towards its rest direction after projection (paper §4.2); "
                "multiplied by the orientation map.",
     .solver = true,
     .get = SolverMember<&SolverOptions::orientationPreservation>::get,
     .put = SolverMember<&SolverOptions::orientationPreservation>::put},
    {.name = "smoothing",
     .type = OptionType::Number,
     .high = 1,
     .meaning = "s in Eq. 4: how much as-rigid-as-possible points are smoothed (elastic points are "
                "smoothed fully).",
     .solver = true,
     .get = SolverMember<&SolverOptions::smoothing>::get,
     .put = SolverMember<&SolverOptions::smoothing>::put},
    {.name = "damping",
     .type = OptionType::Number,
     .high = 1,
     .meaning = "The fraction of the velocity removed each iteration (paper §4.1, step 1).",
     .solver = true,
     .get = SolverMember<&SolverOptions::damping>::get,
     .put = SolverMember<&SolverOptions::damping>::put},
    {.name = "coarseStiffness",
     .type = OptionType::Number,
     .high = 1,
     .lowOpen = true,
     .meaning = "Level l applies its corrections scaled by this to the power l (paper §4.4: coarse "
                "segments map to curves, so their corrections are applied more conservatively).",
     .solver = true,
     .get = SolverMember<&SolverOptions::coarseStiffness>::get,
     .put = SolverMember<&SolverOptions::coarseStiffness>::put},
    {.name = "coarseRelaxation",
     .type = OptionType::Number,
     .low = 1,
     .high = 2,
     .meaning = "Over-relaxation of the levels above the finest: their corrections are multiplied by it as "
                "well (1 is the paper's). The live presets use 1.4.",
     .solver = true,
     .get = SolverMember<&SolverOptions::coarseRelaxation>::get,
     .put = SolverMember<&SolverOptions::coarseRelaxation>::put},
    {.name = "maskBorderWidth",
     .type = OptionType::Integer,
     .low = 1,
     .high = 64,
     .unit = "texels",
     .meaning = "Without a mask map: the band of chart border the derived mask keeps fixed (1: the texels "
                "a border edge crosses or touches).",
     .get = [](const TileWarpOptions& o) { return std::vector<double>{double(o.derivedMask.borderWidth)}; },
     .put = [](TileWarpOptions& o,
               std::span<const double> v) { o.derivedMask.borderWidth = static_cast<int32_t>(v[0]); }},
    {.name = "seamSlide",
     .type = OptionType::Flag,
     .meaning = "Without a mask map: content next to a seam slides along it, the same way in both charts, so "
                "that rigid detail a seam cuts is undone along the seam too (seams stay continuous; open "
                "borders and seams into another tile stay fixed). It took the Fox's Run at 1024^2 from 81.2 "
                "to 83.1% median, 74.1 to 74.7% worst frame, the Walk from 87.2 to 88.6%. The live preset "
                "has none.",
     .get = [](const TileWarpOptions& o) { return std::vector<double>{o.seamSlide ? 1.0 : 0.0}; },
     .put = [](TileWarpOptions& o, std::span<const double> v) { o.seamSlide = v[0] != 0.0; }},
    {.name = "orientationDensity",
     .type = OptionType::Integer,
     .low = kAutomaticDensity,
     .high = 4096,
     .unit = "texels",
     .zeroMeans = "off",
     .lowMeans = "by the map's size: 1/16 of its texels, on grids up to 8192 cells, off on finer ones",
     .meaning =
         "Without an orientation map: orientation preservation scaled by the rigidity's local "
         "density over a window of this radius, high where rigid detail is dense and low where it is "
         "sparse (the paper's heuristic for severe compression, §6). The shot preset's window of 1/16 "
         "of the map took rigged characters at 1024^2 further where skinning squashes rigid detail (the "
         "Fox's Survey 73.3 to 79.0% worst frame, Spot bent 83.5 to 85.7%, seams fixed); the live preset has "
         "none.",
     .get = TileMember<&TileWarpOptions::orientationDensity>::get,
     .put = TileMember<&TileWarpOptions::orientationDensity>::put},
    {.name = "dilationRings",
     .type = OptionType::Integer,
     .high = 64,
     .meaning = "Rings of grid points the geometry images are extended by past chart borders, so look-ups "
                "near seams read plausible positions.",
     .get = TileMember<&TileWarpOptions::dilationRings>::get,
     .put = TileMember<&TileWarpOptions::dilationRings>::put},
    {.name = "geometryImageCells",
     .type = OptionType::Integer,
     .high = 32768,
     .powerOfTwo = true,
     .unit = "cells",
     .zeroMeans = "by the grid's size: the grid's cells up to 8192, half of them from 16384",
     .meaning =
         "Cells per side of the geometry images of the rest and posed surfaces: the grid's, or half of "
         "them (any other value is refused when the grid's size is known), which holds them in a quarter of "
         "the memory (a 16384^2 tile: 18 bytes a cell less). "
         "The surfaces are affine inside each UV triangle, where the solver's look-ups between the "
         "image's points are exact; the cells that straddle a triangle's edge cost the rigged Fox (shot "
         "preset without refinement) 3.9 points of rigid stretch removed at 512^2, 2.4 at 1024^2 and 0.8 "
         "at 2048^2, less as the grid grows.",
     .get = TileMember<&TileWarpOptions::geometryImageCells>::get,
     .put = TileMember<&TileWarpOptions::geometryImageCells>::put},
    {.name = "warmStart",
     .type = OptionType::Flag,
     .meaning = "Start each solve from the last frame's warp, as a live preview does (the paper's temporal "
                "coherence), instead of from the identity. It changes only where a solve starts, not the "
                "schedule: iterations and sweeps stay as set (a live preset sets those); a frame whose warm "
                "start jams (its fold repair spreads) is solved again from the identity. Off, a frame's "
                "maps depend on that frame alone, whatever range of frames a job covers.",
     .solver = true,
     .get = SolverMember<&SolverOptions::warmStart>::get,
     .put = SolverMember<&SolverOptions::warmStart>::put},
    {.name = "threads",
     .type = OptionType::Integer,
     .high = 4096,
     .zeroMeans = "all the caller allows, or one where measured faster",
     .meaning = "OpenMP threads of an iteration, at most those the caller allows. The warp is the same, "
                "byte for byte, whatever the count.",
     .solver = true,
     .recorded = false,
     .get = SolverMember<&SolverOptions::threads>::get,
     .put = SolverMember<&SolverOptions::threads>::put},
};

// "coarseRelaxation" -> "coarse" + separator + "relaxation".
std::string splitCamel(std::string_view name, char separator) {
    std::string out;
    for (char c : name) {
        if (c >= 'A' && c <= 'Z') {
            out += separator;
            out += static_cast<char>(c - 'A' + 'a');
        } else {
            out += c;
        }
    }
    return out;
}

// The shortest text that reads back as the float (0.05, not 0.0500000007).
std::string optionFloatText(double value) {
    char text[32];
    const auto [end, ec] = std::to_chars(text, text + sizeof(text), static_cast<float>(value));
    return ec == std::errc() ? std::string(text, end) : numberText(value);
}

// A number as a person writes it: 100000, not 1e+05.
std::string plainNumberText(double value) {
    if (value == std::floor(value) && std::abs(value) < 1e15)
        return std::to_string(static_cast<int64_t>(value));
    return numberText(value);
}

std::string optionNumberText(const OptionSpec& spec, double value) {
    return spec.type == OptionType::Number ? optionFloatText(value) : plainNumberText(value);
}

bool isPowerOfTwoValue(double v) {
    return v >= 1 && std::exp2(std::round(std::log2(v))) == v;
}

std::string shownOptionValue(const OptionValue& value) {
    if (!value.shown.empty()) return value.shown;
    switch (value.kind) {
        case OptionValue::Kind::Boolean:
            return value.numbers.empty() || value.numbers[0] == 0 ? "false" : "true";
        case OptionValue::Kind::List: {
            std::string out = "[";
            for (size_t i = 0; i < value.numbers.size(); ++i) {
                if (i > 0) out += ", ";
                out += plainNumberText(value.numbers[i]);
            }
            return out + "]";
        }
        case OptionValue::Kind::Other:
            return value.shown;
        case OptionValue::Kind::Number:
            break;
    }
    return value.numbers.empty() ? value.shown : plainNumberText(value.numbers[0]);
}

// Whether one number (an element of a list) is a valid value of `spec`.
bool validOptionNumber(const OptionSpec& spec, double given) {
    // A number option is stored as a float: its range holds for the float (1e-60 is 0 as a float, 1e39 inf),
    // so a value is refused as given, not later as what it became.
    const double v = spec.type == OptionType::Number ? static_cast<double>(static_cast<float>(given)) : given;
    if (!std::isfinite(v)) return false;
    if (spec.type != OptionType::Number && v != std::floor(v)) return false;
    if (spec.lowOpen ? !(v > spec.low) : v < spec.low) return false;
    if (v > spec.high) return false;
    return !spec.powerOfTwo || v == 0 || (v >= 2 && isPowerOfTwoValue(v));
}

bool validOptionValue(const OptionSpec& spec, const OptionValue& value) {
    switch (spec.type) {
        case OptionType::Flag:
            return value.kind == OptionValue::Kind::Boolean && value.numbers.size() == 1;
        case OptionType::IntegerList:
            // Empty: the library's choice (zeroMeans); else not all 0.
            return value.kind == OptionValue::Kind::List &&
                   std::all_of(value.numbers.begin(), value.numbers.end(),
                               [&](double v) { return validOptionNumber(spec, v); }) &&
                   (value.numbers.empty() ||
                    std::any_of(value.numbers.begin(), value.numbers.end(), [](double v) { return v > 0; }));
        case OptionType::Integer:
        case OptionType::Number:
            break;
    }
    return value.kind == OptionValue::Kind::Number && value.numbers.size() == 1 &&
           validOptionNumber(spec, value.numbers[0]);
}

OptionValue optionValueOf(const OptionSpec& spec, const TileWarpOptions& options) {
    OptionValue value;
    value.numbers = spec.get(options);
    value.kind = spec.type == OptionType::Flag          ? OptionValue::Kind::Boolean
                 : spec.type == OptionType::IntegerList ? OptionValue::Kind::List
                                                        : OptionValue::Kind::Number;
    if (spec.type == OptionType::Number) value.shown = optionFloatText(value.numbers.front());  // a float32
    return value;
}

void checkOptionValue(const OptionSpec& spec, const OptionValue& value, std::string_view source,
                      std::string_view element) {
    if (!validOptionValue(spec, value))
        throw InvalidInput(
            formatError(source, element, "is " + shownOptionValue(value), expectedValue(spec)));
}

void checkEveryOption(const TileWarpOptions& options, std::string_view source, bool solverOnly) {
    for (const OptionSpec& spec : optionSpecs()) {
        if (!solverOnly || spec.solver)
            checkOptionValue(spec, optionValueOf(spec, options), source, "option " + std::string(spec.name));
    }
}

std::string optionDefaultText(const OptionSpec& spec) {
    const auto shown = [&](const TileWarpOptions& o) {
        const std::vector<double> v = spec.get(o);
        return spec.type == OptionType::IntegerList && v.empty() ? std::string("empty") : valueText(spec, v);
    };
    const std::string library = shown(TileWarpOptions{});
    const std::string shot = shown(shotOptions());
    std::string text = library;
    if (shot != library) text += "; in a shot: " + shot;
    return text;
}

}  // namespace

std::span<const OptionSpec> optionSpecs() {
    return kSpecs;
}

const OptionSpec* findOption(std::string_view name) {
    for (const OptionSpec& spec : kSpecs) {
        if (spec.name == name) return &spec;
    }
    return nullptr;
}

std::string cliName(const OptionSpec& spec) {
    return "--" + splitCamel(spec.name, '-');
}

std::string pythonName(const OptionSpec& spec) {
    return splitCamel(spec.name, '_');
}

std::string expectedValue(const OptionSpec& spec) {
    const auto number = [&](double v) { return optionNumberText(spec, v); };
    const std::string unit = spec.unit.empty() ? "" : ", " + std::string(spec.unit);
    if (!spec.lowMeans.empty()) {  // a whole number from 0 with one special value below it
        return "a whole number from 0" +
               (spec.zeroMeans.empty() ? "" : " (" + std::string(spec.zeroMeans) + ")") + " to " +
               number(spec.high) + unit + ", or " + number(spec.low) + " (" + std::string(spec.lowMeans) +
               ")";
    }
    std::string low = number(spec.low);
    if (spec.low == 0 && !spec.zeroMeans.empty()) low += " (" + std::string(spec.zeroMeans) + ")";
    switch (spec.type) {
        case OptionType::Flag:
            return "true or false";
        case OptionType::IntegerList:
            return "a list of whole numbers from " + number(spec.low) + " to " + number(spec.high) +
                   ", not all 0; empty: " + std::string(spec.zeroMeans);
        case OptionType::Integer:
            if (spec.powerOfTwo) return low + " or a power of two from 2 to " + number(spec.high) + unit;
            return "a whole number from " + low + " to " + number(spec.high) + unit;
        case OptionType::Number:
            break;
    }
    if (spec.lowOpen) return "a number in (" + low + ", " + number(spec.high) + "]" + unit;
    return "a number from " + low + " to " + number(spec.high) + unit;
}

std::string valueText(const OptionSpec& spec, std::span<const double> values) {
    if (spec.type == OptionType::Flag) return !values.empty() && values[0] != 0 ? "true" : "false";
    std::string out;
    for (size_t i = 0; i < values.size(); ++i) {
        if (i > 0) out += ' ';
        out += optionNumberText(spec, values[i]);
    }
    return out;
}

void setOption(TileWarpOptions& options, const OptionSpec& spec, const OptionValue& value,
               std::string_view source, std::string_view element) {
    checkOptionValue(spec, value, source, element);
    spec.put(options, value.numbers);
}

void checkOptions(const TileWarpOptions& options, std::string_view source) {
    checkEveryOption(options, source, false);
}

void checkOptions(const SolverOptions& options, std::string_view source) {
    TileWarpOptions all;
    all.solver = options;
    checkEveryOption(all, source, true);
}

std::string_view presetName(Preset preset) {
    return preset == Preset::Live ? "live" : "shot";
}

Preset presetNamed(std::string_view name, std::string_view source, std::string_view element) {
    if (name == "shot") return Preset::Shot;
    if (name == "live") return Preset::Live;
    throw InvalidInput(formatError(source, element, "is '" + std::string(name) + "'", "shot or live"));
}

TileWarpOptions presetOptions(Preset preset, int32_t cells) {
    TileWarpOptions options = shotOptions();
    if (preset == Preset::Live) {
        options.solver = liveOptions(cells);
        options.refinementSweeps = 0;    // a live frame's budget has no room for a grid of twice the cells
        options.orientationDensity = 0;  // nor its memory for the orientation fields (UV-40)
        options.seamSlide = false;       // measured: median up, worst frame down (UV-42)
    }
    options.cells = cells;
    return options;
}

TileWarpOptions withPreset(Preset preset, int32_t cells, const TileWarpOptions& options,
                           std::span<const std::string> own) {
    TileWarpOptions out = presetOptions(preset, cells);
    for (const std::string& name : own) {
        const OptionSpec* spec = findOption(name);
        if (spec == nullptr)
            throw InvalidInput(
                formatError("preset", "option '" + name + "'", "is not an option", "a UV-warp option"));
        spec->put(out, spec->get(options));
    }
    return out;
}

std::string optionReference(bool markdown) {
    std::string out;
    if (markdown) {
        out += "| option (scenes, Maya, shot header) | CLI | Python | default | values | meaning |\n";
        out += "| --- | --- | --- | --- | --- | --- |\n";
    }
    for (const OptionSpec& spec : kSpecs) {
        if (markdown) {
            out += "| `" + std::string(spec.name) + "` | `" + cliName(spec) + "` | `" + pythonName(spec) +
                   "` | " + optionDefaultText(spec) + " | " + expectedValue(spec) + " | " +
                   std::string(spec.meaning) + " |\n";
        } else {
            out += std::string(spec.name) + " (CLI " + cliName(spec) + ", Python " + pythonName(spec) +
                   "): " + expectedValue(spec) + "; default " + optionDefaultText(spec) + "\n    " +
                   std::string(spec.meaning) + "\n";
        }
    }
    return out;
}

}  // namespace deformkit::uvwarp
