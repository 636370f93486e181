// polygonLoops (io/polygon_loops.h): the loops a polygon that visits a vertex twice is made of, against the
// rule written out here the slow way (split at the first corner that comes back to a vertex, again and
// again), over random polygons; and polygons of many corners, which must cost a pass, not its square.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "io/polygon_loops.h"

using deformkit::io::polygonLoops;

namespace {

// The rule, literally: repeats one after the other dropped (around the polygon too); while some corner comes
// back to a vertex an earlier corner has, the corners from that earlier one up to it are a loop of their own
// and the repeat is dropped; loops of fewer than 3 corners dropped; a loop with the same vertices in the same
// turn as one kept before dropped. The loops in the order they close, the outline's rest last.
std::vector<std::vector<size_t>> loopsByTheRule(const std::vector<int32_t>& v) {
    std::vector<size_t> rest;
    for (size_t k = 0; k < v.size(); ++k)
        if (rest.empty() || v[rest.back()] != v[k]) rest.push_back(k);
    while (rest.size() > 1 && v[rest.back()] == v[rest.front()])
        rest.pop_back();
    std::vector<std::vector<size_t>> closed;
    for (bool split = true; split;) {
        split = false;
        for (size_t j = 0; j < rest.size() && !split; ++j) {
            for (size_t i = 0; i < j; ++i) {
                if (v[rest[i]] != v[rest[j]]) continue;
                closed.emplace_back(rest.begin() + static_cast<ptrdiff_t>(i),
                                    rest.begin() + static_cast<ptrdiff_t>(j));
                rest.erase(rest.begin() + static_cast<ptrdiff_t>(i) + 1,
                           rest.begin() + static_cast<ptrdiff_t>(j) + 1);
                split = true;
                break;
            }
        }
    }
    closed.push_back(rest);
    std::vector<std::vector<size_t>> kept;
    std::vector<std::vector<int32_t>> turns;
    for (const std::vector<size_t>& loop : closed) {
        if (loop.size() < 3) continue;
        std::vector<int32_t> turn;
        for (const size_t k : loop)
            turn.push_back(v[k]);
        std::rotate(turn.begin(), std::min_element(turn.begin(), turn.end()), turn.end());
        if (std::find(turns.begin(), turns.end(), turn) != turns.end()) continue;
        turns.push_back(turn);
        kept.push_back(loop);
    }
    return kept;
}

}  // namespace

TEST_CASE("polygon loops: the rule, on random polygons that revisit vertices", "[io][obj]") {
    std::mt19937 rng(20261207);
    int withLoops = 0, split = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const int corners = std::uniform_int_distribution<int>(1, 24)(rng);
        const int distinct = std::uniform_int_distribution<int>(1, corners + 2)(rng);
        std::vector<int32_t> v(static_cast<size_t>(corners));
        for (int32_t& x : v)
            x = std::uniform_int_distribution<int32_t>(0, distinct - 1)(rng);
        const std::vector<std::vector<size_t>> loops = polygonLoops(v);
        INFO("trial " << trial);
        REQUIRE(loops == loopsByTheRule(v));
        for (const std::vector<size_t>& loop : loops) {
            // Corners in the polygon's order, of distinct vertices.
            CHECK(std::is_sorted(loop.begin(), loop.end()));
            std::vector<int32_t> seen;
            for (const size_t k : loop)
                seen.push_back(v[k]);
            std::sort(seen.begin(), seen.end());
            CHECK(std::adjacent_find(seen.begin(), seen.end()) == seen.end());
        }
        withLoops += loops.empty() ? 0 : 1;
        split += loops.size() > 1 ? 1 : 0;
    }
    // The draws cover both kinds of answer.
    CHECK(withLoops > 1000);
    CHECK(split > 100);
}

TEST_CASE("polygon loops: polygons of 200,000 corners", "[io][obj]") {
    constexpr int32_t n = 100000;
    // A line walked there and back: every loop has 2 corners, none is kept.
    std::vector<int32_t> line;
    for (int32_t i = 0; i < n; ++i)
        line.push_back(i);
    for (int32_t i = n - 1; i >= 0; --i)
        line.push_back(i);
    CHECK(polygonLoops(line).empty());
    // A fan of triangles joined at its hub (0 1 2 0 2 3 0 3 4 ...): every triangle, once.
    std::vector<int32_t> fan;
    for (int32_t i = 1; i < n; ++i)
        fan.insert(fan.end(), {0, i, i + 1});
    const std::vector<std::vector<size_t>> loops = polygonLoops(fan);
    REQUIRE(loops.size() == static_cast<size_t>(n - 1));
    CHECK(loops.front() == std::vector<size_t>{0, 1, 2});
    // Each keeps the hub's first corner.
    CHECK(loops.back() == std::vector<size_t>{0, 3 * (n - 2) + 1, 3 * (n - 2) + 2});
    // Distinct vertices: one loop, as it is.
    CHECK(polygonLoops(std::vector<int32_t>(line.begin(), line.begin() + n)).size() == 1);
}
