#include "demo_uvwarp.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/preview.h"
#include "deformkit/io/udim.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/html_report.h"
#include "deformkit/uvwarp/shot_job.h"
#include "deformkit/uvwarp/tile_warp.h"
#include "deformkit/warp/barr.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

// Images laid out in rows on the first image's background, `gap` pixels apart.
io::Image sheet(const std::vector<std::vector<const io::Image*>>& rows, int32_t gap) {
    const io::Image& first = *rows[0][0];
    int32_t width = 0, height = 0;
    for (const auto& row : rows) {
        int32_t w = 0, h = 0;
        for (const io::Image* image : row) {
            w += image->width + gap;
            h = std::max(h, image->height);
        }
        width = std::max(width, w - gap);
        height += h + gap;
    }
    height -= gap;
    io::Image out(width, height, 3);
    for (int32_t y = 0; y < height; ++y)
        for (int32_t x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
                out.at(x, y, c) = first.at(0, 0, c);
    int32_t y0 = 0;
    for (const auto& row : rows) {
        int32_t x0 = 0, h = 0;
        for (const io::Image* image : row) {
            for (int32_t y = 0; y < image->height; ++y)
                for (int32_t x = 0; x < image->width; ++x)
                    for (int c = 0; c < 3; ++c)
                        out.at(x0 + x, y0 + y, c) = image->at(x, y, c);
            x0 += image->width + gap;
            h = std::max(h, image->height);
        }
        y0 += h + gap;
    }
    return out;
}

}  // namespace

namespace {

// The tube bent about the axis frame's "up" (+x) over its length, `amount` of the demo's pose: at 1 the
// bend radius 1/k ~ 1.9 puts the -x side (1 unit further out) at ~1.5x stretch and the +x side at ~0.5x.
std::vector<glm::vec3> bentTube(const geom::Mesh& tube, float amount) {
    const warp::AxisFrame axis{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}};
    warp::BendWarp bend(axis, {amount * std::numbers::pi_v<float> / 2 / 3.0f, 0.5f, 0.5f, 3.5f});
    std::vector<glm::vec3> points(tube.points().begin(), tube.points().end());
    warp::SparseFields unused;
    bend.bind(points, unused);
    bend.deform(points);
    return points;
}

}  // namespace

DemoUvWarp makeDemoUvWarp(const geom::Mesh& tube, const io::Image& rigidity, const io::Image& mask,
                          const io::Image& albedo) {
    const std::vector<glm::vec3> points = bentTube(tube, 1.0f);
    DemoUvWarp demo{tube, {}, {}, {}, {}};
    demo.bent.setPoints(points);

    uvwarp::TileWarpOptions options;
    options.cells = std::min<int32_t>(rigidity.width, 256);
    uvwarp::TileWarp tile(tube, 1001, rigidity, mask, options, {}, "demo tube");
    // Two solves of the same pose: the second warm-starts from the first, as frames of a held pose would.
    tile.solve(points);
    tile.solve(points);
    demo.redirect = tile.redirect();
    demo.metrics = tile.metrics();
    demo.delivered = tile.measure(demo.redirect);
    demo.warpedAlbedo = uvwarp::bakeTexture(albedo, demo.redirect);  // bilinear: no overshoot past [0, 1]
    return demo;
}

