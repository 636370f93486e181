#pragma once

// Private to the UV-warp solver: the row-block wavefront its sweeps and regularisation run on. The same
// bytes for any thread count.

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <span>
#include <thread>

#include "solver_state.h"

namespace deformkit::uvwarp::detail {

// The most row blocks a wavefront over at most `rows` rows has (blocks have at least 2 rows).
[[nodiscard]] constexpr int32_t mostWavefrontBlocks(int32_t rows) {
    return rows <= 0 ? 0 : (rows + 1) / 2;
}

// A task waiting for a neighbouring block spins a little (a block takes microseconds), then yields the core:
// next to other work the thread it waits for may need it.
constexpr int32_t kSpinsBeforeYield = 256;
inline void waitAWhile(int32_t spins) {
    if (spins < kSpinsBeforeYield) {
#if defined(__x86_64__) || defined(__i386__)
        __builtin_ia32_pause();
#endif
    } else {
        std::this_thread::yield();
    }
}

// Runs rowFn(j) for j in [first, last), `passes` times over: each pass in blocks of wavefrontBlockRows rows,
// even blocks, then odd ones, the results those of that order (a block reads and writes only rows of its own
// and its two neighbours). In parallel the blocks are tasks handed out in that order, and a task waits only
// for its two neighbours to have finished the phase before it (a phase: one parity of one pass), not for the
// whole phase: one parallel region for all the passes, no barrier between them, and a pass may start while
// the last blocks of the one before are still being swept (docs/decisions.md UV-29). `done` holds a flag per
// block, mostWavefrontBlocks(last - first) of them will do (the caller's, so that a solve allocates nothing;
// with fewer the blocks run serially, the same bytes).
template <class RowFn>
void forRowBlocks(int32_t first, int32_t last, int32_t passes, std::span<std::atomic<int32_t>> done,
                  const RowFn& rowFn) {
    const int32_t rows = last - first;
    if (rows <= 0 || passes <= 0) return;
    const int32_t blockRows = wavefrontBlockRows(rows);
    const int32_t blocks = (rows + blockRows - 1) / blockRows;
    const auto runBlock = [&](int32_t b) {
        const int32_t end = std::min(last, first + (b + 1) * blockRows);
        for (int32_t j = first + b * blockRows; j < end; ++j)
            rowFn(j);
    };
    if (rows <= kParallelWavefrontRows || omp_get_max_threads() == 1 || blocks < 2 ||
        done.size() < static_cast<size_t>(blocks)) {
        for (int32_t pass = 0; pass < passes; ++pass)
            for (int32_t parity = 0; parity < 2; ++parity)
                for (int32_t b = parity; b < blocks; b += 2)
                    runBlock(b);
        return;
    }
    // done[b]: the last phase block b finished (-1: none). Block b's phases have its parity.
    for (int32_t b = 0; b < blocks; ++b)
        done[static_cast<size_t>(b)].store(-1, std::memory_order_relaxed);
    std::atomic<int64_t> nextTask{0};
    const int32_t evenBlocks = (blocks + 1) / 2;
    const int64_t tasks = static_cast<int64_t>(passes) * blocks;
    const auto reached = [&](int32_t b, int32_t phase) {
        return b < 0 || b >= blocks || done[static_cast<size_t>(b)].load(std::memory_order_acquire) >= phase;
    };
#pragma omp parallel
    for (;;) {
        // Tasks in the serial order: a task waits only for earlier ones, which are finished or running.
        const int64_t task = nextTask.fetch_add(1, std::memory_order_relaxed);
        if (task >= tasks) break;
        const auto pass = static_cast<int32_t>(task / blocks);
        const auto inPass = static_cast<int32_t>(task % blocks);
        const int32_t parity = inPass < evenBlocks ? 0 : 1;
        const int32_t b = parity == 0 ? 2 * inPass : 2 * (inPass - evenBlocks) + 1;
        const int32_t phase = 2 * pass + parity;
        for (int32_t spins = 0; !(reached(b - 1, phase - 1) && reached(b + 1, phase - 1)); ++spins)
            waitAWhile(spins);
        runBlock(b);
        done[static_cast<size_t>(b)].store(phase, std::memory_order_release);
    }
}

}  // namespace deformkit::uvwarp::detail
