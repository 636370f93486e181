#pragma once

// Private to the UV warp: warped grid points as the inversion rasterises them. A point (u, v) lies at raster
// x = u T, y = (1 - v) T (raster pixels are the map's texels), clamped to 2^20 texels, with its position
// snapped to 1/256 texel for exact coverage, as geom::rasterizeTriangle snaps.

#include <cstdint>

namespace deformkit::uvwarp::detail {

// Far-off points (a broken warp) are clamped to 2^20 texels, which keeps every edge function within int64.
constexpr float kRasterLimit = 1048576.0f;

struct RasterPoint {
    float x, y;
    int64_t sx, sy;
};

// Rounds to the nearest 1/256, halves away from zero (llround's rule, without a library call): x * 256 and
// x * 256 +- 0.5 are exact in double for a float |x| < 2^21.
inline int64_t snap(float x) {
    const double scaled = static_cast<double>(x) * 256.0;
    return static_cast<int64_t>(scaled + (scaled >= 0.0 ? 0.5 : -0.5));
}

// snap(x) for |x| <= kRasterLimit, in float arithmetic that vectorises: x * 256 (at most 2^28) is exact, and
// so are its truncation and the fraction it leaves, so halves round away from zero exactly as in snap (the
// two agree on every such float; the unit tests check it).
inline int32_t snapFloat(float x) {
    const float scaled = x * 256.0f;
    const auto whole = static_cast<int32_t>(scaled);
    const float fraction = scaled - static_cast<float>(whole);
    return whole + (fraction >= 0.5f ? 1 : 0) - (fraction <= -0.5f ? 1 : 0);
}

// std::clamp(x, -kRasterLimit, kRasterLimit) for a number, written so that loops over it vectorise.
inline float clampRaster(float x) {
    const float low = x < -kRasterLimit ? -kRasterLimit : x;
    return low > kRasterLimit ? kRasterLimit : low;
}

inline float rasterY(float v, float t) {
    return clampRaster((1.0f - v) * t);
}

// The raster points of up to N consecutive grid points of one row (finite u, v), computed together: two
// loops the compiler vectorises (one would not be: the clamp and the rounding together defeat it), and
// point(m) is point m clamped (clampRaster, rasterY) with its snapped position (snap).
template <int32_t N>
struct RasterRow {
    float x[N], y[N];
    int32_t sx[N], sy[N];

    void compute(const float* __restrict u, const float* __restrict v, int32_t n, float t) {
        float* __restrict px = x;
        float* __restrict py = y;
        int32_t* __restrict psx = sx;
        int32_t* __restrict psy = sy;
        for (int32_t m = 0; m < n; ++m) {
            px[m] = clampRaster(u[m] * t);
            py[m] = rasterY(v[m], t);
        }
        for (int32_t m = 0; m < n; ++m) {
            psx[m] = snapFloat(px[m]);
            psy[m] = snapFloat(py[m]);
        }
    }
    [[nodiscard]] RasterPoint point(int32_t m) const { return {x[m], y[m], sx[m], sy[m]}; }
};

}  // namespace deformkit::uvwarp::detail
