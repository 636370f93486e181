#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/geom/triangulation.h"
#include "deformkit/io/obj.h"
#include "deformkit/uvwarp/geometry_image.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using namespace deformkit::uvwarp;

namespace {

// 3D position as an affine function of tile-local UV.
glm::dvec3 affine(double u, double v) {
    return {2.0 * u + 0.5 * v + 1.0, -u + 3.0 * v, 0.25 * u + 0.1 * v - 2.0};
}

glm::dvec3 valueAt(const PointField& f, int32_t i, int32_t j) {
    const size_t k = f.index(i, j);
    return {f.values[k], f.values[k + 1], f.values[k + 2]};
}

// Chebyshev distance from point (i, j) to the nearest covered point (brute force).
int chebyshevToCovered(const GeometryImager& imager, const std::vector<uint8_t>& coverage, int32_t i,
                       int32_t j) {
    const int32_t side = imager.side();
    int best = std::numeric_limits<int>::max();
    for (int32_t b = 0; b < side; ++b) {
        for (int32_t a = 0; a < side; ++a) {
            if (coverage[static_cast<size_t>(b) * side + a])
                best = std::min(best, std::max(std::abs(a - i), std::abs(b - j)));
        }
    }
    return best;
}

}  // namespace

TEST_CASE("geometry image of an affine chart is the affine function, dilated by continuation",
          "[uvwarp][geometry_image]") {
    // A chart over local UV [0.2, 0.7] x [0.3, 0.9] in tile 1002 (u offset by 1); no grid point of n = 32
    // lies on its outline (0.2 * 32 = 6.4, ...), so coverage is unambiguous.
    const glm::vec2 lo(1.2f, 0.3f), hi(1.7f, 0.9f);
    const geom::Mesh mesh =
        test::planarChart(lo, hi, 5, 7, [](glm::vec2 uv) { return glm::vec3(affine(uv.x - 1.0, uv.y)); });
    const int32_t n = 32;
    GeometryImageOptions options;
    options.dilationRings = 4;
    const GeometryImager imager(mesh, 1002, n, options);
    const std::vector<uint8_t> coverage = imager.coverage();
    const PointField f = imager.sample(mesh.points());
    REQUIRE(f.cells == n);
    REQUIRE(f.channels == 3);
    REQUIRE(imager.numCovered() + imager.numDilated() + imager.numFar() == int64_t{33} * 33);

    int covered = 0, dilated = 0, far = 0;
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i) {
            const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
            const bool inside = u > 0.2 && u < 0.7 && v > 0.3 && v < 0.9;
            const bool isCovered = coverage[static_cast<size_t>(j) * (n + 1) + i] != 0;
            REQUIRE(isCovered == inside);
            const glm::dvec3 got = valueAt(f, i, j);
            const int ring = chebyshevToCovered(imager, coverage, i, j);
            if (isCovered) {
                // Barycentrics and positions are float32: values of size ~5 carry ~1e-6 rounding.
                ++covered;
                CHECK(glm::length(got - affine(u, v)) < 2e-5);
            } else if (ring <= options.dilationRings) {
                // Linear continuation reproduces affine data; each ring's 2a - b can triple the rounding.
                ++dilated;
                CHECK(glm::length(got - affine(u, v)) < 2e-4);
            } else {
                // Beyond the rings: a copy of a covered point at the smallest Euclidean distance. The
                // affine map is injective, so the copied point is recovered from the value.
                ++far;
                double best = std::numeric_limits<double>::max();
                for (int32_t b = 0; b <= n; ++b) {
                    for (int32_t a = 0; a <= n; ++a) {
                        if (coverage[static_cast<size_t>(b) * (n + 1) + a])
                            best = std::min(best, std::hypot(a - i, b - j));
                    }
                }
                bool matchesNearest = false;
                for (int32_t b = 0; b <= n; ++b) {
                    for (int32_t a = 0; a <= n; ++a) {
                        if (!coverage[static_cast<size_t>(b) * (n + 1) + a]) continue;
                        if (std::abs(std::hypot(a - i, b - j) - best) > 1e-9) continue;
                        matchesNearest =
                            matchesNearest || glm::length(got - affine(static_cast<double>(a) / n,
                                                                       static_cast<double>(b) / n)) < 2e-5;
                    }
                }
                CHECK(matchesNearest);
            }
        }
    }
    // Columns 7..22 x rows 10..28 are inside: 16 x 19 points.
    CHECK(covered == 16 * 19);
    CHECK(imager.numCovered() == covered);
    CHECK(imager.numDilated() == dilated);
    CHECK(imager.numFar() == far);
    CHECK(far > 0);
}

