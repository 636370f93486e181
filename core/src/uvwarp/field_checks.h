#pragma once

// The check of a point field's size that the solver and the metrics share.

#include <cstddef>
#include <string>

#include "deformkit/error.h"
#include "deformkit/uvwarp/grid.h"

namespace deformkit::uvwarp::detail {

// A field of `channels` values per point on the (cells + 1)^2 grid points; InvalidInput naming `source` and
// the field (`name`) otherwise.
inline void requireField(const PointField& field, int32_t cells, int32_t channels, const std::string& source,
                         const char* name) {
    if (field.cells != cells || field.channels != channels ||
        field.values.size() != static_cast<size_t>(cells + 1) * (cells + 1) * channels) {
        throw InvalidInput(formatError(source, name,
                                       std::to_string(field.cells) + " cells x " +
                                           std::to_string(field.channels) + " channels, " +
                                           std::to_string(field.values.size()) + " values",
                                       std::to_string(cells) + " cells x " + std::to_string(channels) +
                                           " channels on the (n + 1)^2 grid points"));
    }
}

}  // namespace deformkit::uvwarp::detail
