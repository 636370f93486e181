#include "deformkit/ptex/ptex_udim.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/io/sampling.h"
#include "deformkit/io/udim.h"
#include "deformkit/ptex/ptex_mesh.h"
#include "deformkit/ptex/ptex_sampler.h"
#include "texel_access.h"

namespace deformkit::ptex {

namespace {

// The UDIM tile of a mesh face, as Mesh::udimTiles counts them (a face that overhangs a tile belongs to it).
int faceTile(const geom::Mesh& mesh, int32_t f) {
    return mesh.faceUdimTile(f);
}

// The UV of (u, v) on Ptex face `ptexFace`, interpolated with PtexMesh::cornerWeights.
glm::dvec2 ptexUV(const PtexMesh& ptexMesh, const geom::Mesh& mesh, int32_t ptexFace, double u, double v,
                  std::vector<double>& weights) {
    const int32_t f = ptexMesh.meshFace(ptexFace);
    const auto corners = mesh.faceUVIndices(f);
    weights.resize(corners.size());
    ptexMesh.cornerWeights(ptexFace, u, v, weights);
    glm::dvec2 uv(0.0);
    for (size_t k = 0; k < corners.size(); ++k)
        uv += weights[k] * glm::dvec2(mesh.uvs()[corners[k]]);
    return uv;
}

void requireUVs(const geom::Mesh& mesh, const PtexMesh& ptexMesh) {
    if (!mesh.hasUVs()) {
        throw InvalidInput(formatError(ptexMesh.source(), "", "has no UVs",
                                       "texture coordinates to convert between UDIM images and Ptex"));
    }
    if (mesh.numFaces() != ptexMesh.numMeshFaces() || mesh.numVertices() != ptexMesh.numVertices()) {
        throw InvalidInput(formatError(
            ptexMesh.source(), "", "differs from the mesh its Ptex faces were built from", "the same mesh"));
    }
}

// Barycentric weights of the point of triangle (a, b, c) nearest to p, and its squared distance.
std::pair<glm::dvec3, double> nearestOnTriangle(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b,
                                                const glm::dvec2& c) {
    const glm::dvec2 ab = b - a, ac = c - a, ap = p - a;
    const double det = ab.x * ac.y - ab.y * ac.x;
    if (det != 0.0) {
        const double l1 = (ap.x * ac.y - ap.y * ac.x) / det;
        const double l2 = (ab.x * ap.y - ab.y * ap.x) / det;
        if (l1 >= 0.0 && l2 >= 0.0 && l1 + l2 <= 1.0) return {{1.0 - l1 - l2, l1, l2}, 0.0};
    }
    // Outside (or degenerate): the nearest point of the three edges.
    std::pair<glm::dvec3, double> best{{1.0, 0.0, 0.0}, glm::dot(ap, ap)};
    const std::array<glm::dvec2, 3> corner{a, b, c};
    for (int e = 0; e < 3; ++e) {
        const glm::dvec2 from = corner[e], to = corner[(e + 1) % 3];
        const glm::dvec2 edge = to - from;
        const double length2 = glm::dot(edge, edge);
        const double t = length2 > 0.0 ? std::clamp(glm::dot(p - from, edge) / length2, 0.0, 1.0) : 0.0;
        const glm::dvec2 q = from + t * edge;
        const double d2 = glm::dot(p - q, p - q);
        if (d2 < best.second) {
            glm::dvec3 l(0.0);
            l[e] = 1.0 - t;
            l[(e + 1) % 3] = t;
            best = {l, d2};
        }
    }
    return best;
}

// Texels whose centre lies in a UV face of `tile` (each face fanned into triangles from its first corner),
// rasterised by the same rule as the faces' cells.
std::vector<uint8_t> chartMask(const geom::Mesh& mesh, int tile, const io::TileOrigin& origin, int32_t res) {
    std::vector<glm::vec2> positions;
    std::vector<std::array<int32_t, 3>> triangles;
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        if (faceTile(mesh, f) != tile) continue;
        const auto corners = mesh.faceUVIndices(f);
        const auto base = static_cast<int32_t>(positions.size());
        for (const int32_t c : corners) {
            const glm::vec2 uv = mesh.uvs()[c];
            positions.emplace_back(static_cast<float>((uv.x - origin.u) * res),
                                   static_cast<float>((1.0 - (uv.y - origin.v)) * res));
        }
        for (int32_t k = 1; k + 1 < static_cast<int32_t>(corners.size()); ++k)
            triangles.push_back({base, base + k, base + k + 1});
    }
    const std::vector<float> attributes(positions.size(), 0.0f);
    geom::AttributeRaster raster;
    geom::rasterizeAttributes({res, res}, positions, triangles, attributes, 1, raster);
    std::vector<uint8_t> mask(raster.triangle.size());
    for (size_t i = 0; i < mask.size(); ++i)
        mask[i] = raster.triangle[i] >= 0 ? 1 : 0;
    return mask;
}

// Gives uncovered texels the (u, v) of the nearest point of a covered 8-neighbour's cell, one ring at a
// time: every texel of `chart` (hairline cracks where the cell grids of two faces meet) and `padding` rings
// around the charts, as texture bakers pad chart edges. Neighbours are taken in a fixed order and ties
// keep the first, and each ring reads the texels as the ring before left them, so the result is the same
// on every run. A ring visits only the texels beside the ones the ring before covered (a texel that could
// take a value earlier took it then): the work is the texels filled, not rings x tile (a padding as large
// as the tile took minutes at 2048^2).
void fillFromNeighbours(geom::AttributeRaster& raster, std::span<const glm::vec2> positions,
                        std::span<const std::array<int32_t, 3>> triangles, std::span<const float> attributes,
                        const std::vector<uint8_t>& chart, int32_t padding) {
    const int32_t w = raster.width, h = raster.height;
    struct Update {
        size_t texel;
        int32_t triangle;
        glm::vec2 uv;
    };
    const auto covered = [&](int32_t x, int32_t y) {
        return x >= 0 && y >= 0 && x < w && y < h && raster.triangle[static_cast<size_t>(y) * w + x] >= 0;
    };
    // Ring 1's candidates: uncovered texels beside a covered one.
    std::vector<size_t> candidates;
    size_t chartLeft = 0;  // chart texels not covered
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            const size_t i = static_cast<size_t>(y) * w + x;
            if (raster.triangle[i] >= 0) continue;
            chartLeft += chart[i] ? 1 : 0;
            bool beside = false;
            for (int32_t dy = -1; dy <= 1 && !beside; ++dy)
                for (int32_t dx = -1; dx <= 1 && !beside; ++dx)
                    beside = covered(x + dx, y + dy);
            if (beside) candidates.push_back(i);
        }
    }
    std::vector<int32_t> queued(static_cast<size_t>(w) * h, 0);  // the ring a texel was last queued for
    std::vector<Update> updates;
    for (int32_t ring = 1;; ++ring) {
        updates.clear();
        for (const size_t i : candidates) {
            if (raster.triangle[i] >= 0 || (!chart[i] && ring > padding)) continue;
            const auto x = static_cast<int32_t>(i % static_cast<size_t>(w));
            const auto y = static_cast<int32_t>(i / static_cast<size_t>(w));
            const glm::dvec2 centre(x + 0.5, y + 0.5);
            double bestD2 = std::numeric_limits<double>::infinity();
            Update best{i, -1, {}};
            for (int32_t dy = -1; dy <= 1; ++dy) {
                for (int32_t dx = -1; dx <= 1; ++dx) {
                    const int32_t nx = x + dx, ny = y + dy;
                    if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                    const int32_t t = raster.triangle[static_cast<size_t>(ny) * w + nx];
                    if (t < 0) continue;
                    const auto& tri = triangles[t];
                    const auto [l, d2] =
                        nearestOnTriangle(centre, positions[tri[0]], positions[tri[1]], positions[tri[2]]);
                    if (d2 >= bestD2) continue;
                    bestD2 = d2;
                    glm::dvec2 uv(0.0);
                    for (int k = 0; k < 3; ++k)
                        uv += l[k] * glm::dvec2(attributes[2 * tri[k]], attributes[2 * tri[k] + 1]);
                    best = {i, t, glm::vec2(uv)};
                }
            }
            if (best.triangle >= 0) updates.push_back(best);
        }
        for (const Update& u : updates) {
            raster.triangle[u.texel] = u.triangle;
            raster.values[2 * u.texel] = u.uv.x;
            raster.values[2 * u.texel + 1] = u.uv.y;
            chartLeft -= chart[u.texel] ? 1 : 0;
        }
        if (updates.empty() || (ring >= padding && chartLeft == 0)) break;
        // The next ring's candidates: uncovered texels beside the ones this ring covered.
        candidates.clear();
        for (const Update& u : updates) {
            const auto x = static_cast<int32_t>(u.texel % static_cast<size_t>(w));
            const auto y = static_cast<int32_t>(u.texel / static_cast<size_t>(w));
            for (int32_t dy = -1; dy <= 1; ++dy) {
                for (int32_t dx = -1; dx <= 1; ++dx) {
                    const int32_t nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                    const size_t n = static_cast<size_t>(ny) * w + nx;
                    if (raster.triangle[n] >= 0 || queued[n] == ring + 1) continue;
                    queued[n] = ring + 1;
                    candidates.push_back(n);
                }
            }
        }
    }
}

}  // namespace

