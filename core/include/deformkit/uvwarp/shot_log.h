#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace deformkit::uvwarp {

// The JSON-lines logs of UV-warp shots read back: what `deformkit uvwarp --log`, ShotJob::log, `eval
// --report` and every `farm run` task write (one line per object, tile and frame; a farm mesh task one per
// frame). Logs are merged in any order and a broken or partial log is reported, never thrown: a line that
// is not a JSON object of the expected keys (a truncated last line, an error message a farm wrote into the
// same file) becomes a problem naming its file and line, and reading goes on.

// One line of a log.
struct ShotLogLine {
    std::string file;         // the log it came from, as named to the reader
    int64_t line = 0;         // from 1
    std::optional<int> task;  // a farm task's index
    std::string object;       // a scene's object; empty for `deformkit uvwarp`
    std::optional<int> tile;  // none: a farm mesh task's line (no UV warp)
    int frame = 0;
    std::string status;                     // written, replayed, skipped, unwarped, warm-up
    std::string redirect, bake;             // the outputs, as the job named them
    std::map<std::string, double> metrics;  // counts and numbers; flags as 0 or 1
    double seconds = std::numeric_limits<double>::quiet_NaN();  // the frame's total
};

struct ShotLogProblem {
    std::string file;
    int64_t line = 0;  // 0: the whole file (missing, unreadable)
    std::string message;
};

struct ShotLog {
    std::vector<ShotLogLine> lines;  // in the order read
    std::vector<ShotLogProblem> problems;
};

// Appends the lines of `in` to `log`; `file` names it in lines and problems. Blank lines are skipped.
void readShotLog(std::istream& in, const std::string& file, ShotLog& log);
// Reads a log file; a missing or unreadable one is a problem.
void readShotLogFile(const std::filesystem::path& path, ShotLog& log);

// Opens `path` for appending a shot's log lines (`deformkit uvwarp --log`, Python's log=), its folder made
// when missing, as the shot's outputs' are; a log that ends inside a line (its writer killed) gets a line end
// first. Throws IoError naming the file when it cannot be opened.
void openShotLog(const std::filesystem::path& path, std::ofstream& file);

// One frame of an object's tile as the logs tell it.
struct ShotFrame {
    int frame = 0;
    // The line telling the frame's outcome: the last `written` line read for it, else the last line.
    const ShotLogLine* line = nullptr;
    [[nodiscard]] bool written() const { return line->status == "written"; }
    // A figure of a written frame; NaN when the line does not carry it.
    [[nodiscard]] double figure(const std::string& name) const;
};

struct ShotTileSeries {
    std::string object;
    int tile = 0;
    std::vector<ShotFrame> frames;  // ascending, each once; warm-up lines left out
    // The written frame that removes the least rigid stretch (rigid_stretch_removed; ties: the most
    // inverted triangles, then the earliest); none when no frame was written.
    std::optional<size_t> worst;
    int64_t written = 0;
};

// The UV-warp lines of `log` by object (in the order first seen) and tile (ascending). The lines must
// outlive the series.
[[nodiscard]] std::vector<ShotTileSeries> shotSeries(const ShotLog& log);

}  // namespace deformkit::uvwarp
