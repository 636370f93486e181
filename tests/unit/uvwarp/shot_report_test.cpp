#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/uvwarp/html_report.h"
#include "deformkit/uvwarp/redirect_metrics.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/shot_log.h"
#include "test_support.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using Catch::Contains;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

uvwarp::ShotLog logOf(const std::string& text, const std::string& name = "a.jsonl") {
    uvwarp::ShotLog log;
    std::istringstream in(text);
    uvwarp::readShotLog(in, name, log);
    return log;
}

std::string written(int tile, int frame, double removed, int inverted = 0, const std::string& extra = "") {
    return R"({"tile":)" + std::to_string(tile) + R"(,"frame":)" + std::to_string(frame) +
           R"(,"status":"written","redirect":"r.)" + std::to_string(tile) + "." + std::to_string(frame) +
           R"(.exr","metrics":{"rigid_stretch_removed":)" + std::to_string(removed) +
           R"(,"inverted_triangles":)" + std::to_string(inverted) +
           R"(,"off_chart_texels":0,"converged":false},)" + R"("seconds":{"total":0.5})" + extra + "}\n";
}

// The identity redirect map of a T x T tile (texel centres, v up).
io::Image identityMap(int t) {
    io::Image map(t, t, 2);
    for (int y = 0; y < t; ++y)
        for (int x = 0; x < t; ++x) {
            map.at(x, y, 0) = static_cast<float>((x + 0.5) / t);
            map.at(x, y, 1) = static_cast<float>(1.0 - (y + 0.5) / t);
        }
    return map;
}

// Inverted triangles of cell (x, y), written out apart from the library: the texel-centre cell's four
// triangles (both diagonals), each compared with the identity's orientation.
int invertedTriangles(const io::Image& r, int x, int y) {
    const auto p = [&](int dx, int dy) {
        return glm::dvec2(r.at(x + dx, y + dy, 0), r.at(x + dx, y + dy, 1));
    };
    const auto cross = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
        return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    };
    // In the identity, +x then +y in the image turns clockwise in uv (v falls with y): negative areas.
    int n = 0;
    for (const auto& [a, b, c] :
         {std::array{p(0, 0), p(1, 0), p(1, 1)}, std::array{p(0, 0), p(1, 1), p(0, 1)},
          std::array{p(0, 0), p(1, 0), p(0, 1)}, std::array{p(1, 0), p(1, 1), p(0, 1)}})
        n += cross(a, b, c) > 0.0 ? 1 : 0;
    return n;
}

}  // namespace

TEST_CASE("shot log: broken and partial lines are problems naming the file and line; the rest is read",
          "[uvwarp][report]") {
    const std::string text = written(1001, 1, 0.8) + "\n" +             // 1, blank 2
                             "deformkit: error: task 3: disk full\n" +  // 3: a farm's stderr
                             R"({"tile":1001,"frame":"2","status":"written"})"
                             "\n"  // 4: frame a string
                             R"({"tile":1001,"frame":3,"status":"done"})"
                             "\n"  // 5: unknown status
                             R"({"tile":99,"frame":3,"status":"skipped"})"
                             "\n"  // 6: not a UDIM tile
                             R"({"tile":1001,"frame":4,"status":"written","metrics":{}})"
                             "\n"  // 7: no figure
                             R"({"task":1,"frame":4,"status":"written","seconds":0.01})"
                             "\r\n"                                       // 8: mesh task
                             + written(1001, 5, 0.7) +                    // 9
                             R"({"tile":1001,"frame":6,"status":"writ)";  // 10: cut by a kill
    const uvwarp::ShotLog log = logOf(text, "farm.7_1.log");
    REQUIRE(log.lines.size() == 3);
    CHECK(log.lines[0].line == 1);
    CHECK(log.lines[0].metrics.at("rigid_stretch_removed") == Approx(0.8));
    CHECK(log.lines[0].metrics.at("converged") == 0.0);
    CHECK(log.lines[0].seconds == 0.5);
    CHECK(log.lines[0].redirect == "r.1001.1.exr");
    CHECK((!log.lines[1].tile && log.lines[1].task == 1 && log.lines[1].seconds == 0.01));
    CHECK(log.lines[2].line == 9);
    std::vector<int64_t> lines;
    for (const uvwarp::ShotLogProblem& p : log.problems) {
        CHECK(p.file == "farm.7_1.log");
        lines.push_back(p.line);
    }
    CHECK(lines == std::vector<int64_t>{3, 4, 5, 6, 7, 10});
    CHECK_THAT(log.problems[0].message, Contains("is not JSON: 'deformkit: error: task 3: disk full'"));
    CHECK_THAT(log.problems[1].message, Contains("has no whole-number \"frame\""));
    CHECK_THAT(log.problems[2].message, Contains("has no \"status\" of written, replayed"));
    CHECK_THAT(log.problems[3].message, Contains("not a UDIM tile"));
    CHECK_THAT(log.problems[4].message, Contains("a written frame without metrics.rigid_stretch_removed"));

    uvwarp::ShotLog missing;
    uvwarp::readShotLogFile("no/such/log.jsonl", missing);
    REQUIRE(missing.problems.size() == 1);
    CHECK(missing.problems[0].line == 0);
    CHECK_THAT(missing.problems[0].message, Contains("cannot be opened"));
}

