// Farm throughput: a 100-frame shot of two UDIM tiles, one object (two 64 x 64 quad grids, one
// per tile, 8,450 vertices) under a keyframed twist and the UV warp (64 x 64 rigidity maps, 6 iterations per
// frame, each from the identity: the scene's default). BM_FarmRunPlan runs every task of its farm plan
// (--chunk 10, 6 warm-up frames, which frames solved from the identity skip; one tile per UV-warp task: 10
// mesh tasks and 20 UV-warp tasks) one after the other in this process, as a farm of one slot would;
// BM_FarmEval evaluates the whole shot with one `deformkit eval` (previews off) as the reference. Both
// write every output again each iteration. items/s = frames per second.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "deformkit/geom/primitives.h"
#include "deformkit/io/image.h"
#include "deformkit/io/obj.h"
#include "eval_command.h"
#include "farm_command.h"

namespace {

using namespace deformkit;
namespace fs = std::filesystem;

constexpr int kFrames = 100;
constexpr int kTexels = 64;

// Two grids side by side, the second one's UVs shifted to tile 1002.
geom::Mesh twoTiles() {
    const geom::Mesh a = geom::makeGrid({64, 64, 1.0f, 1.0f});
    geom::Mesh::Data d;
    for (int t = 0; t < 2; ++t) {
        const auto base = static_cast<int32_t>(d.points.size());
        const auto uvBase = static_cast<int32_t>(d.uvs.size());
        for (const glm::vec3& p : a.points())
            d.points.push_back(p + glm::vec3(1.5f * static_cast<float>(t), 0.0f, 0.0f));
        for (const glm::vec2& uv : a.uvs())
            d.uvs.push_back(glm::vec2(0.02f + 0.96f * uv.x + static_cast<float>(t), 0.02f + 0.96f * uv.y));
        d.faceCounts.insert(d.faceCounts.end(), a.faceCounts().begin(), a.faceCounts().end());
        for (int32_t i : a.faceIndices())
            d.faceIndices.push_back(base + i);
        for (int32_t i : a.uvIndices())
            d.uvIndices.push_back(uvBase + i);
    }
    return geom::Mesh(std::move(d), "bench");
}

// Rigid disks of radius 0.08 on a 4 x 4 lattice.
io::Image rigidity() {
    io::Image image(kTexels, kTexels, 1);
    for (int y = 0; y < kTexels; ++y)
        for (int x = 0; x < kTexels; ++x)
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j)
                    if (std::hypot((x + 0.5) / kTexels - (0.125 + 0.25 * i),
                                   (y + 0.5) / kTexels - (0.125 + 0.25 * j)) < 0.08)
                        image.at(x, y, 0) = 1.0f;
    return image;
}

struct Shot {
    fs::path dir;
    fs::path scene;
    Shot() {
        dir = fs::temp_directory_path() / ("deformkit-bench-farm-" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
        io::writeObj(dir / "grids.obj", twoTiles());
        io::ImageWriteOptions floats;
        floats.type = io::PixelType::Float;
        io::writeImage(dir / "rig.1001.exr", rigidity(), floats);
        io::writeImage(dir / "rig.1002.exr", rigidity(), floats);
        scene = dir / "shot.json";
        std::ofstream(scene) << R"({"deformkit_scene": 1, "frames": [1, 100], "objects": [
          {"name": "grids", "mesh": "grids.obj", "stack": [
            {"type": "twist", "params": {"handleOrigin": [1.25, 0.5, 0], "handleY": [1.25, 0, 0],
              "endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": 100, "value": 1.2}]}}},
            {"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": {"iterations": 6}}]}]})";
    }
    ~Shot() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

const Shot& shot() {
    static const Shot s;
    return s;
}

void clear(const fs::path& dir, const fs::path& keep = {}) {
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path() != keep) fs::remove_all(entry.path());
}

void BM_FarmRunPlan(benchmark::State& state) {
    harness::FarmPlanCommand plan;
    plan.scene = shot().scene;
    plan.chunk = 10;
    plan.outDir = shot().dir / "farm";
    const scene::FarmPlan made = harness::farmPlanCommand(plan);
    const fs::path planFile = harness::farmPlanPath(plan);
    for (auto _ : state) {
        state.PauseTiming();
        clear(plan.outDir, planFile);
        state.ResumeTiming();
        for (int k = 0; k < static_cast<int>(made.tasks.size()); ++k)
            benchmark::DoNotOptimize(harness::farmRunCommand({planFile, k}).files.size());
    }
    state.counters["tasks"] = static_cast<double>(made.tasks.size());
    state.SetItemsProcessed(state.iterations() * kFrames);
}

void BM_FarmEval(benchmark::State& state) {
    harness::EvalCommand eval;
    eval.scene = shot().scene;
    eval.outDir = shot().dir / "eval";
    eval.previews = false;
    for (auto _ : state) {
        state.PauseTiming();
        fs::remove_all(eval.outDir);
        state.ResumeTiming();
        benchmark::DoNotOptimize(harness::evalCommand(eval).files.size());
    }
    state.SetItemsProcessed(state.iterations() * kFrames);
}

}  // namespace

BENCHMARK(BM_FarmEval)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_FarmRunPlan)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

BENCHMARK_MAIN();
