#include "demo_slide.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/io/atomic_file.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/udim.h"

namespace deformkit::harness {
namespace fs = std::filesystem;

namespace {

// The angle about the tube's axis that faces the camera of demoSlideView(): the camera looks along
// (-0.45, -0.3, -1), so it sees the side whose outward normal is (0.45, 0, 1) in x and z.
constexpr double kFacingX = 0.45, kFacingZ = 1.0;

}  // namespace

io::Image sideBySide(const io::Image& left, const io::Image& right, int32_t gap) {
    const int32_t height = std::max(left.height, right.height);
    io::Image out(left.width + gap + right.width, height, 3);
    for (int32_t y = 0; y < height; ++y) {
        for (int32_t x = 0; x < out.width; ++x) {
            for (int c = 0; c < 3; ++c)
                out.at(x, y, c) = left.at(0, 0, c);
        }
    }
    auto place = [&](const io::Image& image, int32_t x0) {
        for (int32_t y = 0; y < image.height; ++y) {
            for (int32_t x = 0; x < image.width; ++x) {
                for (int c = 0; c < 3; ++c)
                    out.at(x0 + x, y, c) = image.at(x, y, c);
            }
        }
    };
    place(left, 0);
    place(right, left.width + gap);
    return out;
}

DemoSlide makeDemoSlide(const geom::Mesh& tube) {
    const glm::dvec3 facing = glm::normalize(glm::dvec3(kFacingX, 0.0, kFacingZ));
    const glm::dvec3 target(facing.x, 2.0, facing.z);  // on the unit tube at mid-height
    int32_t handle = 0;
    double best = 1e300;
    for (int32_t v = 0; v < tube.numVertices(); ++v) {
        const double d = glm::length(glm::dvec3(tube.points()[v]) - target);
        if (d < best) {
            best = d;
            handle = v;
        }
    }
    DemoSlide demo{{handle, 1.2, slide::RegionMetric::Geodesic}, glm::dvec3(0.0), tube, {}};
    // Around the tube (the tangent of the circle at the handle) and up its axis: 0.57 units, under the
    // radius / 1.5 at which the smooth falloff would start to fold the texture over itself.
    const glm::dvec3 around(-facing.z, 0.0, facing.x), up(0.0, 1.0, 0.0);
    demo.displacement = 0.45 * around + 0.35 * up;
    const std::vector<slide::SlideHandle> handles = {demo.handle};
    const std::vector<slide::SlideDrive> drives = {{demo.displacement}};
    const std::vector<glm::vec3> points = slide::slide(tube, handles, drives, {}, 1.0f, {}, &demo.result);
    demo.mesh.setPoints(points);
    return demo;
}

io::Image demoChecker(int tile, int32_t resolution) {
    if (tile != 1001 && tile != 1002) {
        throw InvalidInput(
            formatError("demo", "tile " + std::to_string(tile), "has no demo checker", "tile 1001 or 1002"));
    }
    // Side: u runs round the tube (2 pi units), v along it (4 units): 32 x 20 checks are about 0.2 square.
    const int32_t checksU = tile == 1001 ? 32 : 16, checksV = tile == 1001 ? 20 : 16;
    const glm::vec3 light(232.0f / 255.0f, 226.0f / 255.0f, 212.0f / 255.0f);
    const glm::vec3 dark(52.0f / 255.0f, 84.0f / 255.0f, 128.0f / 255.0f);
    io::Image image(resolution, resolution, 3);
    for (int32_t y = 0; y < resolution; ++y) {
        for (int32_t x = 0; x < resolution; ++x) {
            const int32_t cu = x * checksU / resolution, cv = y * checksV / resolution;
            const glm::vec3 c = (cu + cv) % 2 == 0 ? light : dark;
            for (int k = 0; k < 3; ++k)
                image.at(x, y, k) = c[k];
        }
    }
    return image;
}

io::PreviewOptions demoSlideView() {
    io::PreviewOptions view;
    view.width = 480;
    view.height = 480;
    view.viewDirection = {-0.45f, -0.3f, -1.0f};
    return view;
}

std::vector<fs::path> writeDemoSlide(const geom::Mesh& tube, const fs::path& outDir) {
    const fs::path dir = outDir / "slide";
    io::createFolder(dir);
    std::vector<fs::path> written;
    const DemoSlide demo = makeDemoSlide(tube);
    written.push_back(dir / "tube_slid.obj");
    io::writeObj(written.back(), demo.mesh);
    for (const int tile : tube.udimTiles()) {
        written.push_back(dir / io::expandUdim("checker.<UDIM>.png", tile));
        io::writeImage(written.back(), demoChecker(tile, 512));
    }
    // Rendered with the texture as read back from the files, so `deformkit preview` with these files and
    // demoSlideView()'s settings makes the same pictures.
    const io::PreviewTexture checker = io::loadPreviewTexture(dir / "checker.<UDIM>.png");
    const io::PreviewOptions view = demoSlideView();
    const io::Image before = io::renderPreview(tube, view, &checker);
    const io::Image after = io::renderPreview(demo.mesh, view, &checker);
    written.push_back(dir / "before.png");
    io::writeImage(written.back(), before);
    written.push_back(dir / "after.png");
    io::writeImage(written.back(), after);
    written.push_back(dir / "slide.png");
    io::writeImage(written.back(), sideBySide(before, after, 8));
    return written;
}

}  // namespace deformkit::harness
