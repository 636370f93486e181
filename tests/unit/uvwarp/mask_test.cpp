#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "deformkit/error.h"
#include "deformkit/uvwarp/mask.h"
#include "test_support.h"
#include "uvwarp_test_support.h"

using namespace deformkit;
using namespace deformkit::uvwarp;

namespace {

using Segment = std::array<glm::dvec2, 2>;
using Triangle = std::array<glm::dvec2, 3>;

// Separating-axis test: does segment pq meet the closed box [lo, hi]?
bool segmentTouchesBox(const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& lo, const glm::dvec2& hi) {
    if (std::max(p.x, q.x) < lo.x || std::min(p.x, q.x) > hi.x) return false;
    if (std::max(p.y, q.y) < lo.y || std::min(p.y, q.y) > hi.y) return false;
    const glm::dvec2 d = q - p;
    int positive = 0, negative = 0;
    for (const glm::dvec2 c : {lo, hi, glm::dvec2(lo.x, hi.y), glm::dvec2(hi.x, lo.y)}) {
        const double side = d.x * (c.y - p.y) - d.y * (c.x - p.x);
        positive += side > 0.0;
        negative += side < 0.0;
    }
    return positive < 4 && negative < 4;
}

bool insideClosed(const Triangle& t, const glm::dvec2& p) {
    const double area = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x);
    const double b1 = ((p.x - t[0].x) * (t[2].y - t[0].y) - (p.y - t[0].y) * (t[2].x - t[0].x)) / area;
    const double b2 = ((t[1].x - t[0].x) * (p.y - t[0].y) - (t[1].y - t[0].y) * (p.x - t[0].x)) / area;
    return b1 >= -1e-12 && b2 >= -1e-12 && 1.0 - b1 - b2 >= -1e-12;
}

// The derived mask by definition, texel by texel: 1 iff the centre lies in a triangle and no border segment
// (tile-local UV) touches the texel's square grown by (width - 1) / 2 texels.
io::Image referenceMask(int32_t texels, const std::vector<Triangle>& triangles,
                        const std::vector<Segment>& borders, int width) {
    io::Image out(texels, texels, 1, 0.0f);
    const double g = 0.5 * (width - 1), t = texels;
    for (int32_t y = 0; y < texels; ++y) {
        for (int32_t x = 0; x < texels; ++x) {
            const glm::dvec2 centre((x + 0.5) / t, 1.0 - (y + 0.5) / t);
            const bool inside = std::any_of(triangles.begin(), triangles.end(),
                                            [&](const Triangle& tri) { return insideClosed(tri, centre); });
            const double r = texels - 1 - y;  // raster row, v up
            const glm::dvec2 lo(x - g, r - g), hi(x + 1 + g, r + 1 + g);
            const bool border = std::any_of(borders.begin(), borders.end(), [&](const Segment& s) {
                return segmentTouchesBox(s[0] * t, s[1] * t, lo, hi);
            });
            out.at(x, y, 0) = inside && !border ? 1.0f : 0.0f;
        }
    }
    return out;
}

// The outline of an axis-aligned rectangle as 4 segments, and the rectangle as 2 triangles.
std::vector<Segment> outline(glm::dvec2 lo, glm::dvec2 hi) {
    const glm::dvec2 a = lo, b(hi.x, lo.y), c = hi, d(lo.x, hi.y);
    return {Segment{a, b}, Segment{b, c}, Segment{c, d}, Segment{d, a}};
}
std::vector<Triangle> rectangle(glm::dvec2 lo, glm::dvec2 hi) {
    const glm::dvec2 b(hi.x, lo.y), d(lo.x, hi.y);
    return {Triangle{lo, b, hi}, Triangle{lo, hi, d}};
}

int countOnes(const io::Image& image) {
    return static_cast<int>(std::count(image.pixels.begin(), image.pixels.end(), 1.0f));
}

int countMismatches(const io::Image& a, const io::Image& b) {
    int bad = 0;
    for (size_t k = 0; k < a.pixels.size(); ++k)
        bad += a.pixels[k] != b.pixels[k];
    return bad;
}

const auto kFlat = [](glm::vec2 uv) { return glm::vec3(uv, 0.0f); };

}  // namespace

