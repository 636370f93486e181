#include "deformkit/uvwarp/redirect_repair.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>
#include <vector>

#include "deformkit/error.h"
#include "redirect_cells.h"

namespace deformkit::uvwarp {
namespace {

constexpr int32_t kSmoothingPasses = 256;
constexpr int32_t kPassesPerRing = 16;
// Scales tried for a region the smoothing left folded: 2^-1 .. 2^-kScaleHalvings, then 0.
constexpr int32_t kScaleHalvings = 24;
// Bisection steps placing a texel that shows off-chart content back on its chart.
constexpr int32_t kOnChartSteps = 10;
// The local scale-back: folds closer than this (in cells) are one cluster; a cluster's window reaches
// kFirstReach texels past its box, doubling up to kLastReach; the scales tried at its core.
constexpr int32_t kClusterGap = 2;
constexpr int32_t kFirstReach = 4;
constexpr int32_t kLastReach = 256;
constexpr double kCoreScales[] = {0.5, 0.25, 0.125, 0.0};
// How close to its centre (in texels) a texel `held` names must be to be held: the inversion's rounding.
constexpr float kHeldReach = 1e-3f;

class FoldRepairer {
  public:
    FoldRepairer(io::Image& redirect, const ContentCheck& mayShow, const ContentRowCheck& refusedInRow,
                 const TexelCheck& held)
        : r_(redirect),
          mayShow_(mayShow),
          refusedInRow_(refusedInRow),
          held_(held),
          t_(redirect.width),
          u_(static_cast<size_t>(t_)),
          v_(u_.size()) {
        // The identity's values, as invertWarp writes them: u of each column, v of each row.
        const auto size = static_cast<float>(t_);
        for (int32_t k = 0; k < t_; ++k) {
            u_[k] = (static_cast<float>(k) + 0.5f) / size;
            v_[k] = 1.0f - (static_cast<float>(k) + 0.5f) / size;
        }
    }

    FoldRepair run() {
        std::vector<int64_t> cells = scan();
        for (int64_t id : cells)
            report_.invertedFound += detail::invertedInCell(r_, cellX(id), cellY(id));
        placeOnCharts();
        if (report_.offChartFound > 0) cells = scan();
        for (int32_t pass = 0; pass < kSmoothingPasses && !cells.empty(); ++pass) {
            cells = smooth(cells, pass / kPassesPerRing);
            ++report_.passes;
        }
        if (!cells.empty()) cells = scaleLocally(cells);
        if (!cells.empty()) scaleBack(cells);
        return report_;
    }

  private:
    // The identity's value at texel (x, y).
    [[nodiscard]] glm::vec2 identityTexel(int32_t x, int32_t y) const { return {u_[x], v_[y]}; }
    [[nodiscard]] int32_t cellX(int64_t id) const { return static_cast<int32_t>(id % t_); }
    [[nodiscard]] int32_t cellY(int64_t id) const { return static_cast<int32_t>(id / t_); }
    [[nodiscard]] int64_t idOf(int32_t x, int32_t y) const { return static_cast<int64_t>(y) * t_ + x; }
    [[nodiscard]] bool isInverted(int64_t id) const {
        return detail::invertedInCell(r_, cellX(id), cellY(id)) > 0;
    }
    void set(int32_t x, int32_t y, glm::vec2 value) {
        r_.at(x, y, 0) = value.x;
        r_.at(x, y, 1) = value.y;
    }
    // Sets texel (x, y) and asks `mayShow` about the value as stored: the float the map holds, not the
    // expression it was rounded from (GCC was seen to hand the unrounded double on).
    bool setChecked(int32_t x, int32_t y, glm::vec2 value) {
        set(x, y, value);
        return mayShow_(x, y, detail::redirectAt(r_, x, y));
    }

