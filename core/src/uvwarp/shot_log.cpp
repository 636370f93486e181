#include "deformkit/uvwarp/shot_log.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <string_view>
#include <tuple>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"

namespace deformkit::uvwarp {
namespace {

using json = nlohmann::json;

const std::set<std::string, std::less<>> kStatuses = {"written", "replayed", "skipped", "unwarped",
                                                      "warm-up"};

// The start of a line as a message quotes it.
std::string quotedStart(std::string_view text) {
    constexpr size_t kShown = 80;
    std::string out(text.substr(0, kShown));
    if (text.size() > kShown) out += "...";
    return "'" + out + "'";
}

// A whole number within int's range, or nullopt.
std::optional<int> wholeNumber(const json& j) {
    if (j.is_number_unsigned()) {
        const auto v = j.get<uint64_t>();
        if (v <= static_cast<uint64_t>(std::numeric_limits<int>::max())) return static_cast<int>(v);
    } else if (j.is_number_integer()) {
        const auto v = j.get<int64_t>();
        if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max())
            return static_cast<int>(v);
    }
    return std::nullopt;
}

// The line parsed, or the problem with it.
std::optional<std::string> parse(const json& j, ShotLogLine& out) {
    if (!j.is_object()) return "is not a JSON object";
    const auto frame = j.find("frame");
    const std::optional<int> frameNumber = frame == j.end() ? std::nullopt : wholeNumber(*frame);
    if (!frameNumber) return "has no whole-number \"frame\"";
    out.frame = *frameNumber;
    const auto status = j.find("status");
    if (status == j.end() || !status->is_string() || !kStatuses.contains(status->get<std::string>())) {
        return "has no \"status\" of written, replayed, skipped, unwarped or warm-up";
    }
    out.status = status->get<std::string>();
    if (const auto task = j.find("task"); task != j.end()) {
        out.task = wholeNumber(*task);
        if (!out.task || *out.task < 0) return "has a \"task\" that is not a task index";
    }
    if (const auto tile = j.find("tile"); tile != j.end()) {
        out.tile = wholeNumber(*tile);
        if (!out.tile || *out.tile < 1001 || *out.tile > 9999) {
            return "has a \"tile\" that is not a UDIM tile (1001 to 9999)";
        }
    }
    for (const auto& [key, slot] : {std::pair<const char*, std::string*>{"object", &out.object},
                                    {"redirect", &out.redirect},
                                    {"bake", &out.bake}}) {
        const auto it = j.find(key);
        if (it == j.end()) continue;
        if (!it->is_string()) return std::string("has a \"") + key + "\" that is not a string";
        *slot = it->get<std::string>();
    }
    if (const auto metrics = j.find("metrics"); metrics != j.end()) {
        if (!metrics->is_object()) return "has \"metrics\" that are not an object";
        for (const auto& [name, value] : metrics->items()) {
            if (value.is_boolean()) {
                out.metrics[name] = value.get<bool>() ? 1.0 : 0.0;
            } else if (value.is_number()) {
                out.metrics[name] = value.get<double>();
            } else {
                return "has metric \"" + name + "\" that is not a number";
            }
        }
    }
    if (const auto seconds = j.find("seconds"); seconds != j.end()) {
        const json* total =
            seconds->is_object() && seconds->contains("total") ? &(*seconds)["total"] : &*seconds;
        if (!total->is_number())
            return "has \"seconds\" that are neither a number nor an object with \"total\"";
        out.seconds = total->get<double>();
    }
    if (out.tile && out.status == "written" && !out.metrics.contains("rigid_stretch_removed")) {
        return "is a written frame without metrics.rigid_stretch_removed";
    }
    return std::nullopt;
}

}  // namespace

void readShotLog(std::istream& in, const std::string& file, ShotLog& log) {
    std::string text;
    int64_t number = 0;
    while (std::getline(in, text)) {
        ++number;
        if (!text.empty() && text.back() == '\r') text.pop_back();
        if (std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isspace(c) != 0; })) {
            continue;
        }
        ShotLogLine line;
        line.file = file;
        line.line = number;
        std::optional<std::string> problem;
        const json j = json::parse(text, nullptr, false);
        if (j.is_discarded()) {
            problem = "is not JSON: " + quotedStart(text);
        } else if (std::optional<std::string> bad = parse(j, line)) {
            problem = *bad + ": " + quotedStart(text);
        }
        if (problem) {
            log.problems.push_back({file, number, *problem});
        } else {
            log.lines.push_back(std::move(line));
        }
    }
    if (in.bad()) log.problems.push_back({file, number, "could not be read past this line"});
}

void readShotLogFile(const std::filesystem::path& path, ShotLog& log) {
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    if (!in || std::filesystem::is_directory(path, ec)) {
        log.problems.push_back({path.string(), 0, "cannot be opened (expected a JSON-lines shot log)"});
        return;
    }
    readShotLog(in, path.string(), log);
}

double ShotFrame::figure(const std::string& name) const {
    const auto it = line->metrics.find(name);
    return written() && it != line->metrics.end() ? it->second : std::numeric_limits<double>::quiet_NaN();
}

std::vector<ShotTileSeries> shotSeries(const ShotLog& log) {
    std::vector<std::string> objects;  // in the order first seen
    std::map<std::tuple<size_t, int, int>, const ShotLogLine*> chosen;
    for (const ShotLogLine& line : log.lines) {
        if (!line.tile || line.status == "warm-up") continue;
        auto object = std::find(objects.begin(), objects.end(), line.object);
        if (object == objects.end()) object = objects.insert(objects.end(), line.object);
        const auto key =
            std::make_tuple(static_cast<size_t>(object - objects.begin()), *line.tile, line.frame);
        const ShotLogLine*& slot = chosen[key];
        if (!slot || line.status == "written" || slot->status != "written") slot = &line;
    }
    std::vector<ShotTileSeries> out;
    for (const auto& [key, line] : chosen) {
        const auto& [object, tile, frame] = key;
        if (out.empty() || out.back().object != objects[object] || out.back().tile != tile) {
            out.push_back({objects[object], tile, {}, std::nullopt, 0});
        }
        out.back().frames.push_back({frame, line});
    }
    for (ShotTileSeries& s : out) {
        for (size_t k = 0; k < s.frames.size(); ++k) {
            const ShotFrame& f = s.frames[k];
            if (!f.written()) continue;
            ++s.written;
            if (!s.worst) {
                s.worst = k;
                continue;
            }
            const ShotFrame& w = s.frames[*s.worst];
            const double removed = f.figure("rigid_stretch_removed"),
                         worst = w.figure("rigid_stretch_removed");
            const double inverted = f.figure("inverted_triangles"),
                         worstInverted = w.figure("inverted_triangles");
            if (removed < worst || (removed == worst && inverted > worstInverted)) s.worst = k;
        }
    }
    return out;
}

void openShotLog(const std::filesystem::path& path, std::ofstream& file) {
    if (path.has_parent_path()) io::createFolder(path.parent_path());
    file.open(path, std::ios::app | std::ios::binary);
    if (!file) {
        throw IoError(formatError(path.string(), "", "cannot open the log for appending", "a writable file"));
    }
    // A log whose writer was killed mid-line: the next record starts on a line of its own, not glued to the
    // cut one (which stays, a problem the report names).
    std::ifstream existing(path, std::ios::binary | std::ios::ate);
    if (existing && existing.tellg() > 0) {
        existing.seekg(-1, std::ios::end);
        char last = '\n';
        existing.get(last);
        if (last != '\n') file << '\n' << std::flush;
    }
}

}  // namespace deformkit::uvwarp
