#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "deformkit/scene/scene.h"
#include "deformkit/scene/weight_maps.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

constexpr int kSize = 16;  // weight maps: 16 x 16

// An n x n quad grid per tile in `tiles` (tile t: u in [tu + 0.05, tu + 0.95], v likewise), positions in
// the plane z = index of the grid. No seams: each vertex has one uv.
geom::Mesh grids(const std::vector<int>& tiles, int n = 4) {
    geom::Mesh::Data d;
    for (size_t g = 0; g < tiles.size(); ++g) {
        const float tu = static_cast<float>((tiles[g] - 1001) % 10),
                    tv = static_cast<float>((tiles[g] - 1001) / 10);
        for (int j = 0; j <= n; ++j) {
            for (int i = 0; i <= n; ++i) {
                d.points.emplace_back(static_cast<float>(i), static_cast<float>(j), static_cast<float>(g));
                d.uvs.emplace_back(tu + 0.05f + 0.9f * static_cast<float>(i) / n,
                                   tv + 0.05f + 0.9f * static_cast<float>(j) / n);
            }
        }
        const int base = static_cast<int>(g) * (n + 1) * (n + 1);
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const int a = base + j * (n + 1) + i;
                d.faceCounts.push_back(4);
                d.faceIndices.insert(d.faceIndices.end(), {a, a + 1, a + n + 2, a + n + 1});
            }
        }
    }
    d.uvIndices = d.faceIndices;
    return geom::Mesh(std::move(d), "grids");
}

// g(u, v) = offset + 0.5 u + 0.25 v in tile-local uv: bilinear interpolation of its values at pixel centres
// reproduces it exactly inside the band of pixel centres.
double linear(double u, double v, double offset) {
    return offset + 0.5 * u + 0.25 * v;
}

// Channel 1 holds g; channel 0 holds a constant 9 (so reading the wrong channel shows).
io::Image linearMap(double offset) {
    io::Image image(kSize, kSize, 2);
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            image.at(x, y, 0) = 9.0f;
            image.at(x, y, 1) =
                static_cast<float>(linear((x + 0.5) / kSize, 1.0 - (y + 0.5) / kSize, offset));
        }
    }
    return image;
}

void writeFloat(const fs::path& path, const io::Image& image) {
    io::ImageWriteOptions options;
    options.type = io::PixelType::Float;
    io::writeImage(path, image, options);
}

}  // namespace

TEST_CASE("weight maps: per-tile maps sampled through the UVs reproduce a linear painting",
          "[host][weights]") {
    test::TempDir dir;
    writeFloat(dir / "w.1001.exr", linearMap(0.0));
    writeFloat(dir / "w.1012.exr", linearMap(0.1));  // tile 1012: u in [1, 2], v in [1, 2]
    const geom::Mesh mesh = grids({1001, 1012});
    const std::vector<float> w = scene::weightsFromMaps(mesh, dir / "w.<UDIM>.exr", 1, "test");
    REQUIRE(w.size() == static_cast<size_t>(mesh.numVertices()));
    for (int32_t v = 0; v < mesh.numVertices(); ++v) {
        const glm::vec2 uv = mesh.uvs()[static_cast<size_t>(v)];  // uv index = vertex index here
        const bool second = uv.x > 1.0f;
        const double expected =
            linear(uv.x - (second ? 1.0 : 0.0), uv.y - (second ? 1.0 : 0.0), second ? 0.1 : 0.0);
        CAPTURE(v);
        // Float bilinear weights and float texels: a few float ulps of values below 1.
        CHECK(w[static_cast<size_t>(v)] == Approx(expected).margin(1e-6));
    }
    // Without a UDIM token one image serves tile 1001.
    const geom::Mesh one = grids({1001});
    CHECK(scene::weightsFromMaps(one, dir / "w.1001.exr", 1, "test") ==
          std::vector<float>(w.begin(), w.begin() + one.numVertices()));
}