TEST_CASE("shot log: a log cut mid-line by a kill is appended to on a line of its own", "[uvwarp][report]") {
    // The resumed run's first record used to be glued to the cut one, and both were lost.
    test::TempDir dir;
    const fs::path path = dir / "logs" / "shot.jsonl";
    for (const std::string& before :
         {std::string(), written(1001, 1, 0.8), std::string(R"({"tile":1001,"fra)")}) {
        CAPTURE(before);
        if (!before.empty()) test::writeText(path, before);
        {
            std::ofstream file;
            uvwarp::openShotLog(path, file);
            file << written(1001, 2, 0.7);
        }
        uvwarp::ShotLog log;
        uvwarp::readShotLogFile(path, log);
        const bool cut = !before.empty() && before.back() != '\n';
        CHECK(log.problems.size() == (cut ? 1u : 0u));
        REQUIRE(!log.lines.empty());
        CHECK(log.lines.back().frame == 2);
        CHECK(log.lines.back().line == (before.empty() ? 1 : 2));
        CHECK(test::readText(path) == before + (cut ? "\n" : "") + written(1001, 2, 0.7));
        fs::remove(path);
    }
}

TEST_CASE("shot log: logs merge in any order; a written line tells its frame; the worst frame",
          "[uvwarp][report]") {
    // Task 0 wrote frames 1-3 of tile 1001 and was killed; its rerun skipped them and wrote frame 4. Another
    // object's tile, warm-up lines and a tile whose frames were all skipped come along.
    const std::string first = written(1001, 2, 0.60, 3) + written(1001, 1, 0.90) + written(1001, 3, 0.60, 5);
    const std::string rerun = R"({"tile":1001,"frame":1,"status":"skipped"})"
                              "\n"
                              R"({"tile":1001,"frame":0,"status":"warm-up"})"
                              "\n" +
                              written(1001, 4, 0.95) + written(1002, 1, 0.5, 0, R"(,"object":"b")") +
                              R"({"tile":1002,"frame":1,"status":"skipped"})"
                              "\n";
    for (const bool rerunFirst : {false, true}) {
        uvwarp::ShotLog log;
        for (const auto& [text, name] :
             rerunFirst ? std::vector<std::pair<std::string, std::string>>{{rerun, "b"}, {first, "a"}}
                        : std::vector<std::pair<std::string, std::string>>{{first, "a"}, {rerun, "b"}}) {
            std::istringstream in(text);
            uvwarp::readShotLog(in, name, log);
        }
        const std::vector<uvwarp::ShotTileSeries> series = uvwarp::shotSeries(log);
        REQUIRE(series.size() == 3);
        // Objects in the order first seen, tiles ascending.
        const uvwarp::ShotTileSeries& main = series[0];
        CHECK(main.object.empty());
        CHECK(main.tile == 1001);
        std::vector<int> frames;
        for (const uvwarp::ShotFrame& f : main.frames) {
            frames.push_back(f.frame);
            CHECK(f.written());
        }
        CHECK(frames == std::vector<int>{1, 2, 3, 4});  // warm-up left out, the skipped line loses to written
        CHECK(main.written == 4);
        // Frames 2 and 3 tie at 60%; frame 3 has more inverted triangles.
        REQUIRE(main.worst);
        CHECK(main.frames[*main.worst].frame == 3);
        const uvwarp::ShotTileSeries& skippedOnly = series[1].object.empty() ? series[1] : series[2];
        CHECK(skippedOnly.tile == 1002);
        CHECK(skippedOnly.written == 0);
        CHECK_FALSE(skippedOnly.worst);
        CHECK(std::isnan(skippedOnly.frames[0].figure("rigid_stretch_removed")));
    }
}

TEST_CASE("delivered texels: a stretched plane's closed form, and folds and off-chart texels where made",
          "[uvwarp][report]") {
    constexpr int kT = 16;
    // The plane stretched 1.5x along u, rigid everywhere, read through the identity: a texel's right edge is
    // off by |1.5 - 1| = 0.5 and its lower edge by 0, so a texel holds 0.25, 0 in the last column (its lower
    // edge alone), 0.5 in the last row (its right edge alone), nothing at the last corner.
    const geom::Mesh plane =
        test::planarChart({0, 0}, {1, 1}, 4, 4, [](glm::vec2 uv) { return glm::vec3(uv, 0); });
    std::vector<glm::vec3> stretched(plane.points().begin(), plane.points().end());
    for (glm::vec3& p : stretched)
        p.x *= 1.5f;
    const io::Image rigid(kT, kT, 1, 1.0f);
    const uvwarp::RedirectMetrics metrics(plane, 1001, rigid);
    uvwarp::DeliveredTexels texels;
    const io::Image identity = identityMap(kT);
    const uvwarp::DeliveredMetrics m = metrics.measure(stretched, identity, &texels);
    CHECK(m.rigidStretchError == Approx(0.25).epsilon(1e-6));
    for (int y = 0; y < kT; ++y)
        for (int x = 0; x < kT; ++x) {
            const double expected = x + 1 < kT && y + 1 < kT ? 0.25
                                    : x + 1 < kT             ? 0.5
                                    : y + 1 < kT             ? 0.0
                                                             : NAN;
            INFO("texel " << x << ", " << y);
            if (std::isnan(expected)) {
                CHECK(std::isnan(texels.stretch.at(x, y, 0)));
                CHECK(std::isnan(texels.identityStretch.at(x, y, 0)));
            } else {
                CHECK(texels.stretch.at(x, y, 0) == Approx(expected).margin(1e-6));
                CHECK(texels.identityStretch.at(x, y, 0) == texels.stretch.at(x, y, 0));
            }
            CHECK(texels.chart.at(x, y, 0) == 1.0f);
            CHECK(texels.offChart.at(x, y, 0) == 0.0f);
            CHECK(texels.folds.at(x, y, 0) == 0.0f);
        }

    // Two texels swapped: the cells around them fold, as counted here apart from the library.
    io::Image swapped = identity;
    for (int c = 0; c < 2; ++c)
        std::swap(swapped.at(5, 5, c), swapped.at(7, 6, c));
    const uvwarp::DeliveredMetrics folded = metrics.measure(stretched, swapped, &texels);
    int64_t triangles = 0, cells = 0;
    for (int y = 0; y < kT; ++y)
        for (int x = 0; x < kT; ++x) {
            const int n = x + 1 < kT && y + 1 < kT ? invertedTriangles(swapped, x, y) : 0;
            triangles += n;
            cells += n > 0 ? 1 : 0;
            CHECK(texels.folds.at(x, y, 0) == (n > 0 ? 1.0f : 0.0f));
        }
    CHECK(cells > 0);
    CHECK(folded.invertedTriangles == triangles);

    // A chart over the tile's left half; one texel shows content from its right half: off the chart.
    const geom::Mesh half =
        test::planarChart({0, 0}, {0.5f, 1}, 2, 4, [](glm::vec2 uv) { return glm::vec3(uv, 0); });
    io::Image away = identity;
    away.at(2, 8, 0) = 0.75f;
    const uvwarp::RedirectMetrics halfMetrics(half, 1001, rigid);
    const uvwarp::DeliveredMetrics off = halfMetrics.measure(
        std::vector<glm::vec3>(half.points().begin(), half.points().end()), away, &texels);
    CHECK(off.offChartTexels == 1);
    for (int y = 0; y < kT; ++y)
        for (int x = 0; x < kT; ++x) {
            CHECK(texels.chart.at(x, y, 0) == (x < kT / 2 ? 1.0f : 0.0f));
            CHECK(texels.offChart.at(x, y, 0) == (x == 2 && y == 8 ? 1.0f : 0.0f));
        }
}

TEST_CASE(
    "off-chart scan: refusedInRow lists the chart texels whose content lies on no UV triangle, on "
    "Spot's charts over random maps",
    "[uvwarp][report]") {
    constexpr int kT = 256;
    constexpr double kClear = 1e-5;  // barycentric margin beyond which the reference's verdict is taken
    const geom::Mesh spot = io::readObj(DEFORMKIT_TEST_DATA "/spot/spot_quadrangulated.obj").mesh;
    // The reference, apart from the library: each face's UV polygon fanned from its first corner, and a
    // point's largest smallest-barycentric over every triangle (> 0 inside one, < 0 outside all).
    std::vector<std::array<glm::dvec2, 3>> triangles;
    for (int f = 0; f < spot.numFaces(); ++f) {
        const auto uv = spot.faceUVIndices(f);
        for (size_t k = 1; k + 1 < uv.size(); ++k)
            triangles.push_back({glm::dvec2(spot.uvs()[uv[0]]), glm::dvec2(spot.uvs()[uv[k]]),
                                 glm::dvec2(spot.uvs()[uv[k + 1]])});
    }
    const auto depth = [&](glm::dvec2 p) {
        double best = -1e300;
        for (const auto& [a, b, c] : triangles) {
            const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
            if (area == 0.0) continue;
            const double lb = ((p.x - a.x) * (c.y - a.y) - (p.y - a.y) * (c.x - a.x)) / area;
            const double lc = ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / area;
            best = std::max(best, std::min({1.0 - lb - lc, lb, lc}));
        }
        return best;
    };
    const io::Image rigid(kT, kT, 1, 0.0f);
    const uvwarp::RedirectMetrics metrics(spot, 1001, rigid);
    std::mt19937 rng(20261205);
    int64_t refusedTotal = 0, keptTotal = 0, compared = 0, skipped = 0;
    // Content moved up to 0.5, 2, 8 and 40 texels in random directions: within the own triangle, a few
    // triangles on (the walk across edges), and far off, across charts and into the empty tile.
    for (const double reach : {0.5, 2.0, 8.0, 40.0}) {
        std::uniform_real_distribution<double> offset(-reach / kT, reach / kT);
        io::Image map = identityMap(kT);
        for (int y = 0; y < kT; ++y)
            for (int x = 0; x < kT; ++x) {
                map.at(x, y, 0) += static_cast<float>(offset(rng));
                map.at(x, y, 1) += static_cast<float>(offset(rng));
            }
        for (int y = 0; y < kT; y += 7) {  // every seventh row: the reference loops over every triangle
            std::vector<int32_t> refused;
            metrics.refusedInRow(map, y, refused);
            REQUIRE(std::is_sorted(refused.begin(), refused.end()));
            for (int x = 0; x < kT; ++x) {
                const double own = depth({(x + 0.5) / kT, 1.0 - (y + 0.5) / kT});
                const double content = depth({map.at(x, y, 0), map.at(x, y, 1)});
                if (std::abs(own) < kClear || std::abs(content) < kClear) {
                    ++skipped;  // a centre or content on a triangle's edge: either verdict is right
                    continue;
                }
                const bool listed = std::binary_search(refused.begin(), refused.end(), x);
                INFO("reach " << reach << " texel " << x << ", " << y);
                CHECK(listed == (own > 0.0 && content < 0.0));
                ++compared;
                refusedTotal += listed ? 1 : 0;
                keptTotal += own > 0.0 && !listed ? 1 : 0;
            }
        }
    }
    INFO("refused " << refusedTotal << ", kept " << keptTotal << ", skipped " << skipped);
    CHECK(refusedTotal > 1000);  // the cases were met
    CHECK(keptTotal > 10000);
    CHECK(skipped * 1000 < compared);
}

TEST_CASE(
    "shot report: the page's figures are the log's, its heatmaps measure what the log says, problems "
    "and missing farm tasks are listed",
    "[uvwarp][report]") {
    constexpr int kTexels = 32;
    test::TempDir dir;
    const geom::Mesh rest = test::twoTileCharts();
    uvwarp::ShotJob job;
    job.rest = &rest;
    job.restName = "two tiles";
    job.frames = {1, 2, 3, 4, 5};
    job.rigidity.images = {{1001, test::twoDisks(kTexels)}, {1002, test::twoDisks(kTexels)}};
    job.rigidity.name = "painted rigidity";
    job.outPath = [&](int tile, int f) {
        return dir / ("redirect." + std::to_string(tile) + "." + std::to_string(f) + ".exr");
    };
    std::ostringstream logText;
    job.log = &logText;
    std::vector<glm::vec3> frame;
    (void)uvwarp::runShotJob(job, [&](int f, std::string& name) -> std::span<const glm::vec3> {
        name = "frame " + std::to_string(f);
        frame = test::stretchedAndBent(rest, f);
        return frame;
    });
    // Mesh tasks' lines, as farm run prints them (no tile): task 2 wrote frames 1-6 of its 1-7, task 5 all of
    // its 1-2 (frame 2 found written before).
    std::string meshLines;
    for (int f = 1; f <= 6; ++f)
        meshLines += R"({"task":2,"frame":)" + std::to_string(f) +
                     R"(,"status":"written","seconds":0.02})"
                     "\n";
    meshLines += R"({"task":5,"frame":1,"status":"written","seconds":0.02})"
                 "\n";
    meshLines += R"({"task":5,"frame":2,"status":"skipped"})"
                 "\n";
    const fs::path logFile = dir / "shot.jsonl";
    test::writeText(logFile, logText.str() + meshLines + "not a line\n");

    uvwarp::ShotLog log;
    uvwarp::readShotLogFile(logFile, log);
    REQUIRE(log.lines.size() == 18);
    uvwarp::HtmlReportOptions options;
    options.title = "two <tiles>";
    // The maps are in memory, the deformed frames made here: both through the callbacks.
    options.geometry = [&](const std::string& object, int f) -> std::optional<uvwarp::ReportGeometry> {
        CHECK(object.empty());
        return uvwarp::ReportGeometry{rest, test::stretchedAndBent(rest, f)};
    };
    options.rigidity = [&](const std::string&, int tile) -> std::optional<io::Image> {
        return job.rigidity.images.at(tile);
    };
    // Task 1 (frames 6-7 of tile 1002) never ran. Task 3's tile 1001 has maps of two objects, of which the
    // log shows one (the shot's, named ""): a task killed between two objects' maps is missing too. Task 4
    // expects only that object's.
    options.tasks = {{0, 1, 5, {1001, 1002}, {}, "rerun 0"},
                     {1, 6, 7, {1002}, {}, "rerun 1"},
                     {2, 1, 7, {}, {}, "rerun 2"},
                     {3, 1, 5, {1001}, {{"", 1001}, {"other", 1001}}, "rerun 3"},
                     {4, 1, 5, {1001}, {{"", 1001}}, "rerun 4"},
                     {5, 1, 2, {}, {}, "rerun 5"}};
    const fs::path page = dir / "shot.html";
    const uvwarp::HtmlReportResult result = uvwarp::writeHtmlReport(log, page, options);
    CHECK(result.notes.empty());
    CHECK(result.problems == 4);  // the broken line and the missing tasks 1, 2 (a mesh task's frame 7) and 3
    REQUIRE(result.files.size() == 1 + 2 * 4 * 2);  // per tile 4 pictures and their thumbnails
    for (const fs::path& f : result.files)
        CHECK(fs::file_size(f) > 0);

    const std::string html = test::readText(page);
    CHECK_THAT(html, Contains("<title>two &lt;tiles&gt;</title>"));
    CHECK(html.find("<script src") == std::string::npos);
    CHECK(html.find("http") == std::string::npos);  // nothing from a network
    CHECK_THAT(html, Contains("shot.jsonl:19: is not JSON: 'not a line'"));
    CHECK_THAT(html, Contains("data-task=\"1\">task 1 (frames 6–7, tiles 1002): no log line"));
    CHECK_THAT(html, Contains("rerun 1"));
    CHECK(html.find("data-task=\"0\"") == std::string::npos);
    CHECK_THAT(html, Contains("data-task=\"3\">task 3 (frames 1–5, tiles 1001)"));
    CHECK(html.find("data-task=\"4\"") == std::string::npos);
    CHECK_THAT(html,
               Contains("data-task=\"2\">task 2 (frames 1–7, meshes): failed or still running: 1 frame"));
    CHECK_THAT(html, Contains("rerun 2"));
    CHECK(html.find("data-task=\"5\"") == std::string::npos);
    const std::string tag = "id=\"deformkit-shot\">";
    const size_t begin = html.find(tag) + tag.size();
    REQUIRE(begin > tag.size());
    const json data = json::parse(html.substr(begin, html.find("</script>", begin) - begin));
    REQUIRE(data["tiles"].size() == 2);
    for (size_t k = 0; k < 2; ++k) {
        const json& tile = data["tiles"][k];
        CHECK(tile["tile"] == 1001 + static_cast<int>(k));
        std::vector<double> removed;
        for (const uvwarp::ShotLogLine& line : log.lines)
            if (line.tile == tile["tile"].get<int>())
                removed.push_back(line.metrics.at("rigid_stretch_removed"));
        CHECK(tile["rigid_stretch_removed"].get<std::vector<double>>() == removed);
        const auto worst = std::min_element(removed.begin(), removed.end()) - removed.begin();
        CHECK(tile["worst_frame"] == job.frames[static_cast<size_t>(worst)]);
        // The overview row says the same, and the worst frame measured again from its inputs matches the log.
        std::vector<double> sorted = removed;
        std::sort(sorted.begin(), sorted.end());
        CHECK_THAT(html, Contains("data-tile=\"" + std::to_string(1001 + k) +
                                  "\" data-written=\"5\" data-median-removed=\"" + numberText(sorted[2]) +
                                  "\" data-worst-removed=\"" + numberText(sorted[0]) + "\""));
    }
    const auto same = [&](const std::string& s) {
        size_t n = 0;
        for (size_t at = html.find(s); at != std::string::npos; at = html.find(s, at + 1))
            ++n;
        return n;
    };
    CHECK(same("measured again from its files: the same") == 2);
    CHECK(same("data:image/png;base64,") == 8);
    CHECK(same("<polyline") >= 8);

    // Without the callbacks the maps in memory cannot be found: said in the page, not thrown.
    const uvwarp::HtmlReportResult bare = uvwarp::writeHtmlReport(log, dir / "bare.html");
    CHECK(bare.notes.size() >= 2);
    CHECK_THAT(bare.notes[0], Contains("the rest mesh 'two tiles' is not a file"));
    CHECK_THAT(test::readText(dir / "bare.html"), Contains("no heatmaps"));
    CHECK_THROWS_AS(uvwarp::writeHtmlReport(log, dir / "no" / "such" / "page.html"), IoError);
}
