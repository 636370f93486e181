#pragma once

// Ptex files for the tests of meshes' Ptex faces, built directly (no baking through the library).

#include <cstdint>
#include <cstring>

#include "deformkit/ptex/ptex_mesh.h"

namespace deformkit::test {

// A float file of `mesh`'s Ptex faces at 2^log2 x 2^log2, every face constant: channel c of Ptex face p
// holds value(p, c).
template <class Value>
ptex::PtexFile constantFaces(const ptex::PtexMesh& mesh, int32_t channels, int8_t log2, Value value) {
    ptex::PtexFile file;
    file.dataType = ptex::DataType::Float;
    file.channels = channels;
    file.faces = mesh.faceInfos(log2, log2);
    file.texels.resize(file.faces.size());
    for (int32_t p = 0; p < mesh.numPtexFaces(); ++p) {
        for (int32_t c = 0; c < channels; ++c) {
            const float v = value(p, c);
            uint8_t bytes[4];
            std::memcpy(bytes, &v, 4);
            file.constData.insert(file.constData.end(), bytes, bytes + 4);
        }
    }
    return file;
}

}  // namespace deformkit::test