    // Texels showing content `mayShow` refuses (a grid coarser than the map cannot follow a chart border
    // texel by texel) move towards their own centre q, which is always allowed: to q + s (r - q) with the
    // largest s of a bisection (kOnChartSteps steps) whose point is allowed, so they keep as much of the warp
    // as they can. A parallel scan of the displaced texels, then the moves in ascending order.
    void placeOnCharts() {
        std::vector<std::vector<int32_t>> refused(static_cast<size_t>(t_));
#pragma omp parallel for schedule(dynamic, 16)
        for (int32_t y = 0; y < t_; ++y) {
            if (refusedInRow_) {
                refusedInRow_(r_, y, refused[y]);
                continue;
            }
            for (int32_t x = 0; x < t_; ++x)
                if (displaced(x, y) && !mayShow_(x, y, detail::redirectAt(r_, x, y))) refused[y].push_back(x);
        }
        for (int32_t y = 0; y < t_; ++y) {
            for (const int32_t x : refused[y]) {
                const glm::dvec2 q(identityTexel(x, y)), d = detail::redirectAt(r_, x, y) - q;
                double allowed = 0.0, refused = 1.0;
                for (int32_t step = 0; step < kOnChartSteps; ++step) {
                    const double s = 0.5 * (allowed + refused);
                    (setChecked(x, y, glm::vec2(q + s * d)) ? allowed : refused) = s;
                }
                set(x, y, glm::vec2(q + allowed * d));
                if (!setChecked(x, y, glm::vec2(q + allowed * d))) set(x, y, glm::vec2(q));
                ++report_.offChartFound;
            }
        }
    }

    // Cells holding an inverted triangle, ascending (cell id = its first corner's texel id).
    [[nodiscard]] std::vector<int64_t> scan() const {
        std::vector<int64_t> rowCount(static_cast<size_t>(t_), 0);
#pragma omp parallel for schedule(dynamic, 16)
        for (int32_t y = 0; y < t_ - 1; ++y)
            rowCount[y] = detail::foldCandidatesInRow(r_, y) > 0 ? detail::invertedInRows(r_, y, y + 1) : 0;
        std::vector<int64_t> cells;
        for (int32_t y = 0; y < t_ - 1; ++y) {
            if (rowCount[y] == 0) continue;
            for (int32_t x = 0; x + 1 < t_; ++x)
                if (detail::invertedInCell(r_, x, y) > 0) cells.push_back(idOf(x, y));
        }
        return cells;
    }

    // One smoothing pass over the corners of `cells` grown by `rings` texels; returns the cells inverted
    // after it, ascending.
    std::vector<int64_t> smooth(const std::vector<int64_t>& cells, int32_t rings) {
        std::vector<int64_t> movers;
        for (int64_t id : cells) {
            const int32_t x = cellX(id), y = cellY(id);
            for (int32_t dy = -rings; dy <= rings + 1; ++dy) {
                for (int32_t dx = -rings; dx <= rings + 1; ++dx) {
                    const int32_t mx = x + dx, my = y + dy;
                    if (mx > 0 && my > 0 && mx < t_ - 1 && my < t_ - 1) movers.push_back(idOf(mx, my));
                }
            }
        }
        std::sort(movers.begin(), movers.end());
        movers.erase(std::unique(movers.begin(), movers.end()), movers.end());
        std::vector<int64_t> suspects = cells;
        for (int64_t id : movers) {
            const int32_t x = cellX(id), y = cellY(id);
            if (held_ && nearCentre(x, y) && held_(x, y)) continue;  // masked content stays painted
            glm::dvec2 sum(0.0);
            for (int32_t dy = -1; dy <= 1; ++dy)
                for (int32_t dx = -1; dx <= 1; ++dx)
                    if (dx != 0 || dy != 0) sum += detail::redirectAt(r_, x + dx, y + dy);
            const glm::vec2 old(r_.at(x, y, 0), r_.at(x, y, 1));
            const glm::dvec2 mean = sum / 8.0;
            if (!setChecked(x, y, glm::vec2(mean))) {
                // Past a chart border: halfway to the texel's own centre, or the centre itself (its own
                // content, which a chart texel may always show).
                const glm::dvec2 q(identityTexel(x, y));
                if (!setChecked(x, y, glm::vec2((mean + q) * 0.5)) && !setChecked(x, y, glm::vec2(q))) {
                    set(x, y, old);
                    continue;
                }
            }
            if (old.x == r_.at(x, y, 0) && old.y == r_.at(x, y, 1)) continue;
            ++report_.texelsMoved;
            for (int32_t cy = y - 1; cy <= y; ++cy)
                for (int32_t cx = x - 1; cx <= x; ++cx)
                    suspects.push_back(idOf(cx, cy));  // x, y >= 1 and <= T - 2: every one a cell
        }
        std::sort(suspects.begin(), suspects.end());
        suspects.erase(std::unique(suspects.begin(), suspects.end()), suspects.end());
        std::vector<int64_t> inverted;
        for (int64_t id : suspects)
            if (isInverted(id)) inverted.push_back(id);
        return inverted;
    }

