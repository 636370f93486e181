#pragma once

// Meshes and helpers shared by the uvwarp unit tests.

#include <cmath>
#include <functional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
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
