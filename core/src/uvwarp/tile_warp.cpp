#include "deformkit/uvwarp/tile_warp.h"

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/uvwarp/geometry_image.h"
#include "deformkit/uvwarp/inversion.h"
#include "deformkit/uvwarp/mask.h"
#include "deformkit/uvwarp/options.h"
#include "deformkit/uvwarp/redirect_metrics.h"
#include "memory/large_buffers.h"

namespace deformkit::uvwarp {

namespace {

void requireSquare(const io::Image& map, const std::string& source, int tile, const char* what) {
    if (map.width <= 0 || map.width != map.height || map.channels < 1) {
        throw InvalidInput(formatError(source, std::string(what) + ", UDIM tile " + std::to_string(tile),
                                       std::to_string(map.width) + " x " + std::to_string(map.height) +
                                           " x " + std::to_string(map.channels),
                                       "a square map with at least one channel"));
    }
}

}  // namespace

struct TileWarp::Impl {
    std::string source;
    int tile = 0;
    int32_t texels = 0;
    int32_t cells = 0;
    std::unique_ptr<GeometryImager> imager;
    PointField deformed, rigidity, mask;  // f_O lives in the solver
    PointField boundMask;                 // the constructor's mask (given or derived): setMaps' default
    int32_t densityRadius = 0;            // TileWarpOptions::orientationDensity
    std::unique_ptr<Solver> solver;
    bool solved = false;
    std::optional<RedirectMetrics> delivered;  // the figures of the redirect map a renderer reads
    std::vector<glm::vec3> lastDeformed;       // the last solve's positions (the rest ones before any)
};

TileWarp::TileWarp(const geom::Mesh& rest, int tile, const io::Image& rigidity, const io::Image& mask,
                   const TileWarpOptions& options, const io::Image& orientation, const std::string& source)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.source = source;
    m.tile = tile;
    checkOptions(options, source);
    requireSquare(rigidity, source, tile, "rigidity map");
    m.texels = rigidity.width;
    const bool derive = mask.pixels.empty();
    if (!derive) {
        requireSquare(mask, source, tile, "warp mask");
        if (mask.width != m.texels) {
            throw InvalidInput(formatError(source, "warp mask, UDIM tile " + std::to_string(tile),
                                           std::to_string(mask.width) + " texels per side",
                                           std::to_string(m.texels) + ", the rigidity map's size"));
        }
    }
    if (!orientation.pixels.empty()) requireSquare(orientation, source, tile, "orientation map");
    m.cells = options.cells == 0 ? m.texels : options.cells;
    if (!isPowerOfTwo(m.cells) || m.cells < 2) {
        throw InvalidInput(formatError(source, "grid resolution, UDIM tile " + std::to_string(tile),
                                       std::to_string(m.cells) + " cells per side" +
                                           (options.cells == 0 ? " (the rigidity map's size)" : ""),
                                       "a power of two, at least 2"));
    }

    GeometryImageOptions imageOptions;
    imageOptions.dilationRings = options.dilationRings;
    imageOptions.label = source;
    m.imager = std::make_unique<GeometryImager>(rest, tile, m.cells, imageOptions);
    PointField restImage;
    m.imager->sample(rest.points(), restImage);

    const MapLabel rigidityLabel{source + " rigidity map", tile};
    m.rigidity = rigidityAtPoints(rigidity, m.cells, rigidityLabel);
    if (derive) {
        DerivedMaskOptions maskOptions = options.derivedMask;
        maskOptions.label = source;
        m.mask = maskAtPoints(deriveWarpMask(rest, tile, m.texels, maskOptions), m.cells,
                              {source + " derived mask", tile});
    } else {
        m.mask = maskAtPoints(mask, m.cells, {source + " warp mask", tile});
    }
    m.densityRadius = options.orientationDensity;
    PointField orientationAtPoints;
    if (!orientation.pixels.empty()) {
        orientationAtPoints = rigidityAtPoints(orientation, m.cells, {source + " orientation map", tile});
    } else if (m.densityRadius > 0) {
        orientationAtPoints = rigidityAtPoints(densityOrientationMap(rigidity, m.densityRadius), m.cells,
                                               {source + " density orientation", tile});
    }
    m.boundMask.cells = m.mask.cells;
    m.boundMask.channels = m.mask.channels;
    deformkit::detail::copyLarge(m.boundMask.values, m.mask.values);
    m.solver = std::make_unique<Solver>(std::move(restImage), m.rigidity, m.mask, options.solver,
                                        orientationAtPoints, source + ", UDIM tile " + std::to_string(tile));
    m.delivered.emplace(rest, tile, rigidity, source);
    m.lastDeformed.assign(rest.points().begin(), rest.points().end());
}