    // Within kHeldReach texel of its centre: where the inversion leaves a texel W fixes (exactly when a texel
    // spans a power-of-two number of cells, within a float rounding otherwise).
    [[nodiscard]] bool nearCentre(int32_t x, int32_t y) const {
        const glm::vec2 q = identityTexel(x, y);
        const float reach = kHeldReach / static_cast<float>(t_);
        return std::abs(r_.at(x, y, 0) - q.x) <= reach && std::abs(r_.at(x, y, 1) - q.y) <= reach;
    }

    [[nodiscard]] bool displaced(int32_t x, int32_t y) const {
        const glm::vec2 q = identityTexel(x, y);
        return r_.at(x, y, 0) != q.x || r_.at(x, y, 1) != q.y;
    }

    // Clusters of `cells` (ascending): cells fewer than kClusterGap cells apart (Chebyshev) are in one. Each
    // cluster ascending, clusters in the order of their first cell.
    [[nodiscard]] std::vector<std::vector<int64_t>> clusters(const std::vector<int64_t>& cells) const {
        std::unordered_set<int64_t> left(cells.begin(), cells.end());
        std::vector<std::vector<int64_t>> out;
        for (int64_t first : cells) {
            if (left.erase(first) == 0) continue;
            std::vector<int64_t> cluster{first};
            for (size_t k = 0; k < cluster.size(); ++k) {
                const int32_t x = cellX(cluster[k]), y = cellY(cluster[k]);
                for (int32_t dy = -kClusterGap; dy <= kClusterGap; ++dy) {
                    for (int32_t dx = -kClusterGap; dx <= kClusterGap; ++dx) {
                        const int32_t nx = x + dx, ny = y + dy;
                        if (nx < 0 || ny < 0 || nx >= t_ || ny >= t_) continue;
                        if (left.erase(idOf(nx, ny)) > 0) cluster.push_back(idOf(nx, ny));
                    }
                }
            }
            std::sort(cluster.begin(), cluster.end());
            out.push_back(std::move(cluster));
        }
        return out;
    }

    // Before the guarantee, the displacement is scaled back around each cluster of folds the smoothing left
    // only: in a window `reach` texels past the cluster's box, by `core` inside the box and its first
    // reach / 2 texels, rising linearly to 1 at the window's edge (Chebyshev distance to the box). Windows
    // from kFirstReach texels doubling to kLastReach, core scales kCoreScales; the first that leaves no cell
    // it touches inverted and every texel it moves showing content mayShow allows is kept. The displacement
    // of a texel of a wide region of warp (a chart's worth) is then kept outside a neighbourhood of the fold
    // instead of halved with the whole region. Returns the cells still inverted, for the guarantee.
    std::vector<int64_t> scaleLocally(const std::vector<int64_t>& cells) {
        std::vector<int64_t> left;
        for (const std::vector<int64_t>& cluster : clusters(cells)) {
            int32_t x0 = t_, y0 = t_, x1 = -1, y1 = -1;  // the box of the cluster's cells' corners
            for (int64_t id : cluster) {
                x0 = std::min(x0, cellX(id));
                y0 = std::min(y0, cellY(id));
                x1 = std::max(x1, cellX(id) + 1);
                y1 = std::max(y1, cellY(id) + 1);
            }
            if (!scaleWindow(x0, y0, x1, y1)) {
                for (int64_t id : cluster)
                    if (isInverted(id)) left.push_back(id);
            }
        }
        std::sort(left.begin(), left.end());
        return left;
    }

