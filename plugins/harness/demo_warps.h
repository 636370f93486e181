#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/preview.h"

namespace deformkit::harness {

// One warp of the demo applied to the demo tube: its name and the deformed mesh.
struct DemoWarp {
    std::string name;  // "ffd", "twist", ...
    geom::Mesh mesh;   // the tube after the warp
};

// Each 3-D warp of the framework (FFD, FFD with frames, taper, twist, bend, Wires, smooth Wires, mesh
// warp) applied to `tube` (the demo's capped tube: radius 1, y from 0 to 4) with settings a rigger
// would try first.
[[nodiscard]] std::vector<DemoWarp> makeDemoWarps(const geom::Mesh& tube);

// Writes warps/<name>.obj and warps/<name>.png (textured preview) for each demo warp, and
// warps/beier_neely.png (the Beier-Neely global variant applied to `image`); returns the files written.
std::vector<std::filesystem::path> writeDemoWarps(const geom::Mesh& tube, const io::PreviewTexture& texture,
                                                  const io::Image& image,
                                                  const std::filesystem::path& outDir);

}  // namespace deformkit::harness
