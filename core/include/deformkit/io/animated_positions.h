#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/point_cache.h"

namespace deformkit::io {

// Whether a frame of positions keeps a rest mesh's vertex order. A point cache written by another tool can
// have as many vertices as the rest mesh and still number them otherwise (an FBX or Collada rest mesh is
// welded and renumbered on reading, docs/io.md); its frames then join points far apart on the surface, and
// every result made from them is torn. A frame is judged on up to kSampledEdges edges of the rest mesh,
// spread evenly over its corners: an edge is torn when it is longer than kStretch times its rest length,
// scaled by how much the whole mesh grew (the RMS distance of the points from their centroid, so a cache in
// other units, moved or turned, is not torn). Real animation (skinning, a bone scaled to nothing, squash and
// stretch) tears a few edges where it is extreme; a mesh read in another order tears most of them (39-69%
// on a rigged Blender export and on the Fox with its vertices shuffled). More than a quarter torn is a
// different order.
class VertexOrderCheck {
  public:
    static constexpr int32_t kSampledEdges = 4096;
    static constexpr double kStretch = 4.0;
    // Fewer edges with a rest length than this are not judged.
    static constexpr int32_t kFewestEdges = 16;

    explicit VertexOrderCheck(const geom::Mesh& rest);

    struct Tear {
        int32_t torn = 0;    // edges longer than kStretch times their scaled rest length
        int32_t edges = 0;   // edges judged
        double scale = 1.0;  // how much the whole mesh grew
    };
    // The tear of `points` (as many as the rest mesh's vertices, else InvalidInput) when more than a quarter
    // of the edges judged are torn; nothing when the frame keeps the order, or cannot be judged (too few
    // edges, or the rest mesh or the frame all in one point).
    [[nodiscard]] std::optional<Tear> tear(std::span<const glm::vec3> points) const;

  private:
    std::vector<std::pair<int32_t, int32_t>> edges_;
    std::vector<double> restLength_;
    double restSpread_ = 0.0;
    size_t vertices_ = 0;
};

// The deformed positions of one mesh, frame by frame, as pipelines hand them over: an OBJ sequence
// ("anim.####.obj", ObjSequence) or a point cache ("anim.pc2", "anim.mdd", PointCache). Everything that
// takes a deformed shot (the uvwarp command, scenes, farm tasks, Python) reads it through this class, so
// the same positions give the same results whichever form they came in.
class AnimatedPositions {
  public:
    // The forms this reads, for messages.
    static constexpr const char* kForms =
        "an OBJ sequence such as 'anim.####.obj' (one # per digit) or 'anim.%04d.obj', or a point cache "
        "('anim.pc2', 'anim.mdd')";

    // True when `path` names one: a frame token in its file name, or a .pc2 / .mdd extension.
    [[nodiscard]] static bool accepts(const std::filesystem::path& path);

    // Throws InvalidInput naming `name` (an option, a JSON path) when `path` is neither form, and a cache's
    // own errors (PointCache) for a bad cache. `cacheFirstFrame` sets the frame of a cache's first sample
    // (PointCache); it is refused for an OBJ sequence, whose files carry their frames.
    AnimatedPositions(std::filesystem::path path, const std::string& name,
                      std::optional<double> cacheFirstFrame = std::nullopt);

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    [[nodiscard]] bool isCache() const { return cache_ != nullptr; }

    // Every frame read must match `rest` (read from `restName`): an OBJ frame its connectivity, a cache its
    // vertex count, checked now (InvalidInput naming the cache and both counts), and its vertex order,
    // checked on every frame read (VertexOrderCheck).
    void setReference(const geom::Mesh& rest, const std::string& restName);

    // Checks that every one of `frames` is there: IoError naming the first missing file of a sequence,
    // InvalidInput naming the cache, the frame and the frames it has.
    void requireFrames(std::span<const int> frames) const;
    // What names a frame in logs and headers: the sequence's file, or "anim.pc2 frame 7".
    [[nodiscard]] std::string frameName(int frame) const;

    // Reads the positions of `frame` (errors as ObjSequence::read and PointCache::read; a frame with
    // another vertex count than the reference names the frame and both counts; a cache frame that tears the
    // reference, VertexOrderCheck, names the frame and the share of edges torn).
    void read(int frame, std::vector<glm::vec3>& points);

  private:
    std::filesystem::path path_;
    std::unique_ptr<ObjSequence> sequence_;
    std::unique_ptr<PointCache> cache_;
    std::optional<VertexOrderCheck> order_;  // a cache's, once it has a reference
    std::string restName_;
};

}  // namespace deformkit::io
