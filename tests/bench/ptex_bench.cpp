// Ptex speed, each against an in-run reference (scripts/bench_table.py prints the ratios):
// - reading a 50,176-face float RGB file (8 x 8 texels a face, smooth content: every face zipped) against a
//   plain read of the file's bytes and a plain zlib inflate of the same texels compressed as one stream;
//   writing it against zlib alone deflating the same texels as one stream;
// - per-vertex values of a 1,002,001-vertex quad grid (1-channel float, 4 x 4 a face) against a minimal
//   loop over the same corner texels; and filtered look-ups at random points.

#include <benchmark/benchmark.h>

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "deformkit/geom/primitives.h"
#include "deformkit/io/read_file.h"
#include "deformkit/ptex/ptex_file.h"
#include "deformkit/ptex/ptex_mesh.h"

namespace fs = std::filesystem;
using namespace deformkit;

namespace {

struct ReadFixture {
    fs::path path;
    size_t texelBytes = 0;
    std::vector<uint8_t> raw;       // every face's texels, one after the other
    std::vector<uint8_t> deflated;  // `raw` as one zlib stream, at the writer's level

    ReadFixture() {
        constexpr int kSide = 224;  // 224^2 = 50,176 faces
        ptex::PtexFile file;
        file.dataType = ptex::DataType::Float;
        file.channels = 3;
        file.faces.resize(kSide * kSide);
        file.texels.resize(file.faces.size());
        file.constData.assign(file.faces.size() * file.pixelSize(), 0);
        for (int f = 0; f < kSide * kSide; ++f) {
            file.faces[f].ulog2 = file.faces[f].vlog2 = 3;
            std::vector<uint8_t>& t = file.texels[f];
            t.resize(64 * 3 * 4);
            for (int j = 0; j < 8; ++j)
                for (int i = 0; i < 8; ++i) {
                    const double x = (f % kSide) + (i + 0.5) / 8, y = (f / kSide) + (j + 0.5) / 8;
                    const float rgb[3] = {static_cast<float>(0.5 + 0.5 * std::sin(0.05 * x)),
                                          static_cast<float>(0.5 + 0.5 * std::cos(0.07 * y)),
                                          static_cast<float>(0.5 + 0.25 * std::sin(0.03 * (x + y)))};
                    std::memcpy(t.data() + 12 * (j * 8 + i), rgb, 12);
                }
            raw.insert(raw.end(), t.begin(), t.end());
        }
        texelBytes = raw.size();
        path = fs::temp_directory_path() / ("deformkit-bench-" + std::to_string(::getpid()) + ".ptx");
        ptex::writePtex(path, file);
        uLongf size = compressBound(raw.size());
        deflated.resize(size);
        compress2(deflated.data(), &size, raw.data(), raw.size(), ptex::WriteOptions{}.compressionLevel);
        deflated.resize(size);
    }
    ~ReadFixture() {
        std::error_code ec;
        fs::remove(path, ec);
    }
};

ReadFixture& readFixture() {
    static ReadFixture fixture;
    return fixture;
}

void BM_PtexRead(benchmark::State& state) {
    ReadFixture& f = readFixture();
    for (auto _ : state) {
        ptex::PtexFile file = ptex::readPtex(f.path);
        benchmark::DoNotOptimize(file.texels.data());
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * f.texelBytes));
    state.counters["file_MB"] = static_cast<double>(fs::file_size(f.path)) / 1e6;
}
BENCHMARK(BM_PtexRead)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PtexPlainRead(benchmark::State& state) {
    ReadFixture& f = readFixture();
    for (auto _ : state) {
        std::string bytes = io::readFile(f.path, "Ptex file");
        benchmark::DoNotOptimize(bytes.data());
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * f.texelBytes));
}
BENCHMARK(BM_PtexPlainRead)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PtexZlibInflate(benchmark::State& state) {
    ReadFixture& f = readFixture();
    std::vector<uint8_t> out(f.raw.size());
    for (auto _ : state) {
        uLongf size = out.size();
        uncompress(out.data(), &size, f.deflated.data(), f.deflated.size());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * f.texelBytes));
}
BENCHMARK(BM_PtexZlibInflate)->Unit(benchmark::kMillisecond)->UseRealTime();

