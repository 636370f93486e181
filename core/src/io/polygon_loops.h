#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

namespace deformkit::io {

// Exporters write polygons that visit a vertex twice: corners repeated one after the other (a long line
// repeating its corners), or a polygon with a hole joined to its outline by an edge walked both ways (CAD).
// The loops such a polygon is made of, as positions of its corners (so a reader carries any per-corner data
// along): repeats one after the other are dropped (around the polygon too), the polygon is split where it
// comes back to a vertex, loops of fewer than 3 corners are dropped, and a loop walked again is kept once.
// Empty when nothing of 3 distinct corners is left. A polygon of distinct vertices is one loop, as it is.
inline std::vector<std::vector<size_t>> polygonLoops(std::span<const int32_t> vertices) {
    std::vector<size_t> corners;
    for (size_t k = 0; k < vertices.size(); ++k) {
        if (!corners.empty() && vertices[corners.back()] == vertices[k]) continue;
        corners.push_back(k);
    }
    while (corners.size() > 1 && vertices[corners.back()] == vertices[corners.front()])
        corners.pop_back();
    std::vector<std::vector<size_t>> loops;
    std::vector<std::vector<int32_t>> emitted;  // the loops' vertices, rotated to start at their least
    std::vector<std::vector<size_t>> pending{std::move(corners)};
    while (!pending.empty()) {
        std::vector<size_t> loop = std::move(pending.back());
        pending.pop_back();
        // The first corner that revisits a vertex (`again`) and that vertex's first corner (`first`), in one
        // pass: a long polygon must not cost the square of its corners.
        size_t first = 0, again = 0;
        std::unordered_map<int32_t, size_t> seen;
        for (size_t j = 0; j < loop.size(); ++j) {
            const auto [at, inserted] = seen.try_emplace(vertices[loop[j]], j);
            if (!inserted) {
                first = at->second;
                again = j;
                break;
            }
        }
        if (again == 0) {
            if (loop.size() < 3) continue;
            std::vector<int32_t> key;
            for (const size_t k : loop)
                key.push_back(vertices[k]);
            std::rotate(key.begin(), std::min_element(key.begin(), key.end()), key.end());
            if (std::find(emitted.begin(), emitted.end(), key) != emitted.end()) continue;
            emitted.push_back(std::move(key));
            loops.push_back(std::move(loop));
            continue;
        }
        std::vector<size_t> inner(loop.begin() + static_cast<ptrdiff_t>(first),
                                  loop.begin() + static_cast<ptrdiff_t>(again));
        loop.erase(loop.begin() + static_cast<ptrdiff_t>(first) + 1,
                   loop.begin() + static_cast<ptrdiff_t>(again) + 1);
        pending.push_back(std::move(loop));
        pending.push_back(std::move(inner));
    }
    return loops;
}

}  // namespace deformkit::io
