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
    std::vector<std::vector<int32_t>> perRow(static_cast<size_t>(rows));  // start, value pairs
#pragma omp parallel for schedule(dynamic, 16)
    for (int32_t y = 0; y < rows; ++y) {
        const int32_t* row = values.data() + static_cast<size_t>(y) * columns;
        std::vector<int32_t>& runs = perRow[static_cast<size_t>(y)];
        for (int32_t x = 0; x < columns; ++x) {
            if (x > 0 && row[x] == row[x - 1]) continue;
            runs.push_back(x);
            runs.push_back(row[x]);
        }
    }
    rowBegin.assign(static_cast<size_t>(rows) + 1, 0);
    for (int32_t y = 0; y < rows; ++y)
        rowBegin[y + 1] = rowBegin[y] + static_cast<int64_t>(perRow[static_cast<size_t>(y)].size() / 2);
    start.resize(static_cast<size_t>(rowBegin[rows]));
    value.resize(start.size());
#pragma omp parallel for schedule(dynamic, 16)
    for (int32_t y = 0; y < rows; ++y) {
        const std::vector<int32_t>& runs = perRow[static_cast<size_t>(y)];
        for (size_t r = 0; r < runs.size() / 2; ++r) {
            start[static_cast<size_t>(rowBegin[y]) + r] = runs[2 * r];
            value[static_cast<size_t>(rowBegin[y]) + r] = runs[2 * r + 1];
        }
    }
}

}  // namespace deformkit::uvwarp::detail
