#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "deformkit/geom/mesh.h"
#include "deformkit/io/obj_sequence.h"
#include "deformkit/io/point_cache.h"

namespace deformkit::io {

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
    // vertex count, checked now (InvalidInput naming the cache and both counts).
    void setReference(const geom::Mesh& rest, const std::string& restName);

    // Checks that every one of `frames` is there: IoError naming the first missing file of a sequence,
    // InvalidInput naming the cache, the frame and the frames it has.
    void requireFrames(std::span<const int> frames) const;
    // What names a frame in logs and headers: the sequence's file, or "anim.pc2 frame 7".
    [[nodiscard]] std::string frameName(int frame) const;

    // Reads the positions of `frame` (errors as ObjSequence::read and PointCache::read; a frame with
    // another vertex count than the reference names the frame and both counts).
    void read(int frame, std::vector<glm::vec3>& points);

  private:
    std::filesystem::path path_;
    std::unique_ptr<ObjSequence> sequence_;
    std::unique_ptr<PointCache> cache_;
};

}  // namespace deformkit::io
