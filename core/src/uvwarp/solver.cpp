#include "deformkit/uvwarp/solver.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "deformkit/error.h"

namespace deformkit::uvwarp {

namespace {

// The four constraint directions of the 8-connected grid (paper §4.2, V_horz, V_vert, V_shear0, V_shear1),
// as the level-grid offsets of the segment's two ends from the cell corner (I, J), and the segment's
// canonical (rest) direction.
struct EdgeType {
    int32_t ai, aj, bi, bj;
    float canonicalU, canonicalV;
};
constexpr float kHalfSqrt2 = 0.70710678f;
constexpr std::array<EdgeType, 4> kEdgeTypes = {{
    {0, 0, 1, 0, 1.0f, 0.0f},               // horizontal, 0°
    {0, 0, 0, 1, 0.0f, 1.0f},               // vertical, 90°
    {0, 0, 1, 1, kHalfSqrt2, kHalfSqrt2},   // shear0, 45°
    {1, 0, 0, 1, -kHalfSqrt2, kHalfSqrt2},  // shear1, 135°
}};

// Loops over fewer rows than this run on one thread: coarse levels are tiny, and a fork and barrier per
// tiny loop costs more than the loop (badly so when the machine is oversubscribed).
constexpr int64_t kParallelRows = 64;

// 3x3 Gaussian kernel K_G (Eq. 5 and 7): (1 2 1) x (1 2 1) / 16.
constexpr std::array<float, 3> kGauss = {0.25f, 0.5f, 0.25f};

struct Level {
    int32_t cells = 0;   // cells per side at this level
    int32_t stride = 1;  // fine-grid points between neighbouring points of this level
    std::vector<float> rigidity, orientation;
    std::vector<uint8_t> movable;                  // mask and not on the tile border
    std::array<std::vector<float>, 4> restLength;  // l_org per edge type, stored at the edge's cell corner
    std::vector<float> snapshotU, snapshotV;       // positions before this level's sweeps (for propagation)

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t index(int32_t i, int32_t j) const { return static_cast<size_t>(j) * side() + i; }
};

float orient(float ax, float ay, float bx, float by, float cx, float cy) {
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

}  // namespace

struct Solver::Impl {
    std::string source;
    SolverOptions options;
    int32_t cells = 0;
    std::vector<Level> levels;
    WarpGrid grid;
    std::vector<float> oldU, oldV, velU, velV;
    const float* deformed = nullptr;    // f_D of the current solve, 3 floats per fine point
    std::vector<int32_t> untangleWork;  // scratch of untangle(), kept between calls
    std::vector<std::vector<int32_t>> untangleRows;
    std::vector<int32_t> untangleNext;
    SolveStats stats;

    [[nodiscard]] int32_t side() const { return cells + 1; }
    [[nodiscard]] size_t fine(const Level& level, int32_t i, int32_t j) const {
        return static_cast<size_t>(j) * level.stride * side() + static_cast<size_t>(i) * level.stride;
    }

    // f_D(u, v): bilinear look-up in the deformed geometry image (clamped to the tile).
    void sampleDeformed(float u, float v, float out[3]) const {
        const float x = std::clamp(u, 0.0f, 1.0f) * static_cast<float>(cells);
        const float y = std::clamp(v, 0.0f, 1.0f) * static_cast<float>(cells);
        const int32_t i = std::min(static_cast<int32_t>(x), cells - 1);
        const int32_t j = std::min(static_cast<int32_t>(y), cells - 1);
        const float fx = x - static_cast<float>(i), fy = y - static_cast<float>(j);
        const size_t k = static_cast<size_t>(j) * side() + i;
        const float* p00 = deformed + 3 * k;
        const float* p10 = p00 + 3;
        const float* p01 = p00 + 3 * static_cast<size_t>(side());
        const float* p11 = p01 + 3;
        const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
        for (int c = 0; c < 3; ++c)
            out[c] = w00 * p00[c] + w10 * p10[c] + w01 * p01[c] + w11 * p11[c];
    }

