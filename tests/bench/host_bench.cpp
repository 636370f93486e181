// The host layer's cost per frame over direct core calls (target: at most 5% more). A 1,001,000-vertex grid
// under keyframed Maya-style deformers, evaluated frame after frame by host::SceneEvaluator (curves,
// parameters by name, the stack's envelope and weights rule, dirty tracking), against a hand-written host
// doing the same work through the core: the same curves evaluated, fromMayaTwist / fromMayaBend, new
// controls pushed into the bound warps, evaluate from the rest positions into an output buffer.
//   /1: one twist (the cheapest deformer per vertex, so the worst case for a fixed overhead)
//   /2: a twist then a bend
#include <benchmark/benchmark.h>

#include <vector>

#include "deformkit/geom/primitives.h"
#include "deformkit/host/anim_curve.h"
#include "deformkit/host/evaluator.h"
#include "deformkit/host/scene.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_host.h"

namespace {

using namespace deformkit;

constexpr int kFrames = 100;

const geom::Mesh& grid() {
    static const geom::Mesh mesh = geom::makeGrid({1000, 999, 4.0f, 1.0f});
    return mesh;
}

// endAngle: 0 at frame 1 to 3 at frame 100; curvature: 0.2 to 0.9 (auto-clamped Bezier).
host::AnimCurve curve(double from, double to) {
    return host::AnimCurve({{1.0, from}, {static_cast<double>(kFrames), to}}, "bench");
}

host::SceneParameter constant(const char* name, std::vector<double> value) {
    host::SceneParameter p;
    p.name = name;
    p.value.constant = std::move(value);
    p.path = name;
    return p;
}

host::SceneParameter animated(const char* name, const host::AnimCurve& c) {
    host::SceneParameter p;
    p.name = name;
    p.value.curves = {c};
    p.path = name;
    return p;
}

// The handle: origin at the grid's centre, Y along the grid's long side, 2 units per handle unit (bounds
// -1..1 cover x in [0, 4]); the bend's X out of the grid's plane.
host::Scene scene(int deformers) {
    host::Scene s;
    s.source = "bench";
    s.firstFrame = 1;
    s.lastFrame = kFrames;
    host::SceneObject o;
    o.name = "grid";
    o.rest = grid();
    o.path = "objects[0]";
    host::SceneDeformer twist;
    twist.type = "twist";
    twist.label = "twist1";
    twist.envelope.constant = {1.0};
    twist.params = {constant("handleOrigin", {2, 0.5, 0}), constant("handleY", {2, 0, 0}),
                    animated("endAngle", curve(0.0, 3.0))};
    o.stack.push_back(twist);
    if (deformers > 1) {
        host::SceneDeformer bend;
        bend.type = "bend";
        bend.label = "bend1";
        bend.envelope.constant = {1.0};
        bend.params = {constant("handleOrigin", {2, 0.5, 0}), constant("handleX", {0, 0, 2}),
                       constant("handleY", {2, 0, 0}), animated("curvature", curve(0.2, 0.9))};
        o.stack.push_back(bend);
    }
    s.objects.push_back(std::move(o));
    return s;
}

void BM_HostEvaluate(benchmark::State& state) {
    host::SceneEvaluator evaluator(scene(static_cast<int>(state.range(0))));
    int frame = 0;
    for (auto _ : state) {
        const geom::Mesh& mesh = evaluator.evaluate(0, 1 + frame++ % kFrames);
        benchmark::DoNotOptimize(mesh.points().data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().numVertices()));
}

void BM_HostDirect(benchmark::State& state) {
    const bool bend = state.range(0) > 1;
    const std::span<const glm::vec3> rest = grid().points();
    const host::AnimCurve angle = curve(0.0, 3.0), curvature = curve(0.2, 0.9);
    warp::MayaTwist mt;
    mt.handleOrigin = {2, 0.5f, 0};
    mt.handleY = {2, 0, 0};
    warp::MayaBend mb;
    mb.handleOrigin = {2, 0.5f, 0};
    mb.handleX = {0, 0, 2};
    mb.handleY = {2, 0, 0};
    const warp::AxialSetup ts = warp::fromMayaTwist(mt);
    warp::TwistWarp twist(ts.frame, ts.profile);
    const warp::BendSetup bs = warp::fromMayaBend(mb);
    warp::BendWarp bendWarp(bs.frame, bs.params);
    warp::SparseFields fields;
    twist.bind(rest, fields);
    if (bend) bendWarp.bind(rest, fields);
    std::vector<glm::vec3> out(rest.size()), temp(rest.size());
    int frame = 0;
    for (auto _ : state) {
        const double f = 1 + frame++ % kFrames;
        mt.endAngle = angle.evaluate(f);
        twist.setProfile(warp::fromMayaTwist(mt).profile);
        if (!bend) {
            twist.evaluate(rest, out);
        } else {
            mb.curvature = curvature.evaluate(f);
            bendWarp.setParams(warp::fromMayaBend(mb).params);
            twist.evaluate(rest, temp);
            bendWarp.evaluate(temp, out);
        }
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(rest.size()));
}

}  // namespace

BENCHMARK(BM_HostDirect)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_HostEvaluate)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);

BENCHMARK_MAIN();
