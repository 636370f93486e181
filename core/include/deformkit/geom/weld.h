#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "deformkit/geom/mesh.h"

// Split vertices welded back together. glTF, FBX and game-engine files split a vertex wherever its normals
// or UVs break (a glTF may give every triangle its own three vertices); connectivity built on such a mesh
// tears at every seam. Whatever needs connectivity (the slide's walks, regions and fold count, the limit
// surface, previews' normals, the mesh warp's control mesh) works on the welded mesh and hands its result
// back to every copy, so the file's vertex order, UVs and groups are kept.
namespace deformkit::geom {

struct Welding {
    // The welded mesh: one vertex per group of coincident vertices, at the position of the group's first
    // (lowest-index) vertex, numbered in the order of those first vertices; the faces on welded vertices in
    // the file's order (a face whose corners weld together, a sliver of coincident points, is left out);
    // every face corner keeps its UV. Empty when nothing was welded (merged() == 0): the file's mesh is it.
    Mesh mesh;
    std::vector<int32_t> weldedOf;     // per file vertex: its welded vertex
    std::vector<int32_t> firstOf;      // per welded vertex: its first file vertex
    std::vector<int32_t> copyOffsets;  // per welded vertex w: its file vertices are copies[copyOffsets[w] ..
    std::vector<int32_t> copies;       // copyOffsets[w + 1]), ascending
    std::vector<int32_t> fileFaceOf;   // per welded face: its face in the file

    // File vertices merged into another: the file's vertex count minus the welded mesh's.
    [[nodiscard]] int32_t merged() const {
        return static_cast<int32_t>(weldedOf.size()) - static_cast<int32_t>(firstOf.size());
    }
    [[nodiscard]] std::span<const int32_t> copiesOf(int32_t welded) const {
        return std::span<const int32_t>(copies).subspan(
            static_cast<size_t>(copyOffsets[welded]),
            static_cast<size_t>(copyOffsets[welded + 1] - copyOffsets[welded]));
    }
};

// Welds the vertices of `mesh` that lie within `tolerance` of each other (scene units; 0: exactly equal
// positions, the default), transitively. Throws InvalidInput naming `source` for a negative or non-finite
// tolerance, or when every face collapses.
[[nodiscard]] Welding weldVertices(const Mesh& mesh, double tolerance = 0.0,
                                   const std::string& source = "mesh");

// Per-welded-vertex values handed back to the file's vertices: out[v] = welded[weldedOf[v]].
template <class T>
void scatterToCopies(const Welding& weld, std::span<const T> welded, std::span<T> out) {
    for (size_t v = 0; v < out.size(); ++v)
        out[v] = welded[static_cast<size_t>(weld.weldedOf[v])];
}

}  // namespace deformkit::geom
