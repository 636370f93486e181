#include "deformkit/io/animated_positions.h"

#include <algorithm>
#include <cmath>
#include <system_error>

#include "deformkit/error.h"

namespace deformkit::io {
namespace fs = std::filesystem;

namespace {

// The RMS distance of `points` from their centroid.
double spread(std::span<const glm::vec3> points) {
    if (points.empty()) return 0.0;
    double cx = 0.0, cy = 0.0, cz = 0.0;
    for (const glm::vec3& p : points) {
        cx += p.x;
        cy += p.y;
        cz += p.z;
    }
    const double n = static_cast<double>(points.size());
    cx /= n;
    cy /= n;
    cz /= n;
    double sum = 0.0;
    for (const glm::vec3& p : points) {
        const double dx = p.x - cx, dy = p.y - cy, dz = p.z - cz;
        sum += dx * dx + dy * dy + dz * dz;
    }
    return std::sqrt(sum / n);
}

double distance(const glm::vec3& a, const glm::vec3& b) {
    const double dx = static_cast<double>(b.x) - a.x, dy = static_cast<double>(b.y) - a.y,
                 dz = static_cast<double>(b.z) - a.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace

VertexOrderCheck::VertexOrderCheck(const geom::Mesh& rest) {
    const std::span<const glm::vec3> points = rest.points();
    const std::span<const int32_t> offsets = rest.faceOffsets(), indices = rest.faceIndices();
    const auto corners = static_cast<int64_t>(indices.size());
    const int64_t sampled = std::min<int64_t>(kSampledEdges, corners);
    for (int64_t k = 0; k < sampled; ++k) {
        // Corner c and the next one around its face.
        const int64_t c = k * corners / sampled;
        const auto face = std::upper_bound(offsets.begin(), offsets.end(), c) - offsets.begin() - 1;
        const int64_t next = c + 1 < offsets[face + 1] ? c + 1 : offsets[face];
        const int32_t a = indices[c], b = indices[next];
        const double length = distance(points[a], points[b]);
        if (!(length > 0.0) || !std::isfinite(length)) continue;
        edges_.emplace_back(a, b);
        restLength_.push_back(length);
    }
    restSpread_ = spread(points);
    vertices_ = points.size();
}

std::optional<VertexOrderCheck::Tear> VertexOrderCheck::tear(std::span<const glm::vec3> points) const {
    if (points.size() != vertices_) {
        throw InvalidInput(formatError("vertex order check", "frame",
                                       "has " + std::to_string(points.size()) + " points",
                                       std::to_string(vertices_) + ", the rest mesh's vertex count"));
    }
    const auto edges = static_cast<int32_t>(edges_.size());
    if (edges < kFewestEdges || !(restSpread_ > 0.0)) return std::nullopt;
    const double grown = spread(points);
    if (!(grown > 0.0) || !std::isfinite(grown)) return std::nullopt;
    Tear out;
    out.edges = edges;
    out.scale = grown / restSpread_;
    for (int32_t e = 0; e < edges; ++e) {
        const auto [a, b] = edges_[e];
        if (distance(points[a], points[b]) > kStretch * out.scale * restLength_[e]) ++out.torn;
    }
    if (4 * static_cast<int64_t>(out.torn) <= edges) return std::nullopt;
    return out;
}

bool AnimatedPositions::accepts(const fs::path& path) {
    return pointCacheFormat(path).has_value() || ObjSequence::isPattern(path.string());
}

AnimatedPositions::AnimatedPositions(fs::path path, const std::string& name,
                                     std::optional<double> cacheFirstFrame)
    : path_(std::move(path)) {
    if (pointCacheFormat(path_)) {
        cache_ = std::make_unique<PointCache>(path_, cacheFirstFrame);
        return;
    }
    if (!ObjSequence::isPattern(path_.string())) {
        throw InvalidInput(
            formatError(name, path_.string(), "has no frame token and is no point cache", kForms));
    }
    if (cacheFirstFrame) {
        throw InvalidInput(
            formatError(name, path_.string(),
                        "is an OBJ sequence, given a cache's first frame " + numberText(*cacheFirstFrame),
                        "a first frame for a point cache only (an OBJ sequence's files carry "
                        "their frames)"));
    }
    sequence_ = std::make_unique<ObjSequence>(path_);
}

void AnimatedPositions::setReference(const geom::Mesh& rest, const std::string& restName) {
    if (sequence_) {
        sequence_->setReference(rest, restName);
        return;
    }
    if (cache_->vertexCount() != rest.numVertices()) {
        throw InvalidInput(formatError(
            path_.string(), "header", "has " + std::to_string(cache_->vertexCount()) + " vertices per frame",
            std::to_string(rest.numVertices()) + " vertices, as the rest mesh '" + restName + "'"));
    }
    order_.emplace(rest);
    restName_ = restName;
}

void AnimatedPositions::requireFrames(std::span<const int> frames) const {
    for (const int frame : frames) {
        if (cache_) {
            if (!cache_->sampleOf(frame)) {
                throw InvalidInput(formatError(path_.string(), "frame " + std::to_string(frame),
                                               "is not in the cache", "one of its " + cache_->rangeText()));
            }
            continue;
        }
        const fs::path file = sequence_->framePath(frame);
        std::error_code ec;
        if (!fs::is_regular_file(file, ec)) {
            throw IoError(formatError(file.string(), "frame " + std::to_string(frame), "is missing",
                                      "a file for every frame of '" + path_.string() + "'"));
        }
    }
}

std::string AnimatedPositions::frameName(int frame) const {
    return cache_ ? cache_->frameName(frame) : sequence_->framePath(frame).string();
}

void AnimatedPositions::read(int frame, std::vector<glm::vec3>& points) {
    if (cache_) {
        cache_->read(frame, points);
        if (!order_) return;
        if (const std::optional<VertexOrderCheck::Tear> tear = order_->tear(points)) {
            const auto percent = static_cast<int>(std::lround(100.0 * tear->torn / tear->edges));
            throw InvalidInput(formatError(
                path_.string(), "frame " + std::to_string(frame),
                "stretches " + std::to_string(percent) + "% of " + std::to_string(tear->edges) +
                    " edges of the rest mesh '" + restName_ + "' beyond " +
                    numberText(VertexOrderCheck::kStretch) +
                    " times their rest length (the mesh as a whole " + "scaled by " +
                    numberText(std::round(tear->scale * 1000.0) / 1000.0) +
                    "): its vertices are not in the rest mesh's order",
                "the rest mesh's vertex order; an FBX or Collada rest mesh is welded and renumbered on "
                "reading, so give the rest mesh as the OBJ or glTF exported with the cache"));
        }
        return;
    }
    const ObjContent content = sequence_->read(frame);
    const auto p = content.mesh.points();
    points.assign(p.begin(), p.end());
}

}  // namespace deformkit::io
