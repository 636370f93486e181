#include "deformkit/warp/mesh_warp.h"
#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Dense>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "deformkit/error.h"
#include "deformkit/geom/half_edge.h"
#include "deformkit/geom/weld.h"
#include "warp/point_text.h"

namespace deformkit::warp {
namespace {

void checkOptions(const MeshWarpOptions& o, const std::string& source) {
    const auto bad = [&](const char* element, const std::string& problem, const char* expected) {
        throw InvalidInput(formatError(source, element, problem, expected));
    };
    for (const auto& [name, value] : {std::pair{"alpha", o.alpha}, std::pair{"beta", o.beta},
                                      std::pair{"gamma", o.gamma}, std::pair{"mu", o.mu}}) {
        if (!std::isfinite(value)) bad(name, "is " + numberText(value), "a finite number");
    }
    if (o.alpha < 0.0f) bad("alpha", "is " + numberText(o.alpha), "alpha >= 0");
    if (!(o.alpha < o.beta)) {
        bad("alpha", "is " + numberText(o.alpha) + " with beta " + numberText(o.beta), "alpha < beta");
    }
    if (!(o.mu > 0.0f)) {
        bad("mu",
            "is " + numberText(o.mu) + ": every control vertex would weigh 0 past itself along its edges",
            "mu > 0 (1: the weight ends at each edge's far end)");
    }
    if (!(o.gamma < o.mu)) {
        bad("gamma", "is " + numberText(o.gamma) + " with mu " + numberText(o.mu), "gamma < mu");
    }
    if (!(o.rankTolerance >= 0.0 && o.rankTolerance < 1.0)) {
        bad("rankTolerance", "is " + numberText(o.rankTolerance), "a value in [0, 1)");
    }
}

// A uniform grid over the control vertices' supports (balls of radius beta |E_im|, outside which the
// radial factor and so the weight are zero). Each cell lists, ascending, every control vertex whose
// support's bounding box overlaps it, so a point looks at one cell only.
struct SupportGrid {
    glm::vec3 origin{0.0f};
    float cell = 1.0f;
    glm::ivec3 dims{0};
    std::vector<int32_t> offsets, vertices;

    [[nodiscard]] std::span<const int32_t> candidates(const glm::vec3& p) const {
        const glm::vec3 q = (p - origin) / cell;
        if (!(q.x >= 0.0f && q.y >= 0.0f && q.z >= 0.0f)) return {};
        const glm::ivec3 c(static_cast<int32_t>(q.x), static_cast<int32_t>(q.y), static_cast<int32_t>(q.z));
        if (q.x >= static_cast<float>(dims.x) || q.y >= static_cast<float>(dims.y) ||
            q.z >= static_cast<float>(dims.z)) {
            return {};
        }
        const int64_t id = (static_cast<int64_t>(c.z) * dims.y + c.y) * dims.x + c.x;
        return std::span<const int32_t>(vertices).subspan(offsets[id], offsets[id + 1] - offsets[id]);
    }
};

SupportGrid buildGrid(std::span<const glm::vec3> centres, std::span<const float> radii) {
    SupportGrid g;
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    std::vector<float> sorted(radii.begin(), radii.end());
    for (size_t i = 0; i < centres.size(); ++i) {
        lo = glm::min(lo, centres[i] - radii[i]);
        hi = glm::max(hi, centres[i] + radii[i]);
    }
    // Cell size: half the median support radius (fewer candidates per point than whole radii, ~15 r^3
    // of box per ball against ~27 r^3), grown until the grid has at most 2^22 cells.
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    float cell = 0.5f * sorted[sorted.size() / 2];
    const glm::vec3 extent = hi - lo;
    cell = std::max(cell, 1e-6f * std::max({extent.x, extent.y, extent.z, 1e-30f}));
    auto dimsFor = [&](float h) {
        return glm::ivec3(static_cast<int32_t>(std::floor(extent.x / h)) + 1,
                          static_cast<int32_t>(std::floor(extent.y / h)) + 1,
                          static_cast<int32_t>(std::floor(extent.z / h)) + 1);
    };
    while (true) {
        const glm::dvec3 d(extent / cell + 1.0f);
        if (d.x * d.y * d.z <= double(1 << 22)) break;
        cell *= 1.5f;
    }
    g.origin = lo;
    g.cell = cell;
    g.dims = dimsFor(cell);
    const int64_t numCells = static_cast<int64_t>(g.dims.x) * g.dims.y * g.dims.z;
    auto range = [&](size_t i, glm::ivec3& a, glm::ivec3& b) {
        const glm::vec3 qa = (centres[i] - radii[i] - lo) / cell, qb = (centres[i] + radii[i] - lo) / cell;
        a = glm::clamp(glm::ivec3(glm::floor(qa)), glm::ivec3(0), g.dims - 1);
        b = glm::clamp(glm::ivec3(glm::floor(qb)), glm::ivec3(0), g.dims - 1);
    };
    std::vector<int32_t> counts(static_cast<size_t>(numCells) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t i = 0; i < centres.size(); ++i) {
            glm::ivec3 a, b;
            range(i, a, b);
            for (int32_t z = a.z; z <= b.z; ++z) {
                for (int32_t y = a.y; y <= b.y; ++y) {
                    for (int32_t x = a.x; x <= b.x; ++x) {
                        const int64_t id = (static_cast<int64_t>(z) * g.dims.y + y) * g.dims.x + x;
                        if (pass == 0) {
                            ++counts[id + 1];
                        } else {
                            g.vertices[counts[id]++] = static_cast<int32_t>(i);
                        }
                    }
                }
            }
        }
        if (pass == 0) {
            for (int64_t c = 0; c < numCells; ++c)
                counts[c + 1] += counts[c];
            g.offsets = counts;
            g.vertices.resize(static_cast<size_t>(counts[numCells]));
        }
    }
    return g;
}

}  // namespace

