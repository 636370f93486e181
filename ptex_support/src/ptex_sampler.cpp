#include "deformkit/ptex/ptex_sampler.h"

#include <algorithm>
#include <cmath>

#include "deformkit/error.h"
#include "texel_access.h"

namespace deformkit::ptex {

PtexSampler::PtexSampler(const PtexFile& file, const std::string& source, uint64_t maxBytes)
    : source_(source), channels_(file.channels), faces_(file.faces) {
    if (file.meshType != MeshType::Quad) {
        throw InvalidInput(formatError(source, "header", "is a triangle-mesh Ptex file",
                                       "a quad-mesh Ptex file for filtered look-ups"));
    }
    detail::requireAdjacency(faces_, source);
    detail::requireBuffers(file, source);
    const size_t pixel = file.pixelSize(), bytes = bytesPerChannel(file.dataType);
    offsets_.resize(faces_.size() + 1);
    constant_.resize(faces_.size());
    size_t total = 0;
    for (size_t f = 0; f < faces_.size(); ++f) {
        offsets_[f] = total;
        // A constant face (no texels of its own, as files of unpainted 32768^2 faces have) is one value.
        constant_[f] = file.texels[f].empty() ? 1 : 0;
        total += (constant_[f] ? 1 : faces_[f].texelCount()) * static_cast<size_t>(channels_);
    }
    offsets_.back() = total;
    uint64_t stored = file.constData.size();
    for (const std::vector<uint8_t>& texels : file.texels)
        stored += texels.size();
    const uint64_t copy = static_cast<uint64_t>(total) * sizeof(float);
    if (copy > maxBytes || stored > maxBytes - copy) {
        throw InvalidInput(formatError(
            source, "texels",
            std::to_string(stored) + " bytes as stored and " + std::to_string(copy) +
                " as floats for filtering",
            "at most " + std::to_string(maxBytes) + " bytes in all (ReadOptions::maxDecodedBytes)"));
    }
    values_.resize(total);
    for (size_t f = 0; f < faces_.size(); ++f) {
        float* out = values_.data() + offsets_[f];
        const std::vector<uint8_t>& texels = file.texels[f];
        if (constant_[f]) {
            for (int32_t c = 0; c < channels_; ++c)
                out[c] = detail::loadValue(file.constData.data() + f * pixel + c * bytes, file.dataType);
        } else {
            const size_t count = faces_[f].texelCount() * static_cast<size_t>(channels_);
            for (size_t t = 0; t < count; ++t)
                out[t] = detail::loadValue(texels.data() + t * bytes, file.dataType);
        }
        // A non-finite texel (half and float files) would spread through every filtered look-up that
        // reaches it (inf - inf is NaN): named, as the per-vertex read names its corner texels.
        for (size_t t = 0; t < offsets_[f + 1] - offsets_[f]; ++t) {
            if (std::isfinite(out[t])) continue;
            const auto texel = static_cast<int64_t>(t / static_cast<size_t>(channels_));
            const int32_t ures = faces_[f].ures();
            const std::string where = constant_[f] ? "constant value"
                                                   : "texel (" + std::to_string(texel % ures) + ", " +
                                                         std::to_string(texel / ures) + ")";
            throw InvalidInput(formatError(source,
                                           "face " + std::to_string(f) + " " + where + " channel " +
                                               std::to_string(t % static_cast<size_t>(channels_)),
                                           "is " + numberText(out[t]),
                                           "finite values (look-ups filter across texels)"));
        }
    }
}

void PtexSampler::acrossEdge(int32_t f, int edge, int32_t i, int32_t j, float* out) const {
    const FaceInfo& info = faces_[f];
    const int32_t ures = info.ures(), vres = info.vres();
    int32_t g = info.adjFaces[edge];
    int ge = info.adjEdges[edge];
    if (g < 0) {  // boundary: repeat the edge texel
        const float* src = at(f, std::clamp(i, 0, ures - 1), std::clamp(j, 0, vres - 1));
        std::copy(src, src + channels_, out);
        return;
    }
    // Parameter of the ghost texel's centre along this face's edge, counter-clockwise (edge 0 runs from
    // (0,0) to (1,0), edge 1 from (1,0) to (1,1), edge 2 from (1,1) to (0,1), edge 3 from (0,1) to (0,0)).
    const double uc = (i + 0.5) / ures, vc = (j + 0.5) / vres;
    const double t = edge == 0 ? uc : edge == 1 ? vc : edge == 2 ? 1.0 - uc : 1.0 - vc;
    // The neighbour's edge runs the other way. A sub-face's outer edges are halves of a mesh edge whose
    // neighbour may be a whole quad edge, and the reverse (OpenSubdiv names the sub-face at the start of
    // the quad's edge, through its edge 3; the other half is that sub-face's neighbour across its edge 2).
    double s = 1.0 - t;
    const bool fSub = info.subface, gSub = faces_[g].subface;
    if (fSub && !gSub && (edge == 0 || edge == 3)) {
        s = edge == 0 ? 1.0 - 0.5 * t : 0.5 - 0.5 * t;
    } else if (!fSub && gSub && (ge == 0 || ge == 3)) {
        const bool firstHalf = t < 0.5;  // near this edge's start: the sub-face through its edge 3
        const bool atEdge3 = ge == 3;
        if (firstHalf == atEdge3) {
            s = atEdge3 ? 1.0 - 2.0 * t : 2.0 * (1.0 - t);
        } else {
            const int32_t sibling = faces_[g].adjFaces[atEdge3 ? 2 : 1];
            if (sibling >= 0) {
                g = sibling;
                ge = atEdge3 ? 0 : 3;
                s = atEdge3 ? 2.0 * (1.0 - t) : 1.0 - 2.0 * t;
            } else {
                s = std::clamp(atEdge3 ? 1.0 - 2.0 * t : 2.0 * (1.0 - t), 0.0, 1.0);
            }
        }
    }
    const FaceInfo& other = faces_[g];
    const int32_t gu = other.ures(), gv = other.vres();
    const auto cell = [](double x, int32_t res) {
        return std::clamp(static_cast<int32_t>(std::floor(x * res)), 0, res - 1);
    };
    int32_t gi = 0, gj = 0;
    switch (ge) {
        case 0:
            gi = cell(s, gu), gj = 0;
            break;
        case 1:
            gi = gu - 1, gj = cell(s, gv);
            break;
        case 2:
            gi = cell(1.0 - s, gu), gj = gv - 1;
            break;
        default:
            gi = 0, gj = cell(1.0 - s, gv);
            break;
    }
    const float* src = at(g, gi, gj);
    std::copy(src, src + channels_, out);
}

void PtexSampler::ghost(int32_t f, int32_t i, int32_t j, float* out) const {
    const FaceInfo& info = faces_[f];
    const int32_t ures = info.ures(), vres = info.vres();
    const bool uOut = i < 0 || i >= ures, vOut = j < 0 || j >= vres;
    if (!uOut && !vOut) {
        const float* src = at(f, i, j);
        std::copy(src, src + channels_, out);
        return;
    }
    const int uEdge = i < 0 ? 3 : 1, vEdge = j < 0 ? 0 : 2;
    if (!vOut) {
        acrossEdge(f, uEdge, i, j, out);
        return;
    }
    if (!uOut) {
        acrossEdge(f, vEdge, i, j, out);
        return;
    }
    // Beyond a corner: the parallelogram of the two edge neighbours and the corner texel.
    const int32_t ci = std::clamp(i, 0, ures - 1), cj = std::clamp(j, 0, vres - 1);
    float a[64], b[64];
    acrossEdge(f, uEdge, i, cj, a);
    acrossEdge(f, vEdge, ci, j, b);
    const float* c = at(f, ci, cj);
    for (int32_t k = 0; k < channels_; ++k)
        out[k] = a[k] + b[k] - c[k];
}

void PtexSampler::sample(int32_t f, double u, double v, std::span<float> out) const {
    const FaceInfo& info = faces_[f];
    const double x = std::clamp(u, 0.0, 1.0) * info.ures() - 0.5,
                 y = std::clamp(v, 0.0, 1.0) * info.vres() - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const auto i0 = static_cast<int32_t>(fx), j0 = static_cast<int32_t>(fy);
    const double wx = x - fx, wy = y - fy;
    const float *t00, *t10, *t01, *t11;
    float g00[64], g10[64], g01[64], g11[64];
    if (i0 >= 0 && j0 >= 0 && i0 + 1 < info.ures() && j0 + 1 < info.vres()) {
        // All four texels inside the face (the common case): read them in place.
        t00 = at(f, i0, j0);
        t10 = at(f, i0 + 1, j0);
        t01 = at(f, i0, j0 + 1);
        t11 = at(f, i0 + 1, j0 + 1);
    } else {
        ghost(f, i0, j0, g00);
        ghost(f, i0 + 1, j0, g10);
        ghost(f, i0, j0 + 1, g01);
        ghost(f, i0 + 1, j0 + 1, g11);
        t00 = g00, t10 = g10, t01 = g01, t11 = g11;
    }
    for (int32_t c = 0; c < channels_; ++c) {
        const double bottom = t00[c] + wx * (static_cast<double>(t10[c]) - t00[c]);
        const double top = t01[c] + wx * (static_cast<double>(t11[c]) - t01[c]);
        out[c] = static_cast<float>(bottom + wy * (top - bottom));
    }
}

}  // namespace deformkit::ptex