std::vector<fs::path> writeDemoUvWarp(const geom::Mesh& tube, const io::Image& rigidity,
                                      const io::Image& mask, const std::map<int, io::Image>& albedo,
                                      const fs::path& outDir) {
    const fs::path dir = outDir / "uvwarp";
    io::createFolder(dir);
    const DemoUvWarp demo = makeDemoUvWarp(tube, rigidity, mask, albedo.at(1001));
    std::vector<fs::path> written;
    written.push_back(dir / "tube_bent.obj");
    io::writeObj(written.back(), demo.bent);
    io::ImageWriteOptions exr;
    exr.type = io::PixelType::Float;
    exr.attributes = {{"deformkit:content", "uv redirect, tile-local uv' = W^-1(uv)"},
                      {"deformkit:tile", "1001"}};
    written.push_back(dir / "redirect.1001.exr");
    io::writeImage(written.back(), demo.redirect, exr);

    io::PreviewTexture before, after;
    for (const auto& [tile, image] : albedo) {
        before.tiles.emplace(tile, image);
        const io::Image& warped = tile == 1001 ? demo.warpedAlbedo : image;
        after.tiles.emplace(tile, warped);
        written.push_back(dir / io::expandUdim("albedo_warped.<UDIM>.png", tile));
        io::writeImage(written.back(), warped);
    }
    io::PreviewOptions outer;  // looks along +x at the stretched -x side
    outer.width = 420;
    outer.height = 420;
    outer.fieldOfViewDegrees = 22.0f;
    outer.viewDirection = {1.0f, -0.25f, -0.15f};
    io::PreviewOptions inner = outer;            // the squashed +x side, seen from below the crook
    inner.viewDirection = {-1.0f, 0.8f, -0.3f};  // from below the crook
    const io::Image outerBefore = io::renderPreview(demo.bent, outer, &before);
    const io::Image outerAfter = io::renderPreview(demo.bent, outer, &after);
    const io::Image innerBefore = io::renderPreview(demo.bent, inner, &before);
    const io::Image innerAfter = io::renderPreview(demo.bent, inner, &after);
    for (const auto& [name, image] :
         std::vector<std::pair<std::string, const io::Image*>>{{"outer_before.png", &outerBefore},
                                                               {"outer_after.png", &outerAfter},
                                                               {"inner_before.png", &innerBefore},
                                                               {"inner_after.png", &innerAfter}}) {
        written.push_back(dir / name);
        io::writeImage(written.back(), *image);
    }
    written.push_back(dir / "uvwarp.png");
    io::writeImage(written.back(), sheet({{&outerBefore, &outerAfter}, {&innerBefore, &innerAfter}}, 8));

    // The redirect map's figures (uvwarp/redirect_metrics.h), as the shot log names them.
    std::string json = "{\"tile\": 1001";
    for (const uvwarp::ReportedFigure& f : uvwarp::reportedFigures(demo.delivered)) {
        json += ", \"" + std::string(f.name) + "\": ";
        json += f.kind == uvwarp::ReportedFigure::Kind::Count ? std::to_string(static_cast<int64_t>(f.value))
                                                              : std::to_string(f.value);
    }
    json += "}\n";
    written.push_back(dir / "metrics.json");
    io::writeFileAtomically(written.back(), json);
    return written;
}

std::vector<fs::path> writeDemoUvWarpShot(const geom::Mesh& tube, int32_t cells, const fs::path& outDir) {
    // Absolute names: the maps' headers then name files a report finds from any folder.
    const fs::path root = fs::absolute(outDir), dir = root / "uvwarp" / "shot";
    io::createFolder(dir);
    std::vector<fs::path> written;
    std::vector<int> frames;
    for (int frame = 1; frame <= kDemoShotFrames; ++frame) {
        geom::Mesh bent = tube;
        bent.setPoints(bentTube(tube, static_cast<float>(frame) / kDemoShotFrames));
        written.push_back(dir / io::ObjSequence("tube.####.obj").framePath(frame).filename());
        io::writeObj(written.back(), bent);
        frames.push_back(frame);
    }
    uvwarp::ShotJob job;
    job.rest = &tube;
    job.restName = (root / "tube.obj").string();
    job.frames = frames;
    job.tiles = {1001};
    job.rigidity = {root / "rigidity.<UDIM>.exr", {}, "rigidity"};
    job.mask = {root / "mask.<UDIM>.exr", {}, "mask"};
    job.texture = {root / "albedo.<UDIM>.png", {}, "texture"};
    uvwarp::setOutputPatterns(job, dir / "redirect.<UDIM>.####.exr", dir / "albedo.<UDIM>.####.png",
                              "redirect", "bake");
    job.options.cells = cells;
    job.skipExisting = false;
    std::ostringstream log;
    job.log = &log;
    const fs::path deformed = dir / "tube.####.obj";
    const uvwarp::ShotReport report =
        uvwarp::runShotJob(job, uvwarp::animatedFrames(deformed, frames, "demo shot", tube, job.restName));
    for (const uvwarp::ShotTileReport& tile : report.tiles)
        written.insert(written.end(), tile.files.begin(), tile.files.end());
    written.push_back(dir / "uvwarp.jsonl");
    io::writeFileAtomically(written.back(), log.str());
    uvwarp::ShotLog lines;
    std::istringstream text(log.str());
    uvwarp::readShotLog(text, written.back().string(), lines);
    uvwarp::HtmlReportOptions page;
    page.title = "DeformKit demo: the tube bending, UV warp of tile 1001";
    const uvwarp::HtmlReportResult result =
        uvwarp::writeHtmlReport(lines, root / "uvwarp" / "report.html", page);
    written.insert(written.end(), result.files.begin(), result.files.end());
    return written;
}

}  // namespace deformkit::harness