    // scaleLocally's search for one cluster with corner box [x0, x1] x [y0, y1]; true when one window
    // leaves it unfolded (kept), false with the map as it was.
    bool scaleWindow(int32_t x0, int32_t y0, int32_t x1, int32_t y1) {
        for (int32_t reach = kFirstReach; reach <= kLastReach; reach *= 2) {
            // The window's texels (the tile's border ones too: the inversion displaces them as any other).
            const int32_t wx0 = std::max(0, x0 - reach), wy0 = std::max(0, y0 - reach);
            const int32_t wx1 = std::min(t_ - 1, x1 + reach), wy1 = std::min(t_ - 1, y1 + reach);
            const int32_t width = wx1 - wx0 + 1;
            std::vector<glm::vec2> original;
            original.reserve(static_cast<size_t>(width) * (wy1 - wy0 + 1));
            for (int32_t y = wy0; y <= wy1; ++y)
                for (int32_t x = wx0; x <= wx1; ++x)
                    original.emplace_back(r_.at(x, y, 0), r_.at(x, y, 1));
            const double inner = 0.5 * reach;
            for (const double core : kCoreScales) {
                bool shown = true;
                for (int32_t y = wy0; y <= wy1; ++y) {
                    for (int32_t x = wx0; x <= wx1; ++x) {
                        const int32_t distance = std::max({x0 - x, x - x1, y0 - y, y - y1, 0});
                        const double ramp = std::clamp((distance - inner) / (reach - inner), 0.0, 1.0);
                        const double scale = core + (1.0 - core) * ramp;
                        const glm::dvec2 q(identityTexel(x, y));
                        const glm::dvec2 d =
                            glm::dvec2(original[static_cast<size_t>(y - wy0) * width + (x - wx0)]) - q;
                        if (scale == 1.0 || (d.x == 0.0 && d.y == 0.0)) continue;
                        set(x, y, glm::vec2(q + scale * d));
                        if (shown) shown = mayShow_(x, y, detail::redirectAt(r_, x, y));
                    }
                }
                bool unfolded = shown;  // and no cell with a corner in the window inverted
                for (int32_t y = std::max(0, wy0 - 1); unfolded && y <= std::min(wy1, t_ - 2); ++y)
                    for (int32_t x = std::max(0, wx0 - 1); unfolded && x <= std::min(wx1, t_ - 2); ++x)
                        unfolded = !isInverted(idOf(x, y));
                if (unfolded) {
                    ++report_.regionsScaledLocally;
                    report_.smallestScale = std::min(report_.smallestScale, core);
                    return true;
                }
            }
            for (int32_t y = wy0; y <= wy1; ++y)  // as it was
                for (int32_t x = wx0; x <= wx1; ++x)
                    set(x, y, original[static_cast<size_t>(y - wy0) * width + (x - wx0)]);
        }
        return false;
    }

    // The guarantee: the 8-connected regions of displaced texels holding a corner of an inverted cell,
    // their displacement scaled back until nothing they touch is inverted or refused.
    void scaleBack(const std::vector<int64_t>& cells) {
        std::unordered_set<int64_t> seen;
        for (int64_t cell : cells) {
            for (int32_t c = 0; c < 4; ++c) {
                const int32_t x = cellX(cell) + (c & 1), y = cellY(cell) + (c >> 1);
                if (!displaced(x, y) || seen.contains(idOf(x, y))) continue;
                scaleRegion(collectRegion(x, y, seen));
            }
        }
    }

