#pragma once

#include <filesystem>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/ptex/ptex_file.h"

namespace deformkit::harness {

// The demo's Ptex-painted slide: the demo tube without UVs (as Ptex-painted production meshes are), a
// falloff painted texel by texel into a Ptex file (a soft five-pointed star around the demo slide's
// handle), and the demo slide (0.6 of its drive) weighted by the per-vertex values of that file.
struct DemoPtex {
    geom::Mesh mesh;             // the tube without UVs
    ptex::PtexFile falloff;      // one float channel, 2^3 x 2^3 texels per face, with the mesh metadata
    std::vector<float> weights;  // per vertex, ptex::vertexValues of the file
    geom::Mesh slid;             // the tube after the weighted slide
};

// The painted star at a point of the demo tube (radius 1, axis y): 1 inside, 0 outside, a smooth edge
// 0.6 wide; centred on the side point at angle atan2(z, x) = `centreAngle` and height `centreY`.
[[nodiscard]] double demoStar(const glm::dvec3& point, double centreAngle, double centreY);

[[nodiscard]] DemoPtex makeDemoPtex(const geom::Mesh& tube);

// Writes ptex/tube.obj (no UVs), ptex/tube_slid.obj, ptex/falloff.ptx, ptex/before.png and ptex/after.png
// (the rest and the slid tube coloured by the weights, io::weightColor) and ptex/ptex.png (side by side);
// returns the files.
std::vector<std::filesystem::path> writeDemoPtex(const geom::Mesh& tube, const std::filesystem::path& outDir);

}  // namespace deformkit::harness
