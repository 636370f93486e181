#include "deformkit/warp/ffd_frames.h"

#include <cmath>
#include <optional>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "deformkit/error.h"

namespace deformkit::warp {
namespace {

bool finite(const Frame& f) {
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(f.origin[a])) return false;
        for (int b = 0; b < 3; ++b) {
            if (!std::isfinite(f.basis[a][b])) return false;
        }
    }
    return true;
}

std::string controlName(const Lattice& l, size_t c) {
    const int32_t ny = l.divisions.y + 1, nz = l.divisions.z + 1, ci = static_cast<int32_t>(c);
    return "control " + std::to_string(c) + " (i=" + std::to_string(ci / (ny * nz)) +
           ", j=" + std::to_string(ci / nz % ny) + ", k=" + std::to_string(ci % nz) + ")";
}

}  // namespace

namespace {

constexpr double kMaxFrameScale = 1e18, kMaxFrameTranslation = 1e30;

double largestEntry(const glm::dmat3& m) {
    double largest = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            largest = std::max(largest, std::abs(m[c][r]));
    return largest;
}

// A source basis without three linearly independent vectors (relative to their lengths).
bool singular(const Frame& from) {
    const glm::dmat3 b(from.basis);
    double lengths = 1.0;
    for (int a = 0; a < 3; ++a)
        lengths *= glm::length(b[a]);
    return !(std::abs(glm::determinant(b)) > 1e-9 * lengths) || lengths == 0.0;
}

// The affine map taking `from` to `to`, or nothing for a non-finite frame, a singular source basis or a map
// beyond kMaxFrameScale (the cases frameToFrame names): the checks without the message, so an update builds
// no control names.
std::optional<Affine> mapBetween(const Frame& from, const Frame& to) {
    if (!finite(from) || !finite(to) || singular(from)) return std::nullopt;
    const glm::dmat3 linear = glm::dmat3(to.basis) * glm::inverse(glm::dmat3(from.basis));
    const glm::dvec3 translation = glm::dvec3(to.origin) - linear * glm::dvec3(from.origin);
    // A map that scales by more than kMaxFrameScale (a source basis 1e-38 long: finite, yet a point a unit
    // away goes to 1e38 and an extrapolated one to inf) is refused: no rig's frames are that far apart.
    if (largestEntry(linear) > kMaxFrameScale) return std::nullopt;
    for (int r = 0; r < 3; ++r)
        if (!(std::abs(translation[r]) <= kMaxFrameTranslation)) return std::nullopt;
    return Affine{glm::mat3(linear), glm::vec3(translation)};
}

}  // namespace

Affine frameToFrame(const Frame& from, const Frame& to, const std::string& element) {
    if (const std::optional<Affine> t = mapBetween(from, to)) return *t;
    if (!finite(from) || !finite(to)) {
        throw InvalidInput(
            formatError("FFD frames", element, "is not finite", "finite origins and basis vectors"));
    }
    if (singular(from)) {
        throw InvalidInput(formatError("FFD frames", element, "has a singular source basis",
                                       "three linearly independent basis vectors"));
    }
    throw InvalidInput(formatError(
        "FFD frames", element, "maps onto its target frame with a scale beyond 1e18 or a shift beyond 1e30",
        "a source basis at least 1e-18 of the target's size"));
}

FfdFrames::FfdFrames(const Lattice& lattice, const FfdOptions& options) : LatticeWarp(lattice, options) {
    const std::vector<glm::vec3> points = lattice.controlPoints();
    source_.resize(points.size());
    for (size_t c = 0; c < points.size(); ++c)
        source_[c].origin = points[c];
    target_ = source_;
    transform_.resize(points.size());
    delta_.resize(points.size() * 12);
    update();
}

void FfdFrames::checkCount(std::span<const Frame> frames, const char* what) const {
    if (frames.size() != source_.size()) {
        const glm::ivec3 d = lattice_.lattice().divisions;
        throw InvalidInput(formatError("FFD frames", what, "has " + std::to_string(frames.size()) + " frames",
                                       "(l+1)(m+1)(n+1) = " + std::to_string(source_.size()) +
                                           " frames for divisions (" + std::to_string(d.x) + ", " +
                                           std::to_string(d.y) + ", " + std::to_string(d.z) + ")"));
    }
}

void FfdFrames::setSourceFrames(std::span<const Frame> frames) {
    checkCount(frames, "source frames");
    // Validate all before changing anything.
    for (size_t c = 0; c < frames.size(); ++c) {
        (void)frameToFrame(frames[c], target_[c], "source frame of " + controlName(lattice_.lattice(), c));
    }
    source_.assign(frames.begin(), frames.end());
    update();
}

void FfdFrames::setTargetFrames(std::span<const Frame> frames) {
    checkCount(frames, "target frames");
    for (size_t c = 0; c < frames.size(); ++c) {
        if (!finite(frames[c])) {
            throw InvalidInput(formatError("FFD frames",
                                           "target frame of " + controlName(lattice_.lattice(), c),
                                           "is not finite", "finite origins and basis vectors"));
        }
    }
    // Every control's map checked before changing anything (as update() computes it): a refused set leaves
    // the last targets in place.
    for (size_t c = 0; c < frames.size(); ++c) {
        if (!mapBetween(source_[c], frames[c]))
            (void)frameToFrame(source_[c], frames[c], controlName(lattice_.lattice(), c));
    }
    target_.assign(frames.begin(), frames.end());
    update();
}

void FfdFrames::update() {
    for (size_t c = 0; c < source_.size(); ++c) {
        // The control's name is made only for the error: an update allocates nothing.
        const std::optional<Affine> mapped = mapBetween(source_[c], target_[c]);
        const Affine t =
            mapped ? *mapped : frameToFrame(source_[c], target_[c], controlName(lattice_.lattice(), c));
        transform_[c] = t;
        float* d = &delta_[c * 12];
        for (int col = 0; col < 3; ++col) {
            for (int row = 0; row < 3; ++row)
                d[col * 3 + row] = t.linear[col][row] - (col == row ? 1.0f : 0.0f);
        }
        d[9] = t.translation.x;
        d[10] = t.translation.y;
        d[11] = t.translation.z;
    }
}

void FfdFrames::transformations(Transformations& out) const {
    out.method =
        ScaleMethod::Displacement;  // strength 1 everywhere; the weighted sum is of displacements (§3.3)
    out.components.clear();
    out.affine.assign(transform_.begin(), transform_.end());
}

void FfdFrames::evaluate(std::span<const glm::vec3> in, std::span<glm::vec3> out,
                         std::span<const float> weights, float envelope) const {
    lattice_.deform(in, out, delta_, 12, weights, envelope);
}

}  // namespace deformkit::warp
