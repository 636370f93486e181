#include "deformkit/geom/finite.h"

#include <cstdint>
#include <limits>

namespace deformkit::geom {

size_t firstNonFinite(std::span<const glm::vec3> points) {
    if (points.empty()) return 0;
    // On every thread for large spans: the stack checks each deformer's output with it, and one thread's
    // pass over a million points would cost a cheap deformer (a twist) a good share of its time.
    const auto n = static_cast<int64_t>(3 * points.size());
    const float* f = &points.data()->x;
    int finite = 1;
#pragma omp parallel for schedule(static) reduction(& : finite) if (n > (1 << 16))
    for (int64_t i = 0; i < n; ++i)
        finite &= std::abs(f[i]) <= std::numeric_limits<float>::max() ? 1 : 0;
    if (finite) return points.size();
    for (size_t u = 0; u < points.size(); ++u)
        if (!isFinite(points[u])) return u;
    return points.size();
}

}  // namespace deformkit::geom
