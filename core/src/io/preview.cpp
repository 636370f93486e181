#include "deformkit/io/preview.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"
#include "deformkit/geom/normals.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/geom/triangulation.h"
#include "deformkit/geom/weld.h"
#include "deformkit/io/udim.h"
#include "geom/rasterize_triangle.h"

namespace deformkit::io {
namespace {

glm::vec3 texel(const Image& img, int32_t x, int32_t y) {
    const float* p = &img.pixels[(static_cast<size_t>(y) * img.width + x) * img.channels];
    if (img.channels >= 3) return {p[0], p[1], p[2]};
    return glm::vec3(p[0]);
}

// Bilinear look-up at (s, t) in [0, 1]^2 with t = 0 at the image's bottom row (UV convention).
glm::vec3 sampleBilinear(const Image& img, float s, float t) {
    const float fx = std::clamp(s, 0.0f, 1.0f) * img.width - 0.5f;
    const float fy = (1.0f - std::clamp(t, 0.0f, 1.0f)) * img.height - 0.5f;
    const int32_t x0 = static_cast<int32_t>(std::floor(fx)), y0 = static_cast<int32_t>(std::floor(fy));
    const float ax = fx - x0, ay = fy - y0;
    auto at = [&](int32_t x, int32_t y) {
        return texel(img, std::clamp(x, 0, img.width - 1), std::clamp(y, 0, img.height - 1));
    };
    return glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), ax),
                    glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), ax), ay);
}

std::optional<glm::vec3> sampleTexture(const PreviewTexture& tex, const glm::vec2& uv) {
    if (tex.single) return sampleBilinear(*tex.single, uv.x - std::floor(uv.x), uv.y - std::floor(uv.y));
    const int tile = geom::udimTileOf(uv);
    const auto it = tex.tiles.find(tile);
    if (it == tex.tiles.end()) return std::nullopt;
    return sampleBilinear(it->second, uv.x - std::floor(uv.x), uv.y - std::floor(uv.y));
}

}  // namespace

PreviewTexture loadPreviewTexture(const std::filesystem::path& pathOrPattern) {
    PreviewTexture tex;
    if (hasUdimToken(pathOrPattern.string())) {
        for (const UdimFile& f : findUdimFiles(pathOrPattern))
            tex.tiles.emplace(f.tile, readImage(f.path));
    } else {
        tex.single = readImage(pathOrPattern);
    }
    return tex;
}

glm::vec3 weightColor(float weight) {
    // Piecewise linear through blue, cyan, green, yellow and red at 0, 1/4, 1/2, 3/4 and 1.
    static constexpr glm::vec3 stops[5] = {
        {0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 1.0f}, {0.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}};
    const float x = std::isnan(weight) ? 0.0f : 4.0f * std::clamp(weight, 0.0f, 1.0f);
    const int i = std::min(static_cast<int>(x), 3);
    return stops[i] + (x - static_cast<float>(i)) * (stops[i + 1] - stops[i]);
}

