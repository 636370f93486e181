#include "cli.h"

#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>

#include "deformkit/error.h"
#include "deformkit/version.h"

namespace deformkit::harness {

Option& Option::required() {
    option_->required();
    return *this;
}

Option& Option::showDefault() {
    option_->capture_default_str();
    return *this;
}

Option& Option::choices(std::vector<std::string> values) {
    option_->check(CLI::IsMember(std::move(values)));
    return *this;
}

Option& Option::range(double lo, double hi) {
    // CLI11's Range prints its bounds with six decimals ("1.000000 to 65536.000000"): this says them as
    // written.
    const auto text = [](double v) {
        char buffer[32];
        std::snprintf(buffer, sizeof buffer, "%g", v);
        return std::string(buffer);
    };
    const std::string expected = "a number from " + text(lo) + " to " + text(hi);
    option_->check(CLI::Validator(
        [lo, hi, expected](std::string& value) -> std::string {
            double number = 0.0;
            if (!CLI::detail::lexical_cast(value, number))
                return "is '" + value + "' (expected " + expected + ")";
            if (!(number >= lo && number <= hi)) return "is " + value + " (expected " + expected + ")";
            return {};
        },
        "[" + text(lo) + ", " + text(hi) + "]"));
    return *this;
}

Option& Option::nonNegative() {
    option_->check(CLI::NonNegativeNumber);
    return *this;
}

Option& Option::positive() {
    // CLI11's PositiveNumber reports a range up to the largest double ("[4.9e-324 - 1.8e+308]"): this says
    // what is expected in words.
    option_->check(CLI::Validator(
        [](std::string& text) -> std::string {
            double value = 0.0;
            if (!CLI::detail::lexical_cast(text, value)) return "is '" + text + "' (expected a number)";
            if (!(value > 0.0)) return "is " + text + " (expected a number > 0)";
            return {};
        },
        "> 0"));
    return *this;
}

Option& Option::needs(const Option& other) {
    option_->needs(other.option_);
    return *this;
}

bool Option::given() const {
    return option_->count() > 0;
}

Option& Option::typeName(const std::string& name) {
    option_->type_name(name);
    return *this;
}

// Text and path options: an empty value names nothing (no file, no value), and the command would fail later
// with a message that names nothing; refused as a usage error naming the option. (CLI11 runs no validator
// on an empty value.)
namespace {

template <class Target>
CLI::Option* nonEmptyOption(CLI::App& app, const std::string& name, Target& target, const std::string& help) {
    CLI::Option* option = app.add_option_function<std::string>(
        name,
        [&target, name](const std::string& value) {
            if (value.empty()) throw CLI::ValidationError(name, "is empty (expected a value)");
            target = value;
        },
        help);
    if constexpr (std::is_same_v<Target, std::filesystem::path>) {
        option->default_str(target.string());
    } else {
        option->default_str(target);
    }
    return option;
}

}  // namespace

Option Command::option(const std::string& name, std::string& target, const std::string& help) {
    return Option(nonEmptyOption(*app_, name, target, help));
}

Option Command::option(const std::string& name, std::filesystem::path& target, const std::string& help) {
    return Option(nonEmptyOption(*app_, name, target, help));
}

Option Command::option(const std::string& name, int32_t& target, const std::string& help) {
    return Option(app_->add_option(name, target, help));
}

Option Command::option(const std::string& name, double& target, const std::string& help) {
    return Option(app_->add_option(name, target, help));
}

Option Command::option(const std::string& name, float& target, const std::string& help) {
    return Option(app_->add_option(name, target, help));
}

Option Command::option(const std::string& name, std::vector<int32_t>& target, const std::string& help) {
    return Option(app_->add_option(name, target, help));
}

Option Command::option(const std::string& name, std::vector<std::string>& target, const std::string& help) {
    return Option(app_->add_option(name, target, help));
}

Option Command::option(const std::string& name, std::vector<double>& target, const std::string& help) {
    return Option(app_->add_option(name, target, help));
}

Option Command::option(const std::string& name, std::function<void(const std::string& value)> parse,
                       const std::string& shownDefault, const std::string& help) {
    CLI::Option* option = app_->add_option_function<std::string>(name, std::move(parse), help);
    option->default_str(shownDefault);
    return Option(option);
}

Option Command::listOption(const std::string& name,
                           std::function<void(const std::vector<std::string>& values)> parse,
                           const std::string& shownDefault, const std::string& help) {
    CLI::Option* option = app_->add_option_function<std::vector<std::string>>(name, std::move(parse), help);
    option->default_str(shownDefault);
    return Option(option);
}

void Command::listing(const std::string& name, const std::string& fallback, const std::string& help,
                      std::function<void(const std::string& value)> print) {
    app_->add_option_function<std::string>(
            name,
            [print = std::move(print)](const std::string& value) {
                print(value);
                throw CLI::Success();
            },
            help)
        ->expected(0, 1)
        ->trigger_on_parse()
        ->default_str(fallback);
}

Option Command::flag(const std::string& name, bool& target, const std::string& help) {
    return Option(app_->add_flag(name, target, help));
}

CommandLine::CommandLine()
    : app_(std::make_unique<CLI::App>("DeformKit: production deformers (slide, warps, content-aware UV warp)",
                                      "deformkit")) {
    app_->set_version_flag("--version", std::string("deformkit ") + kVersionString);
    app_->require_subcommand(1);
}

CommandLine::~CommandLine() = default;

Command CommandLine::add(const std::string& name, const std::string& description, std::function<int()> run) {
    Command root(app_.get());
    return add(root, name, description, std::move(run));
}

Command CommandLine::add(Command& group, const std::string& name, const std::string& description,
                         std::function<int()> run) {
    CLI::App* command = group.app_->add_subcommand(name, description);
    commands_.emplace_back(command, std::move(run));
    return Command(command);
}

Command CommandLine::group(const std::string& name, const std::string& description) {
    CLI::App* group = app_->add_subcommand(name, description);
    group->require_subcommand(1);
    return Command(group);
}

namespace {

// "'nosuch' is not a command (expected one of: info, preview, ...)" when a word that names no subcommand
// stands where one is required (CLI11 says only "A subcommand is required"); the deepest command that
// was parsed names its own subcommands ("deformkit farm nosuch").
std::optional<std::string> unknownCommand(const CLI::App& app) {
    for (const CLI::App* sub : app.get_subcommands({})) {
        if (sub->parsed()) return unknownCommand(*sub);
    }
    const std::vector<std::string> left = app.remaining();
    const std::vector<const CLI::App*> subs = app.get_subcommands({});
    if (left.empty() || subs.empty() || left.front().starts_with("-")) return std::nullopt;
    std::string names;
    for (const CLI::App* sub : subs)
        names += (names.empty() ? "" : ", ") + sub->get_name();
    const std::string where = app.get_parent() ? "a " + app.get_name() + " command" : "a command";
    return "'" + left.front() + "' is not " + where + " (expected one of: " + names + ")";
}

// `code`, or 1 when standard output could not be written (a full disk under a redirect): what a command
// prints there is its result or, for a farm task, its log. An exit code that already reports an error stays.
int checkedStdout(int code) {
    std::cout.flush();
    const bool written = std::cout.good() && std::fflush(stdout) == 0 && std::ferror(stdout) == 0;
    if (written || code != 0) return code;
    std::cerr << "deformkit: error: standard output: cannot write (expected a writable standard output)\n";
    return 1;
}

}  // namespace

int CommandLine::run(int argc, char** argv) {
    try {
        app_->parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // Help and version print and exit 0; a usage error is one line on stderr and exit code 2.
        if (e.get_exit_code() == 0) return checkedStdout(app_->exit(e));
        std::cerr << "deformkit: usage error: " << unknownCommand(*app_).value_or(e.what())
                  << " (see deformkit --help)\n";
        return 2;
    } catch (const Error& e) {  // from an option that acts as it is parsed (listing)
        std::cerr << "deformkit: error: " << e.what() << "\n";
        return 2;
    }
    try {
        for (const auto& [command, run] : commands_) {
            if (command->parsed()) return checkedStdout(run());
        }
    } catch (const StorageError& e) {
        // Storage that failed while writing (a full disk): not the input's fault, exit 1 as for anything a
        // retry may cure (docs/farm.md, Exit codes).
        std::cerr << "deformkit: error: " << e.what() << "\n";
        return 1;
    } catch (const Error& e) {
        std::cerr << "deformkit: error: " << e.what() << "\n";
        return 2;
    } catch (const OutOfMemory& e) {
        std::cerr << "deformkit: error: " << e.what() << "\n";  // names the input
        return 1;
    } catch (const std::bad_alloc&) {
        // Exit 1, as for anything a retry on a larger machine may cure (docs/farm.md, Exit codes).
        std::cerr
            << "deformkit: error: out of memory (expected a task this machine's memory holds: fewer frames, "
               "vertices or texels at a time)\n";
        return 1;
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
    addReportCommand(cli);
    addPtexCommands(cli);
    addDeformersCommand(cli);
}

}  // namespace deformkit::harness