float meshWarpFalloff(float t, float a, float b) {
    if (t <= a) return 1.0f;
    if (t >= b) return 0.0f;
    const float x = (t - a) / (b - a);
    // 1 - (3x^2 - 2x^3) factored as (1 - x)^2 (1 + 2x): no cancellation near x = 1, where the weights
    // of a point at the edge of a support are small.
    const float y = 1.0f - x;
    return y * y * (1.0f + 2.0f * x);
}

MeshWarp::MeshWarp(const geom::Mesh& fileCage, const MeshWarpOptions& options, const std::string& source)
    : options_(options), source_(source) {
    checkOptions(options_, source_);
    if (fileCage.numVertices() == 0 || fileCage.numFaces() == 0) {
        throw InvalidInput(
            formatError(source_, "cage", "has no vertices or no faces", "a control mesh with faces"));
    }
    // A cage with split vertices (UV seams, per-triangle corners) is welded: its control vertices are its
    // positions, each with its whole edge star.
    geom::Welding weld = geom::weldVertices(fileCage, options_.weldTolerance, source_ + " cage");
    cageVertices_ = fileCage.numVertices();
    const bool welded = weld.merged() > 0;
    if (welded) {
        controlOf_ = std::move(weld.weldedOf);
        firstCopy_ = std::move(weld.firstOf);
    }
    const geom::Mesh& cage = welded ? weld.mesh : fileCage;
    const int32_t n = cage.numVertices();
    geom::requireManifold(cage, source_ + " cage");
    const geom::HalfEdgeMesh& he = cage.halfEdges();
    rest_.assign(cage.points().begin(), cage.points().end());
    target_ = rest_;
    neighborOffsets_.assign(1, 0);
    longest_.resize(n);
    rank_.resize(n);
    for (int32_t i = 0; i < n; ++i) {
        const auto nb = he.vertexNeighbors(i);
        if (nb.empty()) {
            throw InvalidInput(formatError(source_, "cage vertex " + std::to_string(cageVertexOf(i)),
                                           "has no edges", "every control vertex on at least one edge"));
        }
        const int32_t k = static_cast<int32_t>(nb.size());
        Eigen::MatrixXd e(k, 3);
        float longest = 0.0f;
        for (int32_t j = 0; j < k; ++j) {
            const glm::vec3 edge = rest_[nb[j]] - rest_[i];
            const float len2 = glm::dot(edge, edge);
            if (!(len2 > 0.0f)) {
                throw InvalidInput(formatError(source_,
                                               "cage edge (" + std::to_string(cageVertexOf(i)) + ", " +
                                                   std::to_string(cageVertexOf(nb[j])) + ")",
                                               "has zero length",
                                               "distinct positions at the ends of every edge"));
            }
            neighbors_.push_back(nb[j]);
            edges_.push_back(edge);
            invLengthSq_.push_back(1.0f / len2);
            longest = std::max(longest, std::sqrt(len2));
            e.row(j) = Eigen::RowVector3d(edge.x, edge.y, edge.z);
        }
        neighborOffsets_.push_back(static_cast<int32_t>(neighbors_.size()));
        longest_[i] = longest;
        // E^+ = V S^+ U^T from a thin SVD, singular values below rankTolerance * the largest dropped: the
        // minimal-norm least-squares solution for a rank-deficient star.
        const Eigen::JacobiSVD<Eigen::MatrixXd> svd(e, Eigen::ComputeThinU | Eigen::ComputeThinV);
        const Eigen::VectorXd& sv = svd.singularValues();
        Eigen::VectorXd inv = Eigen::VectorXd::Zero(sv.size());
        int32_t rank = 0;
        for (Eigen::Index s = 0; s < sv.size(); ++s) {
            if (sv(s) > options_.rankTolerance * sv(0)) {
                inv(s) = 1.0 / sv(s);
                ++rank;
            }
        }
        rank_[i] = rank;
        const Eigen::MatrixXd pinv = svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose();  // 3 x k
        for (int32_t j = 0; j < k; ++j) {
            for (int r = 0; r < 3; ++r)
                pinv_.push_back(pinv(r, j));
        }
    }
}

