#include "report_pictures.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>

#include <nlohmann/json.hpp>

#include "deformkit/error.h"
#include "deformkit/io/mesh_file.h"
#include "deformkit/io/point_cache.h"
#include "deformkit/uvwarp/bake.h"
#include "deformkit/uvwarp/mask.h"
#include "tile_uvs.h"

namespace deformkit::uvwarp {

glm::vec3 heatmapColour(double e) {
    // Viridis at five stops, linear between them.
    static constexpr std::array<glm::vec3, 5> kStops = {
        glm::vec3(0.267f, 0.005f, 0.329f), glm::vec3(0.229f, 0.322f, 0.546f),
        glm::vec3(0.128f, 0.567f, 0.551f), glm::vec3(0.369f, 0.789f, 0.383f),
        glm::vec3(0.993f, 0.906f, 0.144f)};
    const double t = std::clamp(std::isfinite(e) ? e / kHeatmapTop : 1.0, 0.0, 1.0) * (kStops.size() - 1);
    const auto k = std::min(static_cast<size_t>(t), kStops.size() - 2);
    const auto f = static_cast<float>(t - static_cast<double>(k));
    return kStops[k] * (1.0f - f) + kStops[k + 1] * f;
}

namespace detail {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const glm::vec3 kOutside(0.96f), kElastic(0.80f), kBorder(0.15f), kFold(1.0f, 0.0f, 1.0f),
    kOffChart(0.0f, 0.9f, 1.0f);

void put(io::Image& image, int32_t x, int32_t y, glm::vec3 c) {
    if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
    for (int k = 0; k < 3; ++k)
        image.at(x, y, k) = c[k];
}

// Chart borders as lines one texel wide, so the heatmap reads over the UV layout.
void drawBorders(io::Image& image, const TileUVs& uvs) {
    const auto t = static_cast<double>(image.width);
    for (const auto& edge : uvs.borderEdges) {
        const glm::dvec2 a(edge[0].x * t, (1.0 - edge[0].y) * t), b(edge[1].x * t, (1.0 - edge[1].y) * t);
        const int steps =
            std::max(1, static_cast<int>(std::ceil(std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)))));
        for (int s = 0; s <= steps; ++s) {
            const glm::dvec2 p = a + (b - a) * (static_cast<double>(s) / steps);
            put(image, static_cast<int32_t>(std::floor(p.x)), static_cast<int32_t>(std::floor(p.y)), kBorder);
        }
    }
}

// Marks where `flags` is set, `radius` texels around, so a mark survives the thumbnail's shrink.
void mark(io::Image& image, const io::Image& flags, glm::vec3 colour, int32_t radius) {
    for (int32_t y = 0; y < flags.height; ++y)
        for (int32_t x = 0; x < flags.width; ++x)
            if (flags.at(x, y, 0) > 0.0f)
                for (int32_t dy = -radius; dy <= radius; ++dy)
                    for (int32_t dx = -radius; dx <= radius; ++dx)
                        put(image, x + dx, y + dy, colour);
}

io::Image heatmap(const io::Image& stretch, const DeliveredTexels& texels, const TileUVs& uvs) {
    io::Image out(stretch.width, stretch.height, 3);
    for (int32_t y = 0; y < out.height; ++y) {
        for (int32_t x = 0; x < out.width; ++x) {
            const float e = stretch.at(x, y, 0);
            put(out, x, y,
                texels.chart.at(x, y, 0) == 0.0f ? kOutside
                : std::isnan(e)                  ? kElastic
                                                 : heatmapColour(e));
        }
    }
    drawBorders(out, uvs);
    return out;
}

io::Image rgb(const io::Image& image) {
    io::Image out(image.width, image.height, 3);
    for (int32_t y = 0; y < image.height; ++y)
        for (int32_t x = 0; x < image.width; ++x)
            for (int k = 0; k < 3; ++k)
                out.at(x, y, k) = std::clamp(image.at(x, y, std::min(k, image.channels - 1)), 0.0f, 1.0f);
    return out;
}

std::string text(const json& j, const char* key) {
    const auto it = j.find(key);
    return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

// The deformed positions a header names: a mesh file, or "<cache> frame <n>".
std::optional<std::vector<glm::vec3>> deformedFrom(const std::string& name,
                                                   const std::vector<fs::path>& folders, std::string& why) {
    // io::PointCache::frameName's "<cache> frame <n>".
    const size_t at = name.rfind(" frame ");
    const std::string number = at == std::string::npos ? std::string() : name.substr(at + 7);
    int frame = 0;
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), frame);
    if (!number.empty() && error == std::errc() && end == number.data() + number.size()) {
        if (const std::optional<fs::path> file = findFile(name.substr(0, at), folders)) {
            io::PointCache cache(*file);
            std::vector<glm::vec3> points;
            cache.read(frame, points);
            return points;
        }
    }
    if (const std::optional<fs::path> file = findFile(name, folders)) {
        const geom::Mesh mesh = io::readMesh(*file).mesh;
        return std::vector<glm::vec3>(mesh.points().begin(), mesh.points().end());
    }
    why = "the deformed mesh '" + name + "' is not a file found beside the logs or maps";
    return std::nullopt;
}

}  // namespace

