#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/box.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/preview.h"
#include "mesh_support.h"

using namespace deformkit;

namespace {

bool isBackground(const io::Image& img, int32_t x, int32_t y, const glm::vec3& bg) {
    return std::abs(img.at(x, y, 0) - bg.r) < 1e-6f && std::abs(img.at(x, y, 1) - bg.g) < 1e-6f &&
           std::abs(img.at(x, y, 2) - bg.b) < 1e-6f;
}

io::Image solid(glm::vec3 c) {
    io::Image img(4, 4, 3);
    for (int32_t i = 0; i < 16; ++i) {
        for (int k = 0; k < 3; ++k)
            img.pixels[3 * i + k] = c[k];
    }
    return img;
}

}  // namespace

TEST_CASE("preview: a sphere's silhouette matches the perspective closed form", "[io][preview]") {
    const float r = 1.0f;
    const geom::Mesh sphere = geom::makeSphere({r, 256, 128});
    io::PreviewOptions o;
    o.width = o.height = 400;
    o.viewDirection = {0.0f, 0.0f, -1.0f};
    const io::Image img = io::renderPreview(sphere, o);
    int64_t covered = 0;
    for (int32_t y = 0; y < o.height; ++y) {
        for (int32_t x = 0; x < o.width; ++x)
            covered += isBackground(img, x, y, o.background) ? 0 : 1;
    }
    // Documented framing: distance D = 1.08 R_box / sin(fov/2), R_box = r sqrt(3) for the sphere's box.
    // A sphere seen from D projects to a disk of radius focal * r / sqrt(D^2 - r^2), focal = (H/2) /
    // tan(fov/2).
    const double halfFov = 15.0 * std::numbers::pi / 180.0;
    const double D = 1.08 * r * std::sqrt(3.0) / std::sin(halfFov);
    const double focal = 0.5 * o.height / std::tan(halfFov);
    const double rho = focal * r / std::sqrt(D * D - r * r);
    CHECK(static_cast<double>(covered) == Approx(std::numbers::pi * rho * rho).epsilon(0.01));
    // Centred: the centre pixel is covered and lit, the corners are background.
    CHECK_FALSE(isBackground(img, 200, 200, o.background));
    CHECK(isBackground(img, 0, 0, o.background));
    CHECK(isBackground(img, 399, 399, o.background));
}

TEST_CASE("preview: textures follow UV orientation and UDIM tiles", "[io][preview]") {
    io::PreviewOptions o;
    o.width = 200;
    o.height = 100;
    o.viewDirection = {0.0f, 0.0f, -1.0f};  // looking down -z: x to the right, y up

    SECTION("one image: top row of the image is v = 1") {
        const geom::Mesh grid = geom::makeGrid({4, 4, 1.0f, 1.0f});
        io::PreviewTexture tex;
        tex.single = io::Image(2, 2, 3);
        for (int32_t x = 0; x < 2; ++x) {
            tex.single->at(x, 0, 1) = 1.0f;  // top row green
            tex.single->at(x, 1, 0) = 1.0f;  // bottom row red
        }
        const io::Image img = io::renderPreview(grid, o, &tex);
        const int32_t top = 30, bottom = 70, cx = 100;
        CHECK(img.at(cx, top, 1) > 0.3f);
        CHECK(img.at(cx, top, 0) < 0.05f);
        CHECK(img.at(cx, bottom, 0) > 0.3f);
        CHECK(img.at(cx, bottom, 1) < 0.05f);
    }
    SECTION("UDIM: u in [0, 1) reads tile 1001, u in [1, 2) tile 1002") {
        geom::Mesh grid = geom::makeGrid({8, 4, 2.0f, 1.0f});
        for (auto& uv : grid.uvs())
            uv.x *= 2.0f;
        io::PreviewTexture tex;
        tex.tiles.emplace(1001, solid({1.0f, 0.0f, 0.0f}));
        tex.tiles.emplace(1002, solid({0.0f, 0.0f, 1.0f}));
        const io::Image img = io::renderPreview(grid, o, &tex);
        CHECK(img.at(75, 50, 0) > 0.3f);
        CHECK(img.at(75, 50, 2) == 0.0f);
        CHECK(img.at(125, 50, 2) > 0.3f);
        CHECK(img.at(125, 50, 0) == 0.0f);
    }
}

