#include "cli.h"

#include <exception>
#include <iostream>

#include "deformkit/error.h"

namespace deformkit::harness {

CLI::App* CommandLine::add(CLI::App& parent, const std::string& name, const std::string& description,
                           std::function<int()> run) {
    CLI::App* command = parent.add_subcommand(name, description);
    commands_.emplace_back(command, std::move(run));
    return command;
}

int CommandLine::run(int argc, char** argv) {
    try {
        app_.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // Help and version print and exit 0; a usage error is one line on stderr and exit code 2.
        if (e.get_exit_code() == 0) return app_.exit(e);
        std::cerr << "deformkit: usage error: " << e.what() << " (see deformkit --help)\n";
        return 2;
    }
    try {
        for (const auto& [command, run] : commands_) {
            if (command->parsed()) return run();
        }
    } catch (const Error& e) {
        std::cerr << "deformkit: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "deformkit: internal error: " << e.what() << "\n";
        return 1;
    }
    return 0;
}

void addCommands(CommandLine& cli) {
    addInfoCommand(cli);
    addPreviewCommand(cli);
    addDemoCommand(cli);
    addEvalCommand(cli);
    addFarmCommands(cli);
    addWarpCommand(cli);
    addSlideCommand(cli);
    addUvWarpCommand(cli);
    addPtexCommands(cli);
    addDeformersCommand(cli);
}

}  // namespace deformkit::harness
