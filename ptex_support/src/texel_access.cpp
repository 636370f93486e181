#include "texel_access.h"

#include "deformkit/error.h"

namespace deformkit::ptex::detail {

void requireAdjacency(std::span<const FaceInfo> faces, const std::string& source) {
    const auto n = static_cast<int32_t>(faces.size());
    for (int32_t f = 0; f < n; ++f) {
        for (int e = 0; e < 4; ++e) {
            const int32_t g = faces[f].adjFaces[e];
            if (g < -1 || g >= n || faces[f].adjEdges[e] > 3) {
                throw InvalidInput(formatError(
                    source, "face " + std::to_string(f) + " edge " + std::to_string(e),
                    "has neighbour " + std::to_string(g) + " edge " + std::to_string(faces[f].adjEdges[e]),
                    "a face in [-1, " + std::to_string(n) + ") and an edge in [0, 3]"));
            }
        }
    }
}

// The file's channel count and texel buffers as the look-ups read them (a file built in memory may be
// inconsistent; one read from disk never is).
void requireBuffers(const PtexFile& file, const std::string& source) {
    if (file.channels < 1 || file.channels > 64) {
        throw InvalidInput(formatError(source, "header", "has " + std::to_string(file.channels) + " channels",
                                       "1 to 64 channels"));
    }
    if (file.texels.size() != file.faces.size() ||
        file.constData.size() != file.faces.size() * file.pixelSize()) {
        throw InvalidInput(formatError(
            source, "",
            "has texels for " + std::to_string(file.texels.size()) + " faces and " +
                std::to_string(file.constData.size()) + " bytes of constant data",
            "texels and constant data for each of its " + std::to_string(file.faces.size()) + " faces"));
    }
    for (size_t f = 0; f < file.faces.size(); ++f) {
        const size_t expected = file.faces[f].texelCount() * file.pixelSize();
        if (!file.texels[f].empty() && file.texels[f].size() != expected) {
            throw InvalidInput(
                formatError(source, "face " + std::to_string(f),
                            "has " + std::to_string(file.texels[f].size()) + " bytes of texels",
                            std::to_string(expected) + " bytes"));
        }
    }
}

}  // namespace deformkit::ptex::detail
