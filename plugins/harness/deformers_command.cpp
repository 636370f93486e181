// `deformkit deformers [--markdown]`: the parameter reference of every deformer type, made from the
// parameters' declarations (host/parameter_reference.h); docs/deformers.md holds its Markdown form.
#include <iostream>

#include "cli.h"
#include "deformkit/host/parameter_reference.h"

namespace deformkit::harness {

void addDeformersCommand(CommandLine& cli) {
    auto markdown = std::make_shared<bool>(false);
    Command deformers = cli.add(
        "deformers", "List every deformer type with its parameters (the parameter reference)", [markdown] {
            std::cout << host::parameterReference(*markdown ? host::ReferenceFormat::Markdown
                                                            : host::ReferenceFormat::Text);
            return 0;
        });
    deformers.flag("--markdown", *markdown, "as the Markdown of docs/deformers.md");
}

}  // namespace deformkit::harness