TEST_CASE("weight maps: a vertex on a UV seam gets the mean of its corners' samples", "[host][weights]") {
    test::TempDir dir;
    writeFloat(dir / "w.exr", linearMap(0.0));
    // Two triangles sharing edge (1, 2) in space, cut apart in UV space: vertices 1 and 2 have two uvs.
    geom::Mesh::Data d;
    d.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    d.faceCounts = {3, 3};
    d.faceIndices = {0, 1, 2, 1, 3, 2};
    d.uvs = {{0.1f, 0.1f}, {0.4f, 0.1f}, {0.1f, 0.4f}, {0.6f, 0.6f}, {0.9f, 0.6f}, {0.6f, 0.9f}};
    d.uvIndices = {0, 1, 2, 3, 4, 5};
    const geom::Mesh mesh(std::move(d), "seam");
    const std::vector<float> w = scene::weightsFromMaps(mesh, dir / "w.exr", 1, "test");
    auto g = [](glm::vec2 uv) { return linear(uv.x, uv.y, 0.0); };
    const glm::vec2 uvs[6] = {{0.1f, 0.1f}, {0.4f, 0.1f}, {0.1f, 0.4f},
                              {0.6f, 0.6f}, {0.9f, 0.6f}, {0.6f, 0.9f}};
    CHECK(w[0] == Approx(g(uvs[0])).margin(1e-6));
    CHECK(w[1] == Approx(0.5 * (g(uvs[1]) + g(uvs[3]))).margin(1e-6));
    CHECK(w[2] == Approx(0.5 * (g(uvs[2]) + g(uvs[5]))).margin(1e-6));
    CHECK(w[3] == Approx(g(uvs[4])).margin(1e-6));
}

TEST_CASE("weight maps: bad input names the source, the file and what was expected",
          "[host][weights][errors]") {
    test::TempDir dir;
    writeFloat(dir / "w.1001.exr", linearMap(0.0));
    const geom::Mesh two = grids({1001, 1002});
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] { (void)scene::weightsFromMaps(two, dir / "w.1001.exr", 0, "src"); }),
        Contains("src: ") && Contains("face 16 has its UVs in tile 1002"));
    CHECK_THAT(test::errorOf<InvalidInput>(
                   [&] { (void)scene::weightsFromMaps(grids({1001}), dir / "w.1001.exr", 2, "src"); }),
               Contains("w.1001.exr: has 2 channels, channel 2 asked (expected a channel from 0 to 1)"));
    CHECK_THAT(
        test::errorOf<Error>([&] { (void)scene::weightsFromMaps(two, dir / "w.<UDIM>.exr", 0, "src"); }),
        Contains("w.1002.exr"));
    geom::Mesh::Data d;
    d.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    d.faceCounts = {3};
    d.faceIndices = {0, 1, 2};
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)scene::weightsFromMaps(geom::Mesh(std::move(d), "m"), dir / "w.1001.exr", 0, "src");
               }),
               Contains("a weight map for a mesh without UVs"));
}

TEST_CASE("weight maps: a scene's weights may be an image sampled through the UVs",
          "[host][weights][scene]") {
    test::TempDir dir;
    writeFloat(dir / "w.1001.exr", linearMap(0.0));
    const geom::Mesh mesh = grids({1001});
    io::writeObj(dir / "grid.obj", mesh);
    const std::string head =
        R"({"deformkit_scene": 1, "frames": [1, 1], "objects": [{"name": "g", "mesh": "grid.obj",
      "stack": [{"type": "twist", "weights": )";
    const scene::Scene scene =
        scene::parseScene(head + R"({"image": "w.<UDIM>.exr", "channel": 1}}]}]})", dir / "shot.json");
    const std::vector<float> expected = scene::weightsFromMaps(mesh, dir / "w.<UDIM>.exr", 1, "x");
    CHECK(scene.objects[0].stack[0].weights == expected);
    CHECK(scene.objects[0].stack[0].weightsFile == dir / "w.<UDIM>.exr");
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)scene::parseScene(head + R"({"image": "w.<UDIM>.exr", "chanel": 1}}]}]})",
                                           dir / "shot.json");
               }),
               Contains("shot.json: objects[0].stack[0].weights.chanel: is not a known key"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)scene::parseScene(head + R"({"image": "w.<UDIM>.exr", "channel": 5}}]}]})",
                                           dir / "shot.json");
               }),
               Contains("shot.json: objects[0].stack[0].weights.image: ") && Contains("channel 5 asked"));
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] {
            (void)scene::parseScene(head + R"({"image": "w.<UDIM>.exr", "channel": 1.5}}]}]})",
                                    dir / "shot.json");
        }),
        Contains("shot.json: objects[0].stack[0].weights.channel: is 1.5 (expected a whole number from 0 "
                 "to 64)"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] {
                   (void)scene::parseScene(head + R"({"image": "v.<UDIM>.exr"}}]}]})", dir / "shot.json");
               }),
               Contains("shot.json: objects[0].stack[0].weights.image: ") && Contains("v.1001.exr"));
}
