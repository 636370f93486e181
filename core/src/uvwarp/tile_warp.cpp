#include "deformkit/uvwarp/tile_warp.h"

#include <cstdint>
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
#include "seam_slide.h"
#include "tile_uvs.h"

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

// A mask at grid points (0 or 1, maskAtPoints) as one byte a point, and back.
std::vector<uint8_t> maskBytes(const PointField& mask) {
    std::vector<uint8_t> bytes;
    deformkit::detail::assignLarge(bytes, mask.values.size(), uint8_t{0});
    const auto count = static_cast<int64_t>(bytes.size());
#pragma omp parallel for schedule(static)
    for (int64_t k = 0; k < count; ++k)
        bytes[k] = mask.values[k] >= 0.5f ? 1 : 0;
    return bytes;
}

PointField maskField(const std::vector<uint8_t>& bytes, int32_t cells) {
    PointField mask;
    mask.cells = cells;
    mask.channels = 1;
    deformkit::detail::assignLarge(mask.values, bytes.size(), 0.0f);
    const auto count = static_cast<int64_t>(bytes.size());
#pragma omp parallel for schedule(static)
    for (int64_t k = 0; k < count; ++k)
        mask.values[k] = bytes[k];
    return mask;
}

// The refining grid's mask (TileWarpOptions::refinementSweeps): a point the map fixes (`fine`, the map at the
// refining grid's points) stays only where every point of the solved grid (`coarse`) its start is made from
// (Solver::startFrom: itself, or the two ends of an edge or of a cell's diagonal) is fixed too: there the
// start is the identity, as a fixed point must be. Elsewhere the solved grid has moved that start, and the
// refinement moves it on.
PointField refinedMask(PointField fine, const PointField& coarse) {
    const int32_t side = fine.side(), coarseSide = coarse.side();
    const auto fixed = [&](int32_t i, int32_t j) {
        return coarse.values[static_cast<size_t>(j) * coarseSide + i] < 0.5f;
    };
#pragma omp parallel for schedule(static)
    for (int32_t j = 0; j < side; ++j)
        for (int32_t i = 0; i < side; ++i) {
            float& value = fine.values[static_cast<size_t>(j) * side + i];
            if (value < 0.5f && !(fixed(i / 2, j / 2) && fixed((i + 1) / 2, (j + 1) / 2))) value = 1.0f;
        }
    return fine;
}

// The finest refining grid that keeps its f_D and solve state between solves (Impl::refinementKept): the
// shot preset's, twice kAutomaticRefinementCells.
constexpr int32_t kKeptRefinementCells = 2 * kAutomaticRefinementCells;

}  // namespace

struct TileWarp::Impl {
    std::string source;
    int tile = 0;
    int32_t texels = 0;
    int32_t cells = 0;
    std::unique_ptr<GeometryImager> imager;
    // f_D of the last solve (f_O lives in the solver; the rigidity map, in `delivered`). Kept between solves
    // only when they warm-start (SolverOptions::warmStart): otherwise the redirect map and the figures made
    // after a solve, which read the deformed mesh itself, do not pay for it.
    PointField deformed;
    bool keepDeformed = true;
    // The warp mask at grid points (maskAtPoints: 0 or 1), a byte a point: boundMask the constructor's
    // (given or derived), setMaps' default; mask the one setMaps was last given, empty when it is boundMask.
    std::vector<uint8_t> mask, boundMask;
    int32_t densityRadius = 0;  // the density heuristic's window, texels (orientationDensityFor); 0: none
    std::unique_ptr<Solver> solver;
    // TileWarpOptions::refinementSweeps: the grid of twice the cells the last iteration runs on, its imager,
    // f_D and masks (as above), and the figures of a solve through both grids. A refining grid of at most
    // kKeptRefinementCells (the shot preset's, on grids up to 1024 cells) keeps its f_D (at most 50 MB) and
    // its solver's state (Solver::keepSolveState, 34 MB) between solves: above glibc's mmap threshold,
    // freed, they would go back to the system and be faulted in again by every frame (about 12% of a refined
    // 1024² frame). A finer one, asked for explicitly, frees them after each solve as the solve does.
    int32_t refinedCells = 0;
    std::unique_ptr<GeometryImager> refinedImager;
    std::unique_ptr<Solver> refiner;
    PointField refinedDeformed;
    std::vector<uint8_t> refinedMask, refinedBoundMask;
    [[nodiscard]] bool refinementKept() const { return refinedCells <= kKeptRefinementCells; }
    // TileWarpOptions::seamSlide with a derived mask and seams in the tile: where the solved grid's points
    // next to seams are placed each frame (the refining grid's fixed points follow the solved warp).
    std::unique_ptr<detail::SeamSlide> slide;
    int slideGrid = -1;
    SolveStats stats;
    bool solved = false;
    std::optional<RedirectMetrics> delivered;  // the figures of the redirect map a renderer reads
    std::vector<glm::vec3> lastDeformed;       // the last solve's positions (the rest ones before any)

