// Run-length coding of a per-point table per row (row_runs.h), against the table itself: every row's runs
// start at column 0, each run's value is the table's over its columns, and two neighbouring runs of a row
// differ. Random tables of long runs (as triangles under points make them) and of short ones, on one and two
// threads; rows and columns of 1 and 0.
#include <omp.h>

#include <cstdint>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "uvwarp/row_runs.h"

namespace {

using deformkit::uvwarp::detail::encodeRowRuns;

// A rows x columns table whose values change with probability `change` from one column to the next.
std::vector<int32_t> table(int32_t columns, int32_t rows, double change, std::mt19937& random) {
    std::vector<int32_t> values(static_cast<size_t>(columns) * rows);
    std::uniform_real_distribution<double> coin(0.0, 1.0);
    std::uniform_int_distribution<int32_t> value(-1, 5);
    for (int32_t y = 0; y < rows; ++y) {
        int32_t current = value(random);
        for (int32_t x = 0; x < columns; ++x) {
            if (coin(random) < change) current = value(random);
            values[static_cast<size_t>(y) * columns + x] = current;
        }
    }
    return values;
}

// The runs decoded back into a table, and the coding's own rules, checked.
void checkRuns(const std::vector<int32_t>& values, int32_t columns, int32_t rows) {
    std::vector<int64_t> rowBegin;
    std::vector<int32_t> start, value;
    encodeRowRuns(values, columns, rows, rowBegin, start, value);
    REQUIRE(rowBegin.size() == static_cast<size_t>(rows) + 1);
    REQUIRE(rowBegin.front() == 0);
    REQUIRE(rowBegin.back() == static_cast<int64_t>(start.size()));
    REQUIRE(value.size() == start.size());
    for (int32_t y = 0; y < rows; ++y) {
        const auto first = static_cast<size_t>(rowBegin[y]), last = static_cast<size_t>(rowBegin[y + 1]);
        INFO("row " << y);
        REQUIRE(first <= last);
        if (columns == 0) {
            CHECK(first == last);
            continue;
        }
        REQUIRE(last > first);
        CHECK(start[first] == 0);
        for (size_t r = first; r < last; ++r) {
            const int32_t end = r + 1 < last ? start[r + 1] : columns;
            REQUIRE(start[r] < end);
            if (r > first) CHECK(value[r] != value[r - 1]);
            for (int32_t x = start[r]; x < end; ++x)
                REQUIRE(values[static_cast<size_t>(y) * columns + x] == value[r]);
        }
    }
}

}  // namespace

TEST_CASE("row runs: the runs decode to the table, each run as long as its value lasts", "[uvwarp]") {
    std::mt19937 random(20261206);
    const int previousThreads = omp_get_max_threads();
    for (const int threads : {1, 2}) {
        omp_set_num_threads(threads);
        for (const double change : {0.02, 0.5, 1.0}) {
            for (const auto& [columns, rows] : {std::pair{257, 129}, {1, 40}, {40, 1}, {0, 3}, {3, 0}}) {
                INFO(threads << " threads, change " << change << ", " << columns << " x " << rows);
                checkRuns(table(columns, rows, change, random), columns, rows);
            }
        }
    }
    omp_set_num_threads(previousThreads);
    // Outputs that held other runs before are overwritten, not appended to.
    std::vector<int64_t> rowBegin{7, 7};
    std::vector<int32_t> start(100, 9), value(100, 9);
    encodeRowRuns({4, 4, 5, 6, 6, 6}, 3, 2, rowBegin, start, value);
    CHECK(rowBegin == std::vector<int64_t>{0, 2, 3});
    CHECK(start == std::vector<int32_t>{0, 2, 0});
    CHECK(value == std::vector<int32_t>{4, 5, 6});
}