TEST_CASE("preview: bad input is reported", "[io][preview][errors]") {
    CHECK_THROWS_WITH(io::renderPreview(geom::Mesh()), Catch::Contains("has no faces"));
    geom::Mesh::Data d;
    d.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    d.faceCounts = {3};
    d.faceIndices = {0, 1, 2};
    const geom::Mesh noUVs(d);
    io::PreviewTexture tex;
    tex.single = solid({1, 1, 1});
    CHECK_THROWS_WITH(io::renderPreview(noUVs, {}, &tex), Catch::Contains("no UVs"));
    io::PreviewOptions o;
    o.width = 0;
    CHECK_THROWS_AS(io::renderPreview(noUVs, o), InvalidInput);
    // A view direction of zero length or not finite is refused, not replaced by another view.
    for (const glm::vec3 view :
         {glm::vec3(0.0f), glm::vec3(std::numeric_limits<float>::quiet_NaN(), 1.0f, 1.0f),
          glm::vec3(std::numeric_limits<float>::infinity(), 1.0f, 1.0f)}) {
        io::PreviewOptions bad;
        bad.viewDirection = view;
        CHECK_THROWS_WITH(io::renderPreview(noUVs, bad),
                          Catch::Contains("preview: view direction: is (") &&
                              Catch::Contains("(expected three finite numbers, not all 0)"));
    }
    // Components whose float length overflows still give a direction: the same picture as the unit one.
    io::PreviewOptions huge, unit;
    huge.viewDirection = {0.0f, -1e30f, -3e30f};
    unit.viewDirection = {0.0f, -1.0f, -3.0f};
    CHECK(io::renderPreview(noUVs, huge).pixels == io::renderPreview(noUVs, unit).pixels);
}

TEST_CASE("preview: a framing box sets the camera as the box's bounds would", "[io][preview]") {
    const float r = 1.0f;
    const geom::Mesh sphere = geom::makeSphere({r, 64, 32});
    io::PreviewOptions o;
    o.width = o.height = 200;
    o.viewDirection = {0.0f, 0.0f, -1.0f};
    // The mesh's own box: the default camera, the same pixels.
    io::PreviewOptions own = o;
    own.frame = sphere.bounds();
    CHECK(io::renderPreview(sphere, own).pixels == io::renderPreview(sphere, o).pixels);
    // A box 3 times as large about the same centre: the sphere's disk shrinks by the closed form of the
    // first test, with R_box = 3 r sqrt(3) and the sphere's own r.
    io::PreviewOptions wide = o;
    wide.frame = geom::Box3{glm::vec3(-3.0f * r), glm::vec3(3.0f * r)};
    const io::Image img = io::renderPreview(sphere, wide);
    int64_t covered = 0;
    for (int32_t y = 0; y < o.height; ++y)
        for (int32_t x = 0; x < o.width; ++x)
            covered += isBackground(img, x, y, o.background) ? 0 : 1;
    const double halfFov = 15.0 * std::numbers::pi / 180.0;
    const double D = 1.08 * 3.0 * r * std::sqrt(3.0) / std::sin(halfFov);
    const double focal = 0.5 * o.height / std::tan(halfFov);
    const double rho = focal * r / std::sqrt(D * D - r * r);
    // A disk of about 9 pixels radius: the pixel count of a rasterised disk is within its perimeter of
    // the area, so 2 pi rho / (pi rho^2) ~ 22% is the tolerance.
    CHECK(static_cast<double>(covered) == Approx(std::numbers::pi * rho * rho).epsilon(2.0 / rho));
}