    // The density heuristic's orientation-preservation map (TileWarpOptions::orientationDensity) where no
    // map is painted and the heuristic is on; else empty.
    [[nodiscard]] io::Image densityMap(const io::Image& orientation, const io::Image& rigidity) const {
        if (!orientation.pixels.empty() || densityRadius <= 0) return {};
        return densityOrientationMap(rigidity, densityRadius);
    }
    // The orientation-preservation map at the points of a grid of `n` cells: the painted one, else the
    // density heuristic's (densityMap), else none (1 everywhere).
    [[nodiscard]] PointField orientationAt(const io::Image& orientation, const io::Image& density,
                                           int32_t n) const {
        if (!orientation.pixels.empty())
            return rigidityAtPoints(orientation, n, {source + " orientation map", tile});
        if (!density.pixels.empty())
            return rigidityAtPoints(density, n, {source + " density orientation", tile});
        return {};
    }

    // The solver whose warp is delivered, its grid's cells and its imager.
    [[nodiscard]] const Solver& delivering() const { return refiner ? *refiner : *solver; }
    [[nodiscard]] int32_t deliveredCells() const { return refiner ? refinedCells : cells; }
    [[nodiscard]] const GeometryImager& deliveredImager() const { return refiner ? *refinedImager : *imager; }
    [[nodiscard]] const std::vector<uint8_t>& deliveredMask() const {
        if (refiner) return refinedMask.empty() ? refinedBoundMask : refinedMask;
        return mask.empty() ? boundMask : mask;
    }
};

namespace {

// The refining solver's options: one warm iteration of `sweeps` sweeps on its finest level alone, the rest
// as the main solver's.
SolverOptions refinementOptions(SolverOptions options, int32_t sweeps) {
    options.iterations = 1;
    options.coldIterations = 1;
    options.tolerance = 0.0f;
    options.sweepsPerLevel = {sweeps};
    options.levels = 1;
    options.maxLevels = 0;
    return options;  // warmStart as the solve's: each solve starts from the solved warp (startFrom)
}

}  // namespace