TEST_CASE("derived mask of a rectangular chart", "[uvwarp][mask]") {
    // A 2 x 2-quad chart over [0.25, 0.75]^2 of a 16-texel tile: the outline lies on texel boundaries 4 and
    // 12, so with width 1 the texels on both sides of it are fixed and the ones inside are x, y in 5..10;
    // the shared edges at u = 0.5 and v = 0.5 are not borders.
    const geom::Mesh chart = test::planarChart({0.25f, 0.25f}, {0.75f, 0.75f}, 2, 2, kFlat);
    const io::Image mask = deriveWarpMask(chart, 1001, 16);
    REQUIRE(mask.width == 16);
    REQUIRE(mask.height == 16);
    REQUIRE(mask.channels == 1);
    for (int32_t y = 0; y < 16; ++y) {
        for (int32_t x = 0; x < 16; ++x) {
            const float expected = x >= 5 && x <= 10 && y >= 5 && y <= 10 ? 1.0f : 0.0f;
            CHECK(mask.at(x, y, 0) == expected);
        }
    }
    const auto border = outline({0.25, 0.25}, {0.75, 0.75});
    const auto triangles = rectangle({0.25, 0.25}, {0.75, 0.75});
    CHECK(countMismatches(mask, referenceMask(16, triangles, border, 1)) == 0);

    // Width 3 grows the band by one texel each side: 6..9 remain.
    DerivedMaskOptions wide;
    wide.borderWidth = 3;
    const io::Image wider = deriveWarpMask(chart, 1001, 16, wide);
    CHECK(countOnes(wider) == 16);
    CHECK(countMismatches(wider, referenceMask(16, triangles, border, 3)) == 0);

    // Per-corner UV indices with equal values form the same chart.
    const geom::Mesh unwelded = test::planarChart({0.25f, 0.25f}, {0.75f, 0.75f}, 2, 2, kFlat, true);
    CHECK(countMismatches(deriveWarpMask(unwelded, 1001, 16), mask) == 0);

    // The same chart in tile 1013 (u + 2, v + 1) gives the same mask in tile-local UV.
    const geom::Mesh moved = test::planarChart({2.25f, 1.25f}, {2.75f, 1.75f}, 2, 2, kFlat);
    CHECK(countMismatches(deriveWarpMask(moved, 1013, 16), mask) == 0);
}

TEST_CASE("derived mask of a triangle with slanted borders", "[uvwarp][mask]") {
    geom::Mesh::Data data;
    data.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    data.uvs = {{0.1f, 0.1f}, {0.9f, 0.23f}, {0.31f, 0.85f}};
    data.faceCounts = {3};
    data.faceIndices = {0, 1, 2};
    data.uvIndices = {0, 1, 2};
    const geom::Mesh mesh(std::move(data));
    const Triangle tri{glm::dvec2(0.1f, 0.1f), glm::dvec2(0.9f, 0.23f), glm::dvec2(0.31f, 0.85f)};
    const std::vector<Segment> border{Segment{tri[0], tri[1]}, Segment{tri[1], tri[2]},
                                      Segment{tri[2], tri[0]}};
    for (int width : {1, 2, 4}) {
        DerivedMaskOptions options;
        options.borderWidth = width;
        const io::Image mask = deriveWarpMask(mesh, 1001, 32, options);
        INFO("border width " << width);
        CHECK(countMismatches(mask, referenceMask(32, {tri}, border, width)) == 0);
        CHECK(countOnes(mask) > 0);
    }
}

TEST_CASE("derived mask fixes the texels along a UV seam", "[uvwarp][mask]") {
    // The cylinder's chart is [0.125, 0.875] x [0.2, 0.8]: its outline is the two seam sides and the two
    // open ends; the edges between quads, the seam's 3D neighbours included, are interior.
    const geom::Mesh cylinder = test::seamCylinder(16, 4, 2.0f, {0.125f, 0.2f}, {0.875f, 0.8f});
    const glm::dvec2 lo(0.125f, 0.2f), hi(0.875f, 0.8f);
    const io::Image mask = deriveWarpMask(cylinder, 1001, 32);
    CHECK(countMismatches(mask, referenceMask(32, rectangle(lo, hi), outline(lo, hi), 1)) == 0);
    // The seam at u = 0.125 is texel boundary 4: texels 3 and 4 are fixed, 5 is free, at mid-height.
    CHECK(mask.at(3, 16, 0) == 0.0f);
    CHECK(mask.at(4, 16, 0) == 0.0f);
    CHECK(mask.at(5, 16, 0) == 1.0f);
}