TEST_CASE("a chart filling the tile covers every point, its outline included", "[uvwarp][geometry_image]") {
    // The top-left rule alone would leave the u = 1 column and one of the v rows uncovered.
    const geom::Mesh mesh = test::planarChart({0.0f, 0.0f}, {1.0f, 1.0f}, 4, 4,
                                              [](glm::vec2 uv) { return glm::vec3(affine(uv.x, uv.y)); });
    const int32_t n = 16;
    const GeometryImager imager(mesh, 1001, n);
    CHECK(imager.numCovered() == 17 * 17);
    CHECK(imager.numDilated() == 0);
    CHECK(imager.numFar() == 0);
    const PointField f = imager.sample(mesh.points());
    double worst = 0.0;
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i)
            worst = std::max(worst, glm::length(valueAt(f, i, j) - affine(double(i) / n, double(j) / n)));
    }
    // float32 barycentrics and positions of size ~5.
    CHECK(worst < 2e-5);
}

TEST_CASE("geometry image of a cylinder with a UV seam", "[uvwarp][geometry_image]") {
    // Chart [0.125, 0.875] x [0.2, 0.8]: the seam lies on grid columns 8 and 56 of n = 64.
    const int segments = 16, rows = 4;
    const float height = 2.0f;
    const geom::Mesh mesh = test::seamCylinder(segments, rows, height, {0.125f, 0.2f}, {0.875f, 0.8f});
    const int32_t n = 64;
    const GeometryImager imager(mesh, 1001, n);
    const std::vector<uint8_t> coverage = imager.coverage();
    const PointField f = imager.sample(mesh.points());

    // Reference: a brute-force search of the quads' fan triangles (0, 1, 2), (0, 2, 3) in double.
    const auto uvs = mesh.uvs();
    const auto points = mesh.points();
    auto reference = [&](double u, double v, glm::dvec3& out) {
        for (int32_t face = 0; face < mesh.numFaces(); ++face) {
            const auto c = mesh.face(face);
            const auto t = mesh.faceUVIndices(face);
            for (int k = 1; k <= 2; ++k) {
                const int corner[3] = {0, k, k + 1};
                glm::dvec2 q[3];
                for (int m = 0; m < 3; ++m)
                    q[m] = glm::dvec2(uvs[t[corner[m]]]);
                const double area =
                    (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x);
                const double b1 =
                    ((u - q[0].x) * (q[2].y - q[0].y) - (v - q[0].y) * (q[2].x - q[0].x)) / area;
                const double b2 =
                    ((q[1].x - q[0].x) * (v - q[0].y) - (q[1].y - q[0].y) * (u - q[0].x)) / area;
                const double b0 = 1.0 - b1 - b2;
                if (b0 < -1e-9 || b1 < -1e-9 || b2 < -1e-9) continue;
                out = b0 * glm::dvec3(points[c[corner[0]]]) + b1 * glm::dvec3(points[c[corner[1]]]) +
                      b2 * glm::dvec3(points[c[corner[2]]]);
                return true;
            }
        }
        return false;
    };

    int checked = 0;
    double maxCoveredStep = 0.0;
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i) {
            const double u = double(i) / n, v = double(j) / n;
            glm::dvec3 expected;
            const bool inside = reference(u, v, expected);
            const bool covered = coverage[static_cast<size_t>(j) * (n + 1) + i] != 0;
            REQUIRE(covered == inside);
            if (!covered) continue;
            ++checked;
            // float32 barycentrics and unit-size positions.
            CHECK(glm::length(valueAt(f, i, j) - expected) < 1e-5);
            if (i < n && coverage[static_cast<size_t>(j) * (n + 1) + i + 1])
                maxCoveredStep =
                    std::max(maxCoveredStep, glm::length(valueAt(f, i + 1, j) - valueAt(f, i, j)));
            if (j < n && coverage[static_cast<size_t>(j + 1) * (n + 1) + i])
                maxCoveredStep =
                    std::max(maxCoveredStep, glm::length(valueAt(f, i, j + 1) - valueAt(f, i, j)));
        }
    }
    CHECK(checked == 49 * 39);  // columns 8..56, rows 13..51 (0.2 * 64 = 12.8, 0.8 * 64 = 51.2)

    // Both sides of the seam sample the same 3D line: angle 0, (1, y, 0) with y linear in v.
    for (int32_t j = 13; j <= 51; ++j) {
        const glm::dvec3 seam(1.0, height * (double(j) / n - 0.2) / 0.6, 0.0);
        CHECK(glm::length(valueAt(f, 8, j) - seam) < 1e-5);
        CHECK(glm::length(valueAt(f, 56, j) - seam) < 1e-5);
    }

    // Dilated values continue the surface: finite, and within (ring * sqrt(2)) grid steps of the nearest
    // covered value (a linear continuation moves one step per ring, diagonally at most sqrt(2) steps).
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i) {
            if (coverage[static_cast<size_t>(j) * (n + 1) + i]) continue;
            const glm::dvec3 got = valueAt(f, i, j);
            REQUIRE(std::isfinite(got.x));
            REQUIRE(std::isfinite(got.y));
            REQUIRE(std::isfinite(got.z));
            const int ring = chebyshevToCovered(imager, coverage, i, j);
            if (ring > 4) continue;
            double nearest = std::numeric_limits<double>::max();
            for (int32_t b = std::max(0, j - ring); b <= std::min(n, j + ring); ++b) {
                for (int32_t a = std::max(0, i - ring); a <= std::min(n, i + ring); ++a) {
                    if (coverage[static_cast<size_t>(b) * (n + 1) + a])
                        nearest = std::min(nearest, glm::length(got - valueAt(f, a, b)));
                }
            }
            CHECK(nearest <= 1.01 * ring * std::sqrt(2.0) * maxCoveredStep);
        }
    }
    // Past the seam the continuation is the tangent line: 2 f(8) - f(9) at column 7.
    for (int32_t j = 14; j <= 50; ++j) {
        const glm::dvec3 expected = 2.0 * valueAt(f, 8, j) - valueAt(f, 9, j);
        CHECK(glm::length(valueAt(f, 7, j) - expected) < 1e-5);
    }
}

