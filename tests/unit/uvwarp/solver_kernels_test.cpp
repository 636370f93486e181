// The UV-warp solver's projection kernel (solver_kernel_loops.h, sweepRow) against a reference written
// here: every segment of a row, one after another, in the order of the paper's 8 parallel sets. The kernel
// visits only the runs of segments the row projects (Level::setRuns, found by the solver from the rigidity
// map), packs them into blocks of four pairs of lanes across runs, fills a row's last block with pairs that
// overlap none in it, and puts a segment left alone at the grid's right edge in a short block; none of that
// may change a byte. Random blocks of rigid points on a free background (rows without any, one point wide,
// touching the edge) with fixed points scattered, levels of 8 to 64 cells, compact and in-place layouts of
// the level's points, with and without an orientation map; both instruction sets.
#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "simd/cpu.h"
#include "uvwarp/solver_kernel_loops.h"
#include "uvwarp/solver_state.h"

namespace {

using namespace deformkit::uvwarp::detail;

// One segment of the set of edge type `type`, anchored at level cell (i, j): Eq. 1-3, the turn towards the
// canonical direction, the clamped, fold-checked moves of both ends, written for one segment with scalar
// code. The per-point helpers (f_D look-up, clamp and fold check) are the kernel's own: this reference
// checks which segments are projected, from which state, and where the results go. f_O is read from the rest
// image itself (g.imageCells cells): at a fine point between the points of an image of half the fine grid's
// cells, the mean of the 2 or 4 around it.
void projectSegment(const KernelGrid& g, const float* restImage, const KernelLevel& l, int32_t type,
                    int32_t i, int32_t j, float stiffness) {
    const EdgeType e = kEdgeTypes[type];
    const int32_t ia = i + e.ai, ja = j + e.aj, ib = i + e.bi, jb = j + e.bj;
    const auto at = [&](int32_t pi, int32_t pj) { return static_cast<ptrdiff_t>(pj) * l.row + pi * l.step; };
    const auto ringOf = [&](int32_t pi, int32_t pj) {
        Ring ring;
        for (int32_t q = 0; q < 8; ++q) {
            ring.u[q] = l.u[at(pi + kRingDi[q], pj + kRingDj[q])];
            ring.v[q] = l.v[at(pi + kRingDi[q], pj + kRingDj[q])];
        }
        return ring;
    };
    const auto fD = [&](float u, float v, float& x0, float& x1, float& x2) {
        uint32_t p00 = 0;
        float fx = 0.0f, fy = 0.0f;
        imageCell(g.imageCells, u, v, p00, fx, fy);
        blendCell(g.deformed, g.imageCells, p00, fx, fy, x0, x1, x2);
    };
    const size_t side = static_cast<size_t>(l.cells) + 1;
    const float ra = l.rigidity[static_cast<size_t>(ja) * side + ia];
    const float rb = l.rigidity[static_cast<size_t>(jb) * side + ib];
    const bool fixedA = ra < 0.0f, fixedB = rb < 0.0f;
    const float paintedA = std::max(ra, kFixed - ra), paintedB = std::max(rb, kFixed - rb);
    const bool pinned = fixedA != fixedB && paintedA >= 0.5f && paintedB >= 0.5f;
    const float rig = fixedA ? rb : (fixedB ? ra : std::max(ra, rb));
    // On a coarse level a segment is projected only above rigidity 0.3 (docs/decisions.md UV-36).
    const float least = l.cells < g.cells ? 0.3f : 0.0f;
    const bool active = (!fixedA && !fixedB && rig > least) || pinned;
    if (!active) return;
    Ring ringA = ringOf(ia, ja), ringB = ringOf(ib, jb);
    const float pax = l.u[at(ia, ja)], pay = l.v[at(ia, ja)];
    const float pbx = l.u[at(ib, jb)], pby = l.v[at(ib, jb)];
    float xa0 = 0, xa1 = 0, xa2 = 0, xb0 = 0, xb1 = 0, xb2 = 0;
    fD(pax, pay, xa0, xa1, xa2);
    fD(pbx, pby, xb0, xb1, xb2);
    const float d0 = xb0 - xa0, d1 = xb1 - xa1, d2 = xb2 - xa2;
    const float lDef = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    const float dx = pbx - pax, dy = pby - pay;
    const float length = std::sqrt(dx * dx + dy * dy);
    const int32_t stride = g.cells / l.cells;
    const auto fO = [&](int32_t fi, int32_t fj, int32_t c) {  // f_O at fine point (fi, fj), channel c
        const size_t side = static_cast<size_t>(g.imageCells) + 1;
        const auto at = [&](int32_t x, int32_t y) { return restImage[3 * (y * side + x) + c]; };
        if (g.imageCells == g.cells) return at(fi, fj);
        const int32_t x = fi / 2, y = fj / 2;
        if (fi % 2 == 0 && fj % 2 == 0) return at(x, y);
        if (fj % 2 == 0) return (at(x, y) + at(x + 1, y)) * 0.5f;
        if (fi % 2 == 0) return (at(x, y) + at(x, y + 1)) * 0.5f;
        return (((at(x, y) + at(x + 1, y)) + at(x, y + 1)) + at(x + 1, y + 1)) * 0.25f;
    };
    float restA[3], restB[3];
    for (int32_t c = 0; c < 3; ++c) {
        restA[c] = fO(ia * stride, ja * stride, c);
        restB[c] = fO(ib * stride, jb * stride, c);
    }
    const float r0 = restB[0] - restA[0], r1 = restB[1] - restA[1], r2 = restB[2] - restA[2];
    const float lOrg = std::sqrt(r0 * r0 + r1 * r1 + r2 * r2);
    if (!(lDef > 1e-12f && length > 1e-12f && lOrg > 0.0f)) return;
    const float correction = stiffness * rig * length * (1.0f - lOrg / lDef);
    const float ux = dx / length, uy = dy / length;
    const float shareA = fixedA ? 0.0f : (fixedB ? 1.0f : 0.5f);
    const float shareB = fixedB ? 0.0f : (fixedA ? 1.0f : 0.5f);
    float nax = pax + shareA * correction * ux, nay = pay + shareA * correction * uy;
    float nbx = pbx - shareB * correction * ux, nby = pby - shareB * correction * uy;
    float preserve = g.orientationPreservation;
    if (l.orientation != nullptr) {
        preserve = g.orientationPreservation * 0.5f *
                   (l.orientation[static_cast<size_t>(ja) * side + ia] +
                    l.orientation[static_cast<size_t>(jb) * side + ib]);
    }
    const float hx = 0.5f * (nbx - nax), hy = 0.5f * (nby - nay);
    const float half = std::sqrt(hx * hx + hy * hy);
    if (preserve > 0.0f && half > 0.0f && !fixedA && !fixedB) {
        const float mx = 0.5f * (nax + nbx), my = 0.5f * (nay + nby);
        float tx = hx / half + preserve * (e.canonicalU - hx / half);
        float ty = hy / half + preserve * (e.canonicalV - hy / half);
        const float tl = std::sqrt(tx * tx + ty * ty);
        if (tl > 1e-6f) {
            const float scale = half / tl;
            tx *= scale;
            ty *= scale;
            nax = mx - tx;
            nay = my - ty;
            nbx = mx + tx;
            nby = my + ty;
        }
    }
    if (!fixedA && clampKeepsOrientation(ringA, nax, nay)) {
        l.u[at(ia, ja)] = nax;
        l.v[at(ia, ja)] = nay;
    }
    const int32_t slotA = ringSlot(e.ai - e.bi, e.aj - e.bj);
    ringB.u[slotA] = l.u[at(ia, ja)];
    ringB.v[slotA] = l.v[at(ia, ja)];
    if (!fixedB && clampKeepsOrientation(ringB, nbx, nby)) {
        l.u[at(ib, jb)] = nbx;
        l.v[at(ib, jb)] = nby;
    }
}

// The reference sweep of row of cells j: the 8 sets in the kernel's order (each edge type by the parity of
// its cell column), a set's segments one after another, every one with both ends and their rings inside the
// grid (projectSegment leaves those it does not project).
void referenceSweepRow(const KernelGrid& g, const float* restImage, const KernelLevel& l, int32_t j,
                       float stiffness) {
    const int32_t c = l.cells;
    for (int32_t type : {0, 1, 2, 3}) {
        const EdgeType e = kEdgeTypes[type];
        const int32_t step = type == 1 ? 2 : 4;
        const int32_t limit = type == 1 ? c : c - 1;
        if (j + e.aj < 1 || j + e.bj > c - 1) continue;
        for (int32_t first = 0; first < step; ++first) {
            for (int32_t i = 1; i < limit; ++i) {
                if (i % step == first) projectSegment(g, restImage, l, type, i, j, stiffness);
            }
        }
    }
}

struct Scene {
    int32_t fineCells = 0;
    std::vector<float> rest, deformed;  // 3 floats per point of the geometry images (imageCells)
    int32_t imageCells = 0;
    std::vector<float> u, v;      // the level's points, in its layout
    std::vector<float> restCopy;  // f_O at the level's points (compact scenes), as a warm solver keeps it
    std::vector<float> orientation;
    Level runs;  // cells, rigidity and the runs of projected segments (findSetRuns)
    KernelGrid grid{};
    KernelLevel level{};
};

// A level of `cells` cells (level stride `stride` in a fine grid of cells * stride cells), its points
// jittered about the identity (compact: a copy of its own; otherwise in place in a fine warp), rigidity
// in random blocks on a free background, with fixed points and a fixed border.
Scene makeScene(std::mt19937& rng, int32_t cells, int32_t stride, bool compact, bool mapped, bool halfImage) {
    Scene s;
    s.fineCells = cells * stride;
    s.imageCells = halfImage ? s.fineCells / 2 : s.fineCells;
    const int32_t n = s.fineCells, side = cells + 1, m = s.imageCells;
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), jitter(-0.3f, 0.3f);
    s.rest.resize(3 * static_cast<size_t>(m + 1) * (m + 1));
    s.deformed.resize(s.rest.size());
    for (int32_t y = 0; y <= m; ++y) {
        for (int32_t x = 0; x <= m; ++x) {
            const size_t k = 3 * (static_cast<size_t>(y) * (m + 1) + x);
            const float fu = static_cast<float>(x) / m, fv = static_cast<float>(y) / m;
            s.rest[k] = fu + 0.01f * unit(rng);
            s.rest[k + 1] = fv + 0.01f * unit(rng);
            s.rest[k + 2] = 0.1f * fu * fv;
            s.deformed[k] = 1.4f * s.rest[k] + 0.02f * unit(rng);
            s.deformed[k + 1] = s.rest[k + 1] + 0.2f * s.rest[k] * s.rest[k];
            s.deformed[k + 2] = s.rest[k + 2];
        }
    }
    const int32_t step = compact ? 1 : stride;
    const ptrdiff_t row = compact ? side : static_cast<ptrdiff_t>(stride) * (n + 1);
    const size_t points = compact ? static_cast<size_t>(side) * side : static_cast<size_t>(n + 1) * (n + 1);
    s.u.assign(points, -7.0f);  // fine points between the level's are never read
    s.v.assign(points, -7.0f);
    for (int32_t j = 0; j <= cells; ++j) {
        for (int32_t i = 0; i <= cells; ++i) {
            const bool border = i == 0 || j == 0 || i == cells || j == cells;
            const ptrdiff_t k = j * row + i * step;
            s.u[k] = (static_cast<float>(i) + (border ? 0.0f : jitter(rng))) / cells;
            s.v[k] = (static_cast<float>(j) + (border ? 0.0f : jitter(rng))) / cells;
        }
    }
    s.runs.cells = cells;
    s.runs.rigidity.assign(static_cast<size_t>(side) * side, 0.0f);
    s.orientation.resize(s.runs.rigidity.size());
    std::uniform_int_distribution<int32_t> at(0, cells), width(1, std::max(2, cells / 3));
    for (int32_t block = 0; block < cells / 4; ++block) {
        const int32_t i0 = at(rng), j0 = at(rng), i1 = std::min(cells, i0 + width(rng)),
                      j1 = std::min(cells, j0 + width(rng) / 2);
        const float r = 0.2f + 0.8f * unit(rng);
        for (int32_t j = j0; j <= j1; ++j)
            for (int32_t i = i0; i <= i1; ++i)
                s.runs.rigidity[static_cast<size_t>(j) * side + i] = r;
    }
    for (int32_t j = 0; j <= cells; ++j) {
        for (int32_t i = 0; i <= cells; ++i) {
            const bool border = i == 0 || j == 0 || i == cells || j == cells;
            float& r = s.runs.rigidity[static_cast<size_t>(j) * side + i];
            if (border || unit(rng) < 0.1f) r = kFixed - r;  // fixed: kFixed - R
            s.orientation[static_cast<size_t>(j) * side + i] = unit(rng);
        }
    }
    findSetRuns(s.runs, s.fineCells);
    s.grid = {n, s.deformed.data(), m, mapped ? 0.6f : 0.3f, 0.0f};
    // Compact scenes read f_O from a copy of the level's points (the reference reads the image), taken from
    // an image of half the cells at every (stride / 2)-th point (stride >= 2).
    const int32_t imageStride = halfImage ? stride / 2 : stride;
    if (compact) {
        s.restCopy.resize(3 * static_cast<size_t>(side) * side);
        for (int32_t j = 0; j <= cells; ++j)
            for (int32_t i = 0; i <= cells; ++i)
                for (int32_t c = 0; c < 3; ++c)
                    s.restCopy[3 * (static_cast<size_t>(j) * side + i) + c] =
                        s.rest[3 * (static_cast<size_t>(j) * imageStride * (m + 1) +
                                    static_cast<size_t>(i) * imageStride) +
                               c];
    }
    // The finest level over an image of half its cells reads f_O between the image's points.
    const bool between = !compact && imageStride == 0;
    const int32_t restStride = between ? 1 : imageStride;
    s.level = {cells,
               compact ? s.restCopy.data() : s.rest.data(),
               compact ? 3 * static_cast<ptrdiff_t>(side) : 3 * static_cast<ptrdiff_t>(restStride) * (m + 1),
               compact ? 3 : 3 * restStride,
               between ? 1 : 0,
               s.u.data(),
               s.v.data(),
               step,
               row,
               s.runs.rigidity.data(),
               mapped ? s.orientation.data() : nullptr,
               s.runs.setRunBegin.data(),
               s.runs.setRuns.data(),
               nullptr,
               nullptr};
    return s;
}

