#pragma once

#include <filesystem>
#include <optional>

#include "deformkit/io/obj.h"

// Rest meshes in the formats artists export (docs/io.md, "Mesh files"): Wavefront OBJ through DeformKit's
// own reader (obj.h), glTF 2.0 (.gltf, .glb), FBX, PLY and Collada (.dae) through assimp. Everything that
// reads a mesh from a file (the CLI, scenes, Python's read_mesh, farm plans) reads it here.
namespace deformkit::io {

enum class MeshFormat { Obj, Gltf, Fbx, Ply, Collada };

// The format a file name's extension names (any case); nullopt for any other.
[[nodiscard]] std::optional<MeshFormat> meshFormat(const std::filesystem::path& path);
// The extensions meshFormat knows, for messages: ".obj, .gltf, .glb, .fbx, .ply, .dae".
inline constexpr const char* kMeshExtensions = ".obj, .gltf, .glb, .fbx, .ply, .dae";

// Reads a mesh file by its extension. OBJ as readObj. The others:
// - positions in the scene's world space (node transforms applied) and the file's units (FBX: as stored,
//   centimetres unless the file's unit scale says otherwise, as Maya shows them);
// - one face per polygon (quads stay quads); points and lines are left out;
// - glTF and PLY keep the file's vertices in its order (split wherever the file splits them for UVs or
//   normals; docs/io.md); FBX and Collada, which assimp hands over as one vertex per face corner, are welded
//   back on exactly equal positions, vertices numbered in the order faces first use them;
// - the first UV set; faces of a mesh without UVs have none (uvIndices -1);
// - one group per mesh of the file, named by the mesh (or "mesh<k>" when it has no name), in file order.
// Throws IoError when the file cannot be read, InvalidInput naming the file for an unknown extension (listing
// kMeshExtensions), a file assimp cannot parse (with its reason) or one without a polygon.
[[nodiscard]] ObjContent readMesh(const std::filesystem::path& path);

}  // namespace deformkit::io
