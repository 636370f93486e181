#pragma once

// Private to the UV warp: a per-point (or per-texel) table of values, such as the UV triangle under each
// point, run-length coded per row. Tables of this kind are nearly constant along a row (a triangle covers
// tens to thousands of neighbouring points), so a tile keeps a few bytes a row instead of 4 a point.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace deformkit::uvwarp::detail {

// values: rows x columns, row-major. Afterwards row y holds runs r in [rowBegin[y], rowBegin[y + 1]), run r
// covering columns [start[r], the next run's start or `columns`) with value[r]. Rows are coded in parallel
// and laid end to end: the same arrays as one pass.
inline void encodeRowRuns(const std::vector<int32_t>& values, int32_t columns, int32_t rows,
                          std::vector<int64_t>& rowBegin, std::vector<int32_t>& start,
                          std::vector<int32_t>& value) {
    // Two passes over the rows, in parallel: each row's run count (a run starts at column 0 and wherever the
    // value changes), then, from the counts' prefix sums, its runs in place. No per-row buffers: a bind of a
    // 2048-cell grid would otherwise grow thousands of small vectors on every thread.
    rowBegin.assign(static_cast<size_t>(rows) + 1, 0);
#pragma omp parallel for schedule(dynamic, 16)
    for (int32_t y = 0; y < rows; ++y) {
        const int32_t* row = values.data() + static_cast<size_t>(y) * columns;
        int64_t runs = columns > 0 ? 1 : 0;
        for (int32_t x = 1; x < columns; ++x)
            runs += row[x] != row[x - 1] ? 1 : 0;
        rowBegin[static_cast<size_t>(y) + 1] = runs;
    }
    for (int32_t y = 0; y < rows; ++y)
        rowBegin[static_cast<size_t>(y) + 1] += rowBegin[static_cast<size_t>(y)];
    start.resize(static_cast<size_t>(rowBegin[static_cast<size_t>(rows)]));
    value.resize(start.size());
#pragma omp parallel for schedule(dynamic, 16)
    for (int32_t y = 0; y < rows; ++y) {
        const int32_t* row = values.data() + static_cast<size_t>(y) * columns;
        auto r = static_cast<size_t>(rowBegin[static_cast<size_t>(y)]);
        for (int32_t x = 0; x < columns; ++x) {
            if (x > 0 && row[x] == row[x - 1]) continue;
            start[r] = x;
            value[r] = row[x];
            ++r;
        }
    }
}

}  // namespace deformkit::uvwarp::detail