// The runs [runs[2r], runs[2r + 1]) of i in [from, to) where in(i) holds, one value after another, runs fewer
// than `gap` apart merged; appended to `runs`, returns how many.
template <class In>
int32_t referenceRuns(int32_t from, int32_t to, int32_t gap, const In& in, std::vector<int32_t>& runs) {
    int32_t count = 0, open = -1, last = -1;
    for (int32_t i = from; i < to; ++i) {
        if (!in(i)) continue;
        if (open >= 0 && i - (last + 1) < gap) {
            last = i;
            continue;
        }
        if (open >= 0) {
            runs.insert(runs.end(), {open, last + 1});
            ++count;
        }
        open = last = i;
    }
    if (open >= 0) {
        runs.insert(runs.end(), {open, last + 1});
        ++count;
    }
    return count;
}

}  // namespace

TEST_CASE("uv warp kernels: a row's sweep moves what one segment after another moves", "[uvwarp][kernels]") {
    std::vector<const SolverKernels*> kernels = {&kBaselineKernels};
#ifdef DEFORMKIT_SIMD_X86
    if (deformkit::simd::activeIsa() == deformkit::simd::Isa::Avx2) kernels.push_back(&kAvx2Kernels);
#endif
    // Scenes with geometry images of the fine grid's cells and of half of them (the finest level then reads
    // f_O between the image's points; a level with a compact copy is at least 4 fine points apart).
    std::mt19937 rng(2026);
    int cases = 0, moved = 0, movedOverHalfImages = 0;
    for (const int32_t cells : {8, 16, 32, 64}) {
        for (const int32_t stride : {1, 2}) {
            for (const bool compact : {true, false}) {
                for (const bool mapped : {false, true}) {
                    for (int trial = 0; trial < 4; ++trial) {
                        const bool half = trial == 3;
                        if (half && compact && stride == 1) continue;
                        const Scene scene = makeScene(rng, cells, stride, compact, mapped, half);
                        for (const SolverKernels* k : kernels) {
                            Scene kernel = scene, reference = scene;
                            kernel.grid.deformed = reference.grid.deformed = scene.deformed.data();
                            kernel.level.u = kernel.u.data();
                            kernel.level.v = kernel.v.data();
                            reference.level.u = reference.u.data();
                            reference.level.v = reference.v.data();
                            for (Scene* s : {&kernel, &reference}) {
                                s->level.rigidity = scene.runs.rigidity.data();
                                s->level.orientation = mapped ? scene.orientation.data() : nullptr;
                                s->level.setRunBegin = scene.runs.setRunBegin.data();
                                s->level.setRuns = scene.runs.setRuns.data();
                            }
                            const float stiffness = 0.8f;
                            for (int32_t j = 0; j < cells; ++j) {
                                k->sweepRow(kernel.grid, kernel.level, j, stiffness);
                                referenceSweepRow(reference.grid, scene.rest.data(), reference.level, j,
                                                  stiffness);
                            }
                            INFO("cells " << cells << ", stride " << stride << ", compact " << compact
                                          << ", orientation map " << mapped << ", trial " << trial
                                          << ", images of " << scene.imageCells << " cells"
                                          << (k == &kBaselineKernels ? ", baseline" : ", AVX2"));
                            CHECK(std::memcmp(kernel.u.data(), reference.u.data(), 4 * kernel.u.size()) == 0);
                            CHECK(std::memcmp(kernel.v.data(), reference.v.data(), 4 * kernel.v.size()) == 0);
                            for (size_t q = 0; q < scene.u.size(); ++q) {
                                const bool m = kernel.u[q] != scene.u[q] || kernel.v[q] != scene.v[q];
                                moved += m;
                                movedOverHalfImages += m && half;
                            }
                            ++cases;
                        }
                    }
                }
            }
        }
    }
    CHECK(cases >= 96);
    CHECK(moved > 1000);  // the sweeps did move points: the comparison is not of untouched grids
    CHECK(movedOverHalfImages > 200);
}

