// OBJ reading throughput against the reference of reading the same file's bytes into a string
// (scripts/bench_table.py prints the ratio). The input is the demo asset (makeCappedTube, 22,242
// vertices, with UVs), written once to a temporary file.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "deformkit/geom/primitives.h"
#include "deformkit/io/obj.h"

namespace {

namespace fs = std::filesystem;

class ObjInput {
  public:
    ObjInput()
        : path_(fs::temp_directory_path() / ("deformkit-obj-bench-" + std::to_string(::getpid()) + ".obj")),
          text_(deformkit::io::formatObj(deformkit::geom::makeCappedTube())) {
        deformkit::io::writeObj(path_, deformkit::geom::makeCappedTube());
    }
    ~ObjInput() {
        std::error_code ec;
        fs::remove(path_, ec);
    }
    ObjInput(const ObjInput&) = delete;
    ObjInput& operator=(const ObjInput&) = delete;

    [[nodiscard]] const fs::path& path() const { return path_; }
    [[nodiscard]] const std::string& text() const { return text_; }

  private:
    fs::path path_;
    std::string text_;
};

const ObjInput& input() {
    static const ObjInput instance;
    return instance;
}

void BM_PlainRead(benchmark::State& state) {
    const ObjInput& in = input();
    for (auto _ : state) {
        std::ifstream file(in.path(), std::ios::binary | std::ios::ate);
        std::string bytes(static_cast<size_t>(file.tellg()), '\0');
        file.seekg(0);
        file.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        benchmark::DoNotOptimize(bytes.data());
    }
    state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(in.text().size()));
}

void BM_ObjRead(benchmark::State& state) {
    const ObjInput& in = input();
    for (auto _ : state) {
        const auto content = deformkit::io::readObj(in.path());
        benchmark::DoNotOptimize(content.mesh.points().data());
    }
    state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(in.text().size()));
}

void BM_ObjParse(benchmark::State& state) {
    const ObjInput& in = input();
    for (auto _ : state) {
        const auto content = deformkit::io::parseObj(in.text(), "bench.obj");
        benchmark::DoNotOptimize(content.mesh.points().data());
    }
    state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(in.text().size()));
}

}  // namespace

BENCHMARK(BM_PlainRead)->Unit(benchmark::kMicrosecond)->MinTime(0.2);
BENCHMARK(BM_ObjRead)->Unit(benchmark::kMillisecond)->MinTime(0.2);
BENCHMARK(BM_ObjParse)->Unit(benchmark::kMillisecond)->MinTime(0.2);

BENCHMARK_MAIN();
