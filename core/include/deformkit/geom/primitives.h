#pragma once

#include "deformkit/geom/mesh.h"

namespace deformkit::geom {

// Procedural meshes for tests, benchmarks and the demo. All are UV-mapped, quad-dominant and
// consistently oriented (outward normals for closed shapes, +z for the grid).

struct GridOptions {
    int32_t cellsX = 16;  // quads along x
    int32_t cellsY = 16;  // quads along y
    float sizeX = 1.0f;   // extent along x, scene units, starting at the origin
    float sizeY = 1.0f;   // extent along y
};
// A planar grid of quads in z = 0 over [0, sizeX] x [0, sizeY]; uv = (x / sizeX, y / sizeY), tile 1001.
[[nodiscard]] Mesh makeGrid(const GridOptions& options = {});

struct SphereOptions {
    float radius = 1.0f;
    int32_t segments = 32;  // around the z axis
    int32_t rings = 16;     // pole to pole; the two polar rings are triangle fans
};
// A UV sphere centred at the origin; u = longitude / 2pi (with a seam), v = polar angle / pi.
[[nodiscard]] Mesh makeSphere(const SphereOptions& options = {});

struct CappedTubeOptions {
    float radius = 1.0f;
    float length = 4.0f;     // along y, from y = 0
    int32_t segments = 160;  // around the axis
    int32_t rows = 120;      // quads along the axis
    int32_t capRings = 10;   // concentric rings per cap; the innermost is a triangle fan
};
// A closed tube (the demo asset): the side's UVs fill UDIM tile 1001 with a seam along one side
// (u = 1 - angle / 2pi, v = y / length); both caps are laid out side by side in tile 1002.
// With the defaults it has 22,242 vertices.
[[nodiscard]] Mesh makeCappedTube(const CappedTubeOptions& options = {});

}  // namespace deformkit::geom
