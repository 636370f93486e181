#pragma once

#include <filesystem>
#include <string>
#include <vector>

// Running other programs from the CLI (Slurm's sbatch, ffmpeg): the one place that quotes for a shell, looks
// programs up on PATH and runs them.
namespace deformkit::harness {

// `text` single-quoted for the POSIX shell: nothing inside is expanded; a quote becomes '\''.
[[nodiscard]] std::string shellQuote(const std::string& text);

// The program `name` resolves to: itself when it holds a '/' and is executable, else the first executable
// file of that name on PATH; empty when there is none.
[[nodiscard]] std::filesystem::path findProgram(const std::string& name);

struct ProgramResult {
    int status = 0;  // exit status, or 128 + signal
    std::string out, err;
};

// Runs `program` with `args` (no shell) and collects its standard output and error (short outputs: they are
// read one after the other). Throws Error naming the program when it cannot be started.
ProgramResult runProgram(const std::filesystem::path& program, const std::vector<std::string>& args);

// `text` without leading and trailing white space.
[[nodiscard]] std::string trim(std::string text);

}  // namespace deformkit::harness