TEST_CASE("a deformed frame's geometry image follows an affine motion everywhere",
          "[uvwarp][geometry_image]") {
    const geom::Mesh mesh = test::seamCylinder(12, 3, 1.5f, {0.1f, 0.15f}, {0.6f, 0.55f});
    const int32_t n = 32;
    const GeometryImager imager(mesh, 1001, n);
    REQUIRE(imager.numFar() > 0);
    const PointField rest = imager.sample(mesh.points());
    // A rotation about z by 30 degrees, a scale along x by 1.5, and a translation.
    const double c = std::cos(M_PI / 6.0), s = std::sin(M_PI / 6.0);
    auto motion = [&](const glm::dvec3& p) {
        return glm::dvec3(1.5 * (c * p.x - s * p.y) + 0.3, s * p.x + c * p.y - 1.0, p.z + 2.0);
    };
    std::vector<glm::vec3> deformed;
    for (const glm::vec3& p : mesh.points())
        deformed.emplace_back(motion(glm::dvec3(p)));
    PointField frame;
    imager.sample(deformed, frame);
    // Covered, dilated and copied values are affine combinations (weights summing to 1) of vertex
    // positions, so they commute with the affine motion up to float32 rounding of unit-size values.
    double worst = 0.0;
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i)
            worst = std::max(worst, glm::length(valueAt(frame, i, j) - motion(valueAt(rest, i, j))));
    }
    CHECK(worst < 1e-4);
}

