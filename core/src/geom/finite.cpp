#include "deformkit/geom/finite.h"

#include <algorithm>
#include <cstdint>

namespace deformkit::geom {

size_t firstNonFinite(std::span<const glm::vec3> points) {
    if (points.empty()) return 0;
    // On every thread for large spans (chunks of allFinite): the stack checks each deformer's output with
    // it, and one thread's pass over a million points would cost a cheap deformer (a twist) a good share of
    // its time.
    constexpr int64_t kChunk = 4096;
    const auto n = static_cast<int64_t>(points.size());
    const int64_t chunks = (n + kChunk - 1) / kChunk;
    int finite = 1;
#pragma omp parallel for schedule(static) reduction(& : finite) if (n > (1 << 16) / 3)
    for (int64_t c = 0; c < chunks; ++c) {
        const int64_t begin = c * kChunk;
        finite &= allFinite(points.subspan(static_cast<size_t>(begin),
                                           static_cast<size_t>(std::min(kChunk, n - begin))))
                      ? 1
                      : 0;
    }
    if (finite) return points.size();
    for (size_t u = 0; u < points.size(); ++u)
        if (!isFinite(points[u])) return u;
    return points.size();
}

}  // namespace deformkit::geom