// Writing the same file (level 0 and its reductions, zipped face by face) against zlib alone deflating the
// same texels as one stream: what the writer adds to compression (reductions, planes, headers, zlib
// blocks per face).
void BM_PtexWrite(benchmark::State& state) {
    ReadFixture& f = readFixture();
    const ptex::PtexFile file = ptex::readPtex(f.path);
    for (auto _ : state) {
        std::vector<uint8_t> bytes = ptex::writePtexBytes(file);
        benchmark::DoNotOptimize(bytes.data());
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * f.texelBytes));
}
BENCHMARK(BM_PtexWrite)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PtexZlibDeflate(benchmark::State& state) {
    ReadFixture& f = readFixture();
    std::vector<uint8_t> out(compressBound(f.raw.size()));
    for (auto _ : state) {
        uLongf size = out.size();
        compress2(out.data(), &size, f.raw.data(), f.raw.size(), ptex::WriteOptions{}.compressionLevel);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * f.texelBytes));
}
BENCHMARK(BM_PtexZlibDeflate)->Unit(benchmark::kMillisecond)->UseRealTime();

struct MeshFixture {
    geom::Mesh mesh = geom::makeGrid({1000, 1000, 1.0f, 1.0f});
    ptex::PtexMesh ptexMesh{mesh, "grid"};
    ptex::PtexFile file;
    MeshFixture() {
        std::vector<float> values(static_cast<size_t>(mesh.numVertices()));
        for (size_t v = 0; v < values.size(); ++v)
            values[v] = mesh.points()[v].x * mesh.points()[v].y;
        file = ptex::bakeVertexValues(ptexMesh, values, 1, {2, 2, ptex::DataType::Float});
    }
};

MeshFixture& meshFixture() {
    static MeshFixture fixture;
    return fixture;
}

void BM_PtexVertexValues(benchmark::State& state) {
    MeshFixture& f = meshFixture();
    for (auto _ : state) {
        std::vector<float> values = ptex::vertexValues(f.ptexMesh, f.file, "bench");
        benchmark::DoNotOptimize(values.data());
    }
    state.SetItemsProcessed(state.iterations() * f.mesh.numVertices());
}
BENCHMARK(BM_PtexVertexValues)->Unit(benchmark::kMillisecond)->UseRealTime();

// The least work that gives the same values: each quad's four corner floats added to its vertices, then
// divided by the counts (no checks, no data types, no sub-faces).
void BM_PtexCornerLoop(benchmark::State& state) {
    MeshFixture& f = meshFixture();
    const int32_t n = f.mesh.numVertices();
    const auto indices = f.mesh.faceIndices();
    for (auto _ : state) {
        std::vector<double> sum(static_cast<size_t>(n), 0.0);
        std::vector<int32_t> count(static_cast<size_t>(n), 0);
        for (int32_t face = 0; face < f.mesh.numFaces(); ++face) {
            const auto* t = reinterpret_cast<const float*>(f.file.texels[face].data());
            const float corner[4] = {t[0], t[3], t[15], t[12]};
            for (int k = 0; k < 4; ++k) {
                sum[indices[4 * face + k]] += corner[k];
                ++count[indices[4 * face + k]];
            }
        }
        std::vector<float> values(static_cast<size_t>(n));
        for (int32_t v = 0; v < n; ++v)
            values[v] = count[v] ? static_cast<float>(sum[v] / count[v]) : 0.0f;
        benchmark::DoNotOptimize(values.data());
    }
    state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_PtexCornerLoop)->Unit(benchmark::kMillisecond)->UseRealTime();

// One million filtered look-ups at random (face, u, v) of the same file, the sampler built once.
void BM_PtexSample(benchmark::State& state) {
    MeshFixture& f = meshFixture();
    static const ptex::PtexSampler sampler(f.file, "bench");
    std::mt19937 rng(7);
    std::uniform_int_distribution<int32_t> face(0, sampler.numFaces() - 1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<std::tuple<int32_t, double, double>> points(1'000'000);
    for (auto& p : points)
        p = {face(rng), unit(rng), unit(rng)};
    for (auto _ : state) {
        float sum = 0.0f, value = 0.0f;
        for (const auto& [p, u, v] : points) {
            sampler.sample(p, u, v, std::span<float>(&value, 1));
            sum += value;
        }
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(points.size()));
}
BENCHMARK(BM_PtexSample)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