TileWarp::TileWarp(Bind, const geom::Mesh& rest, int tile, io::Image rigidity, const io::Image& mask,
                   const TileWarpOptions& options, const io::Image& orientation, const std::string& source)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.source = source;
    m.tile = tile;
    checkOptions(options, source);
    requireSquare(rigidity, source, tile, "rigidity map");
    m.texels = rigidity.width;
    const auto rigiditySized = [&](const io::Image& map, const char* what) {
        requireSquare(map, source, tile, what);
        if (map.width != m.texels) {
            throw InvalidInput(formatError(source, std::string(what) + ", UDIM tile " + std::to_string(tile),
                                           std::to_string(map.width) + " texels per side",
                                           std::to_string(m.texels) + ", the rigidity map's size"));
        }
    };
    const bool derive = mask.pixels.empty();
    if (!derive) rigiditySized(mask, "warp mask");
    if (!orientation.pixels.empty()) rigiditySized(orientation, "orientation map");
    m.cells = options.cells == 0 ? m.texels : options.cells;
    if (!isPowerOfTwo(m.cells) || m.cells < 2) {
        throw InvalidInput(formatError(source, "grid resolution, UDIM tile " + std::to_string(tile),
                                       std::to_string(m.cells) + " cells per side" +
                                           (options.cells == 0 ? " (the rigidity map's size)" : ""),
                                       "a power of two, at least 2"));
    }
    const int32_t refinementSweeps = refinementSweepsFor(options.refinementSweeps, m.cells);
    if (refinementSweeps > 0 && m.cells > kMaxGridCells / 2) {
        throw InvalidInput(formatError(
            source, "grid resolution, UDIM tile " + std::to_string(tile),
            std::to_string(m.cells) + " cells per side with refinement sweeps",
            "at most " + std::to_string(kMaxGridCells / 2) + " (the refinement's grid has twice the cells)"));
    }

    const int32_t imageCells = geometryImageCellsFor(options.geometryImageCells, m.cells);
    if (imageCells != m.cells && (imageCells * 2 != m.cells || imageCells < 2)) {
        throw InvalidInput(
            formatError(source, "UDIM tile " + std::to_string(tile) + ": option geometryImageCells",
                        "is " + std::to_string(imageCells),
                        "0 (automatic), " + std::to_string(m.cells) + " (the grid's cells) or " +
                            std::to_string(m.cells / 2) + " (half of them)"));
    }

    // The tile's UV triangles, collected once for the imager, the derived mask and the delivered figures.
    detail::TileUVs uvs = detail::collectTileUVs(rest, tile, source);
    GeometryImageOptions imageOptions;
    imageOptions.dilationRings = options.dilationRings;
    imageOptions.label = source;
    m.imager = std::make_unique<GeometryImager>(rest, uvs, imageCells, imageOptions);
    PointField restImage;
    m.imager->sample(rest.points(), restImage);

    const MapLabel rigidityLabel{source + " rigidity map", tile};
    PointField rigidityAtGrid = rigidityAtPoints(rigidity, m.cells, rigidityLabel);
    io::Image derivedMask;
    if (derive) {
        DerivedMaskOptions maskOptions = options.derivedMask;
        maskOptions.label = source;
        derivedMask = deriveWarpMask(uvs, m.texels, maskOptions);
    }
    const io::Image& maskMap = derive ? derivedMask : mask;
    const MapLabel maskLabel{source + (derive ? " derived mask" : " warp mask"), tile};
    const PointField maskAtGrid = maskAtPoints(maskMap, m.cells, maskLabel);
    m.densityRadius = orientationDensityFor(options.orientationDensity, m.texels, m.cells);
    io::Image density = m.densityMap(orientation, rigidity);
    PointField orientationAtPoints = m.orientationAt(orientation, density, m.cells);
    if (refinementSweeps > 0) {
        m.refinedCells = 2 * m.cells;
        m.refinedImager = std::make_unique<GeometryImager>(rest, uvs, m.refinedCells, imageOptions);
        PointField refinedRest;
        m.refinedImager->sample(rest.points(), refinedRest);
        const PointField refined = refinedMask(maskAtPoints(maskMap, m.refinedCells, maskLabel), maskAtGrid);
        m.refiner = std::make_unique<Solver>(std::move(refinedRest),
                                             rigidityAtPoints(rigidity, m.refinedCells, rigidityLabel),
                                             refined, refinementOptions(options.solver, refinementSweeps),
                                             m.orientationAt(orientation, density, m.refinedCells),
                                             source + ", UDIM tile " + std::to_string(tile) + ", refinement");
        m.refiner->keepSolveState(m.refinementKept());
        m.refinedBoundMask = maskBytes(refined);
    }
    derivedMask = {};
    density = {};
    SolverOptions solverOptions = options.solver;
    if (refinementSweeps > 0 && solverOptions.sweepsPerLevel.empty())
        solverOptions.sweepsPerLevel = defaultSweeps(m.cells, true);  // a refinement follows each solve
    m.solver = std::make_unique<Solver>(std::move(restImage), std::move(rigidityAtGrid), maskAtGrid,
                                        solverOptions, std::move(orientationAtPoints),
                                        source + ", UDIM tile " + std::to_string(tile));
    m.boundMask = maskBytes(maskAtGrid);
    if (options.seamSlide && derive) {
        m.slide = std::make_unique<detail::SeamSlide>(rest, uvs, rigidity);
        if (m.slide->chains() > 0)
            m.slideGrid = m.slide->addGrid(m.cells);
        else
            m.slide.reset();
    }
    m.keepDeformed = options.solver.warmStart;
    m.delivered.emplace(rest, std::move(uvs), std::move(rigidity), source);
    m.lastDeformed.assign(rest.points().begin(), rest.points().end());
}