Image renderPreview(const geom::Mesh& mesh, const PreviewOptions& o, const PreviewTexture* texture) {
    if (mesh.numFaces() == 0) {
        throw InvalidInput(formatError("preview", "mesh", "has no faces", "a mesh with at least one face"));
    }
    if (texture && !mesh.hasUVs()) {
        throw InvalidInput(
            formatError("preview", "mesh", "has no UVs but a texture was given", "a mesh with UVs"));
    }
    if (!o.vertexColors.empty() && o.vertexColors.size() != static_cast<size_t>(mesh.numVertices())) {
        throw InvalidInput(formatError("preview", "vertex colours",
                                       "has " + std::to_string(o.vertexColors.size()) + " colours",
                                       std::to_string(mesh.numVertices()) + ", one per vertex"));
    }
    // Points and UVs as they are now (a host may have written them after the mesh was made): a NaN is named
    // as the vertex or UV it is, not as a corner of a triangle being drawn.
    if (const size_t bad = geom::firstNonFinite(mesh.points()); bad < mesh.points().size()) {
        const glm::vec3 p = mesh.points()[bad];
        throw InvalidInput(
            formatError("preview", "vertex " + std::to_string(bad),
                        "is (" + numberText(p.x) + ", " + numberText(p.y) + ", " + numberText(p.z) + ")",
                        "finite coordinates"));
    }
    if (texture) {
        const auto uvs = mesh.uvs();
        for (size_t i = 0; i < uvs.size(); ++i) {
            if (!std::isfinite(uvs[i].x) || !std::isfinite(uvs[i].y)) {
                throw InvalidInput(
                    formatError("preview", "UV " + std::to_string(i),
                                "is (" + numberText(uvs[i].x) + ", " + numberText(uvs[i].y) + ")",
                                "finite texture coordinates"));
            }
        }
    }
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384) {
        throw InvalidInput(formatError("preview", "size",
                                       std::to_string(o.width) + "x" + std::to_string(o.height) + " pixels",
                                       "1 to 16384 pixels per side"));
    }

    // Camera: auto-framed on the bounding sphere (of the mesh, or of the box asked for).
    const geom::Box3 box = o.frame ? *o.frame : mesh.bounds();
    const glm::vec3 centre = box.center();
    const float radius = std::max(0.5f * glm::length(box.extent()), 1e-6f);
    const double viewLength = glm::length(glm::dvec3(o.viewDirection));
    if (!std::isfinite(viewLength) || !(viewLength > 0.0)) {
        throw InvalidInput(formatError("preview", "view direction",
                                       "is (" + numberText(o.viewDirection.x) + ", " +
                                           numberText(o.viewDirection.y) + ", " +
                                           numberText(o.viewDirection.z) + ")",
                                       "three finite numbers, not all 0"));
    }
    // Normalised in float as before; in double where float's length overflows (components near 1e30).
    const float floatLength = glm::length(o.viewDirection);
    const glm::vec3 forward = std::isfinite(floatLength) && floatLength > 0.0f
                                  ? glm::normalize(o.viewDirection)
                                  : glm::vec3(glm::dvec3(o.viewDirection) / viewLength);
    const glm::vec3 worldUp =
        std::abs(forward.y) > 0.99f ? glm::vec3(0.0f, 0.0f, -1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    const glm::vec3 right = glm::normalize(glm::cross(forward, worldUp));
    const glm::vec3 up = glm::cross(right, forward);
    const float halfFov = 0.5f * o.fieldOfViewDegrees * std::numbers::pi_v<float> / 180.0f;
    const float fitHalfAngle =
        o.width < o.height ? std::atan(std::tan(halfFov) * o.width / o.height) : halfFov;
    const float distance = 1.08f * radius / std::sin(fitHalfAngle);
    const glm::vec3 eye = centre - forward * distance;
    const float focal = 0.5f * o.height / std::tan(halfFov);

    const auto points = mesh.points();
    std::vector<glm::vec3> view(points.size());  // camera space: x right, y up, z depth
    std::vector<glm::vec2> screen(points.size());
    for (size_t v = 0; v < points.size(); ++v) {
        const glm::vec3 d = points[v] - eye;
        view[v] = {glm::dot(d, right), glm::dot(d, up), glm::dot(d, forward)};
        const float z = std::max(view[v].z, 1e-6f);
        screen[v] = {0.5f * o.width + focal * view[v].x / z, 0.5f * o.height - focal * view[v].y / z};
    }
    // Normals over the welded mesh: split vertices (UV seams, a glTF's per-triangle corners) shade smoothly
    // across the split, as the surface they describe.
    std::vector<glm::vec3> normals(static_cast<size_t>(mesh.numVertices()));
    const geom::Welding weld = geom::weldVertices(mesh, 0.0, "preview");
    if (weld.merged() > 0) {
        const std::vector<glm::vec3> welded = geom::vertexNormals(weld.mesh);
        geom::scatterToCopies<glm::vec3>(weld, welded, normals);
    } else {
        normals = geom::vertexNormals(mesh);
    }
    const geom::Triangulation tris = geom::triangulate(mesh);

    Image image(o.width, o.height, 3);
    for (int32_t i = 0; i < o.width * o.height; ++i) {
        image.pixels[3 * i + 0] = o.background.r;
        image.pixels[3 * i + 1] = o.background.g;
        image.pixels[3 * i + 2] = o.background.b;
    }
    std::vector<float> depth(static_cast<size_t>(o.width) * o.height, std::numeric_limits<float>::infinity());

    const glm::vec3 keyLight = glm::normalize(-forward + 0.8f * up + 0.6f * right);
    const auto faceIndices = mesh.faceIndices();
    const auto uvIndices = mesh.uvIndices();
    const auto faceOffsets = mesh.faceOffsets();
    const float nearPlane = 1e-3f * distance;
    const geom::RasterGrid grid{o.width, o.height};

    for (int32_t t = 0; t < tris.size(); ++t) {
        const auto& c = tris.corners[t];
        const int32_t v0 = faceIndices[c[0]], v1 = faceIndices[c[1]], v2 = faceIndices[c[2]];
        if (view[v0].z < nearPlane || view[v1].z < nearPlane || view[v2].z < nearPlane) continue;
        const glm::vec3 invZ(1.0f / view[v0].z, 1.0f / view[v1].z, 1.0f / view[v2].z);

        // Which triangle edges are polygon edges (the fan's diagonals are not).
        const int32_t f = tris.face[t];
        const int32_t first = faceOffsets[f], last = faceOffsets[f + 1] - 1;
        const bool edgeReal[3] = {true /* c1-c2 */, c[2] == last /* c2-c0 */, c[1] == first + 1 /* c0-c1 */};
        const glm::vec2 s0 = screen[v0], s1 = screen[v1], s2 = screen[v2];
        const float area2 = std::abs((s1.x - s0.x) * (s2.y - s0.y) - (s2.x - s0.x) * (s1.y - s0.y));
        const glm::vec3 heights(area2 / std::max(glm::length(s2 - s1), 1e-6f),
                                area2 / std::max(glm::length(s0 - s2), 1e-6f),
                                area2 / std::max(glm::length(s1 - s0), 1e-6f));

        geom::rasterizeTriangle(grid, s0, s1, s2, [&](int32_t x, int32_t y, const glm::vec3& b) {
            // Perspective-correct weights from screen-space barycentrics.
            glm::vec3 w = b * invZ;
            const float sum = w.x + w.y + w.z;
            w /= sum;
            const float z = 1.0f / sum;
            const size_t pix = static_cast<size_t>(y) * o.width + x;
            if (z >= depth[pix]) return;
            depth[pix] = z;

            glm::vec3 n = w.x * normals[v0] + w.y * normals[v1] + w.z * normals[v2];
            n = glm::length(n) > 0.0f ? glm::normalize(n) : -forward;
            if (glm::dot(n, forward) > 0.0f) n = -n;  // two-sided
            const float light = 0.18f + 0.52f * std::max(0.0f, glm::dot(n, keyLight)) +
                                0.38f * std::max(0.0f, -glm::dot(n, forward));
            glm::vec3 albedo = o.vertexColors.empty() ? o.baseColor
                                                      : w.x * o.vertexColors[v0] + w.y * o.vertexColors[v1] +
                                                            w.z * o.vertexColors[v2];
            if (texture && uvIndices[c[0]] >= 0) {  // a face without UVs keeps the base colour
                const glm::vec2 uv = w.x * mesh.uvs()[uvIndices[c[0]]] + w.y * mesh.uvs()[uvIndices[c[1]]] +
                                     w.z * mesh.uvs()[uvIndices[c[2]]];
                if (auto s = sampleTexture(*texture, uv)) albedo = *s;
            }
            glm::vec3 colour = albedo * light;
            if (o.drawEdges) {
                for (int k = 0; k < 3; ++k) {
                    if (edgeReal[k] && b[k] * heights[k] < 0.8f) colour *= 0.45f;
                }
            }
            float* out = &image.pixels[3 * pix];
            out[0] = std::clamp(colour.r, 0.0f, 1.0f);
            out[1] = std::clamp(colour.g, 0.0f, 1.0f);
            out[2] = std::clamp(colour.b, 0.0f, 1.0f);
        });
    }
    return image;
}

}  // namespace deformkit::io
