// deformkit: the standalone host. Exit codes: 0 success, 2 bad input or usage (one line on stderr),
// 1 internal error.
#include <CLI/CLI.hpp>

#include <iostream>

#include "deformkit/error.h"
#include "deformkit/version.h"

int main(int argc, char** argv) {
    CLI::App app{"DeformKit: production deformers (slide, warps, content-aware UV warp)", "deformkit"};
    app.set_version_flag("--version", std::string("deformkit ") + deformkit::kVersionString);
    app.require_subcommand(1);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    return 0;
}
