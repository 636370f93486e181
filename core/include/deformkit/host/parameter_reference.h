#pragma once

#include <string>

namespace deformkit::host {

enum class ReferenceFormat {
    Text,      // for a terminal (`deformkit deformers`)
    Markdown,  // docs/deformers.md holds this text, checked by a test
};

// The parameter reference of every built-in deformer type (deformers.h), made from the declarations: each
// type's summary, then per parameter its name, [bind] when a change rebinds, how many values it takes, its
// default and its description.
[[nodiscard]] std::string parameterReference(ReferenceFormat format);

}  // namespace deformkit::host
