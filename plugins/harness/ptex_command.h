#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "deformkit/ptex/ptex_file.h"

// `deformkit ptex ...`: Ptex files on the command line. Each throws deformkit::Error on bad input (main()
// prints it and exits 2); outputs are written atomically.
namespace deformkit::harness {

// `deformkit ptex info FILE`: header, faces and their resolutions, flags, metadata, mesh metadata.
void ptexInfo(const std::filesystem::path& file, std::ostream& out);

// `deformkit ptex to-vertex FILE MESH --out weights.json [--channel C]`: the per-vertex values of one
// channel (ptex::vertexValues) as a JSON array, the weights file the slide, the scenes and every command
// read. Returns the vertex count.
struct PtexToVertexCommand {
    std::filesystem::path ptex;
    std::filesystem::path mesh;  // OBJ
    std::filesystem::path out;
    int32_t channel = 0;
};
size_t ptexToVertexCommand(const PtexToVertexCommand& command);

// `deformkit ptex to-udim FILE MESH --out 'map.<UDIM>.exr' [--resolution N] [--tiles 1001,1002]`: the map
// rendered into one image per UDIM tile through the mesh's UVs (ptex::ptexToUdim). Returns the files.
struct PtexToUdimCommand {
    std::filesystem::path ptex;
    std::filesystem::path mesh;
    std::string out;  // a UDIM pattern
    int32_t resolution = 1024;
    std::vector<int> tiles;  // empty: every tile of the mesh
    int32_t padding = 8;     // texels of edge padding around the charts
    bool coverage = false;   // a last channel: 1 on the UV charts, 0 in the padding and outside
};
std::vector<std::filesystem::path> ptexToUdimCommand(const PtexToUdimCommand& command);

// `deformkit ptex from-udim 'map.<UDIM>.exr' MESH --out FILE.ptx [--face-res auto|N] [--type ...]`: the
// tiles sampled into a Ptex file of the mesh (ptex::udimToPtex), with the mesh metadata.
struct PtexFromUdimCommand {
    std::string pattern;
    std::filesystem::path mesh;
    std::filesystem::path out;
    int8_t faceLog2 = -1;  // -1: per face from its size in tile texels
    ptex::DataType type = ptex::DataType::Float;
};
// Returns the number of mesh faces without UVs (written as 0).
int32_t ptexFromUdimCommand(const PtexFromUdimCommand& command);

// `deformkit ptex from-vertex weights.json MESH --out FILE.ptx [--face-res N] [--type ...]`: per-vertex
// weights (the JSON weights file) baked into a Ptex file of the mesh (ptex::bakeVertexValues): each texel
// interpolates the weights of its face's corners; with adjacency and the mesh metadata.
struct PtexFromVertexCommand {
    std::filesystem::path weights;
    std::filesystem::path mesh;
    std::filesystem::path out;
    int8_t faceLog2 = 4;
    ptex::DataType type = ptex::DataType::Float;
};
void ptexFromVertexCommand(const PtexFromVertexCommand& command);

// "u8", "u16", "half" or "float"; InvalidInput naming --type otherwise.
[[nodiscard]] ptex::DataType parsePtexType(const std::string& text);
// A face size 1, 2, 4, ... 32768 (its log2), or "auto" (-1) where `allowAuto`; InvalidInput naming
// --face-res and what it takes otherwise.
[[nodiscard]] int8_t parseFaceResolution(const std::string& text, bool allowAuto = true);

}  // namespace deformkit::harness
