#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

// Point caches: the deformed positions of one mesh, frame by frame, in one binary file with random access
// by frame, as DCCs write them for deformed shots (docs/io.md).
//
// PC2 (Blender's io_export_pc2, its Mesh Cache modifier, 3ds Max, Houdini), little-endian:
//   char[12] "POINTCACHE2\0", int32 version (1), int32 vertices, float32 start frame,
//   float32 sampling (frames per sample), int32 samples; then per sample, per vertex, float32 x y z.
//   Sample i is frame start + i * sampling.
// MDD (LightWave's MotionDesigner; Blender's io_shape_mdd), big-endian:
//   int32 frames, int32 vertices, float32 times[frames] (seconds); then per frame, per vertex,
//   float32 x y z. MDD records no frame numbers: sample i is frame first + i, first being 1 unless the
//   reader is told otherwise (Blender's exporter writes times i / fps from 0 whatever its first frame).
//   The times must increase; they are checked, not used.
namespace deformkit::io {

enum class PointCacheFormat { Pc2, Mdd };

// The format a file name's extension (.pc2, .mdd; any case) names; nullopt for any other.
[[nodiscard]] std::optional<PointCacheFormat> pointCacheFormat(const std::filesystem::path& path);
// "PC2" or "MDD".
[[nodiscard]] const char* formatName(PointCacheFormat format);

class PointCache {
  public:
    // Opens `path` and checks its header against the file's size; frames are read on demand. `firstFrame`
    // sets the frame of sample 0 (default: PC2's start frame, MDD's 1). Throws IoError when the file
    // cannot be read and InvalidInput naming the file for a bad header, a truncated or overlong file, or a
    // PC2 sampling that is not a positive number.
    explicit PointCache(std::filesystem::path path, std::optional<double> firstFrame = {});

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    [[nodiscard]] PointCacheFormat format() const { return format_; }
    [[nodiscard]] int32_t vertexCount() const { return vertices_; }
    [[nodiscard]] int32_t sampleCount() const { return samples_; }
    // The frame of sample i: first + i * sampling.
    [[nodiscard]] double sampleFrame(int32_t sample) const { return first_ + sample * sampling_; }
    [[nodiscard]] double sampling() const { return sampling_; }
    // MDD's times in seconds (empty for PC2).
    [[nodiscard]] const std::vector<float>& times() const { return times_; }

    // The whole frames that are samples, ascending, each once.
    [[nodiscard]] std::vector<int> frames() const;
    // The sample of a whole frame; nullopt when the frame is none of the cache's samples.
    [[nodiscard]] std::optional<int32_t> sampleOf(int frame) const;
    // "anim.pc2 frame 7", for messages and logs.
    [[nodiscard]] std::string frameName(int frame) const;
    // The frames it holds, for messages: "frames 1 to 9 every 2", "frame 3", "no frames".
    [[nodiscard]] std::string rangeText() const;

    // Reads the positions of a whole frame into `points` (resized to vertexCount()), seeking to that
    // frame only. Throws InvalidInput naming the file and frame when the frame is none of the cache's
    // (saying which it has), and naming the vertex when a coordinate is not finite; IoError when the read
    // fails. Calls from several threads at once run one at a time (they share the file's stream).
    void read(int frame, std::vector<glm::vec3>& points);

  private:
    std::filesystem::path path_;
    PointCacheFormat format_ = PointCacheFormat::Pc2;
    int32_t vertices_ = 0;
    int32_t samples_ = 0;
    double first_ = 0.0;
    double sampling_ = 1.0;
    std::vector<float> times_;
    std::uintmax_t dataOffset_ = 0;  // bytes before sample 0
    std::mutex readMutex_;           // over in_ and buffer_
    std::ifstream in_;
    std::vector<char> buffer_;
};

// Writes a point cache frame by frame: the header at construction, then append() once per frame, then
// finish(). The file appears at `path`, complete, only when finish() returns (written beside it under a
// hidden temporary name and renamed); a writer destroyed before that leaves any earlier file intact.
class PointCacheWriter {
  public:
    // `frames` frames of `vertices` vertices each, the first at `firstFrame`, one frame apart (PC2 start and
    // sampling 1; MDD times (frame - firstFrame) / fps). The format is the extension's (.pc2, .mdd).
    // Throws InvalidInput naming the file for another extension, no vertices or no frames; IoError when the
    // folder cannot be written.
    PointCacheWriter(std::filesystem::path path, int32_t vertices, int32_t frames, int firstFrame,
                     double fps = 24.0);
    ~PointCacheWriter();
    PointCacheWriter(const PointCacheWriter&) = delete;
    PointCacheWriter& operator=(const PointCacheWriter&) = delete;

    // Appends the next frame. Throws InvalidInput for a wrong vertex count, a non-finite coordinate (naming
    // the vertex) or more frames than announced.
    void append(std::span<const glm::vec3> points);
    // Checks that every announced frame was appended, then moves the file into place.
    void finish();

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  private:
    std::filesystem::path path_, staging_;
    PointCacheFormat format_ = PointCacheFormat::Pc2;
    int32_t vertices_ = 0, frames_ = 0, written_ = 0;
    int firstFrame_ = 0;
    std::ofstream out_;
    std::vector<char> buffer_;
    bool finished_ = false;
};

}  // namespace deformkit::io