void MeshWarp::setTarget(std::span<const glm::vec3> targetCagePoints) {
    if (targetCagePoints.size() != static_cast<size_t>(cageVertices_)) {
        throw InvalidInput(
            formatError(source_, "target cage", "has " + std::to_string(targetCagePoints.size()) + " points",
                        std::to_string(cageVertices_) + " points, the rest cage's vertex count"));
    }
    for (size_t i = 0; i < targetCagePoints.size(); ++i) {
        if (!geom::isFinite(targetCagePoints[i])) {
            throw InvalidInput(formatError(source_, "target cage point " + std::to_string(i),
                                           "is " + detail::pointText(targetCagePoints[i]),
                                           "finite coordinates"));
        }
    }
    if (firstCopy_.empty()) {
        target_.assign(targetCagePoints.begin(), targetCagePoints.end());
        return;
    }
    // A split vertex's copies are one control vertex: its target is their mean (exactly their position when
    // they coincide: a double sum of equal floats). Copies apart by more than the weld allows plus 1% of the
    // vertex's shortest cage edge are a torn cage, which no control vertex can follow: refused, nothing set.
    std::vector<glm::dvec3> sum(target_.size(), glm::dvec3(0.0));
    std::vector<int32_t> copies(target_.size(), 0);
    for (size_t v = 0; v < targetCagePoints.size(); ++v) {
        const auto c = static_cast<size_t>(controlOf_[v]);
        const glm::vec3 first = targetCagePoints[static_cast<size_t>(firstCopy_[c])];
        const double apart = glm::distance(glm::dvec3(targetCagePoints[v]), glm::dvec3(first));
        if (apart > 0.0) {
            float longestInv = 0.0f;
            for (int32_t e = neighborOffsets_[c]; e < neighborOffsets_[c + 1]; ++e)
                longestInv = std::max(longestInv, invLengthSq_[e]);
            const double allowed = 2.0 * options_.weldTolerance + 0.01 / std::sqrt(double(longestInv));
            if (!(apart <= allowed)) {
                throw InvalidInput(formatError(
                    source_, "target cage point " + std::to_string(v),
                    "is " + numberText(apart) + " from point " + std::to_string(firstCopy_[c]) +
                        ", a copy of the same split vertex (control vertex " + std::to_string(c) + ")",
                    "the copies of a split vertex moved together (within " + numberText(allowed) + ")"));
            }
        }
        sum[c] += glm::dvec3(targetCagePoints[v]);
        ++copies[c];
    }
    for (size_t c = 0; c < target_.size(); ++c)
        target_[c] = glm::vec3(sum[c] / static_cast<double>(copies[c]));
}

float MeshWarp::weight(int32_t i, const glm::vec3& p) const {
    const glm::vec3 d = p - rest_[i];
    const float d2 = glm::dot(d, d), reach = options_.beta * longest_[i];
    if (d2 >= reach * reach) return 0.0f;  // outside the support ball: the radial factor is 0
    float w = meshWarpFalloff(std::sqrt(d2) / longest_[i], options_.alpha, options_.beta);
    for (int32_t e = neighborOffsets_[i]; e < neighborOffsets_[i + 1] && w > 0.0f; ++e) {
        w *= meshWarpFalloff(glm::dot(d, edges_[e]) * invLengthSq_[e], options_.gamma, options_.mu);
    }
    return w;
}

