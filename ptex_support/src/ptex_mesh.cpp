#include "deformkit/ptex/ptex_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <utility>

#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <glm/geometric.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/rasterizer.h"
#include "deformkit/io/sampling.h"
#include "deformkit/io/udim.h"
#include "deformkit/ptex/half.h"

namespace deformkit::ptex {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

// Bilinear weights of (u, v) over a quad's corners at (0,0), (1,0), (1,1), (0,1).
std::array<double, 4> bilinear(double u, double v) {
    return {(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v};
}

// The UDIM tile of a mesh face, as Mesh::udimTiles counts them (a face that overhangs a tile belongs to it).
int faceTile(const geom::Mesh& mesh, int32_t f) {
    return mesh.faceUdimTile(f);
}

// The UV of (u, v) on Ptex face `ptexFace`, interpolated with PtexMesh::cornerWeights.
glm::dvec2 ptexUV(const PtexMesh& ptexMesh, const geom::Mesh& mesh, int32_t ptexFace, double u, double v,
                  std::vector<double>& weights) {
    const int32_t f = ptexMesh.meshFace(ptexFace);
    const auto corners = mesh.faceUVIndices(f);
    weights.resize(corners.size());
    ptexMesh.cornerWeights(ptexFace, u, v, weights);
    glm::dvec2 uv(0.0);
    for (size_t k = 0; k < corners.size(); ++k)
        uv += weights[k] * glm::dvec2(mesh.uvs()[corners[k]]);
    return uv;
}

void requireUVs(const geom::Mesh& mesh, const PtexMesh& ptexMesh) {
    if (!mesh.hasUVs()) {
        throw InvalidInput(formatError(ptexMesh.source(), "", "has no UVs",
                                       "texture coordinates to convert between UDIM images and Ptex"));
    }
    if (mesh.numFaces() != ptexMesh.numMeshFaces() || mesh.numVertices() != ptexMesh.numVertices()) {
        throw InvalidInput(formatError(
            ptexMesh.source(), "", "differs from the mesh its Ptex faces were built from", "the same mesh"));
    }
}

// A float value in the file's data type, little-endian bytes.
void storeValue(float value, DataType type, uint8_t* out) {
    switch (type) {
        case DataType::UInt8:
            out[0] = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255.0f));
            return;
        case DataType::UInt16: {
            const auto q = static_cast<uint16_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 65535.0f));
            out[0] = static_cast<uint8_t>(q & 0xff);
            out[1] = static_cast<uint8_t>(q >> 8);
            return;
        }
        case DataType::Half: {
            const uint16_t h = floatToHalf(value);
            out[0] = static_cast<uint8_t>(h & 0xff);
            out[1] = static_cast<uint8_t>(h >> 8);
            return;
        }
        case DataType::Float: {
            uint32_t bits = 0;
            std::memcpy(&bits, &value, 4);
            for (int b = 0; b < 4; ++b)
                out[b] = static_cast<uint8_t>(bits >> (8 * b));
            return;
        }
    }
}

float loadValue(const uint8_t* in, DataType type) {
    switch (type) {
        case DataType::UInt8:
            return static_cast<float>(in[0]) / 255.0f;
        case DataType::UInt16:
            return static_cast<float>(static_cast<uint16_t>(in[0] | (in[1] << 8))) / 65535.0f;
        case DataType::Half:
            return halfToFloat(static_cast<uint16_t>(in[0] | (in[1] << 8)));
        case DataType::Float: {
            const uint32_t bits =
                uint32_t{in[0]} | (uint32_t{in[1]} << 8) | (uint32_t{in[2]} << 16) | (uint32_t{in[3]} << 24);
            float value = 0.0f;
            std::memcpy(&value, &bits, 4);
            return value;
        }
    }
    return 0.0f;
}

void requireAdjacency(std::span<const FaceInfo> faces, const std::string& source) {
    const auto n = static_cast<int32_t>(faces.size());
    for (int32_t f = 0; f < n; ++f) {
        for (int e = 0; e < 4; ++e) {
            const int32_t g = faces[f].adjFaces[e];
            if (g < -1 || g >= n || faces[f].adjEdges[e] > 3) {
                throw InvalidInput(formatError(
                    source, "face " + std::to_string(f) + " edge " + std::to_string(e),
                    "has neighbour " + std::to_string(g) + " edge " + std::to_string(faces[f].adjEdges[e]),
                    "a face in [-1, " + std::to_string(n) + ") and an edge in [0, 3]"));
            }
        }
    }
}

