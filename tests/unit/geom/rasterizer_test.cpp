#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <omp.h>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/geom/triangulation.h"
#include "geom/rasterize_triangle.h"

using namespace deformkit::geom;

namespace {

using Triangle = std::array<glm::vec2, 3>;

// Visits per pixel of a set of triangles; visits outside the grid are counted apart.
struct Coverage {
    std::vector<int> count;
    int outside = 0;
};

Coverage cover(const RasterGrid& grid, const std::vector<Triangle>& triangles) {
    Coverage c;
    c.count.assign(static_cast<size_t>(grid.width) * grid.height, 0);
    for (const auto& t : triangles) {
        rasterizeTriangle(grid, t[0], t[1], t[2], [&](int32_t x, int32_t y, const glm::vec3&) {
            if (x < 0 || y < 0 || x >= grid.width || y >= grid.height) {
                ++c.outside;
            } else {
                ++c.count[static_cast<size_t>(y) * grid.width + x];
            }
        });
    }
    return c;
}

// The pixels a set of triangles tiling the rectangle [lo, hi] must cover exactly once: by the top-left
// rule, those whose centre lies in the half-open [lo.x, hi.x) x [lo.y, hi.y).
int mismatchesWithRectangle(const RasterGrid& grid, const Coverage& c, const glm::dvec2& lo,
                            const glm::dvec2& hi) {
    int bad = 0;
    for (int32_t y = 0; y < grid.height; ++y) {
        for (int32_t x = 0; x < grid.width; ++x) {
            const double cx = x + 0.5, cy = y + 0.5;
            const int expected = cx >= lo.x && cx < hi.x && cy >= lo.y && cy < hi.y ? 1 : 0;
            if (c.count[static_cast<size_t>(y) * grid.width + x] != expected) ++bad;
        }
    }
    return bad;
}

Triangle reversed(const Triangle& t) {
    return {t[0], t[2], t[1]};
}

double signedArea(const Triangle& t) {
    const glm::dvec2 a(t[0]), b(t[1]), c(t[2]);
    return 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

// A (cells + 1)^2 lattice over [lo, hi] whose interior points move by up to `jitter` cells (rounded to
// `quantum` pixels when quantum > 0), each cell split along a random diagonal.
std::vector<Triangle> jitteredGrid(glm::vec2 lo, glm::vec2 hi, int cells, float jitter, float quantum,
                                   std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const glm::vec2 cell = (hi - lo) / static_cast<float>(cells);
    std::vector<glm::vec2> lattice;
    for (int j = 0; j <= cells; ++j) {
        for (int i = 0; i <= cells; ++i) {
            glm::vec2 p = i == cells ? glm::vec2(hi.x, 0.0f) : glm::vec2(lo.x + i * cell.x, 0.0f);
            p.y = j == cells ? hi.y : lo.y + j * cell.y;
            if (i > 0 && i < cells && j > 0 && j < cells) {
                p += jitter * cell * glm::vec2(u(rng), u(rng));
                if (quantum > 0.0f) p = glm::round(p / quantum) * quantum;
            }
            lattice.push_back(p);
        }
    }
    std::vector<Triangle> out;
    for (int j = 0; j < cells; ++j) {
        for (int i = 0; i < cells; ++i) {
            const glm::vec2 a = lattice[j * (cells + 1) + i], b = lattice[j * (cells + 1) + i + 1];
            const glm::vec2 c = lattice[(j + 1) * (cells + 1) + i + 1],
                            d = lattice[(j + 1) * (cells + 1) + i];
            if (rng() % 2) {
                out.push_back({a, b, c});
                out.push_back({a, c, d});
            } else {
                out.push_back({a, b, d});
                out.push_back({b, c, d});
            }
        }
    }
    return out;
}

}  // namespace

TEST_CASE("rasterizer: the two triangles of a quad cover each pixel once", "[geom][rasterizer]") {
    const RasterGrid grid{40, 30};
    std::mt19937 rng(1);
    std::uniform_int_distribution<int> subpixel(0, 256 * 12);
    std::vector<std::pair<glm::vec2, glm::vec2>> rectangles{
        {{3.0f, 2.0f}, {17.0f, 11.0f}},    // integer corners: no centre on an edge
        {{3.5f, 2.5f}, {17.5f, 21.5f}},    // half-integer corners: edges through rows of centres
        {{0.5f, 0.5f}, {39.5f, 29.5f}},    // the whole grid but its last row and column
        {{-5.0f, -3.5f}, {45.0f, 33.0f}},  // more than the grid
    };
    for (int k = 0; k < 20; ++k) {
        // Random corners on the 1/256 subpixel lattice, where snapping is exact.
        const glm::vec2 lo(subpixel(rng) / 256.0f, subpixel(rng) / 256.0f);
        rectangles.push_back({lo, lo + glm::vec2(1 + subpixel(rng) / 256.0f, 1 + subpixel(rng) / 256.0f)});
    }
    for (const auto& [lo, hi] : rectangles) {
        const glm::vec2 a = lo, b(hi.x, lo.y), c = hi, d(lo.x, hi.y);
        for (int variant = 0; variant < 4; ++variant) {
            std::vector<Triangle> tris = variant % 2 == 0 ? std::vector<Triangle>{{a, b, c}, {a, c, d}}
                                                          : std::vector<Triangle>{{a, b, d}, {b, c, d}};
            if (variant >= 2) {
                for (auto& t : tris)
                    t = reversed(t);
            }
            const Coverage cov = cover(grid, tris);
            INFO("rectangle (" << lo.x << ", " << lo.y << ") - (" << hi.x << ", " << hi.y << "), variant "
                               << variant);
            CHECK(cov.outside == 0);
            CHECK(mismatchesWithRectangle(grid, cov, lo, hi) == 0);
        }
    }
}

TEST_CASE("rasterizer: a jittered triangulated grid covers each pixel exactly once", "[geom][rasterizer]") {
    const RasterGrid grid{96, 80};
    std::mt19937 rng(2);
    struct Case {
        glm::vec2 lo, hi;
        int cells;
        float quantum;  // 0: free jitter; 0.5: vertices on pixel centres and corners, edges through centres
    };
    const Case cases[] = {
        {{2.0f, 3.0f}, {90.0f, 75.0f}, 11, 0.0f},
        {{2.0f, 3.0f}, {90.0f, 75.0f}, 11, 0.5f},
        {{4.5f, 0.5f}, {94.5f, 78.5f}, 15, 0.5f},
        {{-10.0f, -7.5f}, {120.0f, 100.0f}, 13, 0.0f},  // larger than the grid: clipped
        {{-10.0f, -7.5f}, {120.0f, 100.0f}, 13, 1.0f},
    };
    for (const auto& c : cases) {
        const std::vector<Triangle> tris = jitteredGrid(c.lo, c.hi, c.cells, 0.2f, c.quantum, rng);
        double area = 0.0;
        for (const auto& t : tris) {
            REQUIRE(signedArea(t) > 0.0);  // the jitter folds no triangle over
            area += signedArea(t);
        }
        REQUIRE(area == Approx((c.hi.x - c.lo.x) * (c.hi.y - c.lo.y)));
        for (int winding = 0; winding < 3; ++winding) {
            std::vector<Triangle> wound = tris;
            for (auto& t : wound) {
                if (winding == 1 || (winding == 2 && rng() % 2)) t = reversed(t);
            }
            const Coverage cov = cover(grid, wound);
            INFO("region (" << c.lo.x << ", " << c.lo.y << ") - (" << c.hi.x << ", " << c.hi.y
                            << "), quantum " << c.quantum << ", winding " << winding);
            CHECK(cov.outside == 0);
            CHECK(mismatchesWithRectangle(grid, cov, c.lo, c.hi) == 0);
        }
    }
}

TEST_CASE("rasterizer: large triangles cover their area to within the perimeter", "[geom][rasterizer]") {
    const RasterGrid grid{600, 500};
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> ux(0.0f, 600.0f), uy(0.0f, 500.0f);
    for (int k = 0; k < 20; ++k) {
        const Triangle t{glm::vec2(ux(rng), uy(rng)), glm::vec2(ux(rng), uy(rng)),
                         glm::vec2(ux(rng), uy(rng))};
        const glm::dvec2 p[3] = {glm::dvec2(t[0]), glm::dvec2(t[1]), glm::dvec2(t[2])};
        const Coverage cov = cover(grid, {t});
        long covered = 0;
        int wrong = 0;
        const double orientation = signedArea(t) > 0.0 ? 1.0 : -1.0;
        for (int32_t y = 0; y < grid.height; ++y) {
            for (int32_t x = 0; x < grid.width; ++x) {
                const int n = cov.count[static_cast<size_t>(y) * grid.width + x];
                covered += n;
                // Independent inside test: signed distance of the centre to the three edge lines. Snapping
                // moves vertices by under 0.003 pixel, so centres 0.01 pixel from every edge are decided.
                const glm::dvec2 centre(x + 0.5, y + 0.5);
                double nearest = std::numeric_limits<double>::infinity();
                for (int e = 0; e < 3; ++e) {
                    const glm::dvec2 a = p[e], b = p[(e + 1) % 3];
                    const double cross = (b.x - a.x) * (centre.y - a.y) - (b.y - a.y) * (centre.x - a.x);
                    nearest = std::min(nearest, orientation * cross / glm::length(b - a));
                }
                if ((nearest > 0.01 && n != 1) || (nearest < -0.01 && n != 0)) ++wrong;
            }
        }
        const double area = std::abs(signedArea(t));
        const double perimeter =
            glm::length(p[1] - p[0]) + glm::length(p[2] - p[1]) + glm::length(p[0] - p[2]);
        INFO("triangle " << k << ": area " << area << ", covered " << covered);
        CHECK(wrong == 0);
        CHECK(cov.outside == 0);
        CHECK(std::abs(covered - area) <= perimeter);
    }
}

TEST_CASE("rasterizer: barycentrics reproduce the pixel centre and linear attributes", "[geom][rasterizer]") {
    const RasterGrid grid{256, 200};
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> ux(-20.0f, 276.0f), uy(-20.0f, 220.0f);
    auto f = [](const glm::dvec2& p) { return 3.0 + 0.25 * p.x - 0.5 * p.y; };
    long visits = 0;
    int badSum = 0, badCentre = 0, badAttribute = 0;
    for (int k = 0; k < 200; ++k) {
        // Unsnapped float vertices: barycentrics refer to these, not to the snapped ones.
        const Triangle t{glm::vec2(ux(rng), uy(rng)), glm::vec2(ux(rng), uy(rng)),
                         glm::vec2(ux(rng), uy(rng))};
        if (std::abs(signedArea(t)) < 10.0) continue;
        rasterizeTriangle(grid, t[0], t[1], t[2], [&](int32_t x, int32_t y, const glm::vec3& b) {
            ++visits;
            const glm::dvec2 centre(x + 0.5, y + 0.5);
            const glm::dvec2 p = double(b[0]) * glm::dvec2(t[0]) + double(b[1]) * glm::dvec2(t[1]) +
                                 double(b[2]) * glm::dvec2(t[2]);
            if (std::abs(double(b[0]) + b[1] + b[2] - 1.0) > 1e-6) ++badSum;
            if (glm::length(p - centre) > 1e-4) ++badCentre;
            const double value = b[0] * f(t[0]) + b[1] * f(t[1]) + b[2] * f(t[2]);
            if (std::abs(value - f(centre)) > 1e-4) ++badAttribute;
        });
    }
    CHECK(visits > 100000);
    CHECK(badSum == 0);
    CHECK(badCentre == 0);
    CHECK(badAttribute == 0);
}

TEST_CASE("rasterizer: clipping at the grid border and degenerate triangles", "[geom][rasterizer]") {
    const RasterGrid grid{50, 40};
    // The same triangles drawn shifted by whole pixels into a grid that holds them entirely: the small
    // grid must see exactly the window of the large one (an integer shift keeps snapping exact).
    const int margin = 64;
    const RasterGrid large{grid.width + 2 * margin, grid.height + 2 * margin};
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> ux(-40.0f, 90.0f), uy(-40.0f, 80.0f);
    for (int k = 0; k < 100; ++k) {
        const Triangle t{glm::vec2(ux(rng), uy(rng)), glm::vec2(ux(rng), uy(rng)),
                         glm::vec2(ux(rng), uy(rng))};
        const glm::vec2 shift(static_cast<float>(margin));
        const Coverage small = cover(grid, {t});
        const Coverage big = cover(large, {{t[0] + shift, t[1] + shift, t[2] + shift}});
        CHECK(small.outside == 0);
        CHECK(big.outside == 0);
        int mismatches = 0;
        for (int32_t y = 0; y < grid.height; ++y) {
            for (int32_t x = 0; x < grid.width; ++x) {
                const int inLarge = big.count[static_cast<size_t>(y + margin) * large.width + x + margin];
                if (small.count[static_cast<size_t>(y) * grid.width + x] != inLarge) ++mismatches;
            }
        }
        CHECK(mismatches == 0);
    }

    auto visits = [&](const RasterGrid& g, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
        int n = 0;
        rasterizeTriangle(g, a, b, c, [&](int32_t, int32_t, const glm::vec3&) { ++n; });
        return n;
    };
    CHECK(visits(grid, {-30, -30}, {-1, -30}, {-1, -1}) == 0);               // entirely outside
    CHECK(visits(grid, {3e7f, 0}, {4e7f, 0}, {3e7f, 1e7f}) == 0);            // far outside
    CHECK(visits(grid, {0.5f, 0.5f}, {10.5f, 10.5f}, {20.5f, 20.5f}) == 0);  // collinear, through centres
    CHECK(visits(grid, {2, 2}, {2, 2}, {30, 20}) == 0);                      // coincident corners
    CHECK(visits(grid, {5.5f, 5.5f}, {5.5f + 1.0f / 1024, 5.5f}, {5.5f, 5.5f + 1.0f / 1024}) ==
          0);  // snaps to a point
    CHECK(visits(RasterGrid{0, 0}, {0, 0}, {10, 0}, {0, 10}) == 0);
    // Centres on the two legs count, those on the hypotenuse (x + y = 11) do not: i + j <= 9, 55 pixels.
    CHECK(visits(grid, {0.5f, 0.5f}, {10.5f, 0.5f}, {0.5f, 10.5f}) == 55);
    CHECK(visits(grid, {0.5f, 0.5f}, {0.5f, 10.5f}, {10.5f, 0.5f}) == 55);
    CHECK_THROWS_AS(visits(grid, {0, 0}, {3e7f, 0}, {0, 10}), deformkit::InvalidInput);
    CHECK_THROWS_AS(visits(grid, {0, 0}, {std::nanf(""), 0}, {0, 10}), deformkit::InvalidInput);
}

TEST_CASE("rasterizeAttributes: a linear function over a UV grid is reproduced at every pixel",
          "[geom][rasterizer]") {
    const RasterGrid grid{128, 96};
    // makeGrid's UVs fill [0, 1]^2; scaled to the raster and jittered inside, they tile it.
    const Mesh uvMesh = makeGrid({13, 9});
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> u(-0.3f, 0.3f);
    std::vector<glm::vec2> positions;
    for (int32_t v = 0; v < uvMesh.numUVs(); ++v) {
        glm::vec2 p = uvMesh.uvs()[v];
        if (p.x > 0.0f && p.x < 1.0f && p.y > 0.0f && p.y < 1.0f) p += glm::vec2(u(rng) / 13, u(rng) / 9);
        positions.push_back(p * glm::vec2(grid.width, grid.height));
    }
    const Triangulation tris = triangulate(uvMesh);
    std::vector<std::array<int32_t, 3>> triangles;
    for (const auto& c : tris.corners) {
        triangles.push_back({uvMesh.uvIndices()[c[0]], uvMesh.uvIndices()[c[1]], uvMesh.uvIndices()[c[2]]});
    }
    auto f0 = [](const glm::dvec2& p) { return 0.5 + 0.02 * p.x - 0.03 * p.y; };
    auto f1 = [&](const glm::dvec2& p) { return p.x / grid.width; };
    std::vector<float> attributes;
    for (const auto& p : positions) {
        attributes.push_back(static_cast<float>(f0(p)));
        attributes.push_back(static_cast<float>(f1(p)));
    }
    AttributeRaster out;
    rasterizeAttributes(grid, positions, triangles, attributes, 2, out);
    REQUIRE(out.width == grid.width);
    REQUIRE(out.height == grid.height);
    REQUIRE(out.channels == 2);
    REQUIRE(out.values.size() == static_cast<size_t>(grid.width * grid.height * 2));
    int uncovered = 0, bad = 0, wrongTriangle = 0;
    for (int32_t y = 0; y < grid.height; ++y) {
        for (int32_t x = 0; x < grid.width; ++x) {
            const size_t pixel = static_cast<size_t>(y) * grid.width + x;
            const glm::dvec2 centre(x + 0.5, y + 0.5);
            const int32_t t = out.triangle[pixel];
            if (t < 0) {
                ++uncovered;
                continue;
            }
            if (std::abs(out.values[2 * pixel] - f0(centre)) > 1e-5 ||
                std::abs(out.values[2 * pixel + 1] - f1(centre)) > 1e-5) {
                ++bad;
            }
            // The reported triangle contains the centre (up to the snapping of its corners).
            const Triangle tri{positions[triangles[t][0]], positions[triangles[t][1]],
                               positions[triangles[t][2]]};
            for (int e = 0; e < 3; ++e) {
                const glm::dvec2 a(tri[e]), b(tri[(e + 1) % 3]);
                const double cross = (b.x - a.x) * (centre.y - a.y) - (b.y - a.y) * (centre.x - a.x);
                if (cross / glm::length(b - a) < -0.01) ++wrongTriangle;
            }
        }
    }
    CHECK(uncovered == 0);
    CHECK(bad == 0);
    CHECK(wrongTriangle == 0);
}

TEST_CASE("rasterizeAttributes: overlaps go to the highest triangle index and bad input throws",
          "[geom][rasterizer]") {
    const RasterGrid grid{20, 20};
    const std::vector<glm::vec2> positions{{0, 0}, {20, 0}, {0, 20}, {2, 2}, {8, 2}, {2, 8}};
    const std::vector<float> attributes{1, 1, 1, 2, 2, 2};
    const std::vector<std::array<int32_t, 3>> bigThenSmall{{0, 1, 2}, {3, 4, 5}};
    const std::vector<std::array<int32_t, 3>> smallThenBig{{3, 4, 5}, {0, 1, 2}};
    AttributeRaster out;
    rasterizeAttributes(grid, positions, bigThenSmall, attributes, 1, out);
    const size_t inSmall = 3 * 20 + 3, inBigOnly = 12 * 20 + 2, outside = 19 * 20 + 19;
    CHECK(out.triangle[inSmall] == 1);
    CHECK(out.values[inSmall] == 2.0f);
    CHECK(out.triangle[inBigOnly] == 0);
    CHECK(out.values[inBigOnly] == 1.0f);
    CHECK(out.triangle[outside] == -1);
    CHECK(out.values[outside] == 0.0f);
    rasterizeAttributes(grid, positions, smallThenBig, attributes, 1, out);  // reuses `out`
    CHECK(out.triangle[inSmall] == 1);
    CHECK(out.values[inSmall] == 1.0f);
    CHECK(out.triangle[outside] == -1);

    using deformkit::InvalidInput;
    CHECK_THROWS_WITH(rasterizeAttributes(grid, positions, bigThenSmall, std::vector<float>(5), 1, out),
                      Catch::Contains("6 positions x 1 channels"));
    const std::vector<std::array<int32_t, 3>> outOfRange{{0, 1, 2}, {3, 6, 5}};
    CHECK_THROWS_WITH(rasterizeAttributes(grid, positions, outOfRange, attributes, 1, out),
                      Catch::Contains("triangle 1 corner 1") && Catch::Contains("[0, 6)"));
    CHECK_THROWS_AS(rasterizeAttributes(RasterGrid{-1, 4}, positions, bigThenSmall, attributes, 1, out),
                    InvalidInput);
    CHECK_THROWS_AS(rasterizeAttributes(grid, positions, bigThenSmall, attributes, -1, out), InvalidInput);
}

TEST_CASE("rasterizeAttributes: bands of rows in parallel give the serial rasterisation, bit for bit",
          "[geom][rasterizer]") {
    // Random overlapping triangles (fixed seed), small and tall ones crossing many 64-row bands, on a grid
    // whose height is not a multiple of 64; some corners off the grid. Reference: every triangle in order
    // through rasterizeTriangle on the whole grid, the last one winning each pixel.
    std::mt19937 random(5150);
    std::uniform_real_distribution<float> coordinate(-40.0f, 560.0f), size(0.5f, 300.0f), unit(0.0f, 1.0f);
    const RasterGrid grid{300, 517};
    std::vector<glm::vec2> positions;
    std::vector<std::array<int32_t, 3>> triangles;
    std::vector<float> attributes;
    for (int32_t t = 0; t < 400; ++t) {
        const glm::vec2 a(coordinate(random), coordinate(random));
        const float s = size(random);
        const auto k = static_cast<int32_t>(positions.size());
        for (int c = 0; c < 3; ++c) {
            positions.push_back(c == 0 ? a : a + s * glm::vec2(unit(random) - 0.3f, unit(random) - 0.3f));
            attributes.insert(attributes.end(), {unit(random), unit(random)});
        }
        triangles.push_back({k, k + 1, k + 2});
    }
    std::vector<int32_t> expectedTriangle(static_cast<size_t>(grid.width) * grid.height, -1);
    std::vector<float> expectedValues(expectedTriangle.size() * 2, 0.0f);
    for (size_t t = 0; t < triangles.size(); ++t) {
        const auto& tri = triangles[t];
        rasterizeTriangle(grid, positions[tri[0]], positions[tri[1]], positions[tri[2]],
                          [&](int32_t x, int32_t y, const glm::vec3& b) {
                              const size_t pixel = static_cast<size_t>(y) * grid.width + x;
                              expectedTriangle[pixel] = static_cast<int32_t>(t);
                              for (int c = 0; c < 2; ++c)
                                  expectedValues[2 * pixel + c] = b[0] * attributes[2 * tri[0] + c] +
                                                                  b[1] * attributes[2 * tri[1] + c] +
                                                                  b[2] * attributes[2 * tri[2] + c];
                          });
    }
    for (const int threads : {1, 2}) {
        const int previous = omp_get_max_threads();
        omp_set_num_threads(threads);
        AttributeRaster raster;
        rasterizeAttributes(grid, positions, triangles, attributes, 2, raster);
        omp_set_num_threads(previous);
        CHECK(raster.triangle == expectedTriangle);
        CHECK(raster.values == expectedValues);
    }
    CHECK(std::count_if(expectedTriangle.begin(), expectedTriangle.end(), [](int32_t t) { return t >= 0; }) >
          grid.width * grid.height / 2);
}