TileWarp::TileWarp(const geom::Mesh& rest, int tile, io::Image rigidity, const io::Image& mask,
                   const TileWarpOptions& options, const io::Image& orientation, const std::string& source)
    : TileWarp(Bind{}, rest, tile, std::move(rigidity), mask, options, orientation, source) {
    deformkit::detail::releaseFreedMemory();  // the bind's rasters and maps at grid points
}

TileWarp::~TileWarp() = default;
TileWarp::TileWarp(TileWarp&&) noexcept = default;
TileWarp& TileWarp::operator=(TileWarp&&) noexcept = default;

const WarpGrid& TileWarp::solve(std::span<const glm::vec3> deformedPoints) {
    Impl& m = *impl_;
    m.imager->sample(deformedPoints, m.deformed);
    m.lastDeformed.assign(deformedPoints.begin(), deformedPoints.end());
    m.solved = true;
    if (m.slide && m.mask.empty()) {  // the derived mask (setMaps given none)
        m.slide->update(deformedPoints);
        const detail::SlidPoints& p = m.slide->points(m.slideGrid);
        m.solver->placePoints(p.index, p.u, p.v);
    }
    const WarpGrid& warp = m.solver->solve(m.deformed);
    m.stats = m.solver->stats();
    if (!m.keepDeformed) m.deformed = {};
    if (!m.refiner) return warp;
    m.refinedImager->sample(deformedPoints, m.refinedDeformed);
    m.refiner->startFrom(warp);
    const WarpGrid& refined = m.refiner->solve(m.refinedDeformed);
    const SolveStats& r = m.refiner->stats();
    m.stats.iterations += r.iterations;
    m.stats.lastMove = r.lastMove;
    m.stats.untangledPoints += r.untangledPoints;
    m.stats.revertedPoints += r.revertedPoints;
    m.stats.shortenedSteps += r.shortenedSteps;
    m.stats.shortenedEverywhere += r.shortenedEverywhere;
    m.stats.remainingFolds = r.remainingFolds;
    if (!m.keepDeformed && !m.refinementKept()) m.refinedDeformed = {};
    return refined;
}

