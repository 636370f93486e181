// The row-block wavefront of the UV-warp solver's sweeps and regularisation (row_wavefront.h): every pass
// runs the even row blocks, then the odd ones, and a block's rows read and write rows of its two
// neighbouring blocks, so a block may run only when its neighbours have done exactly what the serial order
// has them do by then: in pass p, an even block's neighbours p passes, an odd block's p + 1. Each row checks
// that of its neighbours' rows, on two and three threads, with rows delayed at random so that the threads
// interleave differently from run to run; a wavefront that let a block start early or let a neighbour run
// beside it fails here.
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "uvwarp/row_wavefront.h"

namespace {

using deformkit::uvwarp::detail::forRowBlocks;
using deformkit::uvwarp::detail::kParallelWavefrontRows;
using deformkit::uvwarp::detail::mostWavefrontBlocks;
using deformkit::uvwarp::detail::wavefrontBlockRows;

struct Run {
    int64_t rowsRun = 0;
    int64_t outOfOrder = 0;  // rows whose neighbouring blocks were not where the serial order has them
    std::vector<int32_t> passesOfRow;
};

// flags: the wavefront's per-block flags, by default as many as it may need.
Run runWavefront(int32_t first, int32_t last, int32_t passes, int32_t threads, uint32_t seed,
                 int32_t flags = -1) {
    const int32_t rows = last - first;
    const int32_t blockRows = wavefrontBlockRows(rows);
    const int32_t blocks = (rows + blockRows - 1) / blockRows;
    std::vector<std::atomic<int32_t>> visits(static_cast<size_t>(rows));
    for (auto& v : visits)
        v.store(0);
    std::atomic<int64_t> rowsRun{0}, outOfOrder{0};
    const auto rowFn = [&](int32_t j) {
        const int32_t r = j - first;
        const int32_t b = r / blockRows;
        const int32_t pass = visits[static_cast<size_t>(r)].load();
        const int32_t expected = pass + (b % 2 == 1 ? 1 : 0);  // passes of the neighbouring blocks
        for (int32_t nb : {b - 1, b + 1}) {
            if (nb < 0 || nb >= blocks) continue;
            for (int32_t k = nb * blockRows; k < std::min(rows, (nb + 1) * blockRows); ++k)
                if (visits[static_cast<size_t>(k)].load() != expected) ++outOfOrder;
        }
        // A delay on some rows (a hash of row, pass and seed), so that neighbours would overlap if allowed.
        uint32_t h = (static_cast<uint32_t>(j) * 2654435761u) ^ (static_cast<uint32_t>(pass) * 40503u) ^ seed;
        h ^= h >> 15;
        h *= 2246822519u;
        h ^= h >> 13;
        if (h % 5 == 0) std::this_thread::sleep_for(std::chrono::microseconds(h % 40));
        visits[static_cast<size_t>(r)].store(pass + 1);
        ++rowsRun;
    };
    std::vector<std::atomic<int32_t>> done(
        static_cast<size_t>(flags < 0 ? mostWavefrontBlocks(rows) : flags));
    const int32_t before = omp_get_max_threads();
    omp_set_num_threads(threads);
    forRowBlocks(first, last, passes, done, rowFn);
    omp_set_num_threads(before);
    Run run;
    run.rowsRun = rowsRun.load();
    run.outOfOrder = outOfOrder.load();
    for (auto& v : visits)
        run.passesOfRow.push_back(v.load());
    return run;
}

}  // namespace

TEST_CASE("row wavefront: every block runs where the serial order has its neighbours", "[wavefront]") {
    struct Case {
        int32_t first, last, passes;
    };
    // Parallel sizes (over kParallelWavefrontRows rows): 2-row blocks with an odd last block, 2-row blocks
    // with an even count, 4-row blocks with a short last one, 16-row blocks; the regularisation's first = 1.
    const Case cases[] = {{0, 33, 3}, {0, 64, 4}, {1, 64, 1}, {0, 259, 2}, {0, 1024, 1}, {1, 97, 5}};
    uint32_t seed = 1;
    for (const Case& c : cases) {
        REQUIRE(c.last - c.first > kParallelWavefrontRows);
        for (int32_t threads : {2, 3}) {
            for (int32_t repeat = 0; repeat < 3; ++repeat) {
                INFO("rows " << c.first << ".." << c.last << ", " << c.passes << " passes, " << threads
                             << " threads, seed " << seed);
                const Run run = runWavefront(c.first, c.last, c.passes, threads, seed++);
                CHECK(run.outOfOrder == 0);
                CHECK(run.rowsRun == static_cast<int64_t>(c.passes) * (c.last - c.first));
                CHECK(std::count(run.passesOfRow.begin(), run.passesOfRow.end(), c.passes) ==
                      static_cast<int64_t>(run.passesOfRow.size()));
            }
        }
    }
}

TEST_CASE("row wavefront: serial sizes and one thread keep the serial order", "[wavefront]") {
    // 32 rows run serially whatever the threads; and 128 rows on one thread.
    CHECK(runWavefront(0, 32, 3, 2, 7).outOfOrder == 0);
    CHECK(runWavefront(0, 128, 3, 1, 8).outOfOrder == 0);
    // Called from inside another parallel region (nested parallelism off: the inner team has one thread,
    // though omp_get_max_threads() may say more): the tasks run in order on that thread, nothing waits.
    int64_t nestedOutOfOrder = 0, nestedRows = 0, outerThreads = 0;
#pragma omp parallel num_threads(2) reduction(+ : nestedOutOfOrder, nestedRows, outerThreads)
    {
        ++outerThreads;
        const Run run = runWavefront(0, 96, 2, 2, 11u + static_cast<uint32_t>(omp_get_thread_num()));
        nestedOutOfOrder += run.outOfOrder;
        nestedRows += run.rowsRun;
    }
    CHECK(nestedOutOfOrder == 0);
    CHECK(nestedRows == 2 * 96 * outerThreads);
    // Too few flags for the blocks: the blocks run serially, in order.
    const Run fewFlags = runWavefront(0, 128, 2, 2, 12, 10);
    CHECK(fewFlags.outOfOrder == 0);
    CHECK(fewFlags.rowsRun == 256);
    // No passes, or no rows: nothing runs.
    CHECK(runWavefront(0, 64, 0, 2, 9).rowsRun == 0);
    CHECK(runWavefront(5, 5, 2, 2, 10).rowsRun == 0);
}