std::vector<UdimTile> ptexToUdim(const PtexMesh& ptexMesh, const geom::Mesh& mesh, const PtexFile& file,
                                 const std::string& fileSource, const ToUdimOptions& options) {
    requireUVs(mesh, ptexMesh);
    ptexMesh.requireMatches(file, fileSource);
    if (options.resolution < 1 || options.resolution > 65536) {
        throw InvalidInput(formatError(fileSource, "resolution", "is " + std::to_string(options.resolution),
                                       "a tile resolution in [1, 65536]"));
    }
    if (options.padding < 0 || options.padding > 65536) {
        throw InvalidInput(formatError(fileSource, "padding", "is " + std::to_string(options.padding),
                                       "texels of edge padding in [0, 65536]"));
    }
    const std::vector<int> meshTiles = mesh.udimTiles();
    std::vector<int> tiles = options.tiles.empty() ? meshTiles : options.tiles;
    for (int tile : tiles) {  // the mesh's own tiles are valid (Mesh::udimTiles); asked-for ones are checked
        if (tile < 1001 || tile > 9999) {
            throw InvalidInput(formatError(fileSource, "tiles", std::to_string(tile) + " is not a UDIM tile",
                                           "tile numbers 1001 to 9999"));
        }
        if (!std::ranges::binary_search(meshTiles, tile)) {  // it would be written blank
            std::string have;
            for (int t : meshTiles)
                have.append(have.empty() ? "" : " ").append(std::to_string(t));
            throw InvalidInput(formatError(fileSource, "tile " + std::to_string(tile),
                                           "the mesh '" + ptexMesh.source() + "' has no UV face in it",
                                           "tiles of the mesh: " + have));
        }
    }
    // A face off its tile (a layout shifted off the UDIM tiles, or across two) would be drawn outside the
    // tile's image: its texels would be missing without a word.
    const auto tileSource = [&](int tile) {
        return ptexMesh.source() + ", UDIM tile " + std::to_string(tile);
    };
    for (int tile : tiles)
        geom::requireUdimFacesInTile(mesh, tile, tileSource);
    const PtexSampler sampler(file, fileSource, options.maxDecodedBytes);
    const int32_t channels = sampler.channels(), res = options.resolution;
    const int32_t outChannels = channels + (options.coverageChannel ? 1 : 0);

    std::vector<UdimTile> out;
    std::vector<double> weights;
    std::vector<float> value(static_cast<size_t>(channels));
    for (int tile : tiles) {
        const io::TileOrigin origin = io::udimOrigin(tile);
        // Every Ptex face of the tile as a grid of n x n cells (two triangles each) carrying (u, v).
        std::vector<glm::vec2> positions;
        std::vector<float> attributes;
        std::vector<std::array<int32_t, 3>> triangles;
        std::vector<int32_t> triangleFace;
        for (int32_t p = 0; p < ptexMesh.numPtexFaces(); ++p) {
            if (faceTile(mesh, ptexMesh.meshFace(p)) != tile) continue;
            // Cells no larger than ~4 texels of the tile so the bilinear map is followed closely.
            glm::dvec2 lo(1e30), hi(-1e30);
            for (double cu : {0.0, 1.0})
                for (double cv : {0.0, 1.0}) {
                    const glm::dvec2 uv = ptexUV(ptexMesh, mesh, p, cu, cv, weights);
                    lo = glm::min(lo, uv), hi = glm::max(hi, uv);
                }
            const double extent = std::max(hi.x - lo.x, hi.y - lo.y) * res;
            const auto n = std::clamp(static_cast<int32_t>(std::ceil(extent / 4.0)), 1, 64);
            const auto base = static_cast<int32_t>(positions.size());
            for (int32_t b = 0; b <= n; ++b) {
                for (int32_t a = 0; a <= n; ++a) {
                    const double u = static_cast<double>(a) / n, v = static_cast<double>(b) / n;
                    const glm::dvec2 uv = ptexUV(ptexMesh, mesh, p, u, v, weights);
                    positions.emplace_back(static_cast<float>((uv.x - origin.u) * res),
                                           static_cast<float>((1.0 - (uv.y - origin.v)) * res));
                    attributes.push_back(static_cast<float>(u));
                    attributes.push_back(static_cast<float>(v));
                }
            }
            for (int32_t b = 0; b < n; ++b) {
                for (int32_t a = 0; a < n; ++a) {
                    const int32_t v00 = base + b * (n + 1) + a, v10 = v00 + 1, v01 = v00 + n + 1,
                                  v11 = v01 + 1;
                    triangles.push_back({v00, v10, v11});
                    triangles.push_back({v00, v11, v01});
                    triangleFace.push_back(p);
                    triangleFace.push_back(p);
                }
            }
        }
        geom::AttributeRaster raster;
        geom::rasterizeAttributes({res, res}, positions, triangles, attributes, 2, raster);
        const std::vector<uint8_t> chart = chartMask(mesh, tile, origin, res);
        fillFromNeighbours(raster, positions, triangles, attributes, chart, options.padding);
        UdimTile result{tile, io::Image(res, res, outChannels, 0.0f), {}};
        for (int32_t y = 0; y < res; ++y) {
            for (int32_t x = 0; x < res; ++x) {
                const size_t pixel = static_cast<size_t>(y) * res + x;
                const int32_t t = raster.triangle[pixel];
                if (t < 0) continue;
                sampler.sample(triangleFace[t], raster.values[pixel * 2], raster.values[pixel * 2 + 1],
                               value);
                for (int32_t c = 0; c < channels; ++c)
                    result.image.at(x, y, c) = value[c];
                if (options.coverageChannel && chart[pixel]) result.image.at(x, y, channels) = 1.0f;
            }
        }
        out.push_back(std::move(result));
    }
    return out;
}

