#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

// The deformkit command line: each command's source registers its subcommand (options and what to run)
// through one add*Command function; main() only builds the app and runs it.
namespace deformkit::harness {

class CommandLine {
  public:
    explicit CommandLine(CLI::App& app) : app_(app) {}

    [[nodiscard]] CLI::App& app() { return app_; }
    // A subcommand of `parent` (the app, or a group such as `farm`); `run` is called when the user chose it,
    // after parsing, and returns the exit code.
    CLI::App* add(CLI::App& parent, const std::string& name, const std::string& description,
                  std::function<int()> run);
    // Parses and runs the chosen command. Exit codes: 0 success; 2 a usage error or deformkit::Error (bad
    // input), with one line on stderr; 1 any other failure.
    int run(int argc, char** argv);

  private:
    CLI::App& app_;
    std::vector<std::pair<CLI::App*, std::function<int()>>> commands_;
};

// Every subcommand, in the order of `deformkit --help`.
void addCommands(CommandLine& cli);

// One per command source.
void addInfoCommand(CommandLine& cli);       // info_command.cpp
void addPreviewCommand(CommandLine& cli);    // preview_command.cpp
void addDemoCommand(CommandLine& cli);       // demo_command.cpp
void addEvalCommand(CommandLine& cli);       // eval_command.cpp
void addFarmCommands(CommandLine& cli);      // farm_command.cpp: farm plan, run, submit
void addWarpCommand(CommandLine& cli);       // warp_command.cpp
void addSlideCommand(CommandLine& cli);      // slide_command.cpp
void addUvWarpCommand(CommandLine& cli);     // uvwarp_command.cpp
void addPtexCommands(CommandLine& cli);      // ptex_command.cpp: ptex info, to-vertex, to-udim, ...
void addDeformersCommand(CommandLine& cli);  // deformers_command.cpp

}  // namespace deformkit::harness
