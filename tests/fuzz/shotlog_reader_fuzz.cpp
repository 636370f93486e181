// libFuzzer target for UV-warp shot logs read back (uvwarp/shot_log.h). The reader never throws: every
// non-blank line becomes a log line or a problem naming it, and the series made from the lines hold each
// frame once, ascending, with a worst frame among the written ones.
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "deformkit/uvwarp/shot_log.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    deformkit::uvwarp::ShotLog log;
    std::istringstream in(text);
    deformkit::uvwarp::readShotLog(in, "fuzz.jsonl", log);
    int64_t lines = 0;
    std::istringstream count(text);
    for (std::string line; std::getline(count, line);) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.find_first_not_of(" \t\n\v\f\r") != std::string::npos) ++lines;
    }
    if (static_cast<int64_t>(log.lines.size() + log.problems.size()) != lines) std::abort();
    for (const deformkit::uvwarp::ShotTileSeries& s : deformkit::uvwarp::shotSeries(log)) {
        for (size_t k = 1; k < s.frames.size(); ++k)
            if (s.frames[k].frame <= s.frames[k - 1].frame) std::abort();
        if (s.worst && (*s.worst >= s.frames.size() || !s.frames[*s.worst].written())) std::abort();
        if (s.written > 0 && !s.worst) std::abort();
    }
    return 0;
}