    // True when moving level point (i, j) to (x, y) keeps all 12 triangles around it (both splittings of
    // its four cells) positively oriented. Only called for movable points, which are never on the border.
    bool keepsOrientation(const Level& level, int32_t i, int32_t j, float x, float y) const {
        const size_t s = static_cast<size_t>(level.stride);
        const size_t row = s * static_cast<size_t>(side());
        const size_t k = fine(level, i, j);
        const float* u = grid.u.data();
        const float* v = grid.v.data();
        // Neighbours counter-clockwise from east.
        const size_t n[8] = {k + s, k + s + row, k + row, k - s + row,
                             k - s, k - s - row, k - row, k + s - row};
        for (int q = 0; q < 4; ++q) {  // cell between neighbours 2q (edge), 2q+1 (diagonal), 2q+2 (edge)
            const size_t a = n[2 * q], d = n[2 * q + 1], b = n[(2 * q + 2) % 8];
            if (orient(x, y, u[a], v[a], u[d], v[d]) <= 0.0f) return false;
            if (orient(x, y, u[d], v[d], u[b], v[b]) <= 0.0f) return false;
            if (orient(x, y, u[a], v[a], u[b], v[b]) <= 0.0f) return false;
        }
        return true;
    }

    // Moves a point if that keeps the grid unfolded, after clamping to the bounding box of its 8 neighbours
    // (§4.2: no correction overshoots its neighbourhood).
    void tryMove(const Level& level, int32_t i, int32_t j, float x, float y) {
        const size_t s = static_cast<size_t>(level.stride);
        const size_t row = s * static_cast<size_t>(side());
        const size_t k = fine(level, i, j);
        const size_t n[8] = {k + s, k + s + row, k + row, k - s + row,
                             k - s, k - s - row, k - row, k + s - row};
        float minU = grid.u[n[0]], maxU = minU, minV = grid.v[n[0]], maxV = minV;
        for (int q = 1; q < 8; ++q) {
            minU = std::min(minU, grid.u[n[q]]);
            maxU = std::max(maxU, grid.u[n[q]]);
            minV = std::min(minV, grid.v[n[q]]);
            maxV = std::max(maxV, grid.v[n[q]]);
        }
        x = std::clamp(x, minU, maxU);
        y = std::clamp(y, minV, maxV);
        if (keepsOrientation(level, i, j, x, y)) {
            grid.u[k] = x;
            grid.v[k] = y;
        }
    }

    // Eq. 1-3 for one segment, then orientation preservation, then the clamped, fold-safe moves.
    void projectEdge(const Level& level, int32_t type, int32_t ci, int32_t cj, float stiffness) {
        const EdgeType& e = kEdgeTypes[type];
        const int32_t ai = ci + e.ai, aj = cj + e.aj, bi = ci + e.bi, bj = cj + e.bj;
        const size_t la = level.index(ai, aj), lb = level.index(bi, bj);
        const bool moveA = level.movable[la] != 0, moveB = level.movable[lb] != 0;
        if (!moveA || !moveB) return;  // a masked end: the constraint is not projected (§4.2)
        const float rigidity = std::max(level.rigidity[la], level.rigidity[lb]);
        if (rigidity <= 0.0f) return;  // both ends fully elastic
        const size_t a = fine(level, ai, aj), b = fine(level, bi, bj);
        const float pax = grid.u[a], pay = grid.v[a], pbx = grid.u[b], pby = grid.v[b];
        float xa[3], xb[3];
        sampleDeformed(pax, pay, xa);
        sampleDeformed(pbx, pby, xb);
        const float lDef = std::sqrt((xb[0] - xa[0]) * (xb[0] - xa[0]) + (xb[1] - xa[1]) * (xb[1] - xa[1]) +
                                     (xb[2] - xa[2]) * (xb[2] - xa[2]));
        const float dx = pbx - pax, dy = pby - pay;
        const float length = std::sqrt(dx * dx + dy * dy);
        const float lOrg = level.restLength[type][level.index(ci, cj)];
        if (!(lDef > 1e-12f) || !(length > 1e-12f) || !(lOrg > 0.0f)) return;
        // Along the segment f_D is taken as linear, so the UV length that gives l_def = l_org is
        // length * l_org / l_def; stiffness = rigidity x level factor, equal inverse masses (Müller et al.).
        const float correction = stiffness * rigidity * length * (1.0f - lOrg / lDef);
        const float ux = dx / length, uy = dy / length;
        float nax = pax + 0.5f * correction * ux, nay = pay + 0.5f * correction * uy;
        float nbx = pbx - 0.5f * correction * ux, nby = pby - 0.5f * correction * uy;
        const float preserve =
            options.orientationPreservation * 0.5f * (level.orientation[la] + level.orientation[lb]);
        if (preserve > 0.0f) {
            // Turn the segment about its centre towards its canonical direction (normalised lerp of
            // directions).
            const float mx = 0.5f * (nax + nbx), my = 0.5f * (nay + nby);
            const float hx = 0.5f * (nbx - nax), hy = 0.5f * (nby - nay);
            const float half = std::sqrt(hx * hx + hy * hy);
            if (half > 0.0f) {
                float tx = hx / half + preserve * (e.canonicalU - hx / half);
                float ty = hy / half + preserve * (e.canonicalV - hy / half);
                const float tl = std::sqrt(tx * tx + ty * ty);
                if (tl > 1e-6f) {
                    tx *= half / tl;
                    ty *= half / tl;
                    nax = mx - tx;
                    nay = my - ty;
                    nbx = mx + tx;
                    nby = my + ty;
                }
            }
        }
        tryMove(level, ai, aj, nax, nay);
        tryMove(level, bi, bj, nbx, nby);
    }

