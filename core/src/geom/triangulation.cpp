#include "deformkit/geom/triangulation.h"

#include <string>

#include "deformkit/error.h"

namespace deformkit::geom {

Triangulation triangulate(const Mesh& mesh) {
    Triangulation tris;
    const auto counts = mesh.faceCounts();
    const auto offsets = mesh.faceOffsets();
    const size_t total = static_cast<size_t>(mesh.numCorners()) - 2 * static_cast<size_t>(mesh.numFaces());
    tris.corners.reserve(total);
    tris.face.reserve(total);
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const int32_t first = offsets[f];
        for (int32_t k = 1; k + 1 < counts[f]; ++k) {
            tris.corners.push_back({first, first + k, first + k + 1});
            tris.face.push_back(f);
        }
    }
    return tris;
}

std::vector<std::array<int32_t, 3>> triangleVertices(const Mesh& mesh, const Triangulation& tris) {
    const auto indices = mesh.faceIndices();
    const int32_t numCorners = mesh.numCorners();
    std::vector<std::array<int32_t, 3>> out;
    out.reserve(tris.corners.size());
    for (size_t t = 0; t < tris.corners.size(); ++t) {
        const auto& c = tris.corners[t];
        for (int k = 0; k < 3; ++k) {
            if (c[k] < 0 || c[k] >= numCorners) {
                throw InvalidInput(formatError(
                    "triangulation", "triangle " + std::to_string(t) + " corner " + std::to_string(k),
                    "face-corner index " + std::to_string(c[k]) + " is out of range",
                    "an index in [0, " + std::to_string(numCorners) + ")"));
            }
        }
        out.push_back({indices[c[0]], indices[c[1]], indices[c[2]]});
    }
    return out;
}

}  // namespace deformkit::geom
