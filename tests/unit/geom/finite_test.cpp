// geom::allFinite and geom::firstNonFinite against std::isfinite point by point: every kind of float (zeros,
// denormals, the largest finite, infinities, NaNs of either sign) at random places in spans of many sizes,
// below and above the size from which firstNonFinite splits its pass over threads.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "deformkit/geom/finite.h"

using namespace deformkit;

namespace {

float fromBits(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, sizeof(f));
    return f;
}

size_t referenceFirst(const std::vector<glm::vec3>& points) {
    for (size_t u = 0; u < points.size(); ++u)
        if (!std::isfinite(points[u].x) || !std::isfinite(points[u].y) || !std::isfinite(points[u].z))
            return u;
    return points.size();
}

}  // namespace

TEST_CASE("allFinite and firstNonFinite agree with std::isfinite on every kind of float", "[geom][finite]") {
    using limits = std::numeric_limits<float>;
    const std::vector<float> finite = {
        0.0f,          -0.0f,         limits::denorm_min(), -limits::denorm_min(),
        limits::min(), limits::max(), -limits::max(),       1.0f,
        -1.7e38f};
    const std::vector<float> bad = {limits::infinity(),   -limits::infinity(),   limits::quiet_NaN(),
                                    -limits::quiet_NaN(), fromBits(0x7f800001u), fromBits(0xffffffffu)};
    std::mt19937 rng(20261207);
    for (const size_t n : {size_t{1}, size_t{7}, size_t{512}, size_t{4097}, size_t{21846}, size_t{100003}}) {
        for (int trial = 0; trial < 20; ++trial) {
            CAPTURE(n, trial);
            std::vector<glm::vec3> points(n);
            std::uniform_int_distribution<size_t> pickFinite(0, finite.size() - 1),
                pickBad(0, bad.size() - 1);
            for (glm::vec3& p : points)
                p = {finite[pickFinite(rng)], finite[pickFinite(rng)], finite[pickFinite(rng)]};
            // Most trials plant 1 to 3 bad coordinates; every fifth none.
            const int planted = trial % 5 == 0 ? 0 : 1 + trial % 3;
            std::uniform_int_distribution<size_t> where(0, n - 1);
            for (int k = 0; k < planted; ++k)
                points[where(rng)][static_cast<int>(rng() % 3)] = bad[pickBad(rng)];
            const size_t expected = referenceFirst(points);
            CHECK(geom::firstNonFinite(points) == expected);
            CHECK(geom::allFinite(points) == (expected == n));
        }
    }
    CHECK(geom::allFinite({}));
    CHECK(geom::firstNonFinite({}) == 0);
}