    // One sweep over the 8 parallel sets (paper Fig. 8): each edge type split by the parity of its cell
    // column (types 0, 2, 3) or row (type 1), so no two segments of a set share a point. Rows of segments are
    // run in parallel in phases far enough apart that no thread reads a point another one moves, and each
    // row runs in order, so the result does not depend on the thread count.
    void sweep(const Level& level, float stiffness) {
        const int32_t c = level.cells;
        for (int32_t type = 0; type < 4; ++type) {
            for (int32_t parity = 0; parity < 2; ++parity) {
                if (type == 1) {
                    // Vertical segments of cell rows j = parity, parity + 2, ...: a band (rows j, j+1 of
                    // points) reads rows j-1 .. j+2, so bands 4 rows apart run together.
                    for (int32_t phase = 0; phase < 2; ++phase) {
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(c))
                        for (int32_t j = parity + 2 * phase; j < c; j += 4) {
                            for (int32_t i = 0; i <= c; ++i)
                                projectEdge(level, 1, i, j, stiffness);
                        }
                    }
                    continue;
                }
                // Horizontal: a band is one row of points, reading rows j-1 .. j+1 (2 phases). Shears: a band
                // is one row of cells, rows j and j+1 of points, reading j-1 .. j+2 (3 phases).
                const int32_t bands = type == 0 ? c + 1 : c;
                const int32_t phases = type == 0 ? 2 : 3;
                for (int32_t phase = 0; phase < phases; ++phase) {
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(bands))
                    for (int32_t j = phase; j < bands; j += phases) {
                        for (int32_t i = parity; i < c; i += 2)
                            projectEdge(level, type, i, j, stiffness);
                    }
                }
            }
        }
    }