TEST_CASE("stacked copies of a shell keep their borders", "[uvwarp][mask]") {
    // Two shells with the same UVs (a duplicated part): each UV edge is used twice in the same direction,
    // which is not an interior edge.
    const geom::Mesh single = test::planarChart({0.25f, 0.25f}, {0.75f, 0.75f}, 2, 2, kFlat);
    geom::Mesh::Data data;
    for (int copy = 0; copy < 2; ++copy) {
        const int32_t base = static_cast<int32_t>(data.points.size());
        const int32_t uvBase = static_cast<int32_t>(data.uvs.size());
        for (const glm::vec3& p : single.points())
            data.points.push_back(p + glm::vec3(0.0f, 0.0f, static_cast<float>(copy)));
        for (const glm::vec2& uv : single.uvs())
            data.uvs.push_back(uv);
        for (int32_t c : single.faceCounts())
            data.faceCounts.push_back(c);
        for (int32_t v : single.faceIndices())
            data.faceIndices.push_back(base + v);
        for (int32_t t : single.uvIndices())
            data.uvIndices.push_back(uvBase + t);
    }
    const geom::Mesh stacked(std::move(data));
    CHECK(countMismatches(deriveWarpMask(stacked, 1001, 16), deriveWarpMask(single, 1001, 16)) == 0);
}

TEST_CASE("binarising a painted warp mask", "[uvwarp][mask]") {
    io::Image painted(4, 1, 3, 0.0f);
    const float values[4] = {0.2f, 0.5f, 0.7f, 0.49999f};
    for (int32_t x = 0; x < 4; ++x) {
        painted.at(x, 0, 0) = values[x];
        painted.at(x, 0, 1) = 1.0f - values[x];  // other channels are ignored
    }
    // Non-square maps are refused; make it square by repeating the row.
    CHECK_THROWS_WITH(binariseWarpMask(painted, {"mask.exr", 1001}), Catch::Contains("4 x 1"));
    io::Image square(4, 4, 3, 0.0f);
    for (int32_t y = 0; y < 4; ++y) {
        for (int32_t x = 0; x < 4; ++x)
            square.at(x, y, 0) = values[x];
    }
    const io::Image binary = binariseWarpMask(square, {"mask.exr", 1001});
    REQUIRE(binary.channels == 1);
    for (int32_t y = 0; y < 4; ++y) {
        CHECK(binary.at(0, y, 0) == 0.0f);
        CHECK(binary.at(1, y, 0) == 1.0f);  // 0.5 itself may warp
        CHECK(binary.at(2, y, 0) == 1.0f);
        CHECK(binary.at(3, y, 0) == 0.0f);
    }
    square.at(2, 3, 0) = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(binariseWarpMask(square, {"mask.exr", 1001}),
                      Catch::Contains("mask.exr, UDIM tile 1001") && Catch::Contains("texel (2, 3)") &&
                          Catch::Contains("NaN"));
}

TEST_CASE("validating a rigidity map names the texel", "[uvwarp][mask]") {
    io::Image rigidity(8, 8, 1, 0.5f);
    CHECK_NOTHROW(validateRigidityMap(rigidity, {"rig.1001.exr", 1001}));
    rigidity.at(0, 0, 0) = 0.0f;
    rigidity.at(7, 7, 0) = 1.0f;
    CHECK_NOTHROW(validateRigidityMap(rigidity, {"rig.1001.exr", 1001}));
    rigidity.at(3, 2, 0) = 1.5f;
    CHECK_THROWS_WITH(validateRigidityMap(rigidity, {"rig.1001.exr", 1001}),
                      Catch::Contains("rig.1001.exr, UDIM tile 1001") && Catch::Contains("texel (3, 2)") &&
                          Catch::Contains("1.5") && Catch::Contains("[0, 1]"));
    rigidity.at(3, 2, 0) = -0.1f;
    CHECK_THROWS_WITH(validateRigidityMap(rigidity, {"rig", 1002}), Catch::Contains("texel (3, 2)"));
    rigidity.at(3, 2, 0) = 0.5f;
    rigidity.at(5, 6, 0) = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(validateRigidityMap(rigidity, {"rig", 1002}), Catch::Contains("texel (5, 6)"));
    CHECK_THROWS_AS(validateRigidityMap(io::Image(8, 4, 1), {"rig", 1002}), InvalidInput);
}

