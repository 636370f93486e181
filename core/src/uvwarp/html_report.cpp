#include "deformkit/uvwarp/html_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/version.h"
#include "report_pictures.h"

namespace deformkit::uvwarp {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Bytes of inline thumbnails a page holds at most (base64). A browser reads a thumbnail from a file faster
// than from a data URL in the page (headless chromium: 12 noise thumbnails of 256^2 inline cost 1.8 s more
// than an empty page, read from files 0.5 s), so only the first ones are inline: a page mailed alone still
// shows its first tiles.
constexpr size_t kInlineBudget = size_t{1} << 20;

std::string escape(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (const char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

// A number as the page shows it: `digits` after the point, "–" when unknown.
std::string fixed(double v, int digits) {
    if (!std::isfinite(v)) return "–";
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
    return buffer;
}

std::string percent(double v) {
    return std::isfinite(v) ? fixed(100.0 * v, 1) + "%" : "–";
}

std::string base64(const std::string& bytes) {
    static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
        if (i + 1 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 1]) << 8;
        if (i + 2 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 2]);
        out += kDigits[(v >> 18) & 63];
        out += kDigits[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? kDigits[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? kDigits[v & 63] : '=';
    }
    return out;
}

std::string fileBytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

double median(std::vector<double> v) {
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
    if (v.empty()) return std::nan("");
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// One figure of a series, frame by frame (NaN where a frame has none).
std::vector<double> values(const ShotTileSeries& s, const std::function<double(const ShotFrame&)>& of) {
    std::vector<double> out;
    out.reserve(s.frames.size());
    for (const ShotFrame& f : s.frames)
        out.push_back(of(f));
    return out;
}

double sum(const std::vector<double>& v) {
    double total = 0.0;
    for (const double x : v)
        if (std::isfinite(x)) total += x;
    return total;
}

int64_t framesWith(const std::vector<double>& v) {
    return std::count_if(v.begin(), v.end(), [](double x) { return std::isfinite(x) && x > 0.0; });
}

struct Series {
    const ShotTileSeries* s;
    std::string id;  // the tile section's anchor
    std::vector<double> removed, inverted, offChart, seconds;
};

// A line plot of `v` over the series' frames, its worst frame marked.
std::string plot(const Series& series, const std::vector<double>& v, std::string_view title, double scale,
                 int digits, std::string_view unit) {
    constexpr double kW = 300, kH = 130, kLeft = 46, kRight = 10, kTop = 20, kBottom = 22;
    const ShotTileSeries& s = *series.s;
    double lo = 0.0, hi = 0.0;
    for (const double x : v)
        if (std::isfinite(x)) lo = std::min(lo, x * scale), hi = std::max(hi, x * scale);
    if (hi <= lo) hi = lo + 1.0;
    const double f0 = s.frames.front().frame, f1 = s.frames.back().frame;
    const auto px = [&](double frame) {
        return f1 > f0 ? kLeft + (frame - f0) / (f1 - f0) * (kW - kLeft - kRight)
                       : 0.5 * (kW + kLeft - kRight);
    };
    const auto py = [&](double y) { return kTop + (hi - y * scale) / (hi - lo) * (kH - kTop - kBottom); };
    std::ostringstream o;
    o << "<svg class=\"plot\" role=\"img\" width=\"" << kW << "\" height=\"" << kH << "\" viewBox=\"0 0 "
      << kW << ' ' << kH << "\" data-figure=\"" << escape(title) << "\"><title>" << escape(title)
      << "</title>";
    o << "<text x=\"" << kLeft << "\" y=\"13\" class=\"t\">" << escape(title) << "</text>";
    o << "<rect x=\"" << kLeft << "\" y=\"" << kTop << "\" width=\"" << kW - kLeft - kRight << "\" height=\""
      << kH - kTop - kBottom << "\" class=\"frame\"/>";
    o << "<text x=\"" << kLeft - 4 << "\" y=\"" << kTop + 8 << "\" class=\"a r\">" << fixed(hi, digits)
      << unit << "</text><text x=\"" << kLeft - 4 << "\" y=\"" << kH - kBottom << "\" class=\"a r\">"
      << fixed(lo, digits) << unit << "</text>";
    o << "<text x=\"" << kLeft << "\" y=\"" << kH - 6 << "\" class=\"a\">" << s.frames.front().frame
      << "</text><text x=\"" << kW - kRight << "\" y=\"" << kH - 6 << "\" class=\"a r\">"
      << s.frames.back().frame << "</text>";
    std::string points;
    const auto flush = [&] {
        if (points.empty()) return;
        o << "<polyline class=\"l\" points=\"" << points << "\"/>";
        points.clear();
    };
    char buffer[48];
    for (size_t k = 0; k < v.size(); ++k) {
        if (!std::isfinite(v[k])) {
            flush();
            continue;
        }
        std::snprintf(buffer, sizeof buffer, "%s%.1f,%.1f", points.empty() ? "" : " ", px(s.frames[k].frame),
                      py(v[k]));
        points += buffer;
    }
    flush();
    if (s.worst && std::isfinite(v[*s.worst])) {
        const double x = px(s.frames[*s.worst].frame), y = py(v[*s.worst]);
        o << "<line class=\"w\" x1=\"" << fixed(x, 1) << "\" x2=\"" << fixed(x, 1) << "\" y1=\"" << kTop
          << "\" y2=\"" << kH - kBottom << "\"/><circle class=\"w\" cx=\"" << fixed(x, 1) << "\" cy=\""
          << fixed(y, 1) << "\" r=\"3\"/>";
        o << "<text x=\"" << kW - kRight << "\" y=\"13\" class=\"a r w\">worst frame "
          << s.frames[*s.worst].frame << ": " << fixed(v[*s.worst] * scale, digits) << unit << "</text>";
    }
    o << "</svg>";
    return o.str();
}

// "redirect.1001.0019.exr" at tile 1001, frame 19 -> "redirect.<UDIM>.####.exr"; without a frame, the tile
// alone ("rig.1001.exr" -> "rig.<UDIM>.exr").
std::string pattern(const std::string& name, int tile, std::optional<int> frame = std::nullopt) {
    const fs::path path(name);
    std::string file = path.filename().string();
    if (const size_t at = file.rfind(std::to_string(tile)); tile > 0 && at != std::string::npos) {
        file.replace(at, 4, "<UDIM>");
    }
    // The frame's digits nearest the end, zero padded or not.
    for (size_t end = file.size(); frame && end > 0; --end) {
        if (!std::isdigit(static_cast<unsigned char>(file[end - 1]))) continue;
        size_t begin = end;
        while (begin > 0 && std::isdigit(static_cast<unsigned char>(file[begin - 1])))
            --begin;
        const std::string digits = file.substr(begin, end - begin);
        const size_t nonZero = digits.find_first_not_of('0');
        const bool minus = begin > 0 && file[begin - 1] == '-' && *frame < 0;
        if ((nonZero == std::string::npos ? "0" : digits.substr(nonZero)) ==
                std::to_string(std::abs(*frame)) &&
            (*frame >= 0 || minus)) {
            file.replace(minus ? begin - 1 : begin, end - begin + (minus ? 1 : 0),
                         std::string(end - begin, '#'));
        }
        break;
    }
    return (path.parent_path() / file).string();
}

// The shortest text that reads back as float `x`.
std::string floatText(double x) {
    char buffer[32];
    for (int digits = 1; digits <= 9; ++digits) {
        std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
        if (static_cast<float>(std::strtod(buffer, nullptr)) == static_cast<float>(x)) break;
    }
    return buffer;
}

std::string shellWord(const std::string& s) {
    if (!s.empty() &&
        s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=,:") ==
            std::string::npos) {
        return s;
    }
    std::string out = "'";
    for (const char c : s)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

// A `deformkit uvwarp` line that runs a CLI shot again, from its worst frame's header; empty when the
// inputs are not files (a scene's or a DCC's shot).
std::string rerunFromHeader(const ShotTileSeries& s, const json& header) {
    const json inputs = header.value("deformkit:uvwarp:inputs", json::object());
    const json solver = header.value("deformkit:uvwarp:solver", json::object());
    const ShotFrame& worst = s.frames[*s.worst];
    const std::string deformed = inputs.value("deformed", "");
    if (!s.object.empty() || deformed.empty() || !fs::exists(inputs.value("rest", ""))) return {};
    std::string frames = std::to_string(s.frames.front().frame);
    if (s.frames.back().frame != s.frames.front().frame)
        frames += "-" + std::to_string(s.frames.back().frame);
    const size_t cache = deformed.rfind(" frame ");
    std::string line = "deformkit uvwarp --rest " + shellWord(inputs.value("rest", "")) + " --deformed " +
                       shellWord(cache != std::string::npos ? deformed.substr(0, cache)
                                                            : pattern(deformed, 0, worst.frame)) +
                       " --frames " + frames + " --rigidity " +
                       shellWord(pattern(inputs.value("rigidity", ""), s.tile)) + " --out " +
                       shellWord(pattern(worst.line->redirect, s.tile, worst.frame));
    if (inputs.contains("mask") && inputs["mask"] != "derived") {
        line += " --mask " + shellWord(pattern(inputs.value("mask", ""), s.tile));
    }
    if (inputs.contains("texture") && !worst.line->bake.empty()) {
        line += " --texture " + shellWord(pattern(inputs.value("texture", ""), s.tile)) + " --bake " +
                shellWord(pattern(worst.line->bake, s.tile, worst.frame));
    }
    if (solver.contains("cells")) line += " --resolution " + std::to_string(solver["cells"].get<int64_t>());
    const TileWarpOptions defaults = shotOptions();
    for (const OptionSpec& spec : optionSpecs()) {
        const auto it = solver.find(std::string(spec.name));
        if (!spec.recorded || it == solver.end()) continue;
        std::vector<double> value;
        if (it->is_array()) {
            for (const json& x : *it)
                value.push_back(x.get<double>());
        } else {
            value.push_back(it->is_boolean() ? (it->get<bool>() ? 1.0 : 0.0) : it->get<double>());
        }
        // Numbers are recorded as the solver holds them (floats): compared and printed at that precision.
        std::vector<double> fallback = spec.get(defaults);
        const auto asFloat = [](std::vector<double>& v) {
            for (double& x : v)
                x = static_cast<float>(x);
        };
        asFloat(value);
        asFloat(fallback);
        if (value == fallback) continue;
        line += " " + cliName(spec);
        if (spec.type == OptionType::Flag) {
            line += value.front() != 0 ? "" : "=false";
            continue;
        }
        std::string list;
        for (const double x : value)
            list += (list.empty() ? "" : ",") + floatText(x);
        line += " " + list;
    }
    return line;
}

constexpr const char* kStyle =
    R"(body{font:14px/1.4 system-ui,sans-serif;margin:24px;color:#222;max-width:1500px}
h1{font-size:22px;margin:0 0 4px}h2{font-size:17px;margin:28px 0 6px;border-top:1px solid #ccc;padding-top:12px}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ddd;padding:3px 8px;text-align:right}
th{background:#f3f3f3}td.l,th.l{text-align:left}.bad{color:#b00020;font-weight:600}.ok{color:#1b7f2a}
.plots,.pics{display:flex;flex-wrap:wrap;gap:10px}figure{margin:0}figcaption{font-size:12px;color:#555;max-width:256px}
svg.plot{background:#fff;border:1px solid #eee}svg .frame{fill:none;stroke:#ccc}svg .l{fill:none;stroke:#2060c0;stroke-width:1.5}
svg .w{stroke:#d02020;fill:#d02020;stroke-dasharray:3 2}svg text{font-size:10px;fill:#444}svg .t{font-size:12px;fill:#222}
svg .r{text-anchor:end}svg text.w{stroke:none;fill:#d02020}pre{background:#f6f6f6;padding:8px;overflow-x:auto;white-space:pre-wrap}
.key span{display:inline-block;width:12px;height:12px;vertical-align:middle;margin:0 4px 0 12px;border:1px solid #999}
details{margin:6px 0}img{image-rendering:pixelated;border:1px solid #ddd})";

}  // namespace

void prepareHtmlReport(const fs::path& page) {
    const fs::path folder = page.has_parent_path() ? page.parent_path() : fs::path(".");
    io::createFolder(folder);
    io::createFolder(folder / (page.stem().string() + "_files"));
}

HtmlReportResult writeHtmlReport(const ShotLog& log, const fs::path& page, const HtmlReportOptions& options) {
    if (options.thumbnail < 16) {
        throw InvalidInput(
            formatError("report", "thumbnail", std::to_string(options.thumbnail) + " pixels", "at least 16"));
    }
    const fs::path folder = page.has_parent_path() ? page.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) {
        throw IoError(formatError(page.string(), "", "its folder does not exist", "an existing folder"));
    }
    HtmlReportResult result;
    result.files.push_back(page);
    const fs::path filesName = page.stem().string() + "_files";
    const fs::path filesDir = folder / filesName;

    // Where relative names are looked for: the working folder, each log's folder, the caller's.
    std::vector<fs::path> folders;
    for (const ShotLogLine& line : log.lines) {
        const fs::path logFolder = fs::path(line.file).parent_path();
        if (std::find(folders.begin(), folders.end(), logFolder) == folders.end())
            folders.push_back(logFolder);
    }
    folders.insert(folders.begin(), fs::path("."));
    folders.insert(folders.end(), options.searchFolders.begin(), options.searchFolders.end());

    std::vector<Series> all;
    const std::vector<ShotTileSeries> tiles = shotSeries(log);
    for (const ShotTileSeries& s : tiles) {
        Series series{
            &s,
            "tile-" + (s.object.empty() ? std::string() : s.object + "-") + std::to_string(s.tile),
            values(s, [](const ShotFrame& f) { return f.figure("rigid_stretch_removed"); }),
            values(s, [](const ShotFrame& f) { return f.figure("inverted_triangles"); }),
            values(s, [](const ShotFrame& f) { return f.figure("off_chart_texels"); }),
            values(s, [](const ShotFrame& f) { return f.written() ? f.line->seconds : std::nan(""); })};
        for (char& c : series.id)
            if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-') c = '_';
        all.push_back(std::move(series));
    }

    // Farm tasks whose tiles and frames the logs do not show written or skipped.
    struct Missing {
        const HtmlReportOptions::Task* task;
        std::vector<int> frames;
        bool logged;
    };
    std::vector<Missing> missing;
    {
        std::set<std::pair<int, int>> done;                        // (tile, frame), any object
        std::set<std::tuple<std::string, int, int>> doneByObject;  // (object, tile, frame)
        std::set<std::pair<int, int>> meshDone;                    // (task, frame) of a mesh task
        std::set<int> logged;
        for (const ShotLogLine& line : log.lines) {
            if (line.task) logged.insert(*line.task);
            const bool finished = line.status == "written" || line.status == "skipped";
            if (line.tile && finished) {
                done.insert({*line.tile, line.frame});
                doneByObject.insert({line.object, *line.tile, line.frame});
            } else if (!line.tile && line.task && finished) {
                meshDone.insert({*line.task, line.frame});
            }
        }
        for (const HtmlReportOptions::Task& task : options.tasks) {
            Missing m{&task, {}, logged.contains(task.index)};
            for (int frame = task.first; frame <= task.last; ++frame) {
                // A mesh task's lines (no tile) say each frame's OBJs were written or were there.
                const bool all =
                    task.tiles.empty() ? meshDone.contains({task.index, frame})
                    : task.objectTiles.empty()
                        ? std::all_of(task.tiles.begin(), task.tiles.end(),
                                      [&](int tile) {
                                          return done.contains({tile, frame});
                                      })
                        : std::all_of(task.objectTiles.begin(), task.objectTiles.end(), [&](const auto& ot) {
                              return doneByObject.contains({ot.first, ot.second, frame});
                          });
                if (!all) m.frames.push_back(frame);
            }
            if (!m.frames.empty()) missing.push_back(std::move(m));
        }
    }
    result.problems = static_cast<int64_t>(log.problems.size() + missing.size());

    std::ostringstream html;
    html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
         << escape(options.title) << "</title><style>" << kStyle << "</style></head><body>\n";
    html << "<h1>" << escape(options.title) << "</h1><p>DeformKit " << kVersionString
         << " UV-warp shot report: " << all.size() << " tile" << (all.size() == 1 ? "" : "s") << ", "
         << log.lines.size() << " log lines";
    int64_t inverted = 0, offChart = 0;
    for (const Series& s : all)
        inverted += static_cast<int64_t>(sum(s.inverted)), offChart += static_cast<int64_t>(sum(s.offChart));
    html << "; <span class=\"" << (inverted + offChart > 0 ? "bad" : "ok")
         << "\" id=\"totals\" data-inverted=\"" << inverted << "\" data-off-chart=\"" << offChart << "\">"
         << inverted << " inverted triangles, " << offChart
         << " off-chart texels delivered</span>; <span class=\"" << (result.problems ? "bad" : "ok")
         << "\" id=\"problem-count\" data-problems=\"" << result.problems << "\">" << result.problems
         << " problem" << (result.problems == 1 ? "" : "s") << "</span>.</p>\n";

    // Overview.
    html << "<table id=\"overview\"><tr><th class=\"l\">object</th><th>tile</th><th>frames written</th>"
            "<th>rigid stretch removed, median</th><th>worst</th><th>worst frame</th><th>inverted triangles"
            "</th><th>frames with folds</th><th>off-chart texels</th><th>seconds a frame, median</th>"
            "<th>seconds, total</th></tr>\n";
    for (const Series& s : all) {
        const ShotTileSeries& t = *s.s;
        const double worst = t.worst ? s.removed[*t.worst] : std::nan("");
        html << "<tr data-object=\"" << escape(t.object) << "\" data-tile=\"" << t.tile
             << "\" data-written=\"" << t.written << "\" data-median-removed=\""
             << numberText(median(s.removed)) << "\" data-worst-removed=\"" << numberText(worst)
             << "\" data-worst-frame=\""
             << (t.worst ? std::to_string(t.frames[*t.worst].frame) : std::string()) << "\" data-inverted=\""
             << numberText(sum(s.inverted)) << "\" data-off-chart=\"" << numberText(sum(s.offChart)) << "\">";
        html << "<td class=\"l\">" << escape(t.object) << "</td><td><a href=\"#" << s.id << "\">" << t.tile
             << "</a></td><td>" << t.written << " of " << t.frames.size() << "</td><td>"
             << percent(median(s.removed)) << "</td><td>" << percent(worst) << "</td><td>"
             << (t.worst ? std::to_string(t.frames[*t.worst].frame) : "–") << "</td><td"
             << (sum(s.inverted) > 0 ? " class=\"bad\"" : "") << ">" << fixed(sum(s.inverted), 0)
             << "</td><td>" << framesWith(s.inverted) << "</td><td"
             << (sum(s.offChart) > 0 ? " class=\"bad\"" : "") << ">" << fixed(sum(s.offChart), 0)
             << "</td><td>" << fixed(median(s.seconds), 3) << "</td><td>" << fixed(sum(s.seconds), 1)
             << "</td></tr>\n";
    }
    html << "</table>\n";

    // Problems.
    if (result.problems > 0) {
        html << "<h2 id=\"problems\">Problems</h2><ul>";
        for (const Missing& m : missing) {
            html << "<li class=\"bad missing-task\" data-task=\"" << m.task->index << "\">task "
                 << m.task->index << " (frames " << m.task->first << "–" << m.task->last
                 << (m.task->tiles.empty() ? ", meshes" : ", tiles");
            for (const int tile : m.task->tiles)
                html << ' ' << tile;
            html << "): "
                 << (m.logged ? "failed or still running: " : "no log line (not run, or its log not given): ")
                 << m.frames.size() << " frame" << (m.frames.size() == 1 ? "" : "s") << " missing";
            if (!m.task->rerun.empty()) html << "; rerun: <code>" << escape(m.task->rerun) << "</code>";
            html << "</li>";
        }
        for (const ShotLogProblem& p : log.problems)
            html << "<li class=\"log-problem\">" << escape(p.file)
                 << (p.line > 0 ? ":" + std::to_string(p.line) : "") << ": " << escape(p.message) << "</li>";
        html << "</ul>\n";
    }

    // Tiles.
    std::string rerunGuess;
    size_t inlineBytes = 0;
    const io::ImageWriteOptions png;
    for (const Series& s : all) {
        const ShotTileSeries& t = *s.s;
        html << "<h2 id=\"" << s.id << "\">" << (t.object.empty() ? "" : escape(t.object) + ", ") << "tile "
             << t.tile << "</h2>\n<div class=\"plots\">"
             << plot(s, s.removed, "rigid stretch removed", 100.0, 1, "%")
             << plot(s, s.inverted, "inverted triangles", 1.0, 0, "")
             << plot(s, s.offChart, "off-chart texels", 1.0, 0, "")
             << plot(s, s.seconds, "seconds a frame", 1.0, 3, "") << "</div>\n";
        if (!t.worst) {
            html << "<p>No frame written in these logs.</p>\n";
            continue;
        }
        const ShotFrame& worst = t.frames[*t.worst];
        const detail::TilePictures pictures = detail::tilePictures(t, options, folders);
        html << "<p>Worst frame " << worst.frame << ": " << percent(s.removed[*t.worst])
             << " of the rigid stretch removed, " << fixed(s.inverted[*t.worst], 0) << " inverted triangles, "
             << fixed(s.offChart[*t.worst], 0) << " off-chart texels";
        if (pictures.remeasured) {
            const bool same = std::abs(pictures.remeasured->removed - s.removed[*t.worst]) <= 1e-9;
            html << (same ? " (measured again from its files: the same)"
                          : "; <span class=\"bad\">measured again from its files: " +
                                percent(pictures.remeasured->removed) + " (the inputs changed since)</span>");
        }
        html << ".</p>\n<div class=\"pics\">";
        for (size_t k = 0; k < pictures.pictures.size(); ++k) {
            const detail::ReportPicture& picture = pictures.pictures[k];
            const std::string base = s.id + "." + std::to_string(worst.frame) + "." + std::to_string(k);
            io::createFolder(filesDir);
            const fs::path full = filesDir / (base + ".png"), thumb = filesDir / (base + ".thumb.png");
            io::writeImage(full, picture.image, png);
            io::writeImage(thumb, detail::shrinkTo(picture.image, options.thumbnail), png);
            result.files.push_back(full);
            result.files.push_back(thumb);
            // Thumbnails are inline up to a budget that keeps the page small (whatever the tile count and
            // the textures); past it they are read from beside the page.
            std::string source = base64(fileBytes(thumb));
            if (inlineBytes + source.size() <= kInlineBudget) {
                inlineBytes += source.size();
                source = "data:image/png;base64," + source;
            } else {
                source = escape((filesName / (base + ".thumb.png")).generic_string());
            }
            html << "<figure><a href=\"" << escape((filesName / (base + ".png")).generic_string())
                 << "\"><img alt=\"" << escape(picture.caption) << "\" src=\"" << source
                 << "\"></a><figcaption>" << escape(picture.caption) << "</figcaption></figure>";
        }
        html << "</div>\n";
        if (!pictures.pictures.empty() && pictures.remeasured) {
            html << "<p class=\"key\">Heatmaps: | length ratio − 1 | of rigid content,<span "
                    "style=\"background:"
                    "linear-gradient(90deg";
            for (int k = 0; k <= 4; ++k) {
                const glm::vec3 c = heatmapColour(kHeatmapTop * k / 4.0);
                html << ",rgb(" << static_cast<int>(255 * c.x) << ',' << static_cast<int>(255 * c.y) << ','
                     << static_cast<int>(255 * c.z) << ')';
            }
            html << ");width:120px\"></span> 0 to " << kHeatmapTop
                 << " and above; <span style=\"background:#ccc\"></span>"
                 << "elastic; <span style=\"background:#f0f\"></span>folds; <span "
                    "style=\"background:#0ef\"></span>"
                    "off-chart texels; dark lines: chart borders.</p>\n";
        }
        for (const std::string& note : pictures.notes) {
            html << "<p class=\"bad note\">" << escape(note) << "</p>\n";
            result.notes.push_back((t.object.empty() ? "" : t.object + " ") + "tile " +
                                   std::to_string(t.tile) + ": " + note);
        }
        if (!pictures.header.is_null()) {
            const json& header = pictures.header;
            html << "<details><summary>Inputs and options (the header of " << escape(worst.line->redirect)
                 << ")</summary><table>";
            for (const auto& [key, value] : header.items()) {
                if (value.is_object()) {
                    for (const auto& [name, v] : value.items())
                        html << "<tr><td class=\"l\">" << escape(key) << "</td><td class=\"l\">"
                             << escape(name) << "</td><td class=\"l\">"
                             << escape(v.is_string() ? v.get<std::string>() : v.dump()) << "</td></tr>";
                } else {
                    html << "<tr><td class=\"l\">" << escape(key) << "</td><td></td><td class=\"l\">"
                         << escape(value.is_string() ? value.get<std::string>() : value.dump())
                         << "</td></tr>";
                }
            }
            html << "</table></details>\n";
            if (rerunGuess.empty()) rerunGuess = rerunFromHeader(t, header);
        }
        html << "<p>Outputs: <code>" << escape(pattern(worst.line->redirect, t.tile, worst.frame))
             << "</code>";
        if (!worst.line->bake.empty())
            html << ", <code>" << escape(pattern(worst.line->bake, t.tile, worst.frame)) << "</code>";
        html << ", " << t.written << " frame" << (t.written == 1 ? "" : "s") << " written.</p>\n";
    }

    std::vector<std::string> rerun = options.rerun;
    if (rerun.empty() && !rerunGuess.empty())
        rerun.push_back(rerunGuess + "   # made from the maps' headers");
    if (!rerun.empty()) {
        html << "<h2 id=\"rerun\">Run again</h2><pre>";
        for (const std::string& line : rerun)
            html << escape(line) << "\n";
        html << "</pre>\n";
    }

    // The figures the plots are drawn from, as data (not a script: nothing runs).
    json data = {{"title", options.title}, {"problems", result.problems}, {"tiles", json::array()}};
    for (const Series& s : all) {
        json frames = json::array(), status = json::array();
        for (const ShotFrame& f : s.s->frames)
            frames.push_back(f.frame), status.push_back(f.line->status);
        const auto list = [](const std::vector<double>& v) {
            json out = json::array();
            for (const double x : v)
                out.push_back(std::isfinite(x) ? json(x) : json(nullptr));
            return out;
        };
        data["tiles"].push_back(
            {{"object", s.s->object},
             {"tile", s.s->tile},
             {"frames", frames},
             {"status", status},
             {"rigid_stretch_removed", list(s.removed)},
             {"inverted_triangles", list(s.inverted)},
             {"off_chart_texels", list(s.offChart)},
             {"seconds", list(s.seconds)},
             {"worst_frame", s.s->worst ? json(s.s->frames[*s.s->worst].frame) : json(nullptr)}});
    }
    std::string dump = data.dump();
    for (size_t at = dump.find("</"); at != std::string::npos; at = dump.find("</", at + 2))
        dump.replace(at, 2, "<\\/");
    html << "<script type=\"application/json\" id=\"deformkit-shot\">" << dump
         << "</script>\n</body></html>\n";
    io::writeFileAtomically(page, html.str());
    return result;
}

}  // namespace deformkit::uvwarp
