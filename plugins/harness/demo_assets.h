#pragma once

#include <map>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"

namespace deformkit::harness {

// The demo's embedded default scene, generated in code: a UV-mapped capped tube over UDIM tiles 1001
// (side, with a seam) and 1002 (both caps), with per-tile texture-space maps.
struct DemoAssets {
    geom::Mesh mesh;
    std::map<int, io::Image> rigidity;  // 1 channel: 1 = rigid feature, 0 = elastic skin
    std::map<int, io::Image> mask;      // 1 channel: 1 = may warp; 0 outside UV charts and on chart borders
    std::map<int, io::Image> albedo;    // 3 channels: a colour texture that shows the features, for previews
};

struct DemoOptions {
    int32_t resolution = 1024;  // texels per tile side
    int32_t borderTexels = 2;   // chart-border width masked out of the warp mask
};

[[nodiscard]] DemoAssets makeDemoAssets(const DemoOptions& options = {});

// Rigidity map of one demo tile: tile 1001 carries an armour band, scattered disks and a field of
// scales; tile 1002 a ring and a boss on each cap. Feature edges are anti-aliased over one texel.
[[nodiscard]] io::Image demoRigidity(int tile, int32_t resolution);

// Warp mask of `tile` for `mesh`'s UV charts: 1 where a UV triangle covers the texel centre and every
// texel within `borderTexels` (Chebyshev distance) is covered too; 0 elsewhere.
[[nodiscard]] io::Image chartWarpMask(const geom::Mesh& mesh, int tile, int32_t resolution,
                                      int32_t borderTexels);

}  // namespace deformkit::harness
