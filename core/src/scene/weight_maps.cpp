#include "deformkit/scene/weight_maps.h"

#include <cmath>
#include <map>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/io/sampling.h"
#include "deformkit/io/udim.h"

namespace deformkit::scene {

std::vector<float> weightsFromMaps(const geom::Mesh& mesh, const std::filesystem::path& pattern,
                                   int32_t channel, const std::string& source) {
    if (!mesh.hasUVs()) {
        throw InvalidInput(formatError(source, pattern.string(), "is a weight map for a mesh without UVs",
                                       "a mesh with texture coordinates (vt) on its faces"));
    }
    const bool perTile = io::hasUdimToken(pattern.filename().string());
    std::map<int, io::Image> images;  // by tile, read once
    auto imageOf = [&](int tile, int32_t face) -> const io::Image& {
        auto it = images.find(tile);
        if (it != images.end()) return it->second;
        if (!perTile && tile != 1001) {
            throw InvalidInput(
                formatError(source, pattern.string(),
                            "face " + std::to_string(face) + " has its UVs in tile " + std::to_string(tile),
                            "UVs in tile 1001, or a UDIM pattern for meshes on several tiles"));
        }
        const std::filesystem::path file =
            perTile ? std::filesystem::path(io::expandUdim(pattern.string(), tile)) : pattern;
        io::Image image = io::readImage(file, {0, "weight map"});
        if (channel < 0 || channel >= image.channels) {
            throw InvalidInput(formatError(source, file.string(),
                                           "has " + std::to_string(image.channels) + " channels, channel " +
                                               std::to_string(channel) + " asked",
                                           "a channel from 0 to " + std::to_string(image.channels - 1)));
        }
        return images.emplace(tile, std::move(image)).first->second;
    };

    const int32_t n = mesh.numVertices();
    std::vector<double> sum(static_cast<size_t>(n), 0.0);
    std::vector<int32_t> count(static_cast<size_t>(n), 0);
    std::vector<float> sample;
    const auto uvs = mesh.uvs();
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const auto corners = mesh.face(f);
        const auto cornerUVs = mesh.faceUVIndices(f);
        if (cornerUVs.empty()) continue;  // a face without UVs reads no map
        const int tile = mesh.faceUdimTile(f);
        const io::Image& image = imageOf(tile, f);
        sample.resize(static_cast<size_t>(image.channels));
        const float tileU = static_cast<float>((tile - 1001) % 10),
                    tileV = static_cast<float>((tile - 1001) / 10);
        for (size_t c = 0; c < corners.size(); ++c) {
            const glm::vec2 uv = uvs[cornerUVs[c]];
            const glm::vec2 pixel((uv.x - tileU) * static_cast<float>(image.width),
                                  (1.0f - (uv.y - tileV)) * static_cast<float>(image.height));
            io::sampleImage(image, pixel, io::SampleFilter::Bilinear, sample);
            sum[static_cast<size_t>(corners[c])] += sample[static_cast<size_t>(channel)];
            ++count[static_cast<size_t>(corners[c])];
        }
    }
    std::vector<float> weights(static_cast<size_t>(n), 0.0f);
    for (int32_t v = 0; v < n; ++v) {
        if (count[static_cast<size_t>(v)] == 0) continue;
        const double w = sum[static_cast<size_t>(v)] / count[static_cast<size_t>(v)];
        if (!std::isfinite(w) || std::abs(w) > 3.0e38) {
            throw InvalidInput(formatError(source, pattern.string(),
                                           "vertex " + std::to_string(v) + " samples " + numberText(w),
                                           "finite weights in the map"));
        }
        weights[static_cast<size_t>(v)] = static_cast<float>(w);
    }
    return weights;
}

}  // namespace deformkit::scene
