#pragma once

// A scene with a UV-warp stage, as files in a temporary folder: two UV-mapped tubes under a taper, rigidity
// maps for both tiles and a texture for one. Shared by the scene's tests (tests/unit/scene) and the eval
// and farm commands' (tests/unit/harness).

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/host/deformers.h"
#include "deformkit/host/stack.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "image_support.h"
#include "mesh_support.h"
#include "test_support.h"

namespace deformkit::test::uvwarp_scene {

namespace fs = std::filesystem;

inline constexpr int kTexels = 32;

// Two open tubes of radius 0.5 around the Y axis (y from -1 to 1, a seam column), the second shifted by 2
// along X; tube t has its UVs in tile 1001 + t (u in [t, t + 1]), a small margin inside the tile so the
// border texels stay fixed.
inline geom::Mesh twoTubes(int rings = 9, int sides = 12) {
    geom::Mesh::Data d;
    for (int t = 0; t < 2; ++t)
        test::appendTube(d, {.rings = rings,
                             .sides = sides,
                             .center = {2.0f * static_cast<float>(t), 0.0f, 0.0f},
                             .uvs = test::TubeUVs::Seam,
                             .uvOrigin = {static_cast<float>(t) + 0.05f, 0.05f},
                             .uvSize = {0.9f, 0.9f}});
    return geom::Mesh(std::move(d), "tubes");
}

// Rigidity 1 in disks of radius 0.12 at (0.3, 0.5) and (0.7, 0.5) of the tile, 0 elsewhere.
inline io::Image disks() {
    io::Image image(kTexels, kTexels, 1);
    for (int y = 0; y < kTexels; ++y)
        for (int x = 0; x < kTexels; ++x)
            for (double cu : {0.3, 0.7})
                if (std::hypot((x + 0.5) / kTexels - cu, 1.0 - (y + 0.5) / kTexels - 0.5) < 0.12)
                    image.at(x, y, 0) = 1.0f;
    return image;
}

// Frames 1..3: a twist about Y that grows (stretching the tubes' surfaces along their diagonals), then
// the UV warp with rigidity maps for both tiles and a texture for tile 1001 only.
inline const char* kScene = R"({"deformkit_scene": 1, "frames": [1, 3], "objects": [
  {"name": "tubes", "mesh": "tubes.obj", "stack": [
    {"type": "taper", "params": {"handleY": [0, 1, 0], "lowBound": -1, "highBound": 1,
       "endScale": {"keys": [{"frame": 1, "value": 1.2, "interpolation": "linear"}, {"frame": 3, "value": 1.8}]}}},
    {"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "texture": "col.<UDIM>.exr",
     "params": {"iterations": 6, "warmStart": true}}]}]})";

struct Shot {
    test::TempDir dir;
    fs::path scene;
    geom::Mesh rest = twoTubes();
    Shot() {
        io::writeObj(dir / "tubes.obj", rest);
        io::ImageWriteOptions floats;
        floats.type = io::PixelType::Float;
        io::writeImage(dir / "rig.1001.exr", disks(), floats);
        io::writeImage(dir / "rig.1002.exr", disks(), floats);
        io::writeImage(dir / "col.1001.exr", test::exactHalfTexture(kTexels), floats);
        scene = dir / "shot.json";
        test::writeText(scene, kScene);
    }
};

// The stack of kScene built by hand, at `frame` (linear endScale from 1.2 at frame 1 to 1.8 at frame 3).
inline std::vector<glm::vec3> stackPoints(const geom::Mesh& rest, int frame) {
    host::DeformerStack stack;
    stack.setRest(rest);
    const size_t taper = stack.add(host::makeDeformer("taper", "taper1"));
    stack.set(taper, "handleY", std::vector<double>{0, 1, 0});
    stack.set(taper, "lowBound", -1.0);
    stack.set(taper, "highBound", 1.0);
    stack.set(taper, "endScale", 1.2 + 0.3 * (frame - 1));
    std::vector<glm::vec3> points(rest.points().begin(), rest.points().end());
    stack.evaluate(points);
    return points;
}

}  // namespace deformkit::test::uvwarp_scene
