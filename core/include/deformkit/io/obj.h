#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "deformkit/geom/mesh.h"

namespace deformkit::io {

// A named set of faces: OBJ `g` (or `o` when no `g` follows) statements.
struct FaceGroup {
    std::string name;
    std::vector<int32_t> faces;  // ascending face indices
};

struct ObjContent {
    geom::Mesh mesh;
    std::vector<FaceGroup> groups;  // empty when the file names none
    // Polygons that visited a vertex twice, repaired (repeats dropped, split into loops), and the line of
    // the first: `deformkit info` reports them.
    int64_t repairedFaces = 0;
    int64_t firstRepairedLine = 0;
    std::string firstRepairedFace;  // files without lines (glTF, FBX, PLY, Collada): "mesh 'quad' face 3"
    // Faces without texture coordinates in a file whose other faces have them (they belong to no UDIM tile:
    // texture-space work leaves them alone), and the line of the first.
    int64_t facesWithoutUVs = 0;
    int64_t firstLineWithoutUVs = 0;
};

// Reads a Wavefront OBJ: `v` (extra w or colour values ignored), `vt` (u v [w]), `f` with v, v/vt,
// v//vn and v/vt/vn corners, 1-based and negative (relative) indices, n-gons, `g`/`o` groups, line
// continuations (`\`). Normals, materials and smoothing groups are ignored. Throws IoError for a
// missing or unreadable file, ParseError/InvalidInput naming the file and line for: no faces, a malformed
// number, an index of 0 or out of range, a face with fewer than 3 (distinct) vertices, NaN/inf
// coordinates, a face with texture coordinates on some corners only, UTF-16 text. A polygon that visits a
// vertex twice is repaired (ObjContent::repairedFaces); faces without texture coordinates beside faces
// with them are read as faces without UVs (ObjContent::facesWithoutUVs).
[[nodiscard]] ObjContent readObj(const std::filesystem::path& path);

// Parses OBJ text already in memory; `source` names it in errors.
[[nodiscard]] ObjContent parseObj(std::string_view text, const std::string& source);

struct ObjWriteOptions {
    int precision = 9;  // significant digits; 9 round-trips float32 exactly
};

// Writes atomically (temporary file + rename). Groups are written as `g` statements.
void writeObj(const std::filesystem::path& path, const geom::Mesh& mesh,
              const std::vector<FaceGroup>& groups = {}, const ObjWriteOptions& options = {});
[[nodiscard]] std::string formatObj(const geom::Mesh& mesh, const std::vector<FaceGroup>& groups = {},
                                    const ObjWriteOptions& options = {});

}  // namespace deformkit::io
