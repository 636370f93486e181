#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <set>
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
    // One pass with a stack of the corners not yet in a loop, and where on it each of their vertices is: a
    // corner whose vertex is on the stack closes the loop from that vertex's corner to the top, which leaves
    // the stack (the vertex's corner stays, the repeat is dropped). Linear in the corners, whatever the
    // polygon (a line walked there and back closes one loop of 2 corners per corner).
    std::vector<std::vector<size_t>> loops;
    std::set<std::vector<int32_t>> emitted;  // the loops' vertices, rotated to start at their least
    const auto emit = [&](std::vector<size_t> loop) {
        if (loop.size() < 3) return;
        std::vector<int32_t> key;
        key.reserve(loop.size());
        for (const size_t k : loop)
            key.push_back(vertices[k]);
        std::rotate(key.begin(), std::min_element(key.begin(), key.end()), key.end());
        if (emitted.insert(std::move(key)).second) loops.push_back(std::move(loop));
    };
    std::vector<size_t> stack;
    std::unordered_map<int32_t, size_t> onStack;  // a vertex on the stack -> its position there
    for (const size_t k : corners) {
        const auto [at, inserted] = onStack.try_emplace(vertices[k], stack.size());
        if (inserted) {
            stack.push_back(k);
            continue;
        }
        const size_t first = at->second;
        for (size_t p = first + 1; p < stack.size(); ++p)
            onStack.erase(vertices[stack[p]]);
        emit(std::vector<size_t>(stack.begin() + static_cast<ptrdiff_t>(first), stack.end()));
        stack.resize(first + 1);
    }
    emit(std::move(stack));
    return loops;
}

}  // namespace deformkit::io