    std::vector<int64_t> collectRegion(int32_t x0, int32_t y0, std::unordered_set<int64_t>& seen) const {
        std::vector<int64_t> region{idOf(x0, y0)};
        seen.insert(region.front());
        for (size_t k = 0; k < region.size(); ++k) {
            const int32_t x = cellX(region[k]), y = cellY(region[k]);
            for (int32_t dy = -1; dy <= 1; ++dy) {
                for (int32_t dx = -1; dx <= 1; ++dx) {
                    const int32_t nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= t_ || ny >= t_ || !displaced(nx, ny)) continue;
                    if (seen.insert(idOf(nx, ny)).second) region.push_back(idOf(nx, ny));
                }
            }
        }
        std::sort(region.begin(), region.end());
        return region;
    }

    void scaleRegion(const std::vector<int64_t>& region) {
        std::vector<glm::dvec2> displacement(region.size());
        std::vector<int64_t> touched;
        for (size_t k = 0; k < region.size(); ++k) {
            const int32_t x = cellX(region[k]), y = cellY(region[k]);
            displacement[k] = detail::redirectAt(r_, x, y) - glm::dvec2(identityTexel(x, y));
            for (int32_t cy = std::max(0, y - 1); cy <= std::min(y, t_ - 2); ++cy)
                for (int32_t cx = std::max(0, x - 1); cx <= std::min(x, t_ - 2); ++cx)
                    touched.push_back(idOf(cx, cy));
        }
        std::sort(touched.begin(), touched.end());
        touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
        double scale = 1.0;
        for (int32_t halving = 1; halving <= kScaleHalvings + 1; ++halving) {
            scale = halving <= kScaleHalvings ? std::ldexp(1.0, -halving) : 0.0;
            bool shown = true;
            for (size_t k = 0; k < region.size(); ++k) {
                const int32_t x = cellX(region[k]), y = cellY(region[k]);
                const glm::dvec2 q(identityTexel(x, y));
                set(x, y, glm::vec2(q + scale * displacement[k]));
                if (shown && scale > 0.0) shown = mayShow_(x, y, detail::redirectAt(r_, x, y));
            }
            if (scale == 0.0) break;  // the identity: fold-free, and each texel shows its own centre
            if (!shown) continue;
            if (std::none_of(touched.begin(), touched.end(), [&](int64_t id) { return isInverted(id); }))
                break;
        }
        ++report_.regionsScaled;
        report_.smallestScale = std::min(report_.smallestScale, scale);
    }

    io::Image& r_;
    const ContentCheck& mayShow_;
    const ContentRowCheck& refusedInRow_;
    const TexelCheck& held_;
    int32_t t_;
    std::vector<float> u_, v_;
    FoldRepair report_;
};

}  // namespace

FoldRepair repairFolds(io::Image& redirect, const ContentCheck& mayShow, const ContentRowCheck& refusedInRow,
                       const TexelCheck& held) {
    if (redirect.width < 1 || redirect.height != redirect.width || redirect.channels < 2 ||
        redirect.pixels.size() != static_cast<size_t>(redirect.width) * redirect.height * redirect.channels) {
        throw InvalidInput(formatError("fold repair", "redirect map",
                                       "is " + std::to_string(redirect.width) + " x " +
                                           std::to_string(redirect.height) + " with " +
                                           std::to_string(redirect.channels) + " channels",
                                       "a square T x T map with 2 channels (u', v')"));
    }
    return FoldRepairer(redirect, mayShow, refusedInRow, held).run();
}

std::vector<ReportedFigure> reportedFigures(const FoldRepair& r) {
    using Kind = ReportedFigure::Kind;
    return {{"repair_inverted_found", Kind::Count, static_cast<double>(r.invertedFound)},
            {"repair_off_chart_found", Kind::Count, static_cast<double>(r.offChartFound)},
            {"repair_texels_moved", Kind::Count, static_cast<double>(r.texelsMoved)},
            {"repair_passes", Kind::Count, static_cast<double>(r.passes)},
            {"repair_regions_scaled", Kind::Count, static_cast<double>(r.regionsScaled)},
            {"repair_folds_scaled_locally", Kind::Count, static_cast<double>(r.regionsScaledLocally)},
            {"repair_smallest_scale", Kind::Number, r.smallestScale}};
}

}  // namespace deformkit::uvwarp