    // Eq. 4-5 on a level's points of colour (ci, cj): blend with K_G by b = M((1 - R) + R s). Points of
    // one colour are never neighbours, so a colour runs in parallel and reads only settled neighbours.
    void regularise(const Level& level, int32_t colourI, int32_t colourJ, bool onlyNew) {
        const int32_t c = level.cells;
        const size_t s = static_cast<size_t>(level.stride);
        const size_t row = s * static_cast<size_t>(side());
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(c))
        for (int32_t j = 1 + ((colourJ + 1) & 1); j < c; j += 2) {
            for (int32_t i = 1 + ((colourI + 1) & 1); i < c; i += 2) {
                if (onlyNew && (i % 2 == 0) && (j % 2 == 0)) continue;
                const size_t l = level.index(i, j);
                if (!level.movable[l]) continue;
                const float r = level.rigidity[l];
                const float blend = (1.0f - r) + r * options.smoothing;
                if (blend <= 0.0f) continue;
                const size_t k = fine(level, i, j);
                float gu = 0.0f, gv = 0.0f;
                for (int dj = -1; dj <= 1; ++dj) {
                    for (int di = -1; di <= 1; ++di) {
                        const size_t q = k + static_cast<size_t>(di) * s + static_cast<size_t>(dj) * row;
                        const float w = kGauss[di + 1] * kGauss[dj + 1];
                        gu += w * grid.u[q];
                        gv += w * grid.v[q];
                    }
                }
                tryMove(level, i, j, (1.0f - blend) * grid.u[k] + blend * gu,
                        (1.0f - blend) * grid.v[k] + blend * gv);
            }
        }
    }

    void regulariseAll(const Level& level, bool onlyNew) {
        for (int32_t cj = 0; cj < 2; ++cj)
            for (int32_t ci = 0; ci < 2; ++ci)
                regularise(level, ci, cj, onlyNew);
    }

    // Repairs folds a propagation or prediction step may have made: a point with a non-positive triangle
    // around it moves towards the mean of its 8 neighbours (as far as keeps its triangles positive).
    bool isFolded(const Level& level, int32_t i, int32_t j) const {
        const size_t k = fine(level, i, j);
        return !keepsOrientation(level, i, j, grid.u[k], grid.v[k]);
    }

    // One full scan finds the points with a non-positive triangle around them; after that only the
    // neighbourhoods of moved points are looked at again, in ascending order (deterministic, serial: the
    // list is short in normal use).
    int32_t untangle(const Level& level) {
        const int32_t c = level.cells;
        std::vector<int32_t>& work = untangleWork;
        work.clear();
        std::vector<std::vector<int32_t>>& rows = untangleRows;
        rows.resize(static_cast<size_t>(c + 1));
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(c))
        for (int32_t j = 1; j < c; ++j) {
            rows[j].clear();
            for (int32_t i = 1; i < c; ++i) {
                if (isFolded(level, i, j)) rows[j].push_back(j * (c + 1) + i);
            }
        }
        for (int32_t j = 1; j < c; ++j)
            work.insert(work.end(), rows[j].begin(), rows[j].end());
        int32_t moved = 0;
        const size_t s = static_cast<size_t>(level.stride);
        const size_t row = s * static_cast<size_t>(side());
        std::vector<int32_t>& next = untangleNext;
        for (int pass = 0; pass < 64 && !work.empty(); ++pass) {
            next.clear();
            for (int32_t id : work) {
                const int32_t i = id % (c + 1), j = id / (c + 1);
                if (!level.movable[level.index(i, j)] || !isFolded(level, i, j)) continue;
                const size_t k = fine(level, i, j);
                const size_t n[8] = {k + s, k + s + row, k + row, k - s + row,
                                     k - s, k - s - row, k - row, k + s - row};
                float mu = 0.0f, mv = 0.0f;
                for (size_t q : n) {
                    mu += grid.u[q] / 8.0f;
                    mv += grid.v[q] / 8.0f;
                }
                grid.u[k] = mu;  // the neighbours' mean repairs most folds at once
                grid.v[k] = mv;
                ++moved;
                for (int32_t dj = -1; dj <= 1; ++dj) {
                    for (int32_t di = -1; di <= 1; ++di) {
                        const int32_t ni = i + di, nj = j + dj;
                        if (ni > 0 && nj > 0 && ni < c && nj < c) next.push_back(nj * (c + 1) + ni);
                    }
                }
            }
            std::sort(next.begin(), next.end());
            next.erase(std::unique(next.begin(), next.end()), next.end());
            work.clear();
            for (int32_t id : next) {
                if (isFolded(level, id % (c + 1), id / (c + 1))) work.push_back(id);
            }
        }
        return moved;
    }

    // §4.4: coarse-level displacements interpolated to the in-between points of the next finer level.
    void propagate(const Level& coarse, const Level& finer) {
        const int32_t c = coarse.cells;
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(finer.cells))
        for (int32_t jj = 0; jj <= finer.cells; ++jj) {
            for (int32_t ii = 0; ii <= finer.cells; ++ii) {
                if ((ii & 1) == 0 && (jj & 1) == 0) continue;  // a coarse point: moved by its own level
                if (!finer.movable[finer.index(ii, jj)]) continue;
                const int32_t i0 = ii >> 1, j0 = jj >> 1;
                const int32_t i1 = std::min(i0 + (ii & 1), c), j1 = std::min(j0 + (jj & 1), c);
                float du = 0.0f, dv = 0.0f;
                const int32_t is[2] = {i0, i1}, js[2] = {j0, j1};
                for (int32_t b = 0; b < 2; ++b) {
                    for (int32_t a = 0; a < 2; ++a) {
                        const size_t l = coarse.index(is[a], js[b]);
                        const size_t k = fine(coarse, is[a], js[b]);
                        du += 0.25f * (grid.u[k] - coarse.snapshotU[l]);
                        dv += 0.25f * (grid.v[k] - coarse.snapshotV[l]);
                    }
                }
                const size_t k = fine(finer, ii, jj);
                grid.u[k] += du;
                grid.v[k] += dv;
            }
        }
    }

    void snapshot(Level& level) {
        const int32_t n = level.side();
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(n))
        for (int32_t j = 0; j < n; ++j) {
            for (int32_t i = 0; i < n; ++i) {
                const size_t k = fine(level, i, j);
                level.snapshotU[level.index(i, j)] = grid.u[k];
                level.snapshotV[level.index(i, j)] = grid.v[k];
            }
        }
    }

    int32_t sweepsAt(size_t level) const {
        if (options.sweepsPerLevel.empty()) return 1;
        return options.sweepsPerLevel[std::min(level, options.sweepsPerLevel.size() - 1)];
    }

    void iterate() {
        const size_t n = grid.u.size();
        const float keep = 1.0f - options.damping;
        // §4.1 steps 1-2: damping and prediction (explicit Euler, unit time step, no external force).
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(n))
        for (size_t k = 0; k < n; ++k) {
            oldU[k] = grid.u[k];
            oldV[k] = grid.v[k];
            velU[k] *= keep;
            velV[k] *= keep;
            grid.u[k] += velU[k];
            grid.v[k] += velV[k];
        }
        stats.untangledPoints += untangle(levels[0]);
        // Step 3, hierarchical (§4.4): coarsest level first; then propagate, smooth, and go finer.
        // Every level's points are recorded before any level moves, so the displacement a level hands down
        // includes what it received from the levels above it.
        for (size_t l = 1; l < levels.size(); ++l)
            snapshot(levels[l]);
        for (size_t l = levels.size(); l-- > 0;) {
            Level& level = levels[l];
            const float stiffness = std::pow(options.coarseStiffness, static_cast<float>(l));
            for (int32_t s = 0; s < sweepsAt(l); ++s)
                sweep(level, stiffness);
            if (l > 0) {
                Level& finer = levels[l - 1];
                propagate(level, finer);
                regulariseAll(finer, true);
                stats.untangledPoints += untangle(finer);
            }
        }
        // Step 4: regularisation (Eq. 4-5) on the finest grid.
        regulariseAll(levels[0], false);
        // Step 5: integration.
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(n))
        for (size_t k = 0; k < n; ++k) {
            velU[k] = grid.u[k] - oldU[k];
            velV[k] = grid.v[k] - oldV[k];
        }
    }

    void buildMaps(const PointField& rigidity, const PointField& mask, const PointField& orientation);
};

