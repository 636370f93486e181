#include "deformkit/uvwarp/grid.h"

namespace deformkit::uvwarp {

WarpGrid WarpGrid::identity(int32_t cells) {
    WarpGrid grid;
    grid.cells = cells;
    const int32_t side = cells + 1;
    grid.u.resize(static_cast<size_t>(side) * side);
    grid.v.resize(grid.u.size());
    for (int32_t j = 0; j < side; ++j) {
        for (int32_t i = 0; i < side; ++i) {
            const size_t k = static_cast<size_t>(j) * side + i;
            grid.u[k] = static_cast<float>(i) / static_cast<float>(cells);
            grid.v[k] = static_cast<float>(j) / static_cast<float>(cells);
        }
    }
    return grid;
}

bool isPowerOfTwo(int32_t n) {
    return n > 0 && (n & (n - 1)) == 0;
}

}  // namespace deformkit::uvwarp
