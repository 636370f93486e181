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
#include "uvwarp_test_support.h"

using namespace deformkit;
using uvwarp::PointField;
using uvwarp::WarpGrid;

namespace {

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
        test::pointField(n, 3, [](float u, float v, float* p) { p[0] = u, p[1] = v, p[2] = 0; });
    const PointField deformed =
        test::pointField(n, 3, [](float u, float v, float* p) { p[0] = 1.5f * u, p[1] = v, p[2] = 0; });
    const PointField rigidity =
        test::pointField(n, 1, [](float u, float v, float* p) { p[0] = test::latticeDisks(u, v); });
    const PointField mask = test::pointField(n, 1, [](float, float, float* p) { p[0] = 1.0f; });
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