namespace {

void requireField(const PointField& field, int32_t cells, int32_t channels, const std::string& source,
                  const char* name) {
    if (field.cells != cells || field.channels != channels ||
        field.values.size() != static_cast<size_t>(cells + 1) * (cells + 1) * channels) {
        throw InvalidInput(formatError(source, name,
                                       std::to_string(field.cells) + " cells x " +
                                           std::to_string(field.channels) + " channels, " +
                                           std::to_string(field.values.size()) + " values",
                                       std::to_string(cells) + " cells x " + std::to_string(channels) +
                                           " channels on the (n + 1)^2 grid points"));
    }
}

}  // namespace

void Solver::Impl::buildMaps(const PointField& rigidity, const PointField& mask,
                             const PointField& orientation) {
    requireField(rigidity, cells, 1, source, "rigidity");
    requireField(mask, cells, 1, source, "mask");
    if (!orientation.values.empty()) requireField(orientation, cells, 1, source, "orientation map");
    for (size_t k = 0; k < rigidity.values.size(); ++k) {
        const float r = rigidity.values[k];
        if (!(r >= 0.0f && r <= 1.0f)) {
            throw InvalidInput(formatError(source, "rigidity at grid point " + std::to_string(k),
                                           std::to_string(r), "a value in [0, 1]"));
        }
    }
    for (Level& level : levels) {
        const size_t count = static_cast<size_t>(level.side()) * level.side();
        level.rigidity.assign(count, 0.0f);
        level.orientation.assign(count, 1.0f);
        level.movable.assign(count, 0);
    }
    Level& finest = levels[0];
    for (int32_t j = 0; j <= cells; ++j) {
        for (int32_t i = 0; i <= cells; ++i) {
            const size_t k = finest.index(i, j);
            const bool border = i == 0 || j == 0 || i == cells || j == cells;
            finest.rigidity[k] = rigidity.values[k];
            finest.movable[k] = (!border && mask.values[k] >= 0.5f) ? 1 : 0;
            if (!orientation.values.empty())
                finest.orientation[k] = std::clamp(orientation.values[k], 0.0f, 1.0f);
        }
    }
    // Eq. 7 (rigidity and orientation blurred by K_G) and Eq. 8 (mask min over 3x3), then subsampled.
    for (size_t l = 1; l < levels.size(); ++l) {
        const Level& from = levels[l - 1];
        Level& to = levels[l];
        const int32_t fc = from.cells;
#pragma omp parallel for schedule(static) if (kParallelRows < static_cast <int64_t>(to.cells))
        for (int32_t j = 0; j <= to.cells; ++j) {
            for (int32_t i = 0; i <= to.cells; ++i) {
                float r = 0.0f, o = 0.0f;
                uint8_t m = 1;
                for (int dj = -1; dj <= 1; ++dj) {
                    for (int di = -1; di <= 1; ++di) {
                        const int32_t si = std::clamp(2 * i + di, 0, fc), sj = std::clamp(2 * j + dj, 0, fc);
                        const size_t q = from.index(si, sj);
                        const float w = kGauss[di + 1] * kGauss[dj + 1];
                        r += w * from.rigidity[q];
                        o += w * from.orientation[q];
                        m = std::min(m, from.movable[q]);
                    }
                }
                const size_t k = to.index(i, j);
                const bool border = i == 0 || j == 0 || i == to.cells || j == to.cells;
                to.rigidity[k] = r;
                to.orientation[k] = o;
                to.movable[k] = border ? 0 : m;
            }
        }
    }
}