TileWarp::~TileWarp() = default;
TileWarp::TileWarp(TileWarp&&) noexcept = default;
TileWarp& TileWarp::operator=(TileWarp&&) noexcept = default;

const WarpGrid& TileWarp::solve(std::span<const glm::vec3> deformedPoints) {
    Impl& m = *impl_;
    m.imager->sample(deformedPoints, m.deformed);
    m.lastDeformed.assign(deformedPoints.begin(), deformedPoints.end());
    m.solved = true;
    return m.solver->solve(m.deformed);
}

FoldRepair TileWarp::redirect(io::Image& out) const {
    const Impl& m = *impl_;
    invertWarp(m.solver->warp(), m.texels, out);
    return repairFolds(
        out, [&m](int32_t x, int32_t y, glm::dvec2 r) { return m.delivered->mayShow(x, y, r); },
        [&m](const io::Image& map, int32_t y, std::vector<int32_t>& refused) {
            m.delivered->refusedInRow(map, y, refused);
        });
}

io::Image TileWarp::redirect() const {
    io::Image out;
    redirect(out);
    return out;
}

DeliveredMetrics TileWarp::measure(const io::Image& redirect) const {
    return impl_->delivered->measure(impl_->lastDeformed, redirect);
}

DeliveredMetrics TileWarp::deliveredMetrics(FoldRepair* repair) const {
    io::Image map;
    const FoldRepair done = redirect(map);
    if (repair) *repair = done;
    return measure(map);
}

WarpMetrics TileWarp::metrics() const {
    const Impl& m = *impl_;
    MetricsOptions options;
    options.texels = m.texels;
    const PointField& rest = m.solver->restGeometry();
    return measureWarp(m.solver->warp(), rest, m.solved ? m.deformed : rest, m.rigidity, m.mask, options);
}

void TileWarp::reset() {
    impl_->solver->reset();
}

void TileWarp::setMaps(const io::Image& rigidity, const io::Image& mask, const io::Image& orientation) {
    Impl& m = *impl_;
    const auto sameSize = [&](const io::Image& map, const char* what) {
        requireSquare(map, m.source, m.tile, what);
        if (map.width != m.texels) {
            throw InvalidInput(
                formatError(m.source, std::string(what) + ", UDIM tile " + std::to_string(m.tile),
                            std::to_string(map.width) + " texels per side",
                            std::to_string(m.texels) + ", the size of the bound rigidity map"));
        }
    };
    sameSize(rigidity, "rigidity map");
    if (!mask.pixels.empty()) sameSize(mask, "warp mask");
    if (!orientation.pixels.empty()) sameSize(orientation, "orientation map");
    PointField newRigidity = rigidityAtPoints(rigidity, m.cells, {m.source + " rigidity map", m.tile});
    PointField newMask =
        mask.pixels.empty() ? m.boundMask : maskAtPoints(mask, m.cells, {m.source + " warp mask", m.tile});
    PointField orientationAtPoints;
    if (!orientation.pixels.empty()) {
        orientationAtPoints = rigidityAtPoints(orientation, m.cells, {m.source + " orientation map", m.tile});
    } else if (m.densityRadius > 0) {
        orientationAtPoints = rigidityAtPoints(densityOrientationMap(rigidity, m.densityRadius), m.cells,
                                               {m.source + " density orientation", m.tile});
    }
    m.solver->setMaps(newRigidity, newMask, orientationAtPoints);
    m.rigidity = std::move(newRigidity);
    m.delivered->setRigidity(rigidity);
    m.mask = std::move(newMask);
}

int TileWarp::tile() const {
    return impl_->tile;
}
int32_t TileWarp::texels() const {
    return impl_->texels;
}
int32_t TileWarp::cells() const {
    return impl_->cells;
}
const WarpGrid& TileWarp::warp() const {
    return impl_->solver->warp();
}
const SolveStats& TileWarp::stats() const {
    return impl_->solver->stats();
}
const PointField& TileWarp::rigidityAtGridPoints() const {
    return impl_->rigidity;
}
const PointField& TileWarp::maskAtGridPoints() const {
    return impl_->mask;
}

}  // namespace deformkit::uvwarp