TEST_CASE("reading mask and rigidity files", "[uvwarp][mask]") {
    test::TempDir dir;
    io::Image mask(4, 4, 1, 0.8f);
    mask.at(1, 2, 0) = 0.3f;
    io::ImageWriteOptions exact;
    exact.type = io::PixelType::Float;
    io::writeImage(dir / "mask.1001.exr", mask, exact);
    const io::Image read = readWarpMask(dir / "mask.1001.exr", 1001);
    CHECK(countOnes(read) == 15);
    CHECK(read.at(1, 2, 0) == 0.0f);
    mask.at(3, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    io::writeImage(dir / "nan.1001.exr", mask, exact);
    CHECK_THROWS_WITH(readWarpMask(dir / "nan.1001.exr", 1001),
                      Catch::Contains("nan.1001.exr") && Catch::Contains("texel (3, 0)"));

    io::Image rigidity(4, 4, 3, 0.25f);
    rigidity.at(2, 1, 0) = 2.0f;
    io::writeImage(dir / "rig.1001.exr", rigidity, exact);
    CHECK_THROWS_WITH(readRigidityMap(dir / "rig.1001.exr", 1001), Catch::Contains("rig.1001.exr") &&
                                                                       Catch::Contains("UDIM tile 1001") &&
                                                                       Catch::Contains("texel (2, 1)"));
    rigidity.at(2, 1, 0) = 0.75f;
    io::writeImage(dir / "rig.1001.exr", rigidity, exact);
    const io::Image r = readRigidityMap(dir / "rig.1001.exr", 1001);
    REQUIRE(r.channels == 1);
    CHECK(r.at(2, 1, 0) == 0.75f);
    CHECK(r.at(0, 0, 0) == 0.25f);
}

TEST_CASE("rigidity at grid points samples a linear ramp bilinearly", "[uvwarp][mask]") {
    // R = 0.3 u + 0.6 v at texel centres. Bilinear sampling reproduces it at a point whose texel coordinates
    // lie within the centres' hull; beyond, it clamps to the edge texels: u is clamped to
    // [0.5 / T, 1 - 0.5 / T], and so is v.
    const int32_t t = 16;
    io::Image ramp(t, t, 1);
    for (int32_t y = 0; y < t; ++y) {
        for (int32_t x = 0; x < t; ++x)
            ramp.at(x, y, 0) = static_cast<float>(0.3 * (x + 0.5) / t + 0.6 * (1.0 - (y + 0.5) / t));
    }
    for (int32_t n : {8, 16, 32}) {
        const PointField r = rigidityAtPoints(ramp, n, {"ramp", 1001});
        REQUIRE(r.cells == n);
        REQUIRE(r.channels == 1);
        for (int32_t j = 0; j <= n; ++j) {
            for (int32_t i = 0; i <= n; ++i) {
                const double u = std::clamp(double(i) / n, 0.5 / t, 1.0 - 0.5 / t);
                const double v = std::clamp(double(j) / n, 0.5 / t, 1.0 - 0.5 / t);
                // float32 texels and weights.
                CHECK(r.values[r.index(i, j)] == Approx(0.3 * u + 0.6 * v).margin(1e-6));
            }
        }
    }
    io::Image bad = ramp;
    bad.at(4, 9, 0) = -1.0f;
    CHECK_THROWS_WITH(rigidityAtPoints(bad, 16, {"ramp", 1001}), Catch::Contains("texel (4, 9)"));
    CHECK_THROWS_WITH(rigidityAtPoints(ramp, 12, {"ramp", 1001}), Catch::Contains("power of two"));
}

TEST_CASE("mask at grid points: one fixed texel fixes the points within one texel or one cell",
          "[uvwarp][mask]") {
    // An 8 x 8 mask with texel (3, 2) fixed (image row 2 from the top: v between 5/8 and 6/8).
    io::Image mask(8, 8, 1, 1.0f);
    mask.at(3, 2, 0) = 0.0f;
    auto zeros = [](const PointField& f) {
        std::vector<std::pair<int, int>> out;
        for (int32_t j = 0; j <= f.cells; ++j) {
            for (int32_t i = 0; i <= f.cells; ++i) {
                const float value = f.values[f.index(i, j)];
                REQUIRE((value == 0.0f || value == 1.0f));
                if (value == 0.0f) out.emplace_back(i, j);
            }
        }
        return out;
    };
    // n = T: point (i, j) sits on the corner shared by texel columns i - 1, i and rows 7 - j, 8 - j, so the
    // four corners of texel (3, 2) are fixed: i in {3, 4}, j in {5, 6}.
    CHECK(zeros(maskAtPoints(mask, 8)) == std::vector<std::pair<int, int>>{{3, 5}, {4, 5}, {3, 6}, {4, 6}});
    // n = T / 2: point (i, j) is at texel coordinate (2i - 0.5, 2(4 - j) - 0.5), and the reach is one cell
    // (2 texels): texel column 3 is within it of i = 1 and 2, row 2 of j = 2 and 3. The four corners of
    // the cell holding the texel are fixed (within one texel, only (2, 3) was: on a map finer than the
    // grid, the chart-border band of fixed points was thinner than a cell and the solve fell apart).
    CHECK(zeros(maskAtPoints(mask, 4)) == std::vector<std::pair<int, int>>{{1, 2}, {2, 2}, {1, 3}, {2, 3}});
    // n = T / 4: one cell is 4 texels; texel (3, 2) lies in cell (0, 1) (texels 0-3, rows 0-3 from the top
    // are v in [1/2, 1]): its corners i in {0, 1}, j in {1, 2}.
    CHECK(zeros(maskAtPoints(mask, 2)) == std::vector<std::pair<int, int>>{{0, 1}, {1, 1}, {0, 2}, {1, 2}});
    // n = 2T: point (i, j) at texel coordinate (i / 2 - 0.5, (16 - j) / 2 - 0.5); |i / 2 - 3.5| <= 1 gives
    // i in 5..9, |(16 - j) / 2 - 2.5| <= 1 gives j in 9..13.
    std::vector<std::pair<int, int>> expected;
    for (int j = 9; j <= 13; ++j) {
        for (int i = 5; i <= 9; ++i)
            expected.emplace_back(i, j);
    }
    CHECK(zeros(maskAtPoints(mask, 16)) == expected);
    // Non-binary values are thresholded at 0.5; NaN is neither side of it: refused, naming the texel (a mask
    // in memory took it as fixed without a word).
    mask.at(3, 2, 0) = 0.6f;
    mask.at(0, 0, 0) = 0.0f;
    CHECK(zeros(maskAtPoints(mask, 8)) == std::vector<std::pair<int, int>>{{0, 7}, {1, 7}, {0, 8}, {1, 8}});
    mask.at(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)maskAtPoints(mask, 8, {"paint", 1001});
               }),
               Catch::Contains("texel (0, 0): warp mask value is NaN"));
}

TEST_CASE("derived mask bad input", "[uvwarp][mask]") {
    const geom::Mesh chart = test::planarChart({0.25f, 0.25f}, {0.75f, 0.75f}, 2, 2, kFlat);
    DerivedMaskOptions options;
    options.label = "body.obj";
    options.borderWidth = 0;
    CHECK_THROWS_WITH(deriveWarpMask(chart, 1001, 16, options),
                      Catch::Contains("body.obj") && Catch::Contains("border width"));
    options.borderWidth = 1;
    CHECK_THROWS_WITH(deriveWarpMask(chart, 1001, 0, options), Catch::Contains("texels"));
    const geom::Mesh straddling = test::planarChart({0.5f, 0.2f}, {2.0f, 0.6f}, 2, 1, kFlat);
    CHECK_THROWS_WITH(deriveWarpMask(straddling, 1001, 16, options),
                      Catch::Contains("body.obj, UDIM tile 1001") && Catch::Contains("face 0"));
}