Solver::Solver(const PointField& restGeometry, const PointField& rigidity, const PointField& mask,
               const SolverOptions& options, const PointField& orientation, const std::string& source)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.source = source;
    m.options = options;
    m.cells = restGeometry.cells;
    if (!isPowerOfTwo(m.cells) || m.cells < 2) {
        throw InvalidInput(formatError(source, "grid", std::to_string(m.cells) + " cells per side",
                                       "a power of two, at least 2"));
    }
    requireField(restGeometry, m.cells, 3, source, "rest geometry image");
    if (options.iterations < 0 || options.damping < 0.0f || options.damping > 1.0f ||
        options.smoothing < 0.0f || options.smoothing > 1.0f || options.orientationPreservation < 0.0f ||
        options.orientationPreservation > 1.0f || !(options.coarseStiffness > 0.0f) ||
        options.coarseStiffness > 1.0f || options.levels < 0) {
        throw InvalidInput(
            formatError(source, "solver options", "out of range",
                        "iterations >= 0, levels >= 0, damping, smoothing, orientation preservation "
                        "in [0, 1], coarse stiffness in (0, 1]"));
    }
    for (int32_t s : options.sweepsPerLevel) {
        if (s < 0) throw InvalidInput(formatError(source, "sweepsPerLevel", std::to_string(s), ">= 0"));
    }
    int32_t levelCount = options.levels;
    if (levelCount == 0) {
        levelCount = 1;
        while ((m.cells >> levelCount) >= 8)
            ++levelCount;
    }
    levelCount = std::min(levelCount, static_cast<int32_t>(std::log2(m.cells)));
    levelCount = std::max(levelCount, 1);
    m.levels.resize(levelCount);
    for (int32_t l = 0; l < levelCount; ++l) {
        Level& level = m.levels[l];
        level.cells = m.cells >> l;
        level.stride = 1 << l;
        const size_t count = static_cast<size_t>(level.side()) * level.side();
        if (l > 0) {
            level.snapshotU.resize(count);
            level.snapshotV.resize(count);
        }
        // l_org (Eq. 1) of every segment of this level, through f_O at the rest grid points (Eq. 6).
        for (int32_t type = 0; type < 4; ++type) {
            const EdgeType& e = kEdgeTypes[type];
            auto& lengths = level.restLength[type];
            lengths.assign(count, 0.0f);
            for (int32_t j = 0; j + std::max(e.aj, e.bj) <= level.cells; ++j) {
                for (int32_t i = 0; i + std::max(e.ai, e.bi) <= level.cells; ++i) {
                    const size_t a = restGeometry.index((i + e.ai) * level.stride, (j + e.aj) * level.stride);
                    const size_t b = restGeometry.index((i + e.bi) * level.stride, (j + e.bj) * level.stride);
                    float d2 = 0.0f;
                    for (int c = 0; c < 3; ++c) {
                        const float d = restGeometry.values[b + c] - restGeometry.values[a + c];
                        d2 += d * d;
                    }
                    lengths[level.index(i, j)] = std::sqrt(d2);
                }
            }
        }
    }
    m.buildMaps(rigidity, mask, orientation);
    m.grid = WarpGrid::identity(m.cells);
    const size_t n = m.grid.numPoints();
    m.oldU.assign(n, 0.0f);
    m.oldV.assign(n, 0.0f);
    m.velU.assign(n, 0.0f);
    m.velV.assign(n, 0.0f);
    m.stats.levels = levelCount;
}

Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

