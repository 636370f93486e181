#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/uvwarp/tile_warp.h"

namespace deformkit::uvwarp {

// The UV warp's options (TileWarpOptions, with its SolverOptions and DerivedMaskOptions), declared once:
// each with one name, its type, range, default and meaning. Every interface is made from this table, under
// the same name in its own case:
//   scenes' "params", the Maya node's attributes and the shot header's JSON   camelCase   coarseRelaxation
//   the CLI (`deformkit uvwarp`)                                             kebab-case  --coarse-relaxation
//   Python keyword options                                                   snake_case  coarse_relaxation
// and the parameter table of docs/uvwarp.md is generated from it (`deformkit uvwarp --list-options
// markdown`). Only setOption and checkOptions validate a value, so every interface refuses a bad one with
// the same message, naming the option as that interface spells it.

enum class OptionType {
    Integer,      // a whole number
    Number,       // a real number, kept as float32
    Flag,         // true or false
    IntegerList,  // a list of whole numbers, not all 0; empty: the library's choice (zeroMeans)
};

struct OptionSpec {
    std::string_view name = {};  // camelCase
    OptionType type = OptionType::Number;
    // The range of the value (of each element of a list), inclusive; (low, high] when lowOpen.
    double low = 0.0;
    double high = 0.0;
    bool lowOpen = false;
    bool powerOfTwo = false;          // a value other than 0 must be a power of two (the grid resolution)
    std::string_view unit = {};       // "grid cells", "texels", or empty for a count or a fraction
    std::string_view zeroMeans = {};  // what 0 stands for where it is special ("automatic"), or empty
    // What `low` stands for when it is a value below the range (-1: "by the grid's size"), or empty: the
    // range then starts at 0 and `low` is named apart from it.
    std::string_view lowMeans = {};
    std::string_view meaning = {};  // one or two sentences: help texts and the reference are made from it
    bool solver = false;            // a SolverOptions member, checked by the Solver's constructor as well
    // Written to the shot header (deformkit:uvwarp:solver). False for an option that never changes a
    // result (threads) or whose value in use the header records otherwise (the resolution, as "cells").
    bool recorded = true;
    // Reads and writes the option in a TileWarpOptions; `put` writes without checking (setOption checks).
    std::vector<double> (*get)(const TileWarpOptions&) = nullptr;
    void (*put)(TileWarpOptions&, std::span<const double>) = nullptr;
};

// Every option, in the order of the reference: the grid and the schedule first, then the solver's
// weights, the maps, and how frames and threads run.
[[nodiscard]] std::span<const OptionSpec> optionSpecs();
// The option called `name` (camelCase), or nullptr.
[[nodiscard]] const OptionSpec* findOption(std::string_view name);

// The option's name in each interface: "--coarse-relaxation" (CLI), "coarse_relaxation" (Python).
[[nodiscard]] std::string cliName(const OptionSpec& spec);
[[nodiscard]] std::string pythonName(const OptionSpec& spec);
// What a value must be, for messages and help: "a whole number from 1 to 100000".
[[nodiscard]] std::string expectedValue(const OptionSpec& spec);
// A value as text: "4", "0.05", "true", "4 8 8" (a list).
[[nodiscard]] std::string valueText(const OptionSpec& spec, std::span<const double> values);

// A value as an interface read it, before it is checked.
struct OptionValue {
    enum class Kind {
        Number,   // one number
        Boolean,  // numbers holds 0 or 1
        List,     // numbers holds the elements
        Other,    // anything else: a string, an object; `shown` says what
    };
    Kind kind = Kind::Number;
    std::vector<double> numbers;
    std::string shown;  // how messages show the value, when set; an Other value sets it ("a string")
};

// Sets the option `spec` of `options` to `value` after checking its type and range. Throws InvalidInput
// "<source>: <element>: is <value> (expected <expectedValue>)"; `element` is how the caller's interface
// names the option ("--coarse-relaxation", "uvwarp.params.coarseRelaxation", "coarse_relaxation").
void setOption(TileWarpOptions& options, const OptionSpec& spec, const OptionValue& value,
               std::string_view source, std::string_view element);

// Checks every option of `options` as setOption does, naming it "option <name>". TileWarp's constructor
// calls it.
void checkOptions(const TileWarpOptions& options, std::string_view source);
// The same for the solver's options only (Solver's constructor).
void checkOptions(const SolverOptions& options, std::string_view source);

// The library's presets: every option's value for a use, by name in every interface (`--preset live`,
// "preset": "live", preset="live", the Maya node's preset attribute).
//   shot  the default schedule (4 iterations, sweeps by the grid's size), each frame from the identity,
//         refined by the grid's size: what a shot written as files runs (shotOptions()).
//   live  one warm-started iteration a frame, for a live preview, unrefined: liveOptions(cells), whose
//         schedule depends on the grid's size.
// The shot preset scales orientation preservation by the density of rigid detail (orientationDensity by the
// map's size); the live preset keeps it uniform (its orientation fields would cost a warm-started solver 5
// bytes a texel more, UV-40).
enum class Preset { Shot, Live };
[[nodiscard]] std::string_view presetName(Preset preset);
// "shot" or "live"; InvalidInput "<source>: <element>: is '<name>' (expected shot or live)" otherwise.
[[nodiscard]] Preset presetNamed(std::string_view name, std::string_view source, std::string_view element);
// Every option of `preset` for a grid of `cells` cells per side (options.cells is `cells`).
[[nodiscard]] TileWarpOptions presetOptions(Preset preset, int32_t cells);
// `preset`'s options for a grid of `cells`, but for the options named in `own` (camelCase), which keep their
// values from `options`: what a caller who chose a preset and set some options itself gets. Throws
// InvalidInput for a name that is not an option.
[[nodiscard]] TileWarpOptions withPreset(Preset preset, int32_t cells, const TileWarpOptions& options,
                                         std::span<const std::string> own);

// The reference of every option: one paragraph each for a terminal, or the Markdown table of
// docs/uvwarp.md (its default column shows the library's default and, where a shot starts from another,
// shotOptions()'s).
[[nodiscard]] std::string optionReference(bool markdown);

}  // namespace deformkit::uvwarp
