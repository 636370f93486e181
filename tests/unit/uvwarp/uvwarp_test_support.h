#pragma once

// Meshes and helpers shared by the uvwarp unit tests.

#include <cmath>
#include <functional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/uvwarp/grid.h"

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace deformkit::test {

// A quad grid chart covering UV rectangle [lo, hi] (absolute UVs, so tile offsets included) with
// cellsU x cellsV quads; vertex positions from `position(uv)`. `unwelded` gives every face corner its own
// UV index (as some exporters write), with equal values at shared corners.
inline geom::Mesh planarChart(glm::vec2 lo, glm::vec2 hi, int cellsU, int cellsV,
                              const std::function<glm::vec3(glm::vec2)>& position, bool unwelded = false) {
    geom::Mesh::Data data;
    auto vertex = [&](int a, int b) { return b * (cellsU + 1) + a; };
    for (int b = 0; b <= cellsV; ++b) {
        for (int a = 0; a <= cellsU; ++a) {
            const glm::vec2 uv(lo.x + (hi.x - lo.x) * static_cast<float>(a) / static_cast<float>(cellsU),
                               lo.y + (hi.y - lo.y) * static_cast<float>(b) / static_cast<float>(cellsV));
            data.points.push_back(position(uv));
            data.uvs.push_back(uv);
        }
    }
    for (int b = 0; b < cellsV; ++b) {
        for (int a = 0; a < cellsU; ++a) {
            data.faceCounts.push_back(4);
            for (int c : {vertex(a, b), vertex(a + 1, b), vertex(a + 1, b + 1), vertex(a, b + 1)}) {
                data.faceIndices.push_back(c);
                if (unwelded) {
                    data.uvIndices.push_back(static_cast<int32_t>(data.uvs.size()));
                    data.uvs.push_back(data.uvs[c]);
                } else {
                    data.uvIndices.push_back(c);
                }
            }
        }
    }
    return geom::Mesh(std::move(data), "chart");
}

// Two charts, one per tile (1001 and 1002), 12 x 12 quads each; the rest positions are the tile-local UVs
// (the second chart lifted to z = 1).
inline geom::Mesh twoTileCharts() {
    const auto chart = [](glm::vec2 lo, float z) {
        return planarChart(lo, lo + glm::vec2(1.0f), 12, 12,
                           [lo, z](glm::vec2 uv) { return glm::vec3(uv - lo, z); });
    };
    const geom::Mesh a = chart({0.0f, 0.0f}, 0.0f), b = chart({1.0f, 0.0f}, 1.0f);
    geom::Mesh::Data data;
    for (const geom::Mesh* m : {&a, &b}) {
        const auto offset = static_cast<int32_t>(data.points.size());
        const auto uvOffset = static_cast<int32_t>(data.uvs.size());
        data.points.insert(data.points.end(), m->points().begin(), m->points().end());
        data.uvs.insert(data.uvs.end(), m->uvs().begin(), m->uvs().end());
        data.faceCounts.insert(data.faceCounts.end(), m->faceCounts().begin(), m->faceCounts().end());
        for (int32_t i : m->faceIndices())
            data.faceIndices.push_back(i + offset);
        for (int32_t i : m->uvIndices())
            data.uvIndices.push_back(i + uvOffset);
    }
    return geom::Mesh(std::move(data), "two tiles");
}

// Frame f of a shot of twoTileCharts(): u stretched by 1 + 0.15 (f - 1) and the sheet bent slightly, so every
// frame differs.
inline std::vector<glm::vec3> stretchedAndBent(const geom::Mesh& rest, int frame) {
    std::vector<glm::vec3> points(rest.points().begin(), rest.points().end());
    const float s = 1.0f + 0.15f * static_cast<float>(frame - 1);
    for (glm::vec3& p : points) {
        p.x *= s;
        p.z += 0.05f * static_cast<float>(frame - 1) * p.x * p.x;
    }
    return points;
}

// Two rigid disks in the middle of a texels x texels map (rows from the top).
inline io::Image twoDisks(int texels) {
    io::Image image(texels, texels, 1);
    for (int y = 0; y < texels; ++y)
        for (int x = 0; x < texels; ++x)
            for (double c : {0.3, 0.7})
                if (std::hypot((x + 0.5) / texels - c, 1.0 - (y + 0.5) / texels - 0.5) < 0.12)
                    image.at(x, y, 0) = 1.0f;
    return image;
}

// An open cylinder of radius 1 around the y axis, y in [0, height], `segments` quads around and `rows`
// along; its UVs fill [lo, hi] with a seam: the vertices at angle 0 carry u = lo.x on one side and
// u = hi.x on the other. Angle 2 pi s / segments, position (cos, y, sin).
inline geom::Mesh seamCylinder(int segments, int rows, float height, glm::vec2 lo, glm::vec2 hi) {
    geom::Mesh::Data data;
    for (int r = 0; r <= rows; ++r) {
        for (int s = 0; s < segments; ++s) {
            const double angle = 2.0 * M_PI * s / segments;
            data.points.emplace_back(static_cast<float>(std::cos(angle)),
                                     height * static_cast<float>(r) / rows,
                                     static_cast<float>(std::sin(angle)));
        }
        for (int s = 0; s <= segments; ++s) {
            data.uvs.emplace_back(lo.x + (hi.x - lo.x) * static_cast<float>(s) / static_cast<float>(segments),
                                  lo.y + (hi.y - lo.y) * static_cast<float>(r) / static_cast<float>(rows));
        }
    }
    for (int r = 0; r < rows; ++r) {
        for (int s = 0; s < segments; ++s) {
            data.faceCounts.push_back(4);
            const int s1 = (s + 1) % segments;
            for (int c :
                 {r * segments + s, r * segments + s1, (r + 1) * segments + s1, (r + 1) * segments + s})
                data.faceIndices.push_back(c);
            for (int c : {r * (segments + 1) + s, r * (segments + 1) + s + 1,
                          (r + 1) * (segments + 1) + s + 1, (r + 1) * (segments + 1) + s})
                data.uvIndices.push_back(c);
        }
    }
    return geom::Mesh(std::move(data), "cylinder");
}

// Runs `body` with `threads` OpenMP threads, restoring the previous count.
template <class Body>
auto withThreads(int threads, Body&& body) {
#if defined(_OPENMP)
    const int previous = omp_get_max_threads();
    omp_set_num_threads(threads);
    auto result = body();
    omp_set_num_threads(previous);
    return result;
#else
    (void)threads;
    return body();
#endif
}

// A warp grid with point (i, j) at w(i / n, j / n), evaluated in double.
inline uvwarp::WarpGrid warpFrom(int32_t cells, const std::function<glm::dvec2(double, double)>& w) {
    uvwarp::WarpGrid grid;
    grid.cells = cells;
    for (int32_t j = 0; j <= cells; ++j) {
        for (int32_t i = 0; i <= cells; ++i) {
            const glm::dvec2 p = w(static_cast<double>(i) / cells, static_cast<double>(j) / cells);
            grid.u.push_back(static_cast<float>(p.x));
            grid.v.push_back(static_cast<float>(p.y));
        }
    }
    return grid;
}

// A point field of `cells` + 1 points a side with `channels` values per point, f(u, v, out) at the grid point
// (i / cells, j / cells).
inline uvwarp::PointField pointField(int32_t cells, int32_t channels,
                                     const std::function<void(float, float, float*)>& f) {
    uvwarp::PointField out;
    out.cells = cells;
    out.channels = channels;
    out.values.resize(static_cast<size_t>(cells + 1) * (cells + 1) * channels);
    for (int32_t j = 0; j <= cells; ++j)
        for (int32_t i = 0; i <= cells; ++i)
            f(static_cast<float>(i) / cells, static_cast<float>(j) / cells, &out.values[out.index(i, j)]);
    return out;
}

// Rigid disks of radius 0.07 on a 3 x 3 lattice over an elastic background: 1 inside a disk, else 0.
inline float latticeDisks(float u, float v) {
    for (float cu : {0.25f, 0.5f, 0.75f})
        for (float cv : {0.25f, 0.5f, 0.75f})
            if (std::hypot(u - cu, v - cv) < 0.07f) return 1.0f;
    return 0.0f;
}

}  // namespace deformkit::test
