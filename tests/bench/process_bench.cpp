// A farm task's, a script's and a test's start: the `deformkit` executable run as a process, against
// `/bin/true` run the same way in the same benchmark. BM_ProcessStart times, each as the median of 15 runs
// taken in turn: `/bin/true`, `deformkit --version` (no image: OpenImageIO is not loaded) and `deformkit
// info` of a 4 x 4 PNG (the first image call loads OpenImageIO's module, docs/decisions.md BUILD-4).
// Counters: true_ms, version_ms, image_ms (medians); version_minus_true_ms and image_minus_version_ms (what
// the executable and the image module add); version_ratio_to_true and image_ratio_to_true.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "deformkit/io/image.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Runs `argv` with its output to /dev/null and waits for it; the wall time in ms, or -1 when it fails.
double runMs(const std::vector<std::string>& argv) {
    std::vector<char*> args;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    const auto begin = Clock::now();
    pid_t pid = 0;
    const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0) return -1.0;
    int status = 0;
    if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1.0;
    return std::chrono::duration<double, std::milli>(Clock::now() - begin).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

void BM_ProcessStart(benchmark::State& state) {
    const fs::path dir = fs::temp_directory_path() / ("deformkit_process_bench_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const std::string image = (dir / "tiny.png").string();
    deformkit::io::writeImage(image, deformkit::io::Image(4, 4, 1, 0.5f));
    const std::vector<std::vector<std::string>> commands = {
        {"/bin/true"}, {DEFORMKIT_CLI, "--version"}, {DEFORMKIT_CLI, "info", image}};
    std::vector<std::vector<double>> ms(commands.size());
    for (auto _ : state) {
        for (int run = 0; run < 15; ++run) {
            for (size_t c = 0; c < commands.size(); ++c) {
                const double t = runMs(commands[c]);
                if (t < 0.0) {
                    state.SkipWithError(("failed: " + commands[c][0] + " " + commands[c].back()).c_str());
                    fs::remove_all(dir);
                    return;
                }
                ms[c].push_back(t);
            }
        }
    }
    fs::remove_all(dir);
    const double trueMs = median(ms[0]), versionMs = median(ms[1]), imageMs = median(ms[2]);
    state.counters["true_ms"] = trueMs;
    state.counters["version_ms"] = versionMs;
    state.counters["image_ms"] = imageMs;
    state.counters["version_minus_true_ms"] = versionMs - trueMs;
    state.counters["image_minus_version_ms"] = imageMs - versionMs;
    state.counters["version_ratio_to_true"] = versionMs / trueMs;
    state.counters["image_ratio_to_true"] = imageMs / trueMs;
}

}  // namespace

BENCHMARK(BM_ProcessStart)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

BENCHMARK_MAIN();