TEST_CASE("uv warp kernels: a row's runs of projected segments are every set's projected segments",
          "[uvwarp][kernels]") {
    // findSetRuns against a reference written here: per row and parallel set, each of the set's segments
    // inside the grid (setLanes) tested on its own (segmentProjected), and runs fewer than a pair of lanes
    // apart merged. Random maps with rigid blocks, scattered rigid points, fixed points (painted rigid or
    // not) and a fixed border; fine levels (any rigidity above 0 projects) and coarse ones (above 0.3).
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (const int32_t cells : {8, 16, 64, 256}) {
        for (const int32_t stride : {1, 4}) {
            for (int round = 0; round < 3; ++round) {
                CAPTURE(cells, stride, round);
                Level level;
                level.cells = cells;
                const int32_t side = cells + 1;
                level.rigidity.assign(static_cast<size_t>(side) * side, 0.0f);
                for (int32_t j = 0; j <= cells; ++j) {
                    for (int32_t i = 0; i <= cells; ++i) {
                        float& r = level.rigidity[static_cast<size_t>(j) * side + i];
                        const bool block = ((i / 5 + j / 3 + round) % 3) == 0;
                        r = block ? 0.2f + 0.8f * unit(rng) : (unit(rng) < 0.05f ? unit(rng) : 0.0f);
                        const bool border = i == 0 || j == 0 || i == cells || j == cells;
                        if (border || unit(rng) < 0.1f) r = kFixed - r;
                    }
                }
                findSetRuns(level, cells * stride);

                const float least = stride > 1 ? 0.3f : 0.0f;
                std::vector<int32_t> begin{0}, runs;
                for (int32_t j = 0; j < cells; ++j) {
                    for (int32_t set = 0; set < kSets; ++set) {
                        const int32_t type = kSetType[set], first = kSetFirst[set];
                        const EdgeType e = kEdgeTypes[type];
                        int32_t gMin = 0, gMax = 0;
                        setLanes(type, first, j, cells, gMin, gMax);
                        const auto projected = [&](int32_t g) {
                            const int32_t i = first + g * setStep(type);
                            const float ra = level.rigidity[static_cast<size_t>(j + e.aj) * side + i + e.ai];
                            const float rb = level.rigidity[static_cast<size_t>(j + e.bj) * side + i + e.bi];
                            return segmentProjected(ra, rb, least);
                        };
                        // Fewer than 2 segments between: merged.
                        begin.push_back(begin.back() + referenceRuns(gMin, gMax, 2, projected, runs));
                    }
                }
                CHECK(runs.size() > 0);
                CHECK(level.setRunBegin == begin);
                CHECK(level.setRuns == runs);
            }
        }
    }
}

