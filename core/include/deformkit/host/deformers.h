#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "deformkit/host/deformer.h"

namespace deformkit::host {

// The built-in deformers: host adapters over the core's deformers, by type name. Each holds no deformation
// code: bind builds the core object from the bind-time parameters and binds it to the rest mesh; evaluation
// pushes changed controls into it and runs its evaluation path. Positions, lengths and handle vectors are
// in scene units (world space of the mesh), angles in radians, flags and enumerations whole numbers.
//
// Each type's parameters are declared once, in its source (core/src/host/deformers/), with their meaning;
// `deformkit deformers` prints them and docs/deformers.md is made from that output.
struct DeformerType {
    std::string_view name;     // "ffd"
    std::string_view summary;  // what the type does, for the parameter reference
    std::unique_ptr<Deformer> (*make)(std::string label);
};

// The built-in types in alphabetical order of name.
[[nodiscard]] std::span<const DeformerType> deformerTypes();

// A new, unbound deformer of `type` with default parameters. Throws InvalidInput for an unknown type
// (listing the known ones) or an empty label.
[[nodiscard]] std::unique_ptr<Deformer> makeDeformer(std::string_view type, const std::string& label);

}  // namespace deformkit::host
