#include "deformkit/geom/limit_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include "deformkit/error.h"

namespace deformkit::geom {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

namespace {

// Control points of the largest patch type OpenSubdiv builds for Catmull-Clark (Gregory basis: 20).
constexpr int kMaxPatchPoints = 20;
// OpenSubdiv's limit on face sizes and vertex valences (Vtr::VALENCE_LIMIT).
constexpr int32_t kValenceLimit = Far::VALENCE_LIMIT;
// Corner weights come from barycentric coordinates computed in floating point: this much below 0 or
// away from a sum of 1 is round-off, not a different point.
constexpr double kWeightTolerance = 1e-5;
// (u, v) this far outside [0, 1] is round-off and clamped; beyond it the location is rejected.
constexpr double kParamTolerance = 1e-9;
// dPdu x dPdv shorter than this fraction of |dPdu| |dPdv| has no direction: the surface is singular there.
constexpr double kSingular = 1e-9;

// A primvar of OpenSubdiv's refiners and stencil tables: a position in double precision.
struct Point {
    glm::dvec3 p{0.0};
    void Clear(void* = nullptr) { p = glm::dvec3(0.0); }
    void AddWithWeight(const Point& src, double weight) { p += weight * src.p; }
};

double cross2(const glm::dvec2& a, const glm::dvec2& b) {
    return a.x * b.y - a.y * b.x;
}

// (u, v) with (1-u)(1-v) a + u(1-v) b + uv c + (1-u)v d = q, for a convex quad abcd containing q.
// q - a = u (e + v g) + v f with e = b - a, f = d - a, g = a - b + c - d; crossing with (e + v g)
// eliminates u and leaves k2 v^2 + k1 v + k0 = 0.
glm::dvec2 invertBilinear(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d,
                          const glm::dvec2& q) {
    const glm::dvec2 e = b - a, f = d - a, g = a - b + c - d, h = q - a;
    const double k2 = cross2(g, f);
    const double k1 = cross2(e, f) + cross2(h, g);
    const double k0 = cross2(h, e);
    const double scale = std::abs(cross2(e, f));  // twice the area of triangle abd; > 0 for a convex quad
    double v;
    if (std::abs(k2) <= 1e-12 * scale) {
        v = -k0 / k1;  // a parallelogram: linear in v
    } else {
        const double disc = std::sqrt(std::max(k1 * k1 - 4.0 * k0 * k2, 0.0));
        const double t = -0.5 * (k1 + std::copysign(disc, k1));  // stable quadratic roots: t / k2 and k0 / t
        const double r0 = t / k2;
        const double r1 = t != 0.0 ? k0 / t : r0;
        const auto outside = [](double r) { return std::max({-r, r - 1.0, 0.0}); };
        v = outside(r0) <= outside(r1) ? r0 : r1;
    }
    v = std::clamp(v, 0.0, 1.0);
    const glm::dvec2 dir = e + v * g;
    const double u = std::clamp(glm::dot(h - v * f, dir) / glm::dot(dir, dir), 0.0, 1.0);
    return {u, v};
}

}  // namespace

struct LimitSurface::Impl {
    std::string source;
    int32_t numVertices = 0;
    std::vector<int32_t> faceCounts;  // #F corner counts
    std::vector<int32_t> ptexBase;    // #F + 1: first Ptex face of each face, then the Ptex face count
    // Connectivity, shared by copies and by withPoints(); the refiner only when the surface is deformable.
    std::shared_ptr<const Far::TopologyRefiner> refiner;
    std::shared_ptr<const Far::PatchTable> patches;
    std::shared_ptr<const Far::PatchMap> patchMap;
    std::vector<PtexLocation> vertexCorner;  // #V: a patch corner at each vertex (ptexFace -1: unused)
    std::vector<glm::dvec3> patchPoints;  // refined vertices of every level, then the patches' local points
    std::vector<glm::dvec3> limitPositions;  // #V

    // Patch points and limit positions for cage positions `cage` (#V).
    void setControlPoints(const Far::TopologyRefiner& topology, std::span<const glm::vec3> cage);

    void requireFace(int32_t face) const {
        if (face < 0 || face >= static_cast<int32_t>(faceCounts.size())) {
            throw InvalidInput(formatError(source, "face " + std::to_string(face), "is out of range",
                                           "an index in [0, " + std::to_string(faceCounts.size()) + ")"));
        }
    }