std::optional<fs::path> findFile(const std::string& name, const std::vector<fs::path>& folders) {
    if (name.empty()) return std::nullopt;
    std::error_code ec;
    const fs::path path(name);
    if (fs::is_regular_file(path, ec)) return path;
    if (path.is_absolute()) return std::nullopt;
    for (const fs::path& folder : folders) {
        if (fs::is_regular_file(folder / path, ec)) return folder / path;
    }
    return std::nullopt;
}

io::Image shrinkTo(const io::Image& image, int32_t side) {
    const int32_t longest = std::max(image.width, image.height);
    const int32_t f = std::max(1, (longest + side - 1) / side);
    if (f == 1) return image;
    io::Image out(std::max(1, image.width / f), std::max(1, image.height / f), image.channels);
    for (int32_t y = 0; y < out.height; ++y)
        for (int32_t x = 0; x < out.width; ++x)
            for (int32_t c = 0; c < image.channels; ++c) {
                double sum = 0.0;
                for (int32_t dy = 0; dy < f; ++dy)
                    for (int32_t dx = 0; dx < f; ++dx)
                        sum += image.at(x * f + dx, y * f + dy, c);
                out.at(x, y, c) = static_cast<float>(sum / (f * f));
            }
    return out;
}

TilePictures tilePictures(const ShotTileSeries& series, const HtmlReportOptions& options,
                          std::vector<fs::path> folders) {
    TilePictures out;
    const ShotFrame& worst = series.frames[*series.worst];
    const ShotLogLine& line = *worst.line;
    const std::optional<fs::path> mapFile = findFile(line.redirect, folders);
    if (!mapFile) {
        out.notes.push_back("no pictures: the redirect map '" + line.redirect + "' was not found");
        return out;
    }
    folders.insert(folders.begin() + 1, mapFile->parent_path());
    try {
        const io::ImageInfo info = io::readImageInfo(*mapFile);
        json header = json::object();
        for (const auto& [key, value] : info.attributes) {
            if (key.rfind("deformkit:", 0) != 0) continue;
            const json parsed = json::parse(value, nullptr, false);
            header[key] = parsed.is_discarded() || !parsed.is_object() ? json(value) : parsed;
        }
        out.header = header;
        const json inputs = header.value("deformkit:uvwarp:inputs", json::object());
        const io::Image redirect = io::readImage(*mapFile);

        std::optional<ReportGeometry> geometry;
        if (options.geometry) geometry = options.geometry(series.object, worst.frame);
        if (!geometry) {
            const std::optional<fs::path> rest = findFile(text(inputs, "rest"), folders);
            if (!rest) {
                out.notes.push_back("no heatmaps: the rest mesh '" + text(inputs, "rest") +
                                    "' is not a file found beside the logs or maps");
            } else {
                std::string why;
                if (auto deformed = deformedFrom(text(inputs, "deformed"), folders, why)) {
                    geometry = ReportGeometry{io::readMesh(*rest).mesh, std::move(*deformed)};
                } else {
                    out.notes.push_back("no heatmaps: " + why);
                }
            }
        }
        std::optional<io::Image> rigidity;
        if (options.rigidity) rigidity = options.rigidity(series.object, series.tile);
        if (!rigidity) {
            if (const std::optional<fs::path> file = findFile(text(inputs, "rigidity"), folders)) {
                rigidity = readRigidityMap(*file, series.tile);
            } else {
                out.notes.push_back("the rigidity map '" + text(inputs, "rigidity") + "' was not found");
            }
        }
        std::optional<io::Image> plain;
        std::string plainName = "texture";
        if (options.texture) plain = options.texture(series.object, series.tile);
        if (!plain) {
            if (const std::optional<fs::path> file = findFile(text(inputs, "texture"), folders)) {
                plain = io::readImage(*file);
            } else if (rigidity) {
                plain = *rigidity;
                plainName = "rigidity map";
            }
        }
        const int32_t radius = std::max(1, redirect.width / options.thumbnail);
        if (geometry && rigidity) {
            const TileUVs uvs = collectTileUVs(geometry->rest, series.tile, series.object);
            DeliveredTexels texels;
            const RedirectMetrics metrics(geometry->rest, series.tile, *rigidity, mapFile->string());
            out.remeasured = metrics.measure(geometry->deformed, redirect, &texels);
            io::Image warped = heatmap(texels.stretch, texels, uvs);
            mark(warped, texels.offChart, kOffChart, radius);
            mark(warped, texels.folds, kFold, radius);
            out.pictures.push_back(
                {"rigid stretch left through the map", shrinkTo(warped, kReportPictureSide)});
            out.pictures.push_back(
                {"rigid stretch without the warp",
                 shrinkTo(heatmap(texels.identityStretch, texels, uvs), kReportPictureSide)});
        }
        if (plain) {
            out.pictures.push_back({plainName + " as painted", shrinkTo(rgb(*plain), kReportPictureSide)});
            std::optional<fs::path> bake =
                plainName == "texture" ? findFile(line.bake, folders) : std::nullopt;
            const io::Image warped = bake ? io::readImage(*bake) : bakeTexture(*plain, redirect);
            out.pictures.push_back({plainName + " through the map" + (bake ? " (the bake)" : ""),
                                    shrinkTo(rgb(warped), kReportPictureSide)});
        }
    } catch (const Error& e) {
        out.notes.push_back(std::string("pictures not made: ") + e.what());
    }
    return out;
}

}  // namespace detail
}  // namespace deformkit::uvwarp
