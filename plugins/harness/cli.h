#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

// The deformkit command line. Each command's source declares its subcommand (options, and what to run) in
// one add*Command function through the small interface below; cli.cpp is the one source that compiles
// CLI11, whose templates cost seconds of compile time in every source that uses them.
namespace deformkit::harness {

// An option being declared; each modifier returns it.
class Option {
  public:
    explicit Option(CLI::Option* option) : option_(option) {}
    Option& required();
    Option& showDefault();  // the bound variable's value now, shown in --help
    Option& choices(std::vector<std::string> values);
    Option& range(double lo, double hi);
    Option& nonNegative();
    Option& positive();
    Option& needs(const Option& other);
    Option& typeName(const std::string& name);  // what --help shows for the value: INT, FLOAT, FILE...
    [[nodiscard]] bool given() const;           // after parsing: the command line gave it

  private:
    CLI::Option* option_;
};

// A subcommand, or a group of subcommands (`farm`, `ptex`), being declared. An option is bound to a
// variable that must outlive the command line; NAME (upper case) is positional, --name named.
class Command {
  public:
    explicit Command(CLI::App* app) : app_(app) {}
    Option option(const std::string& name, std::string& target, const std::string& help);
    Option option(const std::string& name, std::filesystem::path& target, const std::string& help);
    Option option(const std::string& name, int32_t& target, const std::string& help);
    Option option(const std::string& name, double& target, const std::string& help);
    Option option(const std::string& name, float& target, const std::string& help);
    Option option(const std::string& name, std::vector<int32_t>& target, const std::string& help);
    Option option(const std::string& name, std::vector<double>& target, const std::string& help);
    Option option(const std::string& name, std::vector<std::string>& target, const std::string& help);
    Option flag(const std::string& name, bool& target, const std::string& help);
    // An option whose value `parse` reads as soon as it is given (a deformkit::Error it throws is a usage
    // error, exit 2); `shownDefault` is what --help shows when it is not given.
    Option option(const std::string& name, std::function<void(const std::string& value)> parse,
                  const std::string& shownDefault, const std::string& help);
    // A list option: `parse` reads its values as given, one or more ("1 1 10", "1,1,10"), with every item
    // there (an empty item between commas is the parser's to refuse, not dropped).
    Option listOption(const std::string& name,
                      std::function<void(const std::vector<std::string>& values)> parse,
                      const std::string& shownDefault, const std::string& help);
    // An option that, as soon as it is parsed, calls `print` with its value (`fallback` when none is given)
    // and ends the program with exit code 0, as --help does: the command's other options, required ones
    // included, are not needed then.
    void listing(const std::string& name, const std::string& fallback, const std::string& help,
                 std::function<void(const std::string& value)> print);

  private:
    friend class CommandLine;
    CLI::App* app_;
};

class CommandLine {
  public:
    CommandLine();
    ~CommandLine();
    CommandLine(const CommandLine&) = delete;
    CommandLine& operator=(const CommandLine&) = delete;

    // A subcommand of deformkit, or of `group`; `run` is called when the user chose it, after parsing, and
    // returns the exit code.
    Command add(const std::string& name, const std::string& description, std::function<int()> run);
    Command add(Command& group, const std::string& name, const std::string& description,
                std::function<int()> run);
    // A group of subcommands, one of which must be given.
    Command group(const std::string& name, const std::string& description);
    // Parses and runs the chosen command. Exit codes: 0 success; 2 a usage error or deformkit::Error (bad
    // input), with one line on stderr; 1 any other failure.
    int run(int argc, char** argv);

  private:
    std::unique_ptr<CLI::App> app_;
    std::vector<std::pair<CLI::App*, std::function<int()>>> commands_;
};

// Every subcommand, in the order of `deformkit --help`.
void addCommands(CommandLine& cli);

// One per command source.
void addInfoCommand(CommandLine& cli);       // info_command.cpp
void addPreviewCommand(CommandLine& cli);    // preview_command.cpp
void addDemoCommand(CommandLine& cli);       // demo_command.cpp
void addEvalCommand(CommandLine& cli);       // eval_command.cpp
void addFarmCommands(CommandLine& cli);      // farm_command.cpp: farm plan, run, submit, report
void addReportCommand(CommandLine& cli);     // report_command.cpp
void addWarpCommand(CommandLine& cli);       // warp_command.cpp
void addSlideCommand(CommandLine& cli);      // slide_command.cpp
void addUvWarpCommand(CommandLine& cli);     // uvwarp_command.cpp
void addPtexCommands(CommandLine& cli);      // ptex_command.cpp: ptex info, to-vertex, to-udim, ...
void addDeformersCommand(CommandLine& cli);  // deformers_command.cpp

}  // namespace deformkit::harness