TEST_CASE(
    "uv warp kernels: a level's runs of movable points and cells are its points and cells that may move",
    "[uvwarp][kernels]") {
    // findMovableRuns against a reference written here: per row, each point that may move (level rigidity
    // >= 0) and each cell with such a corner, tested on its own, runs fewer than 8 apart merged. Random maps:
    // fixed blocks, scattered fixed points and a fixed border, some rows all fixed, some all movable.
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const auto reference = [](int32_t columns, int32_t rows, const auto& in, std::vector<int32_t>& begin,
                              std::vector<int32_t>& runs) {
        begin = {0};
        runs.clear();
        for (int32_t j = 0; j < rows; ++j) {
            const int32_t count = referenceRuns(
                0, columns, 8, [&](int32_t i) { return in(i, j); }, runs);
            begin.push_back(begin.back() + count);
        }
    };
    for (const int32_t cells : {8, 16, 64, 256}) {
        for (int round = 0; round < 3; ++round) {
            CAPTURE(cells, round);
            Level level;
            level.cells = cells;
            const int32_t side = cells + 1;
            level.rigidity.assign(static_cast<size_t>(side) * side, 0.0f);
            for (int32_t j = 0; j <= cells; ++j) {
                const int rowKind = j % 7;  // 0: all fixed, 1: all movable, else mixed
                for (int32_t i = 0; i <= cells; ++i) {
                    float& r = level.rigidity[static_cast<size_t>(j) * side + i];
                    r = unit(rng);
                    const bool block = ((i / (3 + round) + j / 5) % 4) == 0;
                    const bool border = i == 0 || j == 0 || i == cells || j == cells;
                    const bool fixed =
                        rowKind == 0 || (rowKind != 1 && (block || unit(rng) < 0.15f)) || border;
                    if (fixed) r = kFixed - r;
                }
            }
            findMovableRuns(level);
            const auto movable = [&](int32_t i, int32_t j) {
                return level.rigidity[static_cast<size_t>(j) * side + i] >= 0.0f;
            };
            std::vector<int32_t> begin, runs;
            reference(side, side, movable, begin, runs);
            CHECK(runs.size() > 0);
            CHECK(level.movableBegin == begin);
            CHECK(level.movableRuns == runs);
            reference(
                cells, cells,
                [&](int32_t i, int32_t j) {
                    return movable(i, j) || movable(i + 1, j) || movable(i, j + 1) || movable(i + 1, j + 1);
                },
                begin, runs);
            CHECK(level.cellRunBegin == begin);
            CHECK(level.cellRuns == runs);
        }
    }
}
