// deformkit: the standalone host. Exit codes: 0 success; 2 bad input or usage, with one line on stderr;
// 1 internal error.
#include <string>

#include "cli.h"
#include "deformkit/version.h"

int main(int argc, char** argv) {
    CLI::App app{"DeformKit: production deformers (slide, warps, content-aware UV warp)", "deformkit"};
    app.set_version_flag("--version", std::string("deformkit ") + deformkit::kVersionString);
    app.require_subcommand(1);
    deformkit::harness::CommandLine cli(app);
    deformkit::harness::addCommands(cli);
    return cli.run(argc, argv);
}
