#pragma once

// Size checks the warp framework's entry points share, with the message every one of them gives.

#include <cstddef>
#include <string>

#include "deformkit/error.h"

namespace deformkit::warp::detail {

// "<source>: <what>: has <got> entries (expected <expected> entries)".
inline void requireCount(const char* source, const char* what, size_t got, size_t expected) {
    if (got != expected) {
        throw InvalidInput(formatError(source, what, "has " + std::to_string(got) + " entries",
                                       std::to_string(expected) + " entries"));
    }
}

}  // namespace deformkit::warp::detail
