// The host layer's cost per frame over direct core calls (target: at most 5% more). A 1,001,000-vertex grid
// under keyframed Maya-style deformers, evaluated frame after frame by scene::SceneEvaluator (curves,
// parameters by name, the stack's envelope and weights rule, dirty tracking), against a hand-written host
// doing the same work through the core: the same curves evaluated, fromMayaTwist / fromMayaBend, new
// controls pushed into the bound warps, evaluate from the rest positions into an output buffer.
//   /1: one twist (the cheapest deformer per vertex, so the worst case for a fixed overhead)
//   /2: a twist then a bend
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "deformkit/geom/primitives.h"
#include "deformkit/scene/anim_curve.h"
#include "deformkit/scene/evaluator.h"
#include "deformkit/scene/scene.h"
#include "deformkit/warp/barr.h"
#include "deformkit/warp/barr_dcc.h"

namespace {

using namespace deformkit;

constexpr int kFrames = 100;

const geom::Mesh& grid() {
    static const geom::Mesh mesh = geom::makeGrid({1000, 999, 4.0f, 1.0f});
    return mesh;
}

// endAngle: 0 at frame 1 to 3 at frame 100; curvature: 0.2 to 0.9 (auto-clamped Bezier).
scene::AnimCurve curve(double from, double to) {
    return scene::AnimCurve({{1.0, from}, {static_cast<double>(kFrames), to}}, "bench");
}

scene::SceneParameter constant(const char* name, std::vector<double> value) {
    scene::SceneParameter p;
    p.name = name;
    p.value.constant = std::move(value);
    p.path = name;
    return p;
}

scene::SceneParameter animated(const char* name, const scene::AnimCurve& c) {
    scene::SceneParameter p;
    p.name = name;
    p.value.curves = {c};
    p.path = name;
    return p;
}

// The handle: origin at the grid's centre, Y along the grid's long side, 2 units per handle unit (bounds
// -1..1 cover x in [0, 4]); the bend's X out of the grid's plane.
scene::Scene scene(int deformers) {
    scene::Scene s;
    s.source = "bench";
    s.firstFrame = 1;
    s.lastFrame = kFrames;
    scene::SceneObject o;
    o.name = "grid";
    o.rest = grid();
    o.path = "objects[0]";
    scene::SceneDeformer twist;
    twist.type = "twist";
    twist.label = "twist1";
    twist.envelope.constant = {1.0};
    twist.params = {constant("handleOrigin", {2, 0.5, 0}), constant("handleY", {2, 0, 0}),
                    animated("endAngle", curve(0.0, 3.0))};
    o.stack.push_back(twist);
    if (deformers > 1) {
        scene::SceneDeformer bend;
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
    scene::SceneEvaluator evaluator(scene(static_cast<int>(state.range(0))));
    int frame = 0;
    for (auto _ : state) {
        const geom::Mesh& mesh = evaluator.evaluate(0, 1 + frame++ % kFrames);
        benchmark::DoNotOptimize(mesh.points().data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().numVertices()));
}

// The hand-written host: the same curves, fromMayaTwist / fromMayaBend, new controls pushed into the bound
// core warps, evaluation from the rest positions into an output buffer.
class DirectHost {
  public:
    explicit DirectHost(bool bend)
        : bend_(bend), rest_(grid().points()), angle_(curve(0.0, 3.0)), curvature_(curve(0.2, 0.9)) {
        mt_.handleOrigin = {2, 0.5f, 0};
        mt_.handleY = {2, 0, 0};
        mb_.handleOrigin = {2, 0.5f, 0};
        mb_.handleX = {0, 0, 2};
        mb_.handleY = {2, 0, 0};
        const warp::AxialSetup ts = warp::fromMayaTwist(mt_);
        twist_ = std::make_unique<warp::TwistWarp>(ts.frame, ts.profile);
        const warp::BendSetup bs = warp::fromMayaBend(mb_);
        bendWarp_ = std::make_unique<warp::BendWarp>(bs.frame, bs.params);
        warp::SparseFields fields;
        twist_->bind(rest_, fields);
        if (bend_) bendWarp_->bind(rest_, fields);
        out_.resize(rest_.size());
        temp_.resize(rest_.size());
    }

    const std::vector<glm::vec3>& evaluate(double frame) {
        mt_.endAngle = angle_.evaluate(frame);
        twist_->setProfile(warp::fromMayaTwist(mt_).profile);
        if (!bend_) {
            twist_->evaluate(rest_, out_);
        } else {
            mb_.curvature = curvature_.evaluate(frame);
            bendWarp_->setParams(warp::fromMayaBend(mb_).params);
            twist_->evaluate(rest_, temp_);
            bendWarp_->evaluate(temp_, out_);
        }
        return out_;
    }

  private:
    bool bend_;
    std::span<const glm::vec3> rest_;
    scene::AnimCurve angle_, curvature_;
    warp::MayaTwist mt_;
    warp::MayaBend mb_;
    std::unique_ptr<warp::TwistWarp> twist_;
    std::unique_ptr<warp::BendWarp> bendWarp_;
    std::vector<glm::vec3> out_, temp_;
};

void BM_HostDirect(benchmark::State& state) {
    DirectHost direct(state.range(0) > 1);
    int frame = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(direct.evaluate(1 + frame++ % kFrames).data());
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().numVertices()));
}

// Both hosts frame after frame in alternation, timed apart: slow drifts of the machine (other processes,
// clock changes) hit both alike. Counters:
//   overhead_pct     = (median over frames of host time / direct time - 1) x 100: each frame's pair ran
//                      back to back, and the median ignores the frames a noisy neighbour hit in one half;
//   overhead_sum_pct = (sum of host times / sum of direct times - 1) x 100, which such frames do skew.
void BM_HostOverheadPaired(benchmark::State& state) {
    using Clock = std::chrono::steady_clock;
    DirectHost direct(state.range(0) > 1);
    scene::SceneEvaluator evaluator(scene(static_cast<int>(state.range(0))));
    double directSeconds = 0.0, hostSeconds = 0.0;
    std::vector<double> ratios;
    ratios.reserve(4096);
    int frame = 0;
    auto timed = [](auto&& body) {
        const auto start = Clock::now();
        body();
        return std::chrono::duration<double>(Clock::now() - start).count();
    };
    for (auto _ : state) {
        const double f = 1 + frame % kFrames;
        auto runDirect = [&] { benchmark::DoNotOptimize(direct.evaluate(f).data()); };
        auto runHost = [&] { benchmark::DoNotOptimize(evaluator.evaluate(0, f).points().data()); };
        // Which runs first alternates, so neither gains from the other's warm caches or woken threads.
        double d = 0.0, h = 0.0;
        if (frame++ % 2 == 0) {
            d = timed(runDirect);
            h = timed(runHost);
        } else {
            h = timed(runHost);
            d = timed(runDirect);
        }
        directSeconds += d;
        hostSeconds += h;
        ratios.push_back(h / d);
    }
    const auto middle = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
    std::nth_element(ratios.begin(), middle, ratios.end());
    state.counters["overhead_pct"] = (*middle - 1.0) * 100.0;
    state.counters["overhead_sum_pct"] = (hostSeconds / directSeconds - 1.0) * 100.0;
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid().numVertices()));
}

}  // namespace

BENCHMARK(BM_HostDirect)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_HostEvaluate)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_HostOverheadPaired)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

BENCHMARK_MAIN();