TEST_CASE("geometry images are bit-identical for 1 and 2 threads", "[uvwarp][geometry_image]") {
    const geom::Mesh mesh = test::seamCylinder(24, 8, 2.0f, {0.05f, 0.1f}, {0.95f, 0.7f});
    const auto run = [&] {
        const GeometryImager imager(mesh, 1001, 128);
        return imager.sample(mesh.points()).values;
    };
    const std::vector<float> one = test::withThreads(1, run);
    const std::vector<float> two = test::withThreads(2, run);
    CHECK(one == two);
}

TEST_CASE("bilinear look-up of a point field", "[uvwarp][geometry_image]") {
    const int32_t n = 8;
    PointField f;
    f.cells = n;
    f.channels = 3;
    f.values.resize(static_cast<size_t>(n + 1) * (n + 1) * 3);
    for (int32_t j = 0; j <= n; ++j) {
        for (int32_t i = 0; i <= n; ++i) {
            const glm::dvec3 p = affine(double(i) / n, double(j) / n);
            const size_t k = f.index(i, j);
            f.values[k] = static_cast<float>(p.x);
            f.values[k + 1] = static_cast<float>(p.y);
            f.values[k + 2] = static_cast<float>(p.z);
        }
    }
    // Bilinear interpolation reproduces affine data: float32 rounding of values of size ~5.
    for (const auto& uv : {glm::dvec2(0.0, 0.0), glm::dvec2(1.0, 1.0), glm::dvec2(0.3, 0.71),
                           glm::dvec2(0.999, 0.001), glm::dvec2(0.5, 0.25)}) {
        const glm::vec3 got = bilinearLookup(f, static_cast<float>(uv.x), static_cast<float>(uv.y));
        CHECK(glm::length(glm::dvec3(got) - affine(uv.x, uv.y)) < 2e-5);
    }
    // Outside the unit square the look-up clamps.
    const glm::vec3 clamped = bilinearLookup(f, -0.5f, 1.5f);
    CHECK(glm::length(glm::dvec3(clamped) - affine(0.0, 1.0)) < 2e-5);
    // A non-affine field: the value at a cell's centre is the mean of its four corners, exactly.
    f.values[f.index(3, 5)] = 10.0f;
    const glm::vec3 centre = bilinearLookup(f, 3.5f / n, 5.5f / n);
    const double mean =
        (10.0 + f.values[f.index(4, 5)] + f.values[f.index(3, 6)] + f.values[f.index(4, 6)]) / 4.0;
    CHECK(centre.x == Approx(mean).epsilon(1e-6));

    PointField scalar;
    scalar.cells = n;
    scalar.channels = 1;
    scalar.values.assign(static_cast<size_t>(n + 1) * (n + 1), 0.0f);
    CHECK_THROWS_AS((void)bilinearLookup(scalar, 0.5f, 0.5f), InvalidInput);
}

