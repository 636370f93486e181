#pragma once

#include <filesystem>
#include <vector>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"
#include "deformkit/io/preview.h"
#include "deformkit/slide/slider.h"

namespace deformkit::harness {

// The demo's slide: one handle on the side of the demo tube (radius 1, y from 0 to 4), the vertex nearest
// the mid-height point facing the preview camera, its region slid up and around the tube (geodesic radius
// 1.2). The shape stays; the texture travels with the vertices.
struct DemoSlide {
    slide::SlideHandle handle;
    glm::dvec3 displacement{0.0};  // scene units
    geom::Mesh mesh;               // the tube after the slide
    slide::SlideResult result;
};

[[nodiscard]] DemoSlide makeDemoSlide(const geom::Mesh& tube);

// A checker texture for one UDIM tile of the demo tube: 32 x 20 checks on the side (tile 1001, about square
// on the tube) and 16 x 16 on the caps (1002), in two colours that 8-bit files store exactly.
[[nodiscard]] io::Image demoChecker(int tile, int32_t resolution);

// The preview settings of the slide's pictures; `deformkit preview --width 480 --height 480 --view
// -0.45,-0.3,-1` gives the same.
[[nodiscard]] io::PreviewOptions demoSlideView();

// Two images side by side on the first one's background, `gap` pixels apart.
[[nodiscard]] io::Image sideBySide(const io::Image& left, const io::Image& right, int32_t gap);

// Writes slide/tube_slid.obj, slide/checker.<UDIM>.png, slide/before.png and slide/after.png (the rest and
// the slid tube with the checker) and slide/slide.png (the two side by side); returns the files written.
std::vector<std::filesystem::path> writeDemoSlide(const geom::Mesh& tube,
                                                  const std::filesystem::path& outDir);

}  // namespace deformkit::harness