void MeshWarp::bind(std::span<const glm::vec3> restPoints, SparseFields& fields) {
    const int64_t n = static_cast<int64_t>(restPoints.size());
    for (int64_t u = 0; u < n; ++u) {
        if (!geom::isFinite(restPoints[u])) {
            throw InvalidInput(formatError(source_, "rest point " + std::to_string(u),
                                           "is " + detail::pointText(restPoints[u]), "finite coordinates"));
        }
    }
    std::vector<float> radii(rest_.size());
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (size_t i = 0; i < rest_.size(); ++i) {
        radii[i] = options_.beta * longest_[i];
        lo = glm::min(lo, rest_[i] - radii[i]);
        hi = glm::max(hi, rest_[i] + radii[i]);
    }
    // The supports' bounding box must have a finite size for the grid over it (a beta near float's largest
    // value makes it infinite).
    if (!geom::isFinite(hi - lo)) {
        throw InvalidInput(formatError(source_, "beta",
                                       "is " + numberText(options_.beta) +
                                           ": the control vertices' supports (beta times "
                                           "their longest edges) span no finite box",
                                       "beta times the longest cage edge well within float range"));
    }
    const SupportGrid grid = buildGrid(rest_, radii);

    // Points in fixed blocks: each block gathers its points' entries (in candidate order) into its own
    // buffer, then the buffers are copied to the prefix-summed offsets. Each point's entries and their
    // order depend on the point alone, so the fields are identical for any thread count.
    constexpr int64_t kBlock = 8192;
    const int64_t numBlocks = (n + kBlock - 1) / kBlock;
    std::vector<std::vector<int32_t>> blockTransforms(static_cast<size_t>(numBlocks));
    std::vector<std::vector<float>> blockWeights(static_cast<size_t>(numBlocks));
    fields.offsets.assign(static_cast<size_t>(n) + 1, 0);
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t b = 0; b < numBlocks; ++b) {
        auto& ts = blockTransforms[b];
        auto& ws = blockWeights[b];
        for (int64_t u = b * kBlock; u < std::min(n, (b + 1) * kBlock); ++u) {
            int32_t count = 0;
            for (const int32_t i : grid.candidates(restPoints[u])) {
                const float w = weight(i, restPoints[u]);
                if (w > 0.0f) {
                    ts.push_back(i);
                    ws.push_back(w);
                    ++count;
                }
            }
            fields.offsets[u + 1] = count;
        }
    }
    for (int64_t u = 0; u < n; ++u)
        fields.offsets[u + 1] += fields.offsets[u];
    const size_t entries = static_cast<size_t>(fields.offsets[n]);
    fields.transform.resize(entries);
    fields.strength.assign(entries, 1.0f);  // s_i = 1 (§6): a rigid cage motion moves the surface rigidly
    fields.weight.resize(entries);
#pragma omp parallel for schedule(static)
    for (int64_t b = 0; b < numBlocks; ++b) {
        const size_t at = static_cast<size_t>(fields.offsets[b * kBlock]);
        std::copy(blockTransforms[b].begin(), blockTransforms[b].end(), fields.transform.begin() + at);
        std::copy(blockWeights[b].begin(), blockWeights[b].end(), fields.weight.begin() + at);
    }
}

glm::mat3 MeshWarp::linearMap(int32_t i) const {
    // L^T = I + E^+ (E* - E)  =>  column c of L = e_c + sum_j E^+(c, j) (E*_ij - E_ij).
    glm::dmat3 l(1.0);
    for (int32_t e = neighborOffsets_[i]; e < neighborOffsets_[i + 1]; ++e) {
        const glm::dvec3 d = glm::dvec3(target_[neighbors_[e]] - target_[i]) - glm::dvec3(edges_[e]);
        const double* p = &pinv_[3 * static_cast<size_t>(e)];
        for (int c = 0; c < 3; ++c)
            l[c] += p[c] * d;
    }
    return glm::mat3(l);
}

void MeshWarp::transformations(Transformations& out) const {
    out.method = ScaleMethod::Displacement;
    out.affine.resize(rest_.size());
    for (size_t i = 0; i < rest_.size(); ++i) {
        const glm::mat3 l = linearMap(static_cast<int32_t>(i));
        // T_i = A o X: P -> P*_i + L (P - P_i), i.e. the translation P*_i - L P_i after L.
        out.affine[i] = Affine{l, target_[i] - l * rest_[i]};
    }
}

void meshWarp(std::span<glm::vec3> points, const geom::Mesh& cage,
              std::span<const glm::vec3> targetCagePoints, const MeshWarpOptions& options,
              std::span<const float> weights, float envelope) {
    MeshWarp warp(cage, options);
    warp.setTarget(targetCagePoints);
    WarpDeformer deformer(warp, "mesh warp");
    deformer.bind(points);
    deformer.evaluate(points, weights, envelope);
}

}  // namespace deformkit::warp