// The file's channel count and texel buffers as the look-ups read them (a file built in memory may be
// inconsistent; one read from disk never is).
void requireBuffers(const PtexFile& file, const std::string& source) {
    if (file.channels < 1 || file.channels > 64) {
        throw InvalidInput(formatError(source, "header", "has " + std::to_string(file.channels) + " channels",
                                       "1 to 64 channels"));
    }
    if (file.texels.size() != file.faces.size() ||
        file.constData.size() != file.faces.size() * file.pixelSize()) {
        throw InvalidInput(formatError(
            source, "",
            "has texels for " + std::to_string(file.texels.size()) + " faces and " +
                std::to_string(file.constData.size()) + " bytes of constant data",
            "texels and constant data for each of its " + std::to_string(file.faces.size()) + " faces"));
    }
    for (size_t f = 0; f < file.faces.size(); ++f) {
        const size_t expected = file.faces[f].texelCount() * file.pixelSize();
        if (!file.texels[f].empty() && file.texels[f].size() != expected) {
            throw InvalidInput(
                formatError(source, "face " + std::to_string(f),
                            "has " + std::to_string(file.texels[f].size()) + " bytes of texels",
                            std::to_string(expected) + " bytes"));
        }
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// PtexMesh

PtexMesh::PtexMesh(const geom::Mesh& mesh, const std::string& source)
    : source_(source), numVertices_(mesh.numVertices()) {
    if (mesh.numFaces() == 0) {
        throw InvalidInput(formatError(source, "", "has no faces", "a polygon mesh for Ptex faces"));
    }
    faceCounts_.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    faceOffsets_.assign(mesh.faceOffsets().begin(), mesh.faceOffsets().end());
    faceIndices_.assign(mesh.faceIndices().begin(), mesh.faceIndices().end());

    Far::TopologyDescriptor desc;
    desc.numVertices = mesh.numVertices();
    desc.numFaces = mesh.numFaces();
    desc.numVertsPerFace = faceCounts_.data();
    desc.vertIndicesPerFace = faceIndices_.data();
    using RefinerFactory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    std::unique_ptr<Far::TopologyRefiner> refiner(
        RefinerFactory::Create(desc, RefinerFactory::Options(Sdc::SCHEME_CATMARK)));
    if (!refiner) {
        throw TopologyError(formatError(source, "", "OpenSubdiv cannot build a topology from it",
                                        "a polygon mesh within OpenSubdiv's limits"));
    }
    const Far::PtexIndices indicesOf(*refiner);
    const int32_t numPtex = indicesOf.GetNumFaces();
    firstPtex_.resize(static_cast<size_t>(mesh.numFaces()) + 1);
    meshFace_.resize(static_cast<size_t>(numPtex));
    subFace_.resize(static_cast<size_t>(numPtex));
    adjFaces_.resize(static_cast<size_t>(numPtex));
    adjEdges_.resize(static_cast<size_t>(numPtex));
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const int32_t first = indicesOf.GetFaceId(f);
        firstPtex_[f] = first;
        const int32_t n = faceCounts_[f] == 4 ? 1 : faceCounts_[f];
        for (int32_t k = 0; k < n; ++k) {
            const int32_t p = first + k;
            meshFace_[p] = f;
            subFace_[p] = faceCounts_[f] == 4 ? -1 : k;
            int adjF[4], adjE[4];
            indicesOf.GetAdjacency(*refiner, f, k, adjF, adjE);
            for (int e = 0; e < 4; ++e) {
                adjFaces_[p][e] = adjF[e];
                adjEdges_[p][e] = static_cast<uint8_t>(adjF[e] < 0 ? 0 : adjE[e]);
            }
        }
    }
    firstPtex_.back() = numPtex;
}

void PtexMesh::cornerWeights(int32_t ptexFace, double u, double v, std::span<double> weights) const {
    const int32_t f = meshFace_[ptexFace];
    const int32_t n = faceCounts_[f];
    const std::array<double, 4> b = bilinear(u, v);
    if (n == 4) {
        std::copy(b.begin(), b.end(), weights.begin());
        return;
    }
    // Sub-face k: (corner k, midpoint of edge k, centre, midpoint of edge k - 1).
    const int32_t k = subFace_[ptexFace];
    std::fill(weights.begin(), weights.begin() + n, b[2] / n);
    weights[k] += b[0] + 0.5 * b[1] + 0.5 * b[3];
    weights[(k + 1) % n] += 0.5 * b[1];
    weights[(k + n - 1) % n] += 0.5 * b[3];
}

std::vector<FaceInfo> PtexMesh::faceInfos(int8_t ulog2, int8_t vlog2) const {
    std::vector<FaceInfo> infos(meshFace_.size());
    for (size_t p = 0; p < infos.size(); ++p) {
        infos[p].ulog2 = ulog2;
        infos[p].vlog2 = vlog2;
        infos[p].adjFaces = adjFaces_[p];
        infos[p].adjEdges = adjEdges_[p];
        infos[p].subface = subFace_[p] >= 0;
    }
    return infos;
}

void PtexMesh::requireMatches(const PtexFile& file, const std::string& fileSource) const {
    if (file.faces.size() != meshFace_.size()) {
        throw InvalidInput(formatError(fileSource, "", "has " + std::to_string(file.faces.size()) + " faces",
                                       std::to_string(meshFace_.size()) +
                                           " Ptex faces (one per quad, N per N-gon) for mesh " + source_));
    }
    if (file.meshType != MeshType::Quad) {
        throw InvalidInput(formatError(fileSource, "header", "is a triangle-mesh Ptex file",
                                       "a quad-mesh Ptex file (Catmull-Clark faces) for mesh " + source_));
    }
    requireAdjacency(file.faces, fileSource);
}

MeshData meshData(const geom::Mesh& mesh) {
    MeshData data;
    data.faceVertCounts.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    data.faceVertIndices.assign(mesh.faceIndices().begin(), mesh.faceIndices().end());
    data.vertPositions.reserve(static_cast<size_t>(mesh.numVertices()) * 3);
    for (const glm::vec3& p : mesh.points()) {
        data.vertPositions.push_back(p.x);
        data.vertPositions.push_back(p.y);
        data.vertPositions.push_back(p.z);
    }
    return data;
}

// ---------------------------------------------------------------------------------------------------------
// PtexSampler

PtexSampler::PtexSampler(const PtexFile& file, const std::string& source)
    : source_(source), channels_(file.channels), faces_(file.faces) {
    if (file.meshType != MeshType::Quad) {
        throw InvalidInput(formatError(source, "header", "is a triangle-mesh Ptex file",
                                       "a quad-mesh Ptex file for filtered look-ups"));
    }
    requireAdjacency(faces_, source);
    requireBuffers(file, source);
    const size_t pixel = file.pixelSize(), bytes = bytesPerChannel(file.dataType);
    offsets_.resize(faces_.size() + 1);
    size_t total = 0;
    for (size_t f = 0; f < faces_.size(); ++f) {
        offsets_[f] = total;
        total += faces_[f].texelCount() * static_cast<size_t>(channels_);
    }
    offsets_.back() = total;
    values_.resize(total);
    for (size_t f = 0; f < faces_.size(); ++f) {
        float* out = values_.data() + offsets_[f];
        const size_t count = faces_[f].texelCount() * static_cast<size_t>(channels_);
        const std::vector<uint8_t>& texels = file.texels[f];
        if (texels.empty()) {  // constant face
            for (size_t t = 0; t < count; ++t)
                out[t] =
                    loadValue(file.constData.data() + f * pixel + (t % channels_) * bytes, file.dataType);
        } else {
            for (size_t t = 0; t < count; ++t)
                out[t] = loadValue(texels.data() + t * bytes, file.dataType);
        }
    }
}

void PtexSampler::acrossEdge(int32_t f, int edge, int32_t i, int32_t j, float* out) const {
    const FaceInfo& info = faces_[f];
    const int32_t ures = info.ures(), vres = info.vres();
    int32_t g = info.adjFaces[edge];
    int ge = info.adjEdges[edge];
    if (g < 0) {  // boundary: repeat the edge texel
        const float* src =
            &values_[offsets_[f] + ((static_cast<size_t>(std::clamp(j, 0, vres - 1)) << info.ulog2) +
                                    std::clamp(i, 0, ures - 1)) *
                                       channels_];
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
    const float* src = &values_[offsets_[g] + ((static_cast<size_t>(gj) << other.ulog2) + gi) * channels_];
    std::copy(src, src + channels_, out);
}

void PtexSampler::ghost(int32_t f, int32_t i, int32_t j, float* out) const {
    const FaceInfo& info = faces_[f];
    const int32_t ures = info.ures(), vres = info.vres();
    const bool uOut = i < 0 || i >= ures, vOut = j < 0 || j >= vres;
    if (!uOut && !vOut) {
        const float* src = &values_[offsets_[f] + ((static_cast<size_t>(j) << info.ulog2) + i) * channels_];
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
    const float* c = &values_[offsets_[f] + ((static_cast<size_t>(cj) << info.ulog2) + ci) * channels_];
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
        const size_t row = static_cast<size_t>(info.ures()) * channels_;
        t00 = &values_[offsets_[f] + ((static_cast<size_t>(j0) << info.ulog2) + i0) * channels_];
        t10 = t00 + channels_;
        t01 = t00 + row;
        t11 = t01 + channels_;
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

// ---------------------------------------------------------------------------------------------------------
// Per-vertex values and baking

namespace {

// Sums of the corner texels at each vertex and their counts, for one data type (read without a per-value
// switch).
template <DataType Type>
void sumCorners(const PtexMesh& mesh, const PtexFile& file, std::vector<double>& sum,
                std::vector<int32_t>& count) {
    const int32_t channels = file.channels;
    const size_t bytes = bytesPerChannel(Type), pixel = file.pixelSize();
    const auto add = [&](int32_t vertex, int32_t p, int32_t i, int32_t j) {
        const uint8_t* texel =
            file.texels[p].empty()
                ? file.constData.data() + static_cast<size_t>(p) * pixel
                : file.texels[p].data() + ((static_cast<size_t>(j) << file.faces[p].ulog2) + i) * pixel;
        double* out = sum.data() + static_cast<size_t>(vertex) * channels;
        for (int32_t c = 0; c < channels; ++c)
            out[c] += loadValue(texel + c * bytes, Type);
        ++count[static_cast<size_t>(vertex)];
    };
    for (int32_t f = 0; f < mesh.numMeshFaces(); ++f) {
        const auto corners = mesh.faceVertices(f);
        const int32_t p = mesh.firstPtexFace(f);
        if (corners.size() == 4) {
            const int32_t iu = file.faces[p].ures() - 1, jv = file.faces[p].vres() - 1;
            add(corners[0], p, 0, 0);
            add(corners[1], p, iu, 0);
            add(corners[2], p, iu, jv);
            add(corners[3], p, 0, jv);
        } else {
            for (size_t k = 0; k < corners.size(); ++k)
                add(corners[k], p + static_cast<int32_t>(k), 0, 0);
        }
    }
}

}  // namespace

std::vector<float> vertexValues(const PtexMesh& mesh, const PtexFile& file, const std::string& fileSource) {
    mesh.requireMatches(file, fileSource);
    requireBuffers(file, fileSource);
    // Only the corner texels are read, straight from the file's bytes.
    const int32_t channels = file.channels;
    std::vector<double> sum(static_cast<size_t>(mesh.numVertices()) * channels, 0.0);
    std::vector<int32_t> count(static_cast<size_t>(mesh.numVertices()), 0);
    switch (file.dataType) {
        case DataType::UInt8:
            sumCorners<DataType::UInt8>(mesh, file, sum, count);
            break;
        case DataType::UInt16:
            sumCorners<DataType::UInt16>(mesh, file, sum, count);
            break;
        case DataType::Half:
            sumCorners<DataType::Half>(mesh, file, sum, count);
            break;
        case DataType::Float:
            sumCorners<DataType::Float>(mesh, file, sum, count);
            break;
    }
    std::vector<float> values(sum.size(), 0.0f);
    for (size_t v = 0; v < count.size(); ++v) {
        if (count[v] == 0) continue;
        for (int32_t c = 0; c < channels; ++c)
            values[v * channels + c] = static_cast<float>(sum[v * channels + c] / count[v]);
    }
    return values;
}

std::vector<float> weightsFromPtex(const geom::Mesh& mesh, const std::string& meshName,
                                   const std::filesystem::path& file, int32_t channel,
                                   const std::string& source) {
    // The file is named once: a source that is the file itself adds nothing.
    const bool prefix = !source.empty() && source != file.string();
    const std::string fileSource = prefix ? source + ": " + file.string() : file.string();
    const PtexFile ptexFile = [&] {
        try {
            return readPtex(file);  // its errors name the file
        } catch (const IoError& e) {
            throw IoError(prefix ? source + ": " + e.what() : e.what());
        } catch (const ParseError& e) {
            throw ParseError(prefix ? source + ": " + e.what() : e.what());
        }
    }();
    if (channel < 0 || channel >= ptexFile.channels) {
        throw InvalidInput(
            formatError(fileSource, "channel " + std::to_string(channel),
                        "is not one of the file's " + std::to_string(ptexFile.channels) + " channels",
                        "a channel in [0, " + std::to_string(ptexFile.channels) + ")"));
    }
    const PtexMesh ptexMesh(mesh, meshName);
    const std::vector<float> values = vertexValues(ptexMesh, ptexFile, fileSource);
    std::vector<float> weights(static_cast<size_t>(mesh.numVertices()));
    for (size_t v = 0; v < weights.size(); ++v)
        weights[v] = values[v * ptexFile.channels + channel];
    return weights;
}

PtexFile bakeVertexValues(const PtexMesh& mesh, std::span<const float> values, int32_t channels,
                          const BakeOptions& options) {
    if (channels < 1 || channels > 64) {
        throw InvalidInput(
            formatError(mesh.source(), "channels", "is " + std::to_string(channels), "1 to 64 channels"));
    }
    if (values.size() != static_cast<size_t>(mesh.numVertices()) * channels) {
        throw InvalidInput(formatError(
            mesh.source(), "vertex values", "has " + std::to_string(values.size()),
            std::to_string(mesh.numVertices()) + " vertices x " + std::to_string(channels) + " channels"));
    }
    if (options.ulog2 < 0 || options.ulog2 > 15 || options.vlog2 < 0 || options.vlog2 > 15) {
        throw InvalidInput(
            formatError(mesh.source(), "bake resolution",
                        "is 2^" + std::to_string(options.ulog2) + " x 2^" + std::to_string(options.vlog2),
                        "log2 sizes in [0, 15]"));
    }
    for (size_t i = 0; i < values.size(); ++i) {
        if (!std::isfinite(values[i])) {
            throw InvalidInput(formatError(mesh.source(), "vertex " + std::to_string(i / channels),
                                           "has value " + numberText(values[i]), "finite values"));
        }
    }
    PtexFile file;
    file.meshType = MeshType::Quad;
    file.dataType = options.dataType;
    file.channels = channels;
    file.faces = mesh.faceInfos(options.ulog2, options.vlog2);
    file.texels.resize(file.faces.size());
    file.constData.assign(file.faces.size() * file.pixelSize(), 0);
    const size_t bytes = bytesPerChannel(options.dataType);
    std::vector<double> weights;
    for (int32_t p = 0; p < mesh.numPtexFaces(); ++p) {
        const FaceInfo& info = file.faces[p];
        const auto corners = mesh.faceVertices(mesh.meshFace(p));
        weights.resize(corners.size());
        std::vector<uint8_t>& texels = file.texels[p];
        texels.resize(info.texelCount() * file.pixelSize());
        for (int32_t j = 0; j < info.vres(); ++j) {
            for (int32_t i = 0; i < info.ures(); ++i) {
                mesh.cornerWeights(p, (i + 0.5) / info.ures(), (j + 0.5) / info.vres(), weights);
                for (int32_t c = 0; c < channels; ++c) {
                    double value = 0.0;
                    for (size_t k = 0; k < corners.size(); ++k)
                        value += weights[k] * values[static_cast<size_t>(corners[k]) * channels + c];
                    const size_t at = ((static_cast<size_t>(j) * info.ures() + i) * channels + c) * bytes;
                    storeValue(static_cast<float>(value), options.dataType, texels.data() + at);
                }
            }
        }
    }
    return file;
}

// ---------------------------------------------------------------------------------------------------------
// UDIM conversions

namespace {

// Barycentric weights of the point of triangle (a, b, c) nearest to p, and its squared distance.
std::pair<glm::dvec3, double> nearestOnTriangle(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b,
                                                const glm::dvec2& c) {
    const glm::dvec2 ab = b - a, ac = c - a, ap = p - a;
    const double det = ab.x * ac.y - ab.y * ac.x;
    if (det != 0.0) {
        const double l1 = (ap.x * ac.y - ap.y * ac.x) / det;
        const double l2 = (ab.x * ap.y - ab.y * ap.x) / det;
        if (l1 >= 0.0 && l2 >= 0.0 && l1 + l2 <= 1.0) return {{1.0 - l1 - l2, l1, l2}, 0.0};
    }
    // Outside (or degenerate): the nearest point of the three edges.
    std::pair<glm::dvec3, double> best{{1.0, 0.0, 0.0}, glm::dot(ap, ap)};
    const std::array<glm::dvec2, 3> corner{a, b, c};
    for (int e = 0; e < 3; ++e) {
        const glm::dvec2 from = corner[e], to = corner[(e + 1) % 3];
        const glm::dvec2 edge = to - from;
        const double length2 = glm::dot(edge, edge);
        const double t = length2 > 0.0 ? std::clamp(glm::dot(p - from, edge) / length2, 0.0, 1.0) : 0.0;
        const glm::dvec2 q = from + t * edge;
        const double d2 = glm::dot(p - q, p - q);
        if (d2 < best.second) {
            glm::dvec3 l(0.0);
            l[e] = 1.0 - t;
            l[(e + 1) % 3] = t;
            best = {l, d2};
        }
    }
    return best;
}

// Texels whose centre lies in a UV face of `tile` (each face fanned into triangles from its first corner),
// rasterised by the same rule as the faces' cells.
std::vector<uint8_t> chartMask(const geom::Mesh& mesh, int tile, const io::TileOrigin& origin, int32_t res) {
    std::vector<glm::vec2> positions;
    std::vector<std::array<int32_t, 3>> triangles;
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        if (faceTile(mesh, f) != tile) continue;
        const auto corners = mesh.faceUVIndices(f);
        const auto base = static_cast<int32_t>(positions.size());
        for (const int32_t c : corners) {
            const glm::vec2 uv = mesh.uvs()[c];
            positions.emplace_back(static_cast<float>((uv.x - origin.u) * res),
                                   static_cast<float>((1.0 - (uv.y - origin.v)) * res));
        }
        for (int32_t k = 1; k + 1 < static_cast<int32_t>(corners.size()); ++k)
            triangles.push_back({base, base + k, base + k + 1});
    }
    const std::vector<float> attributes(positions.size(), 0.0f);
    geom::AttributeRaster raster;
    geom::rasterizeAttributes({res, res}, positions, triangles, attributes, 1, raster);
    std::vector<uint8_t> mask(raster.triangle.size());
    for (size_t i = 0; i < mask.size(); ++i)
        mask[i] = raster.triangle[i] >= 0 ? 1 : 0;
    return mask;
}

// Gives uncovered texels the (u, v) of the nearest point of a covered 8-neighbour's cell, one ring at a
// time: every texel of `chart` (hairline cracks where the cell grids of two faces meet) and `padding` rings
// around the charts, as texture bakers pad chart edges. Neighbours are taken in a fixed order and ties
// keep the first, so the result is the same on every run.
void fillFromNeighbours(geom::AttributeRaster& raster, std::span<const glm::vec2> positions,
                        std::span<const std::array<int32_t, 3>> triangles, std::span<const float> attributes,
                        const std::vector<uint8_t>& chart, int32_t padding) {
    const int32_t w = raster.width, h = raster.height;
    struct Update {
        size_t texel;
        int32_t triangle;
        glm::vec2 uv;
    };
    std::vector<Update> updates;
    for (int32_t ring = 1;; ++ring) {
        updates.clear();
        size_t chartLeft = 0;
        for (int32_t y = 0; y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                const size_t i = static_cast<size_t>(y) * w + x;
                if (raster.triangle[i] >= 0 || (!chart[i] && ring > padding)) continue;
                const glm::dvec2 centre(x + 0.5, y + 0.5);
                double bestD2 = std::numeric_limits<double>::infinity();
                Update best{i, -1, {}};
                for (int32_t dy = -1; dy <= 1; ++dy) {
                    for (int32_t dx = -1; dx <= 1; ++dx) {
                        const int32_t nx = x + dx, ny = y + dy;
                        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                        const int32_t t = raster.triangle[static_cast<size_t>(ny) * w + nx];
                        if (t < 0) continue;
                        const auto& tri = triangles[t];
                        const auto [l, d2] = nearestOnTriangle(centre, positions[tri[0]], positions[tri[1]],
                                                               positions[tri[2]]);
                        if (d2 >= bestD2) continue;
                        bestD2 = d2;
                        glm::dvec2 uv(0.0);
                        for (int k = 0; k < 3; ++k)
                            uv += l[k] * glm::dvec2(attributes[2 * tri[k]], attributes[2 * tri[k] + 1]);
                        best = {i, t, glm::vec2(uv)};
                    }
                }
                if (best.triangle >= 0) {
                    updates.push_back(best);
                } else if (chart[i]) {
                    ++chartLeft;
                }
            }
        }
        for (const Update& u : updates) {
            raster.triangle[u.texel] = u.triangle;
            raster.values[2 * u.texel] = u.uv.x;
            raster.values[2 * u.texel + 1] = u.uv.y;
        }
        if (updates.empty() || (ring >= padding && chartLeft == 0)) break;
    }
}

}  // namespace

std::vector<UdimTile> ptexToUdim(const PtexMesh& ptexMesh, const geom::Mesh& mesh, const PtexFile& file,
                                 const std::string& fileSource, const ToUdimOptions& options) {
    requireUVs(mesh, ptexMesh);
    ptexMesh.requireMatches(file, fileSource);
    if (options.resolution < 1 || options.resolution > 65536) {
        throw InvalidInput(formatError(fileSource, "resolution", "is " + std::to_string(options.resolution),
                                       "a tile resolution in [1, 65536]"));
    }
    if (options.padding < 0 || options.padding > 65536) {
        throw InvalidInput(formatError(fileSource, "padding", "is " + std::to_string(options.padding),
                                       "texels of edge padding in [0, 65536]"));
    }
    std::vector<int> tiles = options.tiles.empty() ? mesh.udimTiles() : options.tiles;
    for (int tile : tiles) {  // the mesh's own tiles are valid (Mesh::udimTiles); asked-for ones are checked
        if (tile < 1001 || tile > 9999) {
            throw InvalidInput(formatError(fileSource, "tiles", std::to_string(tile) + " is not a UDIM tile",
                                           "tile numbers 1001 to 9999"));
        }
    }
    const PtexSampler sampler(file, fileSource);
    const int32_t channels = sampler.channels(), res = options.resolution;
    const int32_t outChannels = channels + (options.coverageChannel ? 1 : 0);

    std::vector<UdimTile> out;
    std::vector<double> weights;
    std::vector<float> value(static_cast<size_t>(channels));
    for (int tile : tiles) {
        const io::TileOrigin origin = io::udimOrigin(tile);
        // Every Ptex face of the tile as a grid of n x n cells (two triangles each) carrying (u, v).
        std::vector<glm::vec2> positions;
        std::vector<float> attributes;
        std::vector<std::array<int32_t, 3>> triangles;
        std::vector<int32_t> triangleFace;
        for (int32_t p = 0; p < ptexMesh.numPtexFaces(); ++p) {
            if (faceTile(mesh, ptexMesh.meshFace(p)) != tile) continue;
            // Cells no larger than ~4 texels of the tile so the bilinear map is followed closely.
            glm::dvec2 lo(1e30), hi(-1e30);
            for (double cu : {0.0, 1.0})
                for (double cv : {0.0, 1.0}) {
                    const glm::dvec2 uv = ptexUV(ptexMesh, mesh, p, cu, cv, weights);
                    lo = glm::min(lo, uv), hi = glm::max(hi, uv);
                }
            const double extent = std::max(hi.x - lo.x, hi.y - lo.y) * res;
            const auto n = std::clamp(static_cast<int32_t>(std::ceil(extent / 4.0)), 1, 64);
            const auto base = static_cast<int32_t>(positions.size());
            for (int32_t b = 0; b <= n; ++b) {
                for (int32_t a = 0; a <= n; ++a) {
                    const double u = static_cast<double>(a) / n, v = static_cast<double>(b) / n;
                    const glm::dvec2 uv = ptexUV(ptexMesh, mesh, p, u, v, weights);
                    positions.emplace_back(static_cast<float>((uv.x - origin.u) * res),
                                           static_cast<float>((1.0 - (uv.y - origin.v)) * res));
                    attributes.push_back(static_cast<float>(u));
                    attributes.push_back(static_cast<float>(v));
                }
            }
            for (int32_t b = 0; b < n; ++b) {
                for (int32_t a = 0; a < n; ++a) {
                    const int32_t v00 = base + b * (n + 1) + a, v10 = v00 + 1, v01 = v00 + n + 1,
                                  v11 = v01 + 1;
                    triangles.push_back({v00, v10, v11});
                    triangles.push_back({v00, v11, v01});
                    triangleFace.push_back(p);
                    triangleFace.push_back(p);
                }
            }
        }
        geom::AttributeRaster raster;
        geom::rasterizeAttributes({res, res}, positions, triangles, attributes, 2, raster);
        const std::vector<uint8_t> chart = chartMask(mesh, tile, origin, res);
        fillFromNeighbours(raster, positions, triangles, attributes, chart, options.padding);
        UdimTile result{tile, io::Image(res, res, outChannels, 0.0f)};
        for (int32_t y = 0; y < res; ++y) {
            for (int32_t x = 0; x < res; ++x) {
                const size_t pixel = static_cast<size_t>(y) * res + x;
                const int32_t t = raster.triangle[pixel];
                if (t < 0) continue;
                sampler.sample(triangleFace[t], raster.values[pixel * 2], raster.values[pixel * 2 + 1],
                               value);
                for (int32_t c = 0; c < channels; ++c)
                    result.image.at(x, y, c) = value[c];
                if (options.coverageChannel && chart[pixel]) result.image.at(x, y, channels) = 1.0f;
            }
        }
        out.push_back(std::move(result));
    }
    return out;
}

PtexFile udimToPtex(const PtexMesh& ptexMesh, const geom::Mesh& mesh, std::span<const UdimTile> tiles,
                    const FromUdimOptions& options) {
    requireUVs(mesh, ptexMesh);
    if (tiles.empty()) {
        throw InvalidInput(formatError(ptexMesh.source(), "UDIM tiles", "none given", "at least one tile"));
    }
    std::map<int, const io::Image*> byTile;
    const int32_t channels = tiles.front().image.channels;
    for (const UdimTile& t : tiles) {
        if (t.image.channels != channels || t.image.width < 1 || t.image.height < 1) {
            throw InvalidInput(formatError("UDIM tile " + std::to_string(t.tile), "",
                                           "has " + std::to_string(t.image.width) + "x" +
                                               std::to_string(t.image.height) + " pixels of " +
                                               std::to_string(t.image.channels) + " channels",
                                           std::to_string(channels) + " channels like tile " +
                                               std::to_string(tiles.front().tile) + ", at least 1x1"));
        }
        byTile[t.tile] = &t.image;
    }
    if (channels < 1 || channels > 64) {
        throw InvalidInput(formatError("UDIM tile " + std::to_string(tiles.front().tile), "",
                                       "has " + std::to_string(channels) + " channels", "1 to 64 channels"));
    }
    const auto fixedLog2 = [](int8_t value, const char* name) {
        if (value < -1 || value > 15) {
            throw InvalidInput(formatError("from-udim", name, "is " + std::to_string(value),
                                           "-1 (from the image) or a log2 size in [0, 15]"));
        }
        return value;
    };
    const int8_t ulog2 = fixedLog2(options.ulog2, "ulog2"), vlog2 = fixedLog2(options.vlog2, "vlog2");

    PtexFile file;
    file.meshType = MeshType::Quad;
    file.dataType = options.dataType;
    file.channels = channels;
    file.faces = ptexMesh.faceInfos(0, 0);
    file.texels.resize(file.faces.size());
    file.constData.assign(file.faces.size() * file.pixelSize(), 0);
    const size_t bytes = bytesPerChannel(options.dataType);
    std::vector<double> weights;
    std::vector<float> value(static_cast<size_t>(channels));
    const auto log2Near = [](double texels) {
        return static_cast<int8_t>(
            std::clamp(static_cast<int>(std::lround(std::log2(std::max(texels, 1.0)))), 0, 12));
    };
    for (int32_t p = 0; p < ptexMesh.numPtexFaces(); ++p) {
        const int32_t f = ptexMesh.meshFace(p);
        if (!mesh.faceHasUVs(f)) {  // in no tile: 0, at the fixed resolution or 1 × 1
            FaceInfo& info = file.faces[p];
            info.ulog2 = std::max<int8_t>(ulog2, 0);
            info.vlog2 = std::max<int8_t>(vlog2, 0);
            file.texels[p].assign(info.texelCount() * file.pixelSize(), 0);
            continue;
        }
        const int tile = faceTile(mesh, f);
        const auto found = byTile.find(tile);
        if (found == byTile.end()) {
            throw InvalidInput(formatError(ptexMesh.source(), "face " + std::to_string(f),
                                           "lies in UDIM tile " + std::to_string(tile),
                                           "an image for every tile the mesh uses"));
        }
        const io::Image& image = *found->second;
        const io::TileOrigin origin = io::udimOrigin(tile);
        FaceInfo& info = file.faces[p];
        // Automatic resolution: per axis, the mean length of the face's two edges along it in tile texels.
        const glm::dvec2 size(image.width, image.height);
        const auto edge = [&](double u0, double v0, double u1, double v1) {
            return glm::length(
                (ptexUV(ptexMesh, mesh, p, u1, v1, weights) - ptexUV(ptexMesh, mesh, p, u0, v0, weights)) *
                size);
        };
        info.ulog2 = ulog2 >= 0 ? ulog2 : log2Near(0.5 * (edge(0, 0, 1, 0) + edge(0, 1, 1, 1)));
        info.vlog2 = vlog2 >= 0 ? vlog2 : log2Near(0.5 * (edge(0, 0, 0, 1) + edge(1, 0, 1, 1)));
        std::vector<uint8_t>& texels = file.texels[p];
        texels.resize(info.texelCount() * file.pixelSize());
        for (int32_t j = 0; j < info.vres(); ++j) {
            for (int32_t i = 0; i < info.ures(); ++i) {
                const glm::dvec2 uv =
                    ptexUV(ptexMesh, mesh, p, (i + 0.5) / info.ures(), (j + 0.5) / info.vres(), weights);
                const glm::vec2 pixel(static_cast<float>((uv.x - origin.u) * image.width),
                                      static_cast<float>((1.0 - (uv.y - origin.v)) * image.height));
                io::sampleImage(image, pixel, io::SampleFilter::Bilinear, value);
                for (int32_t c = 0; c < channels; ++c) {
                    const size_t at = ((static_cast<size_t>(j) * info.ures() + i) * channels + c) * bytes;
                    storeValue(value[c], options.dataType, texels.data() + at);
                }
            }
        }
    }
    return file;
}

}  // namespace deformkit::ptex
