#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "deformkit/ptex/ptex_file.h"

namespace deformkit::ptex {

// Filtered look-ups into a Ptex file's level-0 texels, decoded once to float (u8 and u16 normalised to
// [0, 1], half widened); a constant face is kept as its one value, whatever resolution it declares. Texel (i,
// j) of a face is centred at ((i + 0.5) / ures, (j + 0.5) / vres).
//
// sample() filters bilinearly between the four texel centres around (u, v). Centres beyond an edge of the
// face are read from the neighbour across it through the file's adjacency (at the neighbour's own
// resolution, the texel under the mirrored centre), so a map is continuous across face edges; a centre
// beyond a corner is extrapolated from the two edge neighbours and the corner texel (exact for a linear
// painting); beyond a boundary edge the face's own edge texel is repeated (clamp).
//
// The float copy counts against the same cap as the file's decoded texels: the file's texels as stored plus
// their float copy may take at most `maxBytes` (ReadOptions::maxDecodedBytes by default), so a small file of
// one huge face cannot claim four times the cap its reading allowed.
class PtexSampler {
  public:
    // Throws InvalidInput naming `source` when the file's adjacency points outside it, a texel is not finite,
    // or the texels and their float copy would take more than `maxBytes`.
    PtexSampler(const PtexFile& file, const std::string& source,
                uint64_t maxBytes = ReadOptions{}.maxDecodedBytes);

    [[nodiscard]] int32_t channels() const { return channels_; }
    [[nodiscard]] int32_t numFaces() const { return static_cast<int32_t>(faces_.size()); }
    [[nodiscard]] const FaceInfo& face(int32_t f) const { return faces_[f]; }
    // Texel (i, j) of face f, channel c (no filtering; i, j inside the face).
    [[nodiscard]] float texel(int32_t f, int32_t i, int32_t j, int32_t c) const { return at(f, i, j)[c]; }
    // Bilinear value at (u, v) in [0, 1]^2 of face f (clamped into it); `out` holds channels() values.
    void sample(int32_t f, double u, double v, std::span<float> out) const;

  private:
    // Texel (i, j) of face f, i and j inside it: a constant face holds its one value for all of them.
    [[nodiscard]] const float* at(int32_t f, int32_t i, int32_t j) const {
        if (constant_[f]) return &values_[offsets_[f]];
        return &values_[offsets_[f] + ((static_cast<size_t>(j) << faces_[f].ulog2) + i) * channels_];
    }
    // Texel (i, j) with i in [-1, ures], j in [-1, vres]: outside the face read across the adjacency.
    void ghost(int32_t f, int32_t i, int32_t j, float* out) const;
    void acrossEdge(int32_t f, int edge, int32_t i, int32_t j, float* out) const;

    std::string source_;
    int32_t channels_ = 0;
    std::vector<FaceInfo> faces_;
    std::vector<size_t> offsets_;    // per face, into values_
    std::vector<uint8_t> constant_;  // per face: 1 for a constant face, stored as one texel
    std::vector<float> values_;
};

}  // namespace deformkit::ptex
