#include "demo_assets.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/geom/triangulation.h"
#include "deformkit/io/udim.h"

namespace deformkit::harness {
namespace {

// Signed distance (tile-local UV units, negative inside) of every feature of a tile, combined by min.
using Sdf = std::function<float(glm::vec2)>;

float circle(glm::vec2 p, glm::vec2 c, float r) {
    return glm::length(p - c) - r;
}

// Distance along u wraps at the tube's seam, so features may straddle it.
glm::vec2 wrapU(glm::vec2 p, glm::vec2 c) {
    float du = p.x - c.x;
    du -= std::round(du);
    return {c.x + du, p.y};
}

Sdf sideFeatures() {
    // A small fixed LCG keeps the disk layout identical on every platform.
    struct Disk {
        glm::vec2 c;
        float r;
    };
    std::vector<Disk> disks;
    uint32_t state = 12345u;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return static_cast<float>(state >> 8) / static_cast<float>(1u << 24);
    };
    for (int i = 0; i < 14; ++i)
        disks.push_back({{next(), 0.06f + 0.32f * next()}, 0.025f + 0.03f * next()});
    return [disks](glm::vec2 p) {
        float d = std::abs(p.y - 0.485f) - 0.035f;  // armour band around the tube
        for (const Disk& k : disks)
            d = std::min(d, circle(wrapU(p, k.c), k.c, k.r));
        // Scales: staggered rows of small ellipses in v in [0.62, 0.94].
        if (p.y > 0.6f && p.y < 0.96f) {
            const float rowH = 0.04f, colW = 0.05f;
            const int row = static_cast<int>(std::floor((p.y - 0.62f) / rowH + 0.5f));
            for (int dr = -1; dr <= 1; ++dr) {
                const int r = row + dr;
                if (r < 0 || r > 8) continue;
                const float cy = 0.62f + r * rowH;
                const float offset = (r % 2) * 0.5f * colW;
                const float cx = std::round((p.x - offset) / colW) * colW + offset;
                for (int dc = -1; dc <= 1; ++dc) {
                    const glm::vec2 q = (p - glm::vec2(cx + dc * colW, cy)) / glm::vec2(0.021f, 0.016f);
                    d = std::min(d, (glm::length(q) - 1.0f) * 0.016f);
                }
            }
        }
        return d;
    };
}

Sdf capFeatures() {
    return [](glm::vec2 p) {
        float d = 1e9f;
        for (const float cx : {0.25f, 0.75f}) {
            const glm::vec2 c(cx, 0.5f);
            d = std::min(d, std::abs(glm::length(p - c) - 0.165f) - 0.018f);  // ring
            d = std::min(d, circle(p, c, 0.05f));                             // central boss
        }
        return d;
    };
}

}  // namespace

io::Image demoRigidity(int tile, int32_t resolution) {
    if (tile != 1001 && tile != 1002) {
        throw InvalidInput(formatError("demo", "tile " + std::to_string(tile), "has no demo rigidity map",
                                       "tile 1001 or 1002"));
    }
    const Sdf sdf = tile == 1001 ? sideFeatures() : capFeatures();
    io::Image img(resolution, resolution, 1);
    for (int32_t y = 0; y < resolution; ++y) {
        for (int32_t x = 0; x < resolution; ++x) {
            const glm::vec2 uv((x + 0.5f) / resolution, 1.0f - (y + 0.5f) / resolution);
            // Coverage of a one-texel-wide ramp across the feature edge.
            img.at(x, y, 0) = std::clamp(0.5f - sdf(uv) * resolution, 0.0f, 1.0f);
        }
    }
    return img;
}

io::Image chartWarpMask(const geom::Mesh& mesh, int tile, int32_t resolution, int32_t borderTexels) {
    if (!mesh.hasUVs()) {
        throw InvalidInput(formatError("demo", "mesh", "has no UVs", "a UV-mapped mesh"));
    }
    const io::TileOrigin origin = io::udimOrigin(tile);
    const geom::Triangulation tris = geom::triangulate(mesh);
    std::vector<glm::vec2> raster;
    std::vector<std::array<int32_t, 3>> triangles;
    for (int32_t t = 0; t < tris.size(); ++t) {
        std::array<int32_t, 3> idx{};
        for (int k = 0; k < 3; ++k) {
            const glm::vec2 uv = mesh.uvs()[mesh.uvIndices()[tris.corners[t][k]]];
            idx[k] = static_cast<int32_t>(raster.size());
            // Image row 0 is the top of the tile (v = 1).
            raster.emplace_back((uv.x - origin.u) * resolution, (1.0f - (uv.y - origin.v)) * resolution);
        }
        triangles.push_back(idx);
    }
    geom::AttributeRaster coverage;
    geom::rasterizeAttributes({resolution, resolution}, raster, triangles, {}, 0, coverage);

    // Erode the coverage by a square of radius borderTexels (separable min: rows, then columns).
    std::vector<uint8_t> covered(coverage.triangle.size()), rows(coverage.triangle.size());
    for (size_t i = 0; i < covered.size(); ++i)
        covered[i] = coverage.triangle[i] >= 0 ? 1 : 0;
    const int32_t n = resolution, b = borderTexels;
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            uint8_t m = 1;
            for (int32_t dx = -b; dx <= b && m; ++dx) {
                const int32_t xx = x + dx;
                m = (xx >= 0 && xx < n) ? covered[static_cast<size_t>(y) * n + xx] : 0;
            }
            rows[static_cast<size_t>(y) * n + x] = m;
        }
    }
    io::Image mask(n, n, 1);
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            uint8_t m = 1;
            for (int32_t dy = -b; dy <= b && m; ++dy) {
                const int32_t yy = y + dy;
                m = (yy >= 0 && yy < n) ? rows[static_cast<size_t>(yy) * n + x] : 0;
            }
            mask.at(x, y, 0) = m;
        }
    }
    return mask;
}

DemoAssets makeDemoAssets(const DemoOptions& options) {
    if (options.resolution < 16 || options.resolution > 8192) {
        throw InvalidInput(formatError("demo", "resolution", std::to_string(options.resolution) + " texels",
                                       "16 to 8192 texels per tile side"));
    }
    DemoAssets assets{geom::makeCappedTube(), {}, {}, {}};
    const int32_t n = options.resolution;
    for (const int tile : assets.mesh.udimTiles()) {
        io::Image rigidity = demoRigidity(tile, n);
        io::Image albedo(n, n, 3);
        const glm::vec3 skin(0.86f, 0.62f, 0.50f), armour(0.28f, 0.42f, 0.62f);
        const int32_t cell = std::max(n / 32, 2);
        for (int32_t y = 0; y < n; ++y) {
            for (int32_t x = 0; x < n; ++x) {
                // A thin grid makes stretch visible; features take the armour colour.
                const bool line = (x % cell) == 0 || (y % cell) == 0;
                const glm::vec3 c = glm::mix(skin, armour, rigidity.at(x, y, 0)) * (line ? 0.7f : 1.0f);
                for (int k = 0; k < 3; ++k)
                    albedo.at(x, y, k) = c[k];
            }
        }
        assets.mask.emplace(tile, chartWarpMask(assets.mesh, tile, n, options.borderTexels));
        assets.rigidity.emplace(tile, std::move(rigidity));
        assets.albedo.emplace(tile, std::move(albedo));
    }
    return assets;
}

}  // namespace deformkit::harness