    PtexLocation ptexLocation(int32_t face, std::span<const double> weights) const;
    LimitSample evaluate(const PtexLocation& at, bool derivatives) const;
    // Position and (when both are given) first derivatives of the patch containing `at`.
    void patchPoint(const PtexLocation& at, glm::dvec3& position, glm::dvec3* dPdu, glm::dvec3* dPdv) const;
};

LimitSurface::PtexLocation LimitSurface::Impl::ptexLocation(int32_t face,
                                                            std::span<const double> weights) const {
    requireFace(face);
    const int32_t n = faceCounts[face];
    if (static_cast<int32_t>(weights.size()) != n) {
        throw InvalidInput(formatError(source, "face " + std::to_string(face),
                                       std::to_string(weights.size()) + " corner weights given",
                                       std::to_string(n) + ", one per corner"));
    }
    double sum = 0.0;
    for (int32_t k = 0; k < n; ++k) {
        if (!std::isfinite(weights[k]) || weights[k] < -kWeightTolerance) {
            throw InvalidInput(formatError(
                source, "face " + std::to_string(face) + " corner " + std::to_string(k),
                "weight " + std::to_string(weights[k]) + " is negative or not finite", "a weight >= 0"));
        }
        sum += std::max(weights[k], 0.0);
    }
    if (std::abs(sum - 1.0) > kWeightTolerance) {
        throw InvalidInput(formatError(source, "face " + std::to_string(face),
                                       "corner weights sum to " + std::to_string(sum), "a sum of 1"));
    }
    const auto w = [&](int32_t k) { return std::max(weights[k], 0.0) / sum; };

    if (n == 4) {
        // Corner (u, v): (0,0), (1,0), (1,1), (0,1).
        return {ptexBase[face], std::clamp(w(1) + w(2), 0.0, 1.0), std::clamp(w(2) + w(3), 0.0, 1.0)};
    }

    // The weighted point in a regular N-gon with corner k at angle k * 2 pi / N (centre at the origin).
    const double step = 2.0 * std::numbers::pi / n;
    glm::dvec2 q(0.0);
    for (int32_t k = 0; k < n; ++k)
        q += w(k) * glm::dvec2(std::cos(k * step), std::sin(k * step));
    // Sub-face k is the kite (corner k, midpoint of edge k, centre, midpoint of edge k - 1): the part of
    // the polygon within half a step of corner k's angle.
    const double angle = std::atan2(q.y, q.x);
    int32_t k = static_cast<int32_t>(std::lround(angle / step));
    k = ((k % n) + n) % n;
    const auto corner = [&](int32_t i) {
        const int32_t j = ((i % n) + n) % n;
        return glm::dvec2(std::cos(j * step), std::sin(j * step));
    };
    const glm::dvec2 pk = corner(k);
    const glm::dvec2 next = 0.5 * (pk + corner(k + 1));
    const glm::dvec2 prev = 0.5 * (pk + corner(k - 1));
    const glm::dvec2 uv = invertBilinear(pk, next, glm::dvec2(0.0), prev, q);
    return {ptexBase[face] + k, uv.x, uv.y};
}

LimitSample LimitSurface::Impl::evaluate(const PtexLocation& at, bool derivatives) const {
    LimitSample s;
    patchPoint(at, s.position, derivatives ? &s.dPdu : nullptr, derivatives ? &s.dPdv : nullptr);
    if (!derivatives) return s;
    glm::dvec3 du = s.dPdu, dv = s.dPdv;
    // Where the surface is singular (a smooth corner of an EdgesOnly boundary, where the boundary curve runs
    // through and dPdu is parallel to dPdv) take the normal of a point slightly inside the Ptex face.
    for (const double t : {1e-5, 1e-3, 1e-1}) {
        const glm::dvec3 n = glm::cross(du, dv);
        const double len = glm::length(n);
        if (len > kSingular * glm::length(du) * glm::length(dv)) {
            s.normal = n / len;
            break;
        }
        glm::dvec3 p;
        patchPoint({at.ptexFace, at.u + t * (0.5 - at.u), at.v + t * (0.5 - at.v)}, p, &du, &dv);
    }
    return s;
}

void LimitSurface::Impl::patchPoint(const PtexLocation& at, glm::dvec3& position, glm::dvec3* dPdu,
                                    glm::dvec3* dPdv) const {
    const Far::PatchMap::Handle* handle = patchMap->FindPatch(at.ptexFace, at.u, at.v);
    if (handle == nullptr) {
        // Every face of a Catmull-Clark surface has patches except the holes the caller asked for.
        throw InvalidInput(formatError(source, "Ptex face " + std::to_string(at.ptexFace),
                                       "has no limit patch (a hole)", "a face that is not a hole"));
    }
    const bool derivatives = dPdu != nullptr && dPdv != nullptr;
    std::array<double, kMaxPatchPoints> wP{}, wDu{}, wDv{};
    patches->EvaluateBasis(*handle, at.u, at.v, wP.data(), derivatives ? wDu.data() : nullptr,
                           derivatives ? wDv.data() : nullptr);
    const Far::ConstIndexArray cvs = patches->GetPatchVertices(*handle);
    position = glm::dvec3(0.0);
    glm::dvec3 du(0.0), dv(0.0);
    for (int i = 0; i < cvs.size(); ++i) {
        const glm::dvec3& p = patchPoints[cvs[i]];
        position += wP[i] * p;
        du += wDu[i] * p;
        dv += wDv[i] * p;
    }
    if (!derivatives) return;
    // EvaluateBasis scales derivatives by 2^depth, while a sub-face of a non-quad is already one level deep
    // in its own Ptex parameterization (PatchParam::GetParamFraction uses depth - 1): halve them so they
    // are per unit of the Ptex face's u and v.
    const double scale = patches->GetPatchParam(*handle).NonQuadRoot() ? 0.5 : 1.0;
    *dPdu = scale * du;
    *dPdv = scale * dv;
}

void LimitSurface::Impl::setControlPoints(const Far::TopologyRefiner& topology,
                                          std::span<const glm::vec3> cage) {
    // Patch control points: the cage, every adaptively refined level, then the local (end-cap) points.
    const int numRefined = topology.GetNumVerticesTotal();
    const int numLocal = patches->GetNumLocalPoints();
    std::vector<Point> points(static_cast<size_t>(numRefined) + numLocal);
    for (int32_t v = 0; v < numVertices; ++v)
        points[v].p = glm::dvec3(cage[v]);
    Far::PrimvarRefinerReal<double> primvars(topology);
    Point* src = points.data();
    for (int level = 1; level <= topology.GetMaxLevel(); ++level) {
        Point* dst = src + topology.GetLevel(level - 1).GetNumVertices();
        primvars.Interpolate(level, src, dst);
        src = dst;
    }
    if (numLocal > 0) {
        const Far::StencilTableReal<double>* local = patches->GetLocalPointStencilTable<double>();
        if (local == nullptr) {
            throw Error(formatError(source, "", "OpenSubdiv built no double-precision local point stencils"));
        }
        local->UpdateValues(points.data(), points.data() + numRefined);
    }
    patchPoints.resize(points.size());
    std::transform(points.begin(), points.end(), patchPoints.begin(), [](const Point& p) { return p.p; });

    limitPositions.resize(numVertices);
    for (int32_t v = 0; v < numVertices; ++v) {
        if (vertexCorner[v].ptexFace < 0) {
            limitPositions[v] = glm::dvec3(cage[v]);
        } else {
            patchPoint(vertexCorner[v], limitPositions[v], nullptr, nullptr);
        }
    }
}

void requireSubdivisionLimits(const Mesh& rest, const std::string& source) {
    const auto counts = rest.faceCounts();
    const auto indices = rest.faceIndices();
    for (int32_t f = 0; f < rest.numFaces(); ++f) {
        if (counts[f] > kValenceLimit) {
            throw TopologyError(formatError(source, "face " + std::to_string(f),
                                            "has " + std::to_string(counts[f]) + " corners",
                                            "at most " + std::to_string(kValenceLimit) + " for subdivision"));
        }
    }
    {
        // A vertex's valence in OpenSubdiv is the larger of its face and edge counts.
        std::vector<int32_t> vertexFaces(rest.numVertices(), 0);
        std::vector<uint64_t> vertexEdges;  // (vertex << 32 | neighbour), both directions of every face edge
        vertexEdges.reserve(2 * indices.size());
        for (int32_t f = 0; f < rest.numFaces(); ++f) {
            const auto corners = rest.face(f);
            for (int32_t k = 0; k < counts[f]; ++k) {
                const auto a = static_cast<uint64_t>(corners[k]);
                const auto b = static_cast<uint64_t>(corners[(k + 1) % counts[f]]);
                ++vertexFaces[corners[k]];
                vertexEdges.push_back(a << 32 | b);
                vertexEdges.push_back(b << 32 | a);
            }
        }
        std::sort(vertexEdges.begin(), vertexEdges.end());
        vertexEdges.erase(std::unique(vertexEdges.begin(), vertexEdges.end()), vertexEdges.end());
        std::vector<int32_t> valence(vertexFaces);
        for (size_t i = 0; i < vertexEdges.size();) {
            const auto v = static_cast<int32_t>(vertexEdges[i] >> 32);
            size_t end = i;
            while (end < vertexEdges.size() && static_cast<int32_t>(vertexEdges[end] >> 32) == v)
                ++end;
            valence[v] = std::max(valence[v], static_cast<int32_t>(end - i));
            i = end;
        }
        for (int32_t v = 0; v < rest.numVertices(); ++v) {
            if (valence[v] > kValenceLimit) {
                throw TopologyError(formatError(
                    source, "vertex " + std::to_string(v), "has valence " + std::to_string(valence[v]),
                    "at most " + std::to_string(kValenceLimit) + " for subdivision"));
            }
        }
    }
}

LimitSurface::LimitSurface(const Mesh& rest, const LimitSurfaceOptions& options, const std::string& source) {
    auto impl = std::make_shared<Impl>();
    impl->source = source;
    if (options.isolationLevel < 1 || options.isolationLevel > 10) {
        throw InvalidInput(
            formatError(source, "limit surface options",
                        "isolation level " + std::to_string(options.isolationLevel) + " is out of range",
                        "an integer in [1, 10]"));
    }
    if (rest.numFaces() == 0) {
        throw InvalidInput(formatError(source, "", "has no faces", "at least one face for a limit surface"));
    }
    const auto counts = rest.faceCounts();
    const auto indices = rest.faceIndices();
    requireSubdivisionLimits(rest, source);

    impl->numVertices = rest.numVertices();
    impl->faceCounts.assign(counts.begin(), counts.end());

    Far::TopologyDescriptor desc;
    desc.numVertices = rest.numVertices();
    desc.numFaces = rest.numFaces();
    desc.numVertsPerFace = counts.data();
    desc.vertIndicesPerFace = indices.data();
    std::vector<uint8_t> isHole(rest.numFaces(), 0);
    for (int32_t f : options.holes) {
        if (f < 0 || f >= rest.numFaces()) {
            throw InvalidInput(formatError(source, "limit surface options", "hole face " + std::to_string(f),
                                           "a face in [0, " + std::to_string(rest.numFaces()) + ")"));
        }
        isHole[f] = 1;
    }
    std::vector<int32_t> holes;
    for (int32_t f = 0; f < rest.numFaces(); ++f) {
        if (isHole[f]) holes.push_back(f);
    }
    desc.numHoles = static_cast<int>(holes.size());
    desc.holeIndices = holes.data();

    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(options.boundary == LimitSurfaceOptions::Boundary::EdgesOnly
                                        ? Sdc::Options::VTX_BOUNDARY_EDGE_ONLY
                                        : Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using RefinerFactory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    std::shared_ptr<Far::TopologyRefiner> refiner(
        RefinerFactory::Create(desc, RefinerFactory::Options(Sdc::SCHEME_CATMARK, sdc)));
    if (!refiner) {
        throw TopologyError(formatError(source, "", "OpenSubdiv cannot build a subdivision topology from it",
                                        "a polygon mesh within OpenSubdiv's limits"));
    }

    Far::PtexIndices ptex(*refiner);
    impl->ptexBase.resize(rest.numFaces() + 1);
    for (int32_t f = 0; f < rest.numFaces(); ++f)
        impl->ptexBase[f] = ptex.GetFaceId(f);
    impl->ptexBase[rest.numFaces()] = ptex.GetNumFaces();

    Far::PatchTableFactory::Options patchOptions(options.isolationLevel);
    patchOptions.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    patchOptions.SetPatchPrecision<double>();
    // Sharp boundaries and corners become exact B-spline boundary patches instead of deep isolation, and
    // smooth corners (EdgesOnly) are not replaced by the legacy sharp approximation.
    patchOptions.useInfSharpPatch = true;
    patchOptions.generateLegacySharpCornerPatches = false;
    patchOptions.generateVaryingTables = false;
    patchOptions.generateVaryingLocalPoints = false;
    refiner->RefineAdaptive(patchOptions.GetRefineAdaptiveOptions());
    impl->patches.reset(Far::PatchTableFactory::Create(*refiner, patchOptions));
    if (!impl->patches) {
        throw TopologyError(formatError(source, "", "OpenSubdiv cannot build limit patches for it"));
    }
    for (int a = 0; a < impl->patches->GetNumPatchArrays(); ++a) {
        if (impl->patches->GetPatchArrayDescriptor(a).GetNumControlVertices() > kMaxPatchPoints) {
            throw Error(formatError(source, "",
                                    "OpenSubdiv built a patch type with more control points than "
                                    "the evaluator supports"));
        }
    }

    impl->patchMap = std::make_shared<Far::PatchMap>(*impl->patches);

    // A patch corner at each cage vertex: Gregory and B-spline patches both interpolate the exact limit
    // position there.
    impl->vertexCorner.assign(rest.numVertices(), PtexLocation{-1, 0.0, 0.0});
    for (int32_t f = 0; f < rest.numFaces(); ++f) {
        if (isHole[f]) continue;
        const auto corners = rest.face(f);
        for (int32_t k = 0; k < counts[f]; ++k) {
            PtexLocation& at = impl->vertexCorner[corners[k]];
            if (at.ptexFace >= 0) continue;
            at = counts[f] == 4
                     ? PtexLocation{impl->ptexBase[f], k == 1 || k == 2 ? 1.0 : 0.0, k >= 2 ? 1.0 : 0.0}
                     : PtexLocation{impl->ptexBase[f] + k, 0.0, 0.0};
        }
    }
    impl->setControlPoints(*refiner, rest.points());
    if (options.deformable) impl->refiner = std::move(refiner);
    impl_ = std::move(impl);
}

int32_t LimitSurface::numVertices() const {
    return impl_->numVertices;
}

int32_t LimitSurface::numFaces() const {
    return static_cast<int32_t>(impl_->faceCounts.size());
}

int32_t LimitSurface::numPtexFaces() const {
    return impl_->ptexBase.back();
}

int32_t LimitSurface::firstPtexFace(int32_t face) const {
    impl_->requireFace(face);
    return impl_->ptexBase[face];
}

LimitSurface::PtexLocation LimitSurface::ptexLocation(int32_t face,
                                                      std::span<const double> cornerWeights) const {
    return impl_->ptexLocation(face, cornerWeights);
}

glm::dvec3 LimitSurface::evaluate(int32_t face, std::span<const double> cornerWeights) const {
    return impl_->evaluate(impl_->ptexLocation(face, cornerWeights), false).position;
}

LimitSample LimitSurface::evaluateWithDerivatives(int32_t face, std::span<const double> cornerWeights) const {
    return impl_->evaluate(impl_->ptexLocation(face, cornerWeights), true);
}

LimitSample LimitSurface::evaluateAt(const PtexLocation& location) const {
    if (location.ptexFace < 0 || location.ptexFace >= numPtexFaces()) {
        throw InvalidInput(formatError(impl_->source, "Ptex face " + std::to_string(location.ptexFace),
                                       "is out of range",
                                       "an index in [0, " + std::to_string(numPtexFaces()) + ")"));
    }
    const auto inside = [](double t) {
        return std::isfinite(t) && t >= -kParamTolerance && t <= 1.0 + kParamTolerance;
    };
    if (!inside(location.u) || !inside(location.v)) {
        throw InvalidInput(formatError(impl_->source, "Ptex face " + std::to_string(location.ptexFace),
                                       "(u, v) = (" + std::to_string(location.u) + ", " +
                                           std::to_string(location.v) + ") is outside the face",
                                       "u and v in [0, 1]"));
    }
    return impl_->evaluate(
        {location.ptexFace, std::clamp(location.u, 0.0, 1.0), std::clamp(location.v, 0.0, 1.0)}, true);
}

LimitSurface LimitSurface::withPoints(std::span<const glm::vec3> cage) const {
    if (!impl_->refiner) {
        throw Error(formatError(impl_->source, "limit surface", "was not built deformable",
                                "LimitSurfaceOptions::deformable for new control points"));
    }
    if (cage.size() != static_cast<size_t>(impl_->numVertices)) {
        throw InvalidInput(formatError(impl_->source, "control points",
                                       std::to_string(cage.size()) + " given",
                                       std::to_string(impl_->numVertices) + ", one per cage vertex"));
    }
    auto impl = std::make_shared<Impl>(*impl_);
    impl->setControlPoints(*impl->refiner, cage);
    LimitSurface out(*this);
    out.impl_ = std::move(impl);
    return out;
}

glm::dvec3 LimitSurface::limitPosition(int32_t vertex) const {
    if (vertex < 0 || vertex >= impl_->numVertices) {
        throw InvalidInput(formatError(impl_->source, "vertex " + std::to_string(vertex), "is out of range",
                                       "an index in [0, " + std::to_string(impl_->numVertices) + ")"));
    }
    return impl_->limitPositions[vertex];
}

}  // namespace deformkit::geom
