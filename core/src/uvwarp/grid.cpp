#include "deformkit/uvwarp/grid.h"

#include "memory/large_buffers.h"

namespace deformkit::uvwarp {

WarpGrid WarpGrid::identity(int32_t cells) {
    WarpGrid grid;
    grid.setIdentity(cells);
    return grid;
}

void WarpGrid::setIdentity(int32_t n) {
    cells = n;
    const int32_t side = n + 1;
    deformkit::detail::assignLarge(u, static_cast<size_t>(side) * side, 0.0f);
    deformkit::detail::assignLarge(v, u.size(), 0.0f);
#pragma omp parallel for schedule(static) if (side > 64)
    for (int32_t j = 0; j < side; ++j) {
        for (int32_t i = 0; i < side; ++i) {
            const size_t k = static_cast<size_t>(j) * side + i;
            u[k] = static_cast<float>(i) / static_cast<float>(n);
            v[k] = static_cast<float>(j) / static_cast<float>(n);
        }
    }
}

bool isPowerOfTwo(int32_t n) {
    return n > 0 && (n & (n - 1)) == 0;
}

}  // namespace deformkit::uvwarp
