#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "deformkit/io/obj.h"

namespace deformkit::io {

// A numbered sequence of OBJ files, one per frame: `name.####.obj` (one # per digit, zero padded) or
// printf style `name.%04d.obj`. Every frame must have the topology of the first one read (same face
// counts and indices): a deformer sequence changes positions only.
class ObjSequence {
  public:
    // Throws InvalidInput if `pattern` has no frame token.
    explicit ObjSequence(std::filesystem::path pattern);

    [[nodiscard]] const std::filesystem::path& pattern() const { return pattern_; }
    // The file of `frame` (whether or not it exists). Negative frames keep the sign before the padding.
    [[nodiscard]] std::filesystem::path framePath(int frame) const;
    // Frames whose file exists in the pattern's folder, ascending. Throws IoError if the folder is missing.
    [[nodiscard]] std::vector<int> frames() const;
    // Reads one frame; throws IoError if it is missing and InvalidInput (naming the file and the first
    // differing face) if its topology differs from the first frame read through this object.
    [[nodiscard]] ObjContent read(int frame);
    // Makes `mesh` (read from `path`) the reference every frame read must match, in place of the first
    // frame read.
    void setReference(const geom::Mesh& mesh, const std::filesystem::path& path);

    // True when `pattern`'s file name has one frame token (#... or %0Nd) of at most 32 digits.
    [[nodiscard]] static bool isPattern(const std::string& pattern);
    // Why it is not ("has no frame token in its file name", "has 2 frame tokens in its file name", "asks for
    // more than 32 digits of padding"); empty when it is.
    [[nodiscard]] static std::string patternProblem(const std::string& pattern);

  private:
    std::filesystem::path pattern_;
    std::string prefix_, suffix_;  // file name around the token
    int padding_ = 0;
    bool haveReference_ = false;
    bool referenceIsFrame_ = false;        // the reference is the first frame read (not setReference's)
    std::filesystem::path referencePath_;  // the first frame read, named in topology errors
    int32_t referenceVertices_ = 0;
    std::vector<int32_t> referenceCounts_, referenceIndices_;
};

}  // namespace deformkit::io