TEST_CASE("preview: per-vertex colours are interpolated over the faces", "[io][preview]") {
    // A grid in the z = 0 plane seen straight down: every pixel has the same light, so colours keep their
    // ratios. Vertex colour (s, 0, 1 - s) with s linear in x: the red share r / (r + b) at a pixel is s at
    // the point it sees, which is 1/2 at the centre and mirror-symmetric about it (the view is).
    const geom::Mesh grid = geom::makeGrid({8, 8, 2.0f, 2.0f});
    const geom::Box3 box = grid.bounds();
    io::PreviewOptions o;
    o.width = o.height = 200;
    o.viewDirection = {0.0f, 0.0f, -1.0f};
    for (const glm::vec3& p : grid.points()) {
        const float s = (p.x - box.min.x) / (box.max.x - box.min.x);
        o.vertexColors.emplace_back(s, 0.0f, 1.0f - s);
    }
    const io::Image img = io::renderPreview(grid, o);
    const auto share = [&](int32_t x) { return img.at(x, 100, 0) / (img.at(x, 100, 0) + img.at(x, 100, 2)); };
    // Pixel centres at 99.5 and 100.5 straddle the centre line: shares 1/2 -+ one pixel's step.
    CHECK(share(99) + share(100) == Approx(1.0).margin(1e-4));
    CHECK(share(60) + share(139) == Approx(1.0).margin(1e-4));
    CHECK(share(60) < 0.4f);
    CHECK(img.at(100, 100, 1) == 0.0f);

    o.vertexColors.pop_back();
    CHECK_THROWS_WITH(io::renderPreview(grid, o), Catch::Contains("one per vertex"));
}

TEST_CASE("preview: weight colours run blue, cyan, green, yellow, red", "[io][preview]") {
    const auto same = [](glm::vec3 a, glm::vec3 b) { return glm::length(a - b) < 1e-6f; };
    CHECK(same(io::weightColor(0.0f), {0, 0, 1}));
    CHECK(same(io::weightColor(0.25f), {0, 1, 1}));
    CHECK(same(io::weightColor(0.5f), {0, 1, 0}));
    CHECK(same(io::weightColor(0.75f), {1, 1, 0}));
    CHECK(same(io::weightColor(1.0f), {1, 0, 0}));
    CHECK(same(io::weightColor(0.125f), {0, 0.5f, 1}));
    CHECK(same(io::weightColor(-2.0f), {0, 0, 1}));
    CHECK(same(io::weightColor(7.0f), {1, 0, 0}));
    CHECK(same(io::weightColor(std::nanf("")), {0, 0, 1}));
}

TEST_CASE("preview: split vertices shade as the shared-vertex mesh, pixel for pixel", "[io][preview][weld]") {
    const geom::Mesh spot = io::readObj(DEFORMKIT_TEST_DATA "/spot/spot_quadrangulated.obj").mesh;
    io::PreviewOptions options;
    options.width = 160;
    options.height = 120;
    const io::Image shared = io::renderPreview(spot, options);
    for (const bool perCorner : {false, true}) {
        CAPTURE(perCorner);
        std::vector<int32_t> original;
        const geom::Mesh split = test::splitCopy(spot, perCorner, original);
        CHECK(io::renderPreview(split, options).pixels == shared.pixels);
    }
    // Without the weld each split face would shade alone: the faceted picture differs.
    geom::Mesh::Data apart;
    std::vector<int32_t> original;
    const geom::Mesh split = test::splitCopy(spot, true, original);
    apart.points.assign(split.points().begin(), split.points().end());
    for (glm::vec3& p : apart.points)
        p.x += 1e-7f * static_cast<float>(&p - apart.points.data() & 1);  // copies no longer coincide
    apart.faceCounts.assign(split.faceCounts().begin(), split.faceCounts().end());
    apart.faceIndices.assign(split.faceIndices().begin(), split.faceIndices().end());
    CHECK(io::renderPreview(geom::Mesh(std::move(apart), "apart"), options).pixels != shared.pixels);
}
