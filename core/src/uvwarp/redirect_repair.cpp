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

class FoldRepairer {
  public:
    FoldRepairer(io::Image& redirect, const ContentCheck& mayShow, const ContentRowCheck& refusedInRow)
        : r_(redirect),
          mayShow_(mayShow),
          refusedInRow_(refusedInRow),
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

    [[nodiscard]] bool displaced(int32_t x, int32_t y) const {
        const glm::vec2 q = identityTexel(x, y);
        return r_.at(x, y, 0) != q.x || r_.at(x, y, 1) != q.y;
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
    int32_t t_;
    std::vector<float> u_, v_;
    FoldRepair report_;
};

}  // namespace

FoldRepair repairFolds(io::Image& redirect, const ContentCheck& mayShow,
                       const ContentRowCheck& refusedInRow) {
    if (redirect.width < 1 || redirect.height != redirect.width || redirect.channels < 2 ||
        redirect.pixels.size() != static_cast<size_t>(redirect.width) * redirect.height * redirect.channels) {
        throw InvalidInput(formatError("fold repair", "redirect map",
                                       "is " + std::to_string(redirect.width) + " x " +
                                           std::to_string(redirect.height) + " with " +
                                           std::to_string(redirect.channels) + " channels",
                                       "a square T x T map with 2 channels (u', v')"));
    }
    return FoldRepairer(redirect, mayShow, refusedInRow).run();
}

std::vector<ReportedFigure> reportedFigures(const FoldRepair& r) {
    using Kind = ReportedFigure::Kind;
    return {{"repair_inverted_found", Kind::Count, static_cast<double>(r.invertedFound)},
            {"repair_off_chart_found", Kind::Count, static_cast<double>(r.offChartFound)},
            {"repair_texels_moved", Kind::Count, static_cast<double>(r.texelsMoved)},
            {"repair_passes", Kind::Count, static_cast<double>(r.passes)},
            {"repair_regions_scaled", Kind::Count, static_cast<double>(r.regionsScaled)},
            {"repair_smallest_scale", Kind::Number, r.smallestScale}};
}

}  // namespace deformkit::uvwarp