PtexFile udimToPtex(const PtexMesh& ptexMesh, const geom::Mesh& mesh, std::span<const UdimTile> tiles,
                    const FromUdimOptions& options) {
    requireUVs(mesh, ptexMesh);
    if (tiles.empty()) {
        throw InvalidInput(formatError(ptexMesh.source(), "UDIM tiles", "none given", "at least one tile"));
    }
    std::map<int, const io::Image*> byTile;
    const int32_t channels = tiles.front().image.channels;
    for (const UdimTile& t : tiles) {
        if (t.image.channels != channels || t.image.width < 1 || t.image.height < 1) {
            throw InvalidInput(formatError("UDIM tile " + std::to_string(t.tile), "",
                                           "has " + std::to_string(t.image.width) + "x" +
                                               std::to_string(t.image.height) + " pixels of " +
                                               std::to_string(t.image.channels) + " channels",
                                           std::to_string(channels) + " channels like tile " +
                                               std::to_string(tiles.front().tile) + ", at least 1x1"));
        }
        byTile[t.tile] = &t.image;
        for (size_t k = 0; k < t.image.pixels.size(); ++k) {
            if (std::isfinite(t.image.pixels[k])) continue;
            const auto c = static_cast<int32_t>(k % static_cast<size_t>(channels));
            const auto texel = static_cast<int64_t>(k / static_cast<size_t>(channels));
            throw InvalidInput(
                formatError(t.source.empty() ? "UDIM tile " + std::to_string(t.tile) : t.source,
                            "texel (" + std::to_string(texel % t.image.width) + ", " +
                                std::to_string(texel / t.image.width) + ") channel " + std::to_string(c),
                            "is " + numberText(t.image.pixels[k]), "a finite value"));
        }
    }
    if (channels < 1 || channels > 64) {
        const UdimTile& first = tiles.front();
        throw InvalidInput(formatError(
            first.source.empty() ? "UDIM tile " + std::to_string(first.tile) : first.source, "",
            "has " + std::to_string(channels) + " channels", "1 to 64 channels (a Ptex file's most)"));
    }

    const auto fixedLog2 = [](int8_t value, const char* name) {
        if (value < -1 || value > 15) {
            throw InvalidInput(formatError("from-udim", name, "is " + std::to_string(value),
                                           "-1 (from the image) or a log2 size in [0, 15]"));
        }
        return value;
    };
    const int8_t ulog2 = fixedLog2(options.ulog2, "ulog2"), vlog2 = fixedLog2(options.vlog2, "vlog2");

    PtexFile file;
    file.meshType = MeshType::Quad;
    file.dataType = options.dataType;
    file.channels = channels;
    file.faces = ptexMesh.faceInfos(0, 0);
    file.texels.resize(file.faces.size());
    file.constData.assign(file.faces.size() * file.pixelSize(), 0);
    const size_t bytes = bytesPerChannel(options.dataType);
    std::vector<double> weights;
    std::vector<float> value(static_cast<size_t>(channels));
    const auto log2Near = [](double texels) {
        return static_cast<int8_t>(
            std::clamp(static_cast<int>(std::lround(std::log2(std::max(texels, 1.0)))), 0, 12));
    };
    // A face off its tile would be read from the tile's clamped edge texels.
    geom::requireUdimFacesInTile(
        mesh, 0, [&](int tile) { return ptexMesh.source() + ", UDIM tile " + std::to_string(tile); });
    for (int32_t p = 0; p < ptexMesh.numPtexFaces(); ++p) {
        const int32_t f = ptexMesh.meshFace(p);
        if (!mesh.faceHasUVs(f)) {  // in no tile: 0, at the fixed resolution or 1 × 1
            FaceInfo& info = file.faces[p];
            info.ulog2 = std::max<int8_t>(ulog2, 0);
            info.vlog2 = std::max<int8_t>(vlog2, 0);
            file.texels[p].assign(info.texelCount() * file.pixelSize(), 0);
            continue;
        }
        const int tile = faceTile(mesh, f);
        const auto found = byTile.find(tile);
        if (found == byTile.end()) {
            throw InvalidInput(formatError(ptexMesh.source(), "face " + std::to_string(f),
                                           "lies in UDIM tile " + std::to_string(tile),
                                           "an image for every tile the mesh uses"));
        }
        const io::Image& image = *found->second;
        const io::TileOrigin origin = io::udimOrigin(tile);
        FaceInfo& info = file.faces[p];
        // Automatic resolution: per axis, the mean length of the face's two edges along it in tile texels.
        const glm::dvec2 size(image.width, image.height);
        const auto edge = [&](double u0, double v0, double u1, double v1) {
            return glm::length(
                (ptexUV(ptexMesh, mesh, p, u1, v1, weights) - ptexUV(ptexMesh, mesh, p, u0, v0, weights)) *
                size);
        };
        info.ulog2 = ulog2 >= 0 ? ulog2 : log2Near(0.5 * (edge(0, 0, 1, 0) + edge(0, 1, 1, 1)));
        info.vlog2 = vlog2 >= 0 ? vlog2 : log2Near(0.5 * (edge(0, 0, 0, 1) + edge(1, 0, 1, 1)));
        std::vector<uint8_t>& texels = file.texels[p];
        texels.resize(info.texelCount() * file.pixelSize());
        for (int32_t j = 0; j < info.vres(); ++j) {
            for (int32_t i = 0; i < info.ures(); ++i) {
                const glm::dvec2 uv =
                    ptexUV(ptexMesh, mesh, p, (i + 0.5) / info.ures(), (j + 0.5) / info.vres(), weights);
                const glm::vec2 pixel(static_cast<float>((uv.x - origin.u) * image.width),
                                      static_cast<float>((1.0 - (uv.y - origin.v)) * image.height));
                io::sampleImage(image, pixel, io::SampleFilter::Bilinear, value);
                for (int32_t c = 0; c < channels; ++c) {
                    // A value beyond the type's range would be clamped (u8, u16) or become inf (half).
                    if (const std::string range = detail::outsideTypeRange(value[c], options.dataType);
                        !range.empty()) {
                        throw InvalidInput(formatError("UDIM tile " + std::to_string(tile),
                                                       "pixel (" + std::to_string(pixel.x) + ", " +
                                                           std::to_string(pixel.y) + ") channel " +
                                                           std::to_string(c) + ", read for mesh face " +
                                                           std::to_string(f),
                                                       "is " + numberText(value[c]), range));
                    }
                    const size_t at = ((static_cast<size_t>(j) * info.ures() + i) * channels + c) * bytes;
                    detail::storeValue(value[c], options.dataType, texels.data() + at);
                }
            }
        }
    }
    return file;
}

}  // namespace deformkit::ptex
