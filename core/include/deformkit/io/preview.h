#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/image.h"

namespace deformkit::io {

// A texture for previews: one image repeated over UV space, or one image per UDIM tile.
struct PreviewTexture {
    std::optional<Image> single;  // used for every UV when set (repeats outside [0, 1))
    std::map<int, Image> tiles;   // UDIM tile number -> image; UVs in other tiles get the base colour
};

// Loads a texture for previews: a UDIM pattern (<UDIM>, <UVTILE>, %(UDIM)d, _MAPID_) loads every tile
// found, any other path one image. Images with 1 or 2 channels are shown as grey.
[[nodiscard]] PreviewTexture loadPreviewTexture(const std::filesystem::path& pathOrPattern);

struct PreviewOptions {
    int32_t width = 960;  // pixels
    int32_t height = 720;
    // Direction the camera looks along (scene units, need not be unit length); y is up. Auto-framing:
    // the camera aims at the bounding box centre from the distance at which the box's circumscribed
    // sphere, enlarged by 8%, exactly fits the narrower field of view.
    glm::vec3 viewDirection{-0.55f, -0.45f, -1.0f};
    // The box the camera frames instead of the mesh's bounding box: one camera for every frame of a shot
    // (the rest pose's box) so previews do not jump. Parts of the mesh outside it may leave the picture.
    std::optional<geom::Box3> frame;
    float fieldOfViewDegrees = 30.0f;  // vertical
    glm::vec3 background{0.16f, 0.17f, 0.19f};
    glm::vec3 baseColor{0.78f, 0.76f, 0.72f};  // where no texture applies
    bool drawEdges = false;                    // darken polygon edges (not the triangulation's diagonals)
    // Per-vertex colours (empty, or one per vertex), interpolated over the faces in place of baseColor, e.g.
    // painted weights through weightColor(); a texture, where it applies, still takes precedence.
    std::vector<glm::vec3> vertexColors;
};

// The colour of a painted weight as weight-paint views show it: 0 blue, then cyan, green, yellow, 1 red
// (clamped to [0, 1]; NaN shows as 0).
[[nodiscard]] glm::vec3 weightColor(float weight);

// Renders a shaded view of `mesh` with the software rasteriser: perspective camera, z-buffer, smooth
// normals, two-sided Lambert lighting from a key light and a headlight, perspective-correct UVs for
// the optional texture (bilinear, UDIM-aware). Returns an RGB image (3 channels, top row first).
// Throws InvalidInput for a mesh without faces or a texture given to a mesh without UVs.
[[nodiscard]] Image renderPreview(const geom::Mesh& mesh, const PreviewOptions& options = {},
                                  const PreviewTexture* texture = nullptr);

}  // namespace deformkit::io