TEST_CASE("geometry image bad input is reported with its element", "[uvwarp][geometry_image]") {
    const auto flat = [](glm::vec2 uv) { return glm::vec3(uv, 0.0f); };
    const geom::Mesh chart = test::planarChart({0.1f, 0.1f}, {0.9f, 0.9f}, 2, 2, flat);
    GeometryImageOptions options;
    options.label = "rest.obj";

    SECTION("mesh without UVs") {
        geom::Mesh::Data data;
        data.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
        data.faceCounts = {3};
        data.faceIndices = {0, 1, 2};
        const geom::Mesh bare(std::move(data));
        CHECK_THROWS_WITH(GeometryImager(bare, 1001, 8, options),
                          Catch::Contains("rest.obj") && Catch::Contains("no UVs"));
    }
    SECTION("a face overhanging its tile by more than a tenth of a tile") {
        // Face 0 runs from u = 0.5 to u = 1.25: its centroid is in tile 1001, a corner 0.25 into 1002.
        const geom::Mesh straddling = test::planarChart({0.5f, 0.2f}, {2.0f, 0.6f}, 2, 1, flat);
        CHECK_THROWS_WITH(GeometryImager(straddling, 1001, 8, options),
                          Catch::Contains("rest.obj") && Catch::Contains("UDIM tile 1001") &&
                              Catch::Contains("face 0") && Catch::Contains("overhangs the tile by 0.25") &&
                              Catch::Contains("in tile 1002"));
        // Tile 1002's own face (u 1.25 to 2) is sound; face 0 belongs to tile 1001.
        CHECK_NOTHROW(GeometryImager(straddling, 1002, 8, options));
    }
    SECTION("corners overhanging a tile by up to a tenth are taken, as far as the tile reaches") {
        // u from -0.08 to 0.72 in two faces: face 0 (centroid u = 0.12) overhangs tile 1001's left edge
        // by 0.08; a face whose centroid itself lies left of u = 0 stays in tile 1001 (no tile 1000).
        const geom::Mesh overhanging = test::planarChart({-0.08f, 0.2f}, {0.72f, 0.6f}, 2, 1, flat);
        const geom::Mesh leftOfZero = test::planarChart({-0.09f, 0.2f}, {0.05f, 0.6f}, 1, 1, flat);
        CHECK(overhanging.udimTiles() == std::vector<int>{1001});
        CHECK(leftOfZero.udimTiles() == std::vector<int>{1001});
        CHECK(leftOfZero.faceUdimOverhang(0) == Approx(0.09f));
        const geom::UdimOverhang report = geom::udimOverhang(overhanging);
        CHECK(report.faces == 1);
        CHECK(report.worstFace == 0);
        CHECK(report.worst == Approx(0.08f));
        const GeometryImager imager(overhanging, 1001, 8, options);
        const std::vector<uint8_t> coverage = imager.coverage();
        // The tile's left column (u = 0) is covered from v = 0.2 to 0.6 (points j = 2..4 of 8 cells) by the
        // overhanging face, and the geometry image there is the face's own position (u, v, 0).
        const PointField field = imager.sample(overhanging.points());
        for (int32_t j = 2; j <= 4; ++j) {
            CHECK(coverage[static_cast<size_t>(j) * 9] == 1);
            const float* p = &field.values[3 * (static_cast<size_t>(j) * 9)];
            CHECK(p[0] == Approx(0.0f).margin(1e-6));
            CHECK(p[1] == Approx(j / 8.0f).margin(1e-6));
        }
        CHECK_NOTHROW(GeometryImager(leftOfZero, 1001, 8, options));
    }
    SECTION("a face without UVs belongs to no tile and is left alone") {
        // The chart plus a triangle without UVs (as OBJ exporters write them beside UV'd faces), on two of
        // the chart's vertices and one far away: the tile's geometry image is the chart's alone.
        geom::Mesh::Data d;
        d.points.assign(chart.points().begin(), chart.points().end());
        d.points.push_back({0.5f, 0.5f, 5.0f});
        d.faceCounts.assign(chart.faceCounts().begin(), chart.faceCounts().end());
        d.faceCounts.push_back(3);
        d.faceIndices.assign(chart.faceIndices().begin(), chart.faceIndices().end());
        d.faceIndices.insert(d.faceIndices.end(), {0, 1, chart.numVertices()});
        d.uvs.assign(chart.uvs().begin(), chart.uvs().end());
        d.uvIndices.assign(chart.uvIndices().begin(), chart.uvIndices().end());
        d.uvIndices.insert(d.uvIndices.end(), {-1, -1, -1});
        const geom::Mesh mixed(std::move(d), "mixed.obj");
        CHECK(mixed.numFacesWithoutUVs() == 1);
        CHECK(mixed.udimTiles() == std::vector<int>{1001});
        const GeometryImager alone(chart, 1001, 8, options);
        const GeometryImager withExtra(mixed, 1001, 8, options);
        CHECK(withExtra.coverage() == alone.coverage());
        std::vector<glm::vec3> moved(mixed.points().begin(), mixed.points().end());
        moved.back() = {7.0f, -3.0f, 2.0f};  // the face without UVs moves: nothing in the tile changes
        CHECK(withExtra.sample(moved).values == alone.sample(chart.points()).values);
    }
    SECTION("a face on the tile border does not overhang") {
        const geom::Mesh onBorder = test::planarChart({0.5f, 0.0f}, {1.0f, 1.0f}, 1, 1, flat);
        CHECK_NOTHROW(GeometryImager(onBorder, 1001, 8, options));
    }
    SECTION("cells not a power of two") {
        CHECK_THROWS_WITH(GeometryImager(chart, 1001, 48, options), Catch::Contains("rest.obj") &&
                                                                        Catch::Contains("48") &&
                                                                        Catch::Contains("power of two"));
        CHECK_THROWS_AS(GeometryImager(chart, 1001, 0, options), InvalidInput);
    }
    SECTION("a tile without faces, a bad tile number") {
        CHECK_THROWS_WITH(GeometryImager(chart, 1005, 8, options),
                          Catch::Contains("UDIM tile 1005") && Catch::Contains("no UV face"));
        CHECK_THROWS_WITH(GeometryImager(chart, 1000, 8, options), Catch::Contains("tile 1000"));
    }
    SECTION("positions of another count or not finite") {
        const GeometryImager imager(chart, 1001, 8, options);
        std::vector<glm::vec3> fewer(chart.points().begin(), chart.points().end() - 1);
        PointField out;
        CHECK_THROWS_WITH(imager.sample(fewer, out), Catch::Contains("rest.obj") &&
                                                         Catch::Contains("has 8") &&
                                                         Catch::Contains("9 (the rest mesh's vertex count)"));
        std::vector<glm::vec3> nan(chart.points().begin(), chart.points().end());
        nan[4].y = std::numeric_limits<float>::quiet_NaN();
        CHECK_THROWS_WITH(imager.sample(nan, out), Catch::Contains("vertex 4"));
        // Finite but beyond where squared lengths stay finite in float (a mesh scaled to 1e18 gave NaN
        // positions): refused at 1e15, the bound's margin; 1e15 itself is taken.
        std::vector<glm::vec3> far(chart.points().begin(), chart.points().end());
        far[6] = glm::vec3(1e15f, 0.0f, -1e15f);
        CHECK_NOTHROW(imager.sample(far, out));
        far[6].x = 1.0001e15f;
        CHECK_THROWS_WITH(imager.sample(far, out),
                          Catch::Contains("vertex 6: position is (1.0001e+15, 0, -1e+15)") &&
                              Catch::Contains("(expected finite coordinates within +-1e15)"));
    }
}

