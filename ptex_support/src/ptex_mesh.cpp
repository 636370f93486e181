#include "deformkit/ptex/ptex_mesh.h"

#include <algorithm>
#include <array>
#include <memory>
#include <unordered_map>

#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include "deformkit/error.h"
#include "deformkit/geom/finite.h"
#include "deformkit/geom/limit_surface.h"
#include "deformkit/geom/weld.h"
#include "texel_access.h"

namespace deformkit::ptex {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

// Bilinear weights of (u, v) over a quad's corners at (0,0), (1,0), (1,1), (0,1).
std::array<double, 4> bilinear(double u, double v) {
    return {(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v};
}

// The faces' corners on welded vertices (geom/weld.h): split copies of a vertex (glTF, FBX) are one vertex,
// so the Ptex faces around a seam are neighbours, as on the shared-vertex mesh a painter used. `weldedOf`:
// per file vertex, its welded vertex; `firstOf`: per welded vertex, its first file vertex. The file's own
// corners where nothing welds, or where welding would give a face the same vertex twice (a sliver of
// coincident points).
std::vector<int32_t> weldedCorners(const geom::Mesh& mesh, std::vector<int32_t>& weldedOf,
                                   std::vector<int32_t>& firstOf) {
    const std::span<const int32_t> corners = mesh.faceIndices();
    weldedOf.resize(static_cast<size_t>(mesh.numVertices()));
    for (size_t v = 0; v < weldedOf.size(); ++v)
        weldedOf[v] = static_cast<int32_t>(v);
    firstOf = weldedOf;
    const geom::Welding weld = geom::weldVertices(mesh);
    if (weld.merged() == 0) return {corners.begin(), corners.end()};
    std::vector<int32_t> welded(corners.size());
    for (size_t c = 0; c < corners.size(); ++c)
        welded[c] = weld.weldedOf[static_cast<size_t>(corners[c])];
    for (int32_t f = 0; f < mesh.numFaces(); ++f) {
        const std::span<const int32_t> face = std::span<const int32_t>(welded).subspan(
            static_cast<size_t>(mesh.faceOffsets()[f]), static_cast<size_t>(mesh.faceCounts()[f]));
        for (size_t i = 0; i < face.size(); ++i)
            for (size_t j = 0; j < i; ++j)
                if (face[i] == face[j]) return {corners.begin(), corners.end()};
    }
    weldedOf = weld.weldedOf;
    firstOf = weld.firstOf;
    return welded;
}

}  // namespace

PtexMesh::PtexMesh(const geom::Mesh& mesh, const std::string& source)
    : source_(source), numVertices_(mesh.numVertices()) {
    if (mesh.numFaces() == 0) {
        throw InvalidInput(formatError(source, "", "has no faces", "a polygon mesh for Ptex faces"));
    }
    geom::requireSubdivisionLimits(mesh, source);  // named here, not printed by OpenSubdiv
    faceCounts_.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    faceOffsets_.assign(mesh.faceOffsets().begin(), mesh.faceOffsets().end());
    faceIndices_.assign(mesh.faceIndices().begin(), mesh.faceIndices().end());
    std::vector<int32_t> firstOf;
    connectivity_ = weldedCorners(mesh, weldedOf_, firstOf);
    numWelded_ = static_cast<int32_t>(firstOf.size());

    Far::TopologyDescriptor desc;
    desc.numVertices = numWelded_;
    desc.numFaces = mesh.numFaces();
    desc.numVertsPerFace = faceCounts_.data();
    desc.vertIndicesPerFace = connectivity_.data();
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
    if (file.meshType != MeshType::Quad) {
        throw InvalidInput(formatError(fileSource, "header", "is a triangle-mesh Ptex file",
                                       "a quad-mesh Ptex file (Catmull-Clark faces) for mesh " + source_));
    }
    if (file.faces.size() != meshFace_.size()) {
        throw InvalidInput(formatError(fileSource, "", "has " + std::to_string(file.faces.size()) + " faces",
                                       std::to_string(meshFace_.size()) +
                                           " Ptex faces (one per quad, N per N-gon) for mesh " + source_));
    }
    // Without the mesh metadata the face count alone would pair a file of 2 quads and a triangle (5 Ptex
    // faces, 3 of them sub-faces) with a mesh of 5 quads: each face's sub-face flag must be the mesh's.
    for (size_t p = 0; p < meshFace_.size(); ++p) {
        const bool sub = subFace_[p] >= 0;
        if (file.faces[p].subface == sub) continue;
        throw InvalidInput(
            formatError(fileSource, "face " + std::to_string(p),
                        std::string(file.faces[p].subface ? "is a sub-face of an N-gon" : "is a whole quad") +
                            ", where mesh " + source_ + " has " +
                            (sub ? "sub-face " + std::to_string(subFace_[p]) + " of its " +
                                       std::to_string(faceCounts_[static_cast<size_t>(meshFace_[p])]) +
                                       "-gon " + std::to_string(meshFace_[p])
                                 : "its quad " + std::to_string(meshFace_[p])),
                        "the Ptex faces of this mesh (a file painted on another mesh with as many faces?)"));
    }
    requireSameMesh(file, fileSource);
    detail::requireAdjacency(file.faces, fileSource);
}

void PtexMesh::requireSameMesh(const PtexFile& file, const std::string& fileSource) const {
    const auto find = [&](const char* key) -> const MetaValue* {
        for (const MetaValue& m : file.metadata)
            if (m.key == key && m.type == MetaType::Int32) return &m;
        return nullptr;
    };
    const MetaValue* counts = find("PtexFaceVertCounts");
    const MetaValue* indices = find("PtexFaceVertIndices");
    if (counts == nullptr || indices == nullptr) return;  // a file without its mesh: the face count decides
    const std::string expected = "the polygons of mesh " + source_ +
                                 ", in its order (a file painted on this mesh; its vertices may be "
                                 "numbered otherwise)";
    if (counts->int32s.size() != faceCounts_.size()) {
        throw InvalidInput(formatError(fileSource, "metadata PtexFaceVertCounts",
                                       "lists " + std::to_string(counts->int32s.size()) + " polygons",
                                       std::to_string(faceCounts_.size()) + ": " + expected));
    }
    // Polygon by polygon, corner by corner: the same sizes, and the file's vertices one-to-one with the
    // mesh's (a renumbering of vertices keeps every face's texels where they were; another order of
    // polygons does not): with the welded vertices (a painter's shared-vertex mesh, DeformKit's metadata),
    // or else with the file's own (metadata that lists the split vertices, as a tool writing the split mesh
    // as it is would).
    const auto pairing = [&](const std::vector<int32_t>& mine) -> std::string {
        std::unordered_map<int32_t, int32_t> meshVertexOf, fileVertexOf;
        size_t corner = 0;
        for (size_t f = 0; f < faceCounts_.size(); ++f) {
            const int32_t n = faceCounts_[f];
            const std::string polygon = "metadata: polygon " + std::to_string(f);
            if (counts->int32s[f] != n) {
                return formatError(fileSource, polygon,
                                   "has " + std::to_string(counts->int32s[f]) +
                                       " corners where mesh polygon " + std::to_string(f) + " has " +
                                       std::to_string(n),
                                   expected);
            }
            if (indices->int32s.size() < corner + static_cast<size_t>(n))
                return formatError(fileSource, polygon, "has no PtexFaceVertIndices left", expected);
            for (int32_t c = 0; c < n; ++c, ++corner) {
                const int32_t theirs = indices->int32s[corner], ours = mine[corner];
                const auto [meshSide, addedMine] = meshVertexOf.try_emplace(theirs, ours);
                const auto [fileSide, addedOther] = fileVertexOf.try_emplace(ours, theirs);
                if (meshSide->second != ours || fileSide->second != theirs) {
                    // The earlier pairing this corner breaks: of its file vertex, or of its mesh vertex.
                    const std::string earlier =
                        meshSide->second != ours ? "file vertex " + std::to_string(theirs) +
                                                       " was mesh vertex " + std::to_string(meshSide->second)
                                                 : "mesh vertex " + std::to_string(ours) +
                                                       " was file vertex " + std::to_string(fileSide->second);
                    return formatError(fileSource, polygon,
                                       "corner " + std::to_string(c) + " pairs file vertex " +
                                           std::to_string(theirs) + " with mesh vertex " +
                                           std::to_string(ours) + ", but in the polygons before it " +
                                           earlier +
                                           ": the file was painted on another mesh, or on its polygons in "
                                           "another order",
                                       expected);
                }
            }
        }
        return {};
    };
    const std::string welded = pairing(connectivity_);
    if (welded.empty()) return;
    if (connectivity_ != faceIndices_ && pairing(faceIndices_).empty()) return;
    throw InvalidInput(welded);
}

MeshData meshData(const geom::Mesh& mesh, const std::string& source) {
    MeshData data;
    data.faceVertCounts.assign(mesh.faceCounts().begin(), mesh.faceCounts().end());
    std::vector<int32_t> weldedOf, firstOf;
    data.faceVertIndices = weldedCorners(mesh, weldedOf, firstOf);  // the polygons a painter's mesh has
    data.vertPositions.reserve(firstOf.size() * 3);
    for (const int32_t v : firstOf) {
        const glm::vec3& p = mesh.points()[static_cast<size_t>(v)];
        if (!geom::isFinite(p)) {  // points changed after the mesh was made (a Python view)
            throw InvalidInput(
                formatError(source, "vertex " + std::to_string(v),
                            "is (" + numberText(p.x) + ", " + numberText(p.y) + ", " + numberText(p.z) + ")",
                            "finite coordinates (the file's mesh metadata)"));
        }
        data.vertPositions.push_back(p.x);
        data.vertPositions.push_back(p.y);
        data.vertPositions.push_back(p.z);
    }
    return data;
}

}  // namespace deformkit::ptex
