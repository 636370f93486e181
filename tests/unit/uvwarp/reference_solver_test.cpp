// The reference for the UV-warp solver (reference_solver.h): the PBD model's energy minimised to convergence
// by Levenberg-Marquardt, fold-free, from the PBD solve and from the identity, on a plane. The real cases
// (Spot, rigged characters) are measured by tests/bench/uvwarp_reference_bench.cpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <functional>

#include "deformkit/uvwarp/metrics.h"
#include "deformkit/uvwarp/solver.h"
#include "reference_solver.h"

using namespace deformkit;
using uvwarp::PointField;
using uvwarp::WarpGrid;

namespace {

PointField pointField(int32_t cells, int32_t channels, const std::function<void(float, float, float*)>& f) {
    PointField out;
    out.cells = cells;
    out.channels = channels;
    out.values.resize(static_cast<size_t>(cells + 1) * (cells + 1) * channels);
    for (int32_t j = 0; j <= cells; ++j)
        for (int32_t i = 0; i <= cells; ++i)
            f(static_cast<float>(i) / cells, static_cast<float>(j) / cells, &out.values[out.index(i, j)]);
    return out;
}

float latticeDisks(float u, float v) {
    for (float cu : {0.25f, 0.5f, 0.75f})
        for (float cv : {0.25f, 0.5f, 0.75f})
            if (std::hypot(u - cu, v - cv) < 0.07f) return 1.0f;
    return 0.0f;
}

double removedOn(const WarpGrid& w, const PointField& rest, const PointField& deformed,
                 const PointField& rigidity, const PointField& mask) {
    const uvwarp::WarpMetrics m = uvwarp::measureWarp(w, rest, deformed, rigidity, mask);
    return 1.0 - m.rigidStretchError / m.identityStretchError;
}

}  // namespace

TEST_CASE("uv warp reference: Levenberg-Marquardt lowers the model's energy below the PBD solve's, fold-free",
          "[uvwarp][reference]") {
    const int32_t n = 64;
    const PointField rest =
        pointField(n, 3, [](float u, float v, float* p) { p[0] = u, p[1] = v, p[2] = 0; });
    const PointField deformed =
        pointField(n, 3, [](float u, float v, float* p) { p[0] = 1.5f * u, p[1] = v, p[2] = 0; });
    const PointField rigidity =
        pointField(n, 1, [](float u, float v, float* p) { p[0] = latticeDisks(u, v); });
    const PointField mask = pointField(n, 1, [](float, float, float* p) { p[0] = 1.0f; });
    uvwarp::Solver solver(rest, rigidity, mask, {});
    const WarpGrid pbd = solver.solve(deformed);
    const PointField movable = solver.levelMovable(0);
    test::ReferenceProblem problem{&rest, &deformed, &rigidity, &movable, 0.1, 1.0};
    // From the identity and from the PBD solve: each step lowers E and keeps every triangle positive.
    const WarpGrid identity = WarpGrid::identity(n);
    const test::ReferenceResult fromIdentity = test::minimiseReference(problem, identity, 40);
    const test::ReferenceResult fromPbd = test::minimiseReference(problem, pbd, 40);
    CHECK(fromIdentity.energy < 0.5 * fromIdentity.startEnergy);
    CHECK(fromPbd.energy <= fromPbd.startEnergy);
    CHECK(test::reference_detail::foldFree(fromIdentity.warp));
    CHECK(test::reference_detail::foldFree(fromPbd.warp));
    CHECK(uvwarp::countFolds(fromPbd.warp) == 0);
    // Both reach the same optimum (the model is smooth near it): energies within 5%.
    CHECK(std::abs(fromIdentity.energy - fromPbd.energy) < 0.05 * fromPbd.energy);
    const double pbdRemoved = removedOn(pbd, rest, deformed, rigidity, mask);
    const double bestRemoved = removedOn(fromPbd.warp, rest, deformed, rigidity, mask);
    std::printf(
        "plane 64^2, 1.5x: energy identity %.4g, PBD %.4g, optimum %.4g; grid rigid stretch removed PBD "
        "%.1f%%, optimum %.1f%%\n",
        fromIdentity.startEnergy, fromPbd.startEnergy, fromPbd.energy, 100 * pbdRemoved, 100 * bestRemoved);
    // The PBD solve is near the optimum of its model.
    CHECK(pbdRemoved > bestRemoved - 0.10);
}