TEST_CASE("geometry image of a real layout: Spot's corners past tile 1001 are taken",
          "[uvwarp][geometry_image]") {
    // Keenan Crane's Spot (tests/data/spot): six faces reach past tile 1001, by up to 0.052 of a tile
    // (left of u = 0, and above v = 1), two of them with their UV centroid left of u = 0. Counted here from
    // the UVs alone, against the mesh's report; the tile binds and covers its charts.
    const geom::Mesh spot = io::readObj(DEFORMKIT_TEST_DATA "/spot/spot_quadrangulated.obj").mesh;
    int outside = 0;
    float reach = 0.0f;
    for (int32_t f = 0; f < spot.numFaces(); ++f) {
        float faceReach = 0.0f;
        for (int32_t t : spot.faceUVIndices(f)) {
            const glm::vec2 uv = spot.uvs()[t];
            faceReach = std::max({faceReach, -uv.x, uv.x - 1.0f, -uv.y, uv.y - 1.0f});
        }
        outside += faceReach > 1e-5f ? 1 : 0;
        reach = std::max(reach, faceReach);
    }
    CHECK(spot.udimTiles() == std::vector<int>{1001});
    const geom::UdimOverhang report = geom::udimOverhang(spot);
    CHECK(report.faces == outside);
    CHECK(outside == 6);
    CHECK(report.worst == reach);
    CHECK(reach == Approx(0.0522).margin(1e-4));
    GeometryImageOptions options;
    options.label = "spot";
    const GeometryImager imager(spot, 1001, 256, options);
    CHECK(imager.numCovered() > 256 * 256 / 4);
}