FoldRepair TileWarp::redirect(io::Image& out) const {
    const Impl& m = *impl_;
    invertWarp(m.delivering().warp(), m.texels, out);
    // A texel is held where the mask fixes every point of the delivered grid around its centre (1, 2 or 4
    // of them): W is the identity there, so the inversion leaves the texel at its centre, and so does the
    // repair. In exact integers: the centre sits at (2x + 1) n / 2T points along u, (2T - 2y - 1) n / 2T
    // along v.
    const std::vector<uint8_t>& mask = m.deliveredMask();
    const int64_t n = m.deliveredCells(), side = n + 1, twoT = 2 * static_cast<int64_t>(m.texels);
    const auto around = [&](int64_t numerator, int64_t& lo, int64_t& hi) {
        lo = numerator / twoT;
        hi = lo + (numerator % twoT != 0 ? 1 : 0);
    };
    const TexelCheck held = [&](int32_t x, int32_t y) {
        int64_t i0 = 0, i1 = 0, j0 = 0, j1 = 0;
        around((2 * x + 1) * n, i0, i1);
        around((twoT - 2 * y - 1) * n, j0, j1);
        for (int64_t j = j0; j <= j1; ++j)
            for (int64_t i = i0; i <= i1; ++i)
                if (mask[static_cast<size_t>(j * side + i)] != 0) return false;
        return true;
    };
    return repairFolds(
        out, [&m](int32_t x, int32_t y, glm::dvec2 r) { return m.delivered->mayShow(x, y, r); },
        [&m](const io::Image& map, int32_t y, std::vector<int32_t>& refused) {
            m.delivered->refusedInRow(map, y, refused);
        },
        held);
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
    const Solver& solver = m.delivering();
    const PointField& rest = solver.restGeometry();
    // The maps at grid points made here are freed on return; their memory stays with the process for the next
    // frame's solve and figures (as the solve state, Solver::Impl::allocateSolveState).
    WarpMetrics figures;
    {
        const PointField rigidity = rigidityAtPoints(m.delivered->rigidity(), m.deliveredCells());
        const PointField mask = maskField(m.deliveredMask(), m.deliveredCells());
        const PointField& kept = m.refiner ? m.refinedDeformed : m.deformed;
        PointField resampled;  // f_D of the last solve, when it was not kept
        if (m.solved && kept.values.empty()) m.deliveredImager().sample(m.lastDeformed, resampled);
        const PointField& deformed = !m.solved ? rest : (kept.values.empty() ? resampled : kept);
        figures = measureWarp(solver.warp(), rest, deformed, rigidity, mask, options);
    }
    return figures;
}

void TileWarp::reset() {
    impl_->solver->reset();
    if (impl_->refiner) impl_->refiner->reset();
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
    PointField newMask = mask.pixels.empty() ? maskField(m.boundMask, m.cells)
                                             : maskAtPoints(mask, m.cells, {m.source + " warp mask", m.tile});
    io::Image density = m.densityMap(orientation, rigidity);
    m.solver->setMaps(std::move(newRigidity), newMask, m.orientationAt(orientation, density, m.cells));
    if (m.refiner) {
        const int32_t n = m.refinedCells;
        const PointField refined =
            mask.pixels.empty()
                ? maskField(m.refinedBoundMask, n)
                : refinedMask(maskAtPoints(mask, n, {m.source + " warp mask", m.tile}), newMask);
        m.refiner->setMaps(rigidityAtPoints(rigidity, n, {m.source + " rigidity map", m.tile}), refined,
                           m.orientationAt(orientation, density, n));
        if (mask.pixels.empty())
            m.refinedMask.clear();
        else
            m.refinedMask = maskBytes(refined);
        m.refinedMask.shrink_to_fit();
    }
    m.delivered->setRigidity(rigidity);
    if (m.slide) {
        m.slide->setRigidity(rigidity);
        if (!mask.pixels.empty()) m.solver->placePoints({}, {}, {});  // a painted mask: its borders stay
    }
    if (mask.pixels.empty())
        m.mask.clear();  // the bound mask again
    else
        m.mask = maskBytes(newMask);
    m.mask.shrink_to_fit();
    newRigidity = {};
    newMask = {};
    density = {};
    deformkit::detail::releaseFreedMemory();  // the maps at grid points just made
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
    return impl_->delivering().warp();
}
const SolveStats& TileWarp::stats() const {
    return impl_->solved ? impl_->stats : impl_->solver->stats();
}
PointField TileWarp::rigidityAtGridPoints() const {
    return rigidityAtPoints(impl_->delivered->rigidity(), impl_->cells);
}
PointField TileWarp::maskAtGridPoints() const {
    const Impl& m = *impl_;
    return maskField(m.mask.empty() ? m.boundMask : m.mask, m.cells);
}

}  // namespace deformkit::uvwarp
