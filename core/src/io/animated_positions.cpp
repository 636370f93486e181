#include "deformkit/io/animated_positions.h"

#include <system_error>

#include "deformkit/error.h"

namespace deformkit::io {
namespace fs = std::filesystem;

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
        return;
    }
    const ObjContent content = sequence_->read(frame);
    const auto p = content.mesh.points();
    points.assign(p.begin(), p.end());
}

}  // namespace deformkit::io