TEST_CASE("the geometry image of a real layout is the rasteriser's barycentric blend, bit for bit",
          "[uvwarp][geometry_image]") {
    // The imager keeps each row's covering triangles as runs and computes the barycentrics again each frame.
    // Reference: the triangles of tile 1001 rasterised here by geom::rasterizeAttributes with the corner
    // attributes (0, 0), (1, 0), (0, 1), which hands back the rasteriser's barycentrics (b, c) of corners B
    // and C, blended as (1 - b - c) A + b B + c C. Every point the rasteriser covers must match exactly, on
    // Spot's own UVs and random positions (fixed seed); the others are chart outlines and dilation.
    const geom::Mesh spot = io::readObj(DEFORMKIT_TEST_DATA "/spot/spot_quadrangulated.obj").mesh;
    const geom::Triangulation tris = geom::triangulate(spot);
    const auto faceIndices = spot.faceIndices();
    const auto uvIndices = spot.uvIndices();
    std::mt19937 random(20261204);
    std::uniform_real_distribution<float> jitter(-0.5f, 0.5f);
    std::vector<glm::vec3> positions(spot.points().begin(), spot.points().end());
    for (glm::vec3& p : positions)
        p += glm::vec3(jitter(random), jitter(random), jitter(random));
    for (const int32_t n : {64, 256}) {
        std::vector<glm::vec2> corners;
        std::vector<std::array<int32_t, 3>> triangles, vertices;
        std::vector<float> attributes;
        for (int32_t t = 0; t < tris.size(); ++t) {
            if (spot.faceUdimTile(tris.face[t]) != 1001) continue;
            const auto& c = tris.corners[t];
            const auto k = static_cast<int32_t>(corners.size());
            for (int m = 0; m < 3; ++m)
                corners.push_back(spot.uvs()[uvIndices[c[m]]] * static_cast<float>(n) + 0.5f);
            triangles.push_back({k, k + 1, k + 2});
            vertices.push_back({faceIndices[c[0]], faceIndices[c[1]], faceIndices[c[2]]});
            attributes.insert(attributes.end(), {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f});
        }
        geom::AttributeRaster raster;
        geom::rasterizeAttributes({n + 1, n + 1}, corners, triangles, attributes, 2, raster);
        const GeometryImager imager(spot, 1001, n);
        const PointField image = imager.sample(positions);
        int64_t compared = 0, differing = 0;
        for (size_t k = 0; k < raster.triangle.size(); ++k) {
            const int32_t t = raster.triangle[k];
            if (t < 0) continue;
            const float b = raster.values[2 * k], c = raster.values[2 * k + 1], a = 1.0f - b - c;
            const auto& v = vertices[static_cast<size_t>(t)];
            const glm::vec3 expected = a * positions[v[0]] + b * positions[v[1]] + c * positions[v[2]];
            const glm::vec3 got(image.values[3 * k], image.values[3 * k + 1], image.values[3 * k + 2]);
            ++compared;
            differing += got == expected ? 0 : 1;
        }
        CHECK(compared > int64_t{n + 1} * (n + 1) / 4);
        CHECK(differing == 0);
    }
}
