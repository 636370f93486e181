#include <catch2/catch.hpp>

#include <cstdint>
#include <vector>

#include "deformkit/uvwarp/grid.h"
#include "memory/large_buffers.h"

using namespace deformkit;
using namespace deformkit::uvwarp;

TEST_CASE("the identity warp, made afresh or in a grid's own storage", "[uvwarp][grid]") {
    for (const int32_t cells : {1, 8, 1024}) {  // 1024: 4.2 MB per coordinate, a large buffer
        const WarpGrid made = WarpGrid::identity(cells);
        REQUIRE(made.cells == cells);
        REQUIRE(made.numPoints() == static_cast<size_t>(cells + 1) * (cells + 1));
        // u = i / n, v = j / n at k = j (n + 1) + i, computed here in double and rounded once.
        for (const int32_t j : {0, 1, cells / 2, cells}) {
            for (const int32_t i : {0, 1, cells / 3, cells}) {
                const size_t k = static_cast<size_t>(j) * (cells + 1) + i;
                CHECK(made.u[k] == static_cast<float>(static_cast<double>(i) / cells));
                CHECK(made.v[k] == static_cast<float>(static_cast<double>(j) / cells));
            }
        }
        // A grid that has moved, or had another size, made the identity again in place.
        WarpGrid grid = WarpGrid::identity(cells == 1 ? 16 : cells);
        for (float& u : grid.u)
            u = 0.25f;
        const float* storage = grid.u.data();
        grid.setIdentity(cells);
        CHECK(grid.cells == cells);
        CHECK(grid.u == made.u);
        CHECK(grid.v == made.v);
        if (cells > 1) CHECK(grid.u.data() == storage);  // the same size: no allocation
    }
}

TEST_CASE("large buffers hold what std::vector::assign gives them", "[uvwarp][grid]") {
    const size_t large = deformkit::detail::kLargeBuffer / sizeof(float) + 3;
    for (const size_t n : {size_t{0}, size_t{5}, large}) {
        std::vector<float> values{1.0f, 2.0f};
        deformkit::detail::assignLarge(values, n, 7.5f);
        CHECK(values == std::vector<float>(n, 7.5f));
    }
    // Bytes and a buffer that already holds enough (reused) or too little (grown).
    std::vector<uint8_t> bytes;
    deformkit::detail::assignLarge(bytes, deformkit::detail::kLargeBuffer, uint8_t{3});
    CHECK(bytes == std::vector<uint8_t>(deformkit::detail::kLargeBuffer, 3));
    const uint8_t* storage = bytes.data();
    deformkit::detail::assignLarge(bytes, deformkit::detail::kLargeBuffer - 1, uint8_t{4});
    CHECK(bytes.data() == storage);
    CHECK(bytes == std::vector<uint8_t>(deformkit::detail::kLargeBuffer - 1, 4));
    deformkit::detail::assignLarge(bytes, 2 * deformkit::detail::kLargeBuffer, uint8_t{5});
    CHECK(bytes == std::vector<uint8_t>(2 * deformkit::detail::kLargeBuffer, 5));
    // Advice on any range, aligned or not, empty or null, changes nothing and never fails.
    deformkit::detail::adviseHugePages(nullptr, 0);
    deformkit::detail::adviseHugePages(bytes.data() + 1, 3);
    deformkit::detail::adviseHugePages(bytes.data() + 1, bytes.size() - 1);
    CHECK(bytes == std::vector<uint8_t>(2 * deformkit::detail::kLargeBuffer, 5));
}
