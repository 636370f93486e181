#include "seam_slide.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <utility>

#include <glm/geometric.hpp>

#include "deformkit/io/sampling.h"

namespace deformkit::uvwarp::detail {

namespace {

// The least share of its deformed length a sub-segment is shown over: the slide keeps content in order.
constexpr double kLeastShare = 0.05;
// Sub-segments of a chain edge: about one texel of the map along its longer UV copy, at most this many.
constexpr int32_t kMostSubSegments = 256;
// Halvings of a slide that folds a cell before the slides of the cell's points are dropped.
constexpr int32_t kHalvings = 10;
// A folded cell halves its chains' slides over this many sub-segments either side of its corners.
constexpr int32_t kRepairSubs = 2;
// Slides shorter than this (grid cells) are none: the cells around them need no check.
constexpr float kLeastSlide = 1e-3f;

uint64_t edgeKey(int32_t a, int32_t b) {
    const auto lo = static_cast<uint64_t>(static_cast<uint32_t>(std::min(a, b)));
    const auto hi = static_cast<uint64_t>(static_cast<uint32_t>(std::max(a, b)));
    return (lo << 32) | hi;
}

// Distance from p to segment ab, and the fraction along it of p's nearest point.
std::pair<float, float> toSegment(glm::vec2 p, glm::vec2 a, glm::vec2 b) {
    const glm::vec2 ab = b - a;
    const float len2 = glm::dot(ab, ab);
    const float f = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
    return {glm::length(p - (a + f * ab)), f};
}

float cross(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
    return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
}

}  // namespace

glm::vec2 SeamSlide::Chain::at(size_t copy, float t) const {
    const int32_t e = std::clamp(static_cast<int32_t>(std::floor(t)), 0, edges() - 1);
    const float f = t - static_cast<float>(e);
    return uv[copy][e] + f * (uv[copy][e + 1] - uv[copy][e]);
}

float SeamSlide::Chain::shownAt(float t) const {
    const int32_t e = std::clamp(static_cast<int32_t>(std::floor(t)), 0, edges() - 1);
    const int32_t subs = firstSub[e + 1] - firstSub[e];
    const float m =
        std::clamp((t - static_cast<float>(e)) * static_cast<float>(subs), 0.0f, static_cast<float>(subs));
    const int32_t s = std::min(static_cast<int32_t>(m), subs - 1);
    const float f = m - static_cast<float>(s);
    const auto j = static_cast<size_t>(firstSub[e] + s);
    return phi[j] + f * (phi[j + 1] - phi[j]);
}

SeamSlide::SeamSlide(const geom::Mesh& rest, const TileUVs& uvs, const io::Image& rigidity) {
    // Faces of the whole mesh on each mesh edge of the tile's borders: a seam into another tile (one copy
    // here) and an open border (one face) do not slide.
    std::map<uint64_t, int32_t> meshUses;
    for (const auto& [p, q] : uvs.borderPoints)
        meshUses[edgeKey(p, q)] = 0;
    for (int32_t f = 0; f < rest.numFaces(); ++f) {
        const auto points = rest.face(f);
        const size_t n = points.size();
        for (size_t k = 0; k < n; ++k) {
            const auto found = meshUses.find(edgeKey(points[k], points[(k + 1) % n]));
            if (found != meshUses.end()) ++found->second;
        }
    }
    // The tile's border copies of each mesh edge: UV at its lower and at its higher mesh point.
    struct Copy {
        glm::vec2 lo, hi;
    };
    std::map<uint64_t, std::vector<Copy>> copies;
    for (size_t b = 0; b < uvs.borderEdges.size(); ++b) {
        const auto [p, q] = uvs.borderPoints[b];
        const auto& e = uvs.borderEdges[b];
        copies[edgeKey(p, q)].push_back(p < q ? Copy{e[0], e[1]} : Copy{e[1], e[0]});
    }
    std::map<int32_t, std::vector<uint64_t>> slidingAt;  // mesh point -> its seam edges
    std::map<int32_t, bool> pinned;                      // mesh points on a border copy that does not slide
    for (const auto& [key, list] : copies) {
        const auto lo = static_cast<int32_t>(key >> 32), hi = static_cast<int32_t>(key & 0xffffffffu);
        if (meshUses[key] == 2 && list.size() == 2) {
            slidingAt[lo].push_back(key);
            slidingAt[hi].push_back(key);
        } else {
            pinned[lo] = true;
            pinned[hi] = true;
            for (const Copy& c : list)
                still_.push_back({c.lo, c.hi});
        }
    }
    const auto uvAt = [&](uint64_t key, size_t copy, int32_t point) {
        const Copy& c = copies[key][copy];
        return point == static_cast<int32_t>(key >> 32) ? c.lo : c.hi;
    };
    // A point inside a chain: two seam edges, no other border copy, and the same two UVs on both edges.
    const auto inside = [&](int32_t point) {
        if (pinned.count(point) != 0) return false;
        const auto& edges = slidingAt[point];
        if (edges.size() != 2) return false;
        for (size_t c = 0; c < 2; ++c) {
            const glm::vec2 uv = uvAt(edges[0], c, point);
            if (uv != uvAt(edges[1], 0, point) && uv != uvAt(edges[1], 1, point)) return false;
        }
        return uvAt(edges[0], 0, point) != uvAt(edges[0], 1, point);
    };
    std::map<uint64_t, bool> walked;
    const auto walk = [&](int32_t start, uint64_t first) {
        Chain chain;
        chain.points.push_back(start);
        for (size_t c = 0; c < 2; ++c)
            chain.uv[c].push_back(uvAt(first, c, start));
        int32_t point = start;
        uint64_t key = first;
        while (true) {
            walked[key] = true;
            const auto lo = static_cast<int32_t>(key >> 32), hi = static_cast<int32_t>(key & 0xffffffffu);
            const int32_t next = point == lo ? hi : lo;
            // Each copy goes on through the edge's copy that shares its UV at `point`.
            const size_t same = uvAt(key, 0, point) == chain.uv[0].back() ? 0 : 1;
            chain.uv[0].push_back(uvAt(key, same, next));
            chain.uv[1].push_back(uvAt(key, 1 - same, next));
            chain.points.push_back(next);
            point = next;
            if (point == start || !inside(point)) break;
            const auto& edges = slidingAt[point];
            key = edges[0] == key ? edges[1] : edges[0];
            if (walked[key]) break;
        }
        chains_.push_back(std::move(chain));
    };
    for (const auto& [point, edges] : slidingAt) {
        if (inside(point)) continue;
        for (uint64_t key : edges)
            if (!walked[key]) walk(point, key);
    }
    for (const auto& [point, edges] : slidingAt)  // closed loops: from their lowest point
        for (uint64_t key : edges)
            if (!walked[key]) walk(point, key);

    const auto points = rest.points();
    for (Chain& chain : chains_) {
        chain.firstSub.push_back(0);
        for (int32_t e = 0; e < chain.edges(); ++e) {
            const float longest = std::max(glm::length(chain.uv[0][e + 1] - chain.uv[0][e]),
                                           glm::length(chain.uv[1][e + 1] - chain.uv[1][e]));
            const int32_t subs =
                std::clamp(static_cast<int32_t>(std::ceil(longest * static_cast<float>(rigidity.width))), 1,
                           kMostSubSegments);
            const float length = glm::length(points[chain.points[e + 1]] - points[chain.points[e]]);
            chain.restLength.insert(chain.restLength.end(), static_cast<size_t>(subs),
                                    length / static_cast<float>(subs));
            chain.firstSub.push_back(chain.firstSub.back() + subs);
        }
        chain.phi.resize(chain.restLength.size() + 1);
        for (int32_t e = 0; e < chain.edges(); ++e) {  // the identity until a frame comes
            const int32_t subs = chain.firstSub[e + 1] - chain.firstSub[e];
            for (int32_t s = 0; s < subs; ++s)
                chain.phi[static_cast<size_t>(chain.firstSub[e] + s)] =
                    static_cast<float>(e) + static_cast<float>(s) / static_cast<float>(subs);
        }
        chain.phi.back() = static_cast<float>(chain.edges());
    }
    setRigidity(rigidity);
}

void SeamSlide::sampleRigidity(Chain& chain, const io::Image& rigidity) {
    const int32_t near = std::max(kLeastNear, rigidity.width / kNearShare);
    const float texel = 1.0f / static_cast<float>(rigidity.width);
    std::vector<float> sample(static_cast<size_t>(rigidity.channels));
    const auto at = [&](glm::vec2 uv) {  // channel 0 at tile-local uv (image row 0 at v = 1), bilinear
        io::sampleImage(
            rigidity,
            {uv.x * static_cast<float>(rigidity.width), (1.0f - uv.y) * static_cast<float>(rigidity.height)},
            io::SampleFilter::Bilinear, sample);
        return sample[0];
    };
    chain.rigidity.assign(chain.restLength.size(), 0.0f);
    for (int32_t e = 0; e < chain.edges(); ++e) {
        const int32_t subs = chain.firstSub[e + 1] - chain.firstSub[e];
        for (int32_t s = 0; s < subs; ++s) {
            const float t = static_cast<float>(e) + (static_cast<float>(s) + 0.5f) / static_cast<float>(subs);
            // The most rigid content within `near` texels across the seam, on either copy and either side.
            float r = 0.0f;
            for (size_t c = 0; c < 2; ++c) {
                const glm::vec2 along = chain.uv[c][e + 1] - chain.uv[c][e];
                const float length = glm::length(along);
                const glm::vec2 across =
                    length > 0.0f ? glm::vec2(-along.y, along.x) / length : glm::vec2(0.0f);
                for (int32_t k = -near; k <= near; ++k)
                    r = std::max(r, at(chain.at(c, t) + static_cast<float>(k) * texel * across));
            }
            chain.rigidity[static_cast<size_t>(chain.firstSub[e] + s)] = std::clamp(r, 0.0f, 1.0f);
        }
    }
}

void SeamSlide::setRigidity(const io::Image& rigidity) {
    for (Chain& chain : chains_)
        sampleRigidity(chain, rigidity);
}

int SeamSlide::addGrid(int32_t cells) {
    // Border copies: the seams' by chain, copy and edge; the others (chain -1) slide nothing.
    struct Segment {
        glm::vec2 a, b;
        int32_t chain, copy, edge;
    };
    std::vector<Segment> segments;
    for (size_t c = 0; c < chains_.size(); ++c)
        for (size_t copy = 0; copy < 2; ++copy)
            for (int32_t e = 0; e < chains_[c].edges(); ++e)
                segments.push_back({chains_[c].uv[copy][e], chains_[c].uv[copy][e + 1],
                                    static_cast<int32_t>(c), static_cast<int32_t>(copy), e});
    for (const auto& e : still_)
        segments.push_back({e[0], e[1], -1, 0, 0});
    const float cell = 1.0f / static_cast<float>(cells);
    const float radius = (kBand + kFade) * cell;
    // The segments within `radius` of each grid point near one, by point (visited segment by segment, so
    // that the cost follows the borders' length, not the grid's area).
    std::vector<std::pair<int64_t, int32_t>> near;
    const auto pointOf = [&](float x) {
        return static_cast<int32_t>(std::floor(x * static_cast<float>(cells)));
    };
    for (size_t k = 0; k < segments.size(); ++k) {
        const Segment& s = segments[k];
        const int32_t i0 = std::max(1, pointOf(std::min(s.a.x, s.b.x) - radius));
        const int32_t i1 = std::min(cells - 1, pointOf(std::max(s.a.x, s.b.x) + radius) + 1);
        const int32_t j0 = std::max(1, pointOf(std::min(s.a.y, s.b.y) - radius));
        const int32_t j1 = std::min(cells - 1, pointOf(std::max(s.a.y, s.b.y) + radius) + 1);
        for (int32_t j = j0; j <= j1; ++j) {
            // The columns of row j within `radius` of the segment: those near its part within `radius` of
            // the row (so a long diagonal border costs its length, not its bounding box's area).
            const float y = static_cast<float>(j) * cell;
            float lo = std::min(s.a.x, s.b.x), hi = std::max(s.a.x, s.b.x);
            if (s.b.y != s.a.y) {
                const float f0 = std::clamp((y - radius - s.a.y) / (s.b.y - s.a.y), 0.0f, 1.0f);
                const float f1 = std::clamp((y + radius - s.a.y) / (s.b.y - s.a.y), 0.0f, 1.0f);
                lo = std::min(s.a.x + f0 * (s.b.x - s.a.x), s.a.x + f1 * (s.b.x - s.a.x));
                hi = std::max(s.a.x + f0 * (s.b.x - s.a.x), s.a.x + f1 * (s.b.x - s.a.x));
            }
            const int32_t first = std::max(i0, pointOf(lo - radius)),
                          last = std::min(i1, pointOf(hi + radius) + 1);
            for (int32_t i = first; i <= last; ++i) {
                const glm::vec2 p{static_cast<float>(i) * cell, static_cast<float>(j) * cell};
                if (toSegment(p, s.a, s.b).first < radius)
                    near.emplace_back(static_cast<int64_t>(j) * (cells + 1) + i, static_cast<int32_t>(k));
            }
        }
    }
    std::sort(near.begin(), near.end());
    Grid grid;
    grid.cells = cells;
    for (size_t begin = 0, end = 0; begin < near.size(); begin = end) {
        while (end < near.size() && near[end].first == near[begin].first)
            ++end;
        const int64_t k = near[begin].first;
        const glm::vec2 p{static_cast<float>(k % (cells + 1)) * cell,
                          static_cast<float>(k / (cells + 1)) * cell};
        // The nearest copy, and the nearest other border (or the tile's): the slide fades to nothing half-way
        // to it, so that two slides meet continuously.
        float nearest = radius, fraction = 0.0f;
        int32_t found = -1;
        for (size_t n = begin; n < end; ++n) {
            const Segment& s = segments[static_cast<size_t>(near[n].second)];
            const auto [d, f] = toSegment(p, s.a, s.b);
            if (d < nearest) {
                nearest = d;
                fraction = f;
                found = near[n].second;
            }
        }
        if (found < 0 || segments[static_cast<size_t>(found)].chain < 0) continue;
        const Segment& own = segments[static_cast<size_t>(found)];
        float other = std::min({radius, p.x, p.y, 1.0f - p.x, 1.0f - p.y});
        for (size_t n = begin; n < end; ++n) {
            const Segment& s = segments[static_cast<size_t>(near[n].second)];
            if (s.chain != own.chain || s.copy != own.copy)
                other = std::min(other, toSegment(p, s.a, s.b).first);
        }
        const float weight = std::clamp((radius - nearest) / (kFade * cell), 0.0f, 1.0f) *
                             std::clamp((other - nearest) / (kBand * cell), 0.0f, 1.0f);
        if (weight <= 0.0f) continue;
        const float t = static_cast<float>(own.edge) + fraction;
        grid.anchors.push_back(
            {own.chain, own.copy, t, chains_[static_cast<size_t>(own.chain)].subOf(t), weight, p});
        grid.slid.index.push_back(k);
        grid.slid.u.push_back(p.x);
        grid.slid.v.push_back(p.y);
    }
    grid.byChain.assign(chains_.size(), {});
    for (size_t a = 0; a < grid.anchors.size(); ++a)
        grid.byChain[static_cast<size_t>(grid.anchors[a].chain)].push_back(static_cast<int32_t>(a));
    for (auto& list : grid.byChain)
        std::stable_sort(list.begin(), list.end(),
                         [&](int32_t x, int32_t y) { return grid.anchors[x].sub < grid.anchors[y].sub; });
    grid.rowBegin.assign(static_cast<size_t>(cells) + 2, 0);
    for (int64_t k : grid.slid.index)
        ++grid.rowBegin[static_cast<size_t>(k / (cells + 1)) + 1];
    for (size_t r = 1; r < grid.rowBegin.size(); ++r)
        grid.rowBegin[r] += grid.rowBegin[r - 1];
    grids_.push_back(std::move(grid));
    return static_cast<int>(grids_.size()) - 1;
}

void SeamSlide::solveChain(Chain& chain, std::span<const glm::vec3> deformed) {
    const auto n = chain.restLength.size();
    Scratch& work = scratch_;  // grown once, kept between frames: a frame allocates nothing
    std::vector<double>&length = work.length, &delta = work.delta, &w = work.w, &c = work.c;
    length.resize(static_cast<size_t>(chain.edges()));
    delta.resize(n);
    w.resize(n);
    c.resize(n);
    double total = 0.0;
    for (int32_t e = 0; e < chain.edges(); ++e) {
        length[e] = glm::length(deformed[chain.points[e + 1]] - deformed[chain.points[e]]);
        total += length[e];
        const int32_t subs = chain.firstSub[e + 1] - chain.firstSub[e];
        for (int32_t s = chain.firstSub[e]; s < chain.firstSub[e + 1]; ++s)
            delta[s] = length[e] / static_cast<double>(subs);
    }
    // Segment j: rigid content asks for its rest length (weight rho), elastic content for its deformed length
    // (weight kElasticWeight (1 - rho)); c_j is the change of its deformed length their mean asks for.
    for (size_t j = 0; j < n; ++j) {
        const double rigid = chain.rigidity[j], elastic = kElasticWeight * (1.0 - chain.rigidity[j]);
        w[j] = rigid + elastic;
        c[j] = (rigid * chain.restLength[j] + elastic * delta[j]) / w[j] - delta[j];
    }
    // The displacements y_1 .. y_{n-1} of the sub-segment ends (y_0 = y_n = 0) minimise
    // sum_j w_j (y_{j+1} - y_j - c_j)^2 + mu sum_b y_b^2:
    // (w_{b-1} + w_b + mu) y_b - w_{b-1} y_{b-1} - w_b y_{b+1} = w_{b-1} c_{b-1} - w_b c_b, tridiagonal
    // (Thomas).
    const double mu = kElasticWeight / (kReach * kReach);
    std::vector<double>&y = work.y, &upper = work.upper, &rhs = work.rhs;
    y.assign(n + 1, 0.0);
    upper.assign(n + 1, 0.0);
    rhs.assign(n + 1, 0.0);
    for (size_t b = 1; b < n; ++b) {
        const double d = w[b - 1] + w[b] + mu - (b > 1 ? w[b - 1] * upper[b - 1] : 0.0);
        upper[b] = w[b] / d;
        rhs[b] = (w[b - 1] * c[b - 1] - w[b] * c[b] + (b > 1 ? w[b - 1] * rhs[b - 1] : 0.0)) / d;
    }
    for (size_t b = n - 1; b >= 1; --b)
        y[b] = rhs[b] + upper[b] * y[b + 1];
    // Where each end is shown in deformed arc length, in order (kLeastShare), ending at the chain's end...
    std::vector<double>& shown = work.shown;
    shown.assign(n + 1, 0.0);
    double identity = 0.0;
    for (size_t j = 0; j < n; ++j) {
        identity += delta[j];
        shown[j + 1] = std::max(identity + y[j + 1], shown[j] + kLeastShare * delta[j]);
    }
    const double fit = shown[n] > 0.0 ? total / shown[n] : 0.0;
    // ... and as a chain parameter: the edge whose arc length reaches it, and the fraction along it.
    double before = 0.0;
    int32_t e = 0;
    chain.phi[0] = 0.0f;
    for (size_t b = 1; b < n; ++b) {
        const double reached = shown[b] * fit;
        while (e < chain.edges() - 1 && before + length[e] < reached) {
            before += length[e];
            ++e;
        }
        const double f = length[e] > 0.0 ? (reached - before) / length[e] : 0.0;
        chain.phi[b] = static_cast<float>(e + std::clamp(f, 0.0, 1.0));
    }
    chain.phi[n] = static_cast<float>(chain.edges());
}

void SeamSlide::update(std::span<const glm::vec3> deformed) {
    for (Chain& chain : chains_)
        solveChain(chain, deformed);
    for (Grid& grid : grids_)
        place(grid);
}

int32_t SeamSlide::Chain::subOf(float t) const {
    const int32_t e = std::clamp(static_cast<int32_t>(std::floor(t)), 0, edges() - 1);
    const int32_t subs = firstSub[e + 1] - firstSub[e];
    return firstSub[e] +
           std::clamp(static_cast<int32_t>((t - static_cast<float>(e)) * static_cast<float>(subs)), 0,
                      subs - 1);
}

void SeamSlide::place(Grid& grid) {
    const size_t count = grid.anchors.size();
    const int32_t n = grid.cells, side = n + 1;
    const float cell = 1.0f / static_cast<float>(n);
    // Each chain's slide may be scaled down per sub-segment, for both copies at once (the repair below).
    Scratch& work = scratch_;  // grown once, kept between frames: a frame allocates nothing
    auto& scale = work.scale;
    auto& halvings = work.halvings;
    scale.resize(chains_.size());
    halvings.resize(chains_.size());
    for (size_t c = 0; c < chains_.size(); ++c) {
        scale[c].assign(chains_[c].restLength.size(), 1.0f);
        halvings[c].assign(chains_[c].restLength.size(), 0);
    }
    std::vector<glm::vec2>& shift = work.shift;
    shift.resize(count);
    const auto slide = [&](size_t a) {
        const Anchor& anchor = grid.anchors[a];
        const Chain& chain = chains_[static_cast<size_t>(anchor.chain)];
        const auto copy = static_cast<size_t>(anchor.copy);
        // Along the copy: the point moves with the part of the copy it is nearest to, by its share of the
        // slide in chain parameter.
        const float share =
            anchor.weight * scale[static_cast<size_t>(anchor.chain)][static_cast<size_t>(anchor.sub)];
        const float shown = anchor.t + share * (chain.shownAt(anchor.t) - anchor.t);
        shift[a] = chain.at(copy, shown) - chain.at(copy, anchor.t);
        if (glm::length(shift[a]) < kLeastSlide * cell) shift[a] = glm::vec2(0.0f);
    };
#pragma omp parallel for schedule(static) if (count > 4096)
    for (size_t a = 0; a < count; ++a)
        slide(a);
    // Fold-free by construction: where the slides fold a cell (either splitting), the chains of its slid
    // corners slide half as far over kRepairSubs sub-segments either side, on both copies (the seam stays
    // continuous), and the cells around every point that changed are checked again, until none folds (the
    // identity folds nothing). Only cells with a slid corner can fold.
    const auto slot = [&](int32_t i, int32_t j) {  // the point's anchor, or -1: a search in its row
        const auto first = grid.slid.index.begin() + grid.rowBegin[static_cast<size_t>(j)];
        const auto last = grid.slid.index.begin() + grid.rowBegin[static_cast<size_t>(j) + 1];
        const int64_t k = static_cast<int64_t>(j) * side + i;
        const auto found = std::lower_bound(first, last, k);
        return found != last && *found == k ? found - grid.slid.index.begin() : ptrdiff_t{-1};
    };
    const auto folds = [&](int32_t i, int32_t j) {
        const auto position = [&](int32_t pi, int32_t pj) {
            const ptrdiff_t a = slot(pi, pj);
            const glm::vec2 p{static_cast<float>(pi) * cell, static_cast<float>(pj) * cell};
            return a < 0 ? p : p + shift[static_cast<size_t>(a)];
        };
        const glm::vec2 p00 = position(i, j), p10 = position(i + 1, j), p01 = position(i, j + 1),
                        p11 = position(i + 1, j + 1);
        return cross(p00, p10, p11) <= 0.0f || cross(p00, p11, p01) <= 0.0f || cross(p00, p10, p01) <= 0.0f ||
               cross(p10, p11, p01) <= 0.0f;
    };
    // The first check, a row of cells at a time: its two rows of points in two rows of slots, so that a
    // check looks each corner up directly.
    std::vector<int64_t>& folded = work.folded;
    std::vector<int32_t>&lower = work.lowerRow, &upper = work.upperRow;
    std::vector<uint8_t>& checked = work.checked;
    folded.clear();
    lower.assign(static_cast<size_t>(side), -1);
    upper.assign(static_cast<size_t>(side), -1);
    checked.assign(static_cast<size_t>(n), 0);
    const auto rowOf = [&](int32_t j) {
        return std::pair{grid.rowBegin[static_cast<size_t>(j)], grid.rowBegin[static_cast<size_t>(j) + 1]};
    };
    const auto fill = [&](std::vector<int32_t>& row, int32_t j, bool set) {
        for (auto [a, end] = rowOf(j); a < end; ++a)
            row[static_cast<size_t>(grid.slid.index[static_cast<size_t>(a)] % side)] = set ? a : -1;
    };
    const auto at = [&](const std::vector<int32_t>& row, int32_t i, int32_t j) {
        const int32_t a = row[static_cast<size_t>(i)];
        const glm::vec2 p{static_cast<float>(i) * cell, static_cast<float>(j) * cell};
        return a < 0 ? p : p + shift[static_cast<size_t>(a)];
    };
    for (int32_t cj = 0; cj < n; ++cj) {
        if (grid.rowBegin[static_cast<size_t>(cj)] == grid.rowBegin[static_cast<size_t>(cj) + 2]) continue;
        fill(lower, cj, true);
        fill(upper, cj + 1, true);
        for (int32_t j = cj; j <= cj + 1; ++j)
            for (auto [a, end] = rowOf(j); a < end; ++a) {
                if (shift[static_cast<size_t>(a)] == glm::vec2(0.0f)) continue;
                const auto i = static_cast<int32_t>(grid.slid.index[static_cast<size_t>(a)] % side);
                for (int32_t ci = std::max(i - 1, 0); ci <= std::min(i, n - 1); ++ci) {
                    if (checked[static_cast<size_t>(ci)]) continue;
                    checked[static_cast<size_t>(ci)] = 1;
                    const glm::vec2 p00 = at(lower, ci, cj), p10 = at(lower, ci + 1, cj),
                                    p01 = at(upper, ci, cj + 1), p11 = at(upper, ci + 1, cj + 1);
                    if (cross(p00, p10, p11) <= 0.0f || cross(p00, p11, p01) <= 0.0f ||
                        cross(p00, p10, p01) <= 0.0f || cross(p10, p11, p01) <= 0.0f)
                        folded.push_back(static_cast<int64_t>(cj) * n + ci);
                }
            }
        for (int32_t j = cj; j <= cj + 1; ++j)  // the row's marks back to 0
            for (auto [a, end] = rowOf(j); a < end; ++a) {
                const auto i = static_cast<int32_t>(grid.slid.index[static_cast<size_t>(a)] % side);
                for (int32_t ci = std::max(i - 1, 0); ci <= std::min(i, n - 1); ++ci)
                    checked[static_cast<size_t>(ci)] = 0;
            }
        fill(lower, cj, false);
        fill(upper, cj + 1, false);
    }
    while (!folded.empty()) {
        // The chains' sub-segments to halve: around each slid corner of a folded cell.
        std::vector<std::pair<int32_t, int32_t>>& subs = work.subs;  // (chain, sub-segment)
        subs.clear();
        for (int64_t c : folded) {
            const auto i = static_cast<int32_t>(c % n), j = static_cast<int32_t>(c / n);
            for (int32_t dj = 0; dj <= 1; ++dj)
                for (int32_t di = 0; di <= 1; ++di) {
                    const ptrdiff_t a = slot(i + di, j + dj);
                    if (a < 0) continue;
                    const Anchor& anchor = grid.anchors[static_cast<size_t>(a)];
                    const Chain& chain = chains_[static_cast<size_t>(anchor.chain)];
                    const int32_t sub = anchor.sub, last = static_cast<int32_t>(chain.restLength.size()) - 1;
                    for (int32_t s = std::max(sub - kRepairSubs, 0); s <= std::min(sub + kRepairSubs, last);
                         ++s)
                        subs.emplace_back(anchor.chain, s);
                }
        }
        std::sort(subs.begin(), subs.end());
        subs.erase(std::unique(subs.begin(), subs.end()), subs.end());
        std::vector<int64_t>& around = work.around;
        around.clear();
        for (size_t b = 0; b < subs.size();) {  // runs of sub-segments of one chain
            size_t e = b;
            while (e + 1 < subs.size() && subs[e + 1].first == subs[b].first &&
                   subs[e + 1].second == subs[e].second + 1)
                ++e;
            const auto c = static_cast<size_t>(subs[b].first);
            for (size_t r = b; r <= e; ++r) {
                uint8_t& halved = halvings[c][static_cast<size_t>(subs[r].second)];
                scale[c][static_cast<size_t>(subs[r].second)] *= halved >= kHalvings ? 0.0f : 0.5f;
                halved = static_cast<uint8_t>(std::min<int32_t>(halved + 1, kHalvings));
            }
            // The chain's anchors (both copies) on those sub-segments slide again.
            const auto& list = grid.byChain[c];
            auto first = std::lower_bound(
                list.begin(), list.end(), subs[b].second,
                [&](int32_t a, int32_t sub) { return grid.anchors[static_cast<size_t>(a)].sub < sub; });
            for (auto it = first;
                 it != list.end() && grid.anchors[static_cast<size_t>(*it)].sub <= subs[e].second; ++it) {
                const auto a = static_cast<size_t>(*it);
                slide(a);
                const int64_t k = grid.slid.index[a];
                const auto i = static_cast<int32_t>(k % side), j = static_cast<int32_t>(k / side);
                for (int32_t cj = std::max(j - 1, 0); cj <= std::min(j, n - 1); ++cj)
                    for (int32_t ci = std::max(i - 1, 0); ci <= std::min(i, n - 1); ++ci)
                        around.push_back(static_cast<int64_t>(cj) * n + ci);
            }
            b = e + 1;
        }
        std::sort(around.begin(), around.end());
        around.erase(std::unique(around.begin(), around.end()), around.end());
        folded.clear();
        for (int64_t c : around)
            if (folds(static_cast<int32_t>(c % n), static_cast<int32_t>(c / n))) folded.push_back(c);
    }
    for (size_t a = 0; a < count; ++a) {
        grid.slid.u[a] = grid.anchors[a].rest.x + shift[a].x;
        grid.slid.v[a] = grid.anchors[a].rest.y + shift[a].y;
    }
}

}  // namespace deformkit::uvwarp::detail