void Solver::setMaps(const PointField& rigidity, const PointField& mask, const PointField& orientation) {
    impl_->buildMaps(rigidity, mask, orientation);
}

const WarpGrid& Solver::solve(const PointField& deformedGeometry) {
    Impl& m = *impl_;
    requireField(deformedGeometry, m.cells, 3, m.source, "deformed geometry image");
    m.deformed = deformedGeometry.values.data();
    m.stats.untangledPoints = 0;
    for (int32_t it = 0; it < m.options.iterations; ++it)
        m.iterate();
    m.stats.iterations = m.options.iterations;
    m.stats.remainingFolds = countFolds(m.grid);
    m.deformed = nullptr;
    return m.grid;
}

void Solver::reset() {
    Impl& m = *impl_;
    m.grid = WarpGrid::identity(m.cells);
    std::fill(m.velU.begin(), m.velU.end(), 0.0f);
    std::fill(m.velV.begin(), m.velV.end(), 0.0f);
}

const WarpGrid& Solver::warp() const {
    return impl_->grid;
}
const SolveStats& Solver::stats() const {
    return impl_->stats;
}
int32_t Solver::cells() const {
    return impl_->cells;
}
int32_t Solver::levels() const {
    return static_cast<int32_t>(impl_->levels.size());
}

int32_t countFolds(const WarpGrid& warp) {
    const int32_t n = warp.cells, side = n + 1;
    int32_t folds = 0;
#pragma omp parallel for schedule(static) reduction(+ : folds) if (kParallelRows < static_cast <int64_t>(n))
    for (int32_t j = 0; j < n; ++j) {
        for (int32_t i = 0; i < n; ++i) {
            const size_t a = static_cast<size_t>(j) * side + i, b = a + 1, c = a + side + 1, d = a + side;
            const float* u = warp.u.data();
            const float* v = warp.v.data();
            folds += orient(u[a], v[a], u[b], v[b], u[c], v[c]) <= 0.0f ? 1 : 0;  // (i,j)-(i+1,j+1) split
            folds += orient(u[a], v[a], u[c], v[c], u[d], v[d]) <= 0.0f ? 1 : 0;
            folds += orient(u[a], v[a], u[b], v[b], u[d], v[d]) <= 0.0f ? 1 : 0;  // (i+1,j)-(i,j+1) split
            folds += orient(u[b], v[b], u[c], v[c], u[d], v[d]) <= 0.0f ? 1 : 0;
        }
    }
    return folds;
}

}  // namespace deformkit::uvwarp
