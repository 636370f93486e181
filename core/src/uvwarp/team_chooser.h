#pragma once

// Private to the UV-warp solver: the OpenMP team size of a job repeated many times (an iteration), chosen
// from the job's measured times, so that a solver next to other work (a host's own threads, another
// process holding a core) is never slower with all threads than with one. The results do not depend on
// the team size (every parallel loop of the solver gives the same bytes for any thread count), so the
// choice changes only the time.
//
// The job runs on all threads for its first 8 runs, then once on one thread (if all threads do not get their
// cores, below); from then on on one thread unless all threads' recent time (a running mean) is clearly lower
// (by a fifth: next to other work all threads are about as fast as one in most runs and much slower in a
// few, and a choice that followed the near-ties would pay for those few), the other team being tried again
// now and then to notice a change (a core taken or given back): after 8 runs, then after twice as many each
// time the try confirms the choice (at most 128), and again after 8 once the choice changes. A try costs at
// most one run at the slower size; a short job (a cold frame's few iterations) pays at most 8 runs of all
// threads next to other work, where they are about 1.25 times as slow as one.
//
// One thread is tried only while all threads do not get their cores: their CPU time over a run
// (teamCpuSeconds) below kQuietShare of the team's wall time, as a running mean (UV-35). On a quiet machine
// they get them (0.96 to 1.0 measured; a core another process holds: 0.5 to 0.86) and one thread is about
// twice as slow: a try would cost a live preset's frame about twice its time, now and then, for nothing.

#include <omp.h>
#include <time.h>

#include <algorithm>
#include <cstdint>

namespace deformkit::uvwarp::detail {

class TeamChooser {
  public:
    // The team for the next run, given the most threads the caller allows (omp_get_max_threads()).
    [[nodiscard]] int32_t next(int32_t allowed) {
        allowed = std::max(allowed, 1);
        if (allowed != all_) {  // the caller changed its thread count: time the new size afresh
            all_ = allowed;
            meanAll_ = -1.0;
            sinceTry_ = 0;
            tryEvery_ = kFirstTryEvery;
        }
        if (all_ == 1) return 1;
        if (meanAll_ < 0.0) return all_;
        const bool quiet = meanShare_ >= kQuietShare;  // all threads get their cores: no try of one
        if (meanOne_ < 0.0) return sinceTry_ >= tryEvery_ && !quiet ? 1 : all_;  // first timed after 8 runs
        const int32_t best = chosen();
        if (sinceTry_ >= tryEvery_ && (best == 1 || !quiet))
            return best == 1 ? all_ : 1;  // try the other one
        return best;
    }

    // The time one run took with `team` threads, and (all threads) the share of the team's wall time they
    // ran: their CPU time / (seconds x team), teamCpuSeconds() before and after the run.
    void record(int32_t team, double seconds, double cpuShare) {
        if (all_ == 1) return;
        const bool one = team == 1;
        if (!one) meanShare_ = meanShare_ < 0.0 ? cpuShare : 0.5 * meanShare_ + 0.5 * cpuShare;
        double& mean = one ? meanOne_ : meanAll_;
        const int32_t before = chosen();
        const bool trying = meanAll_ >= 0.0 && meanOne_ >= 0.0 && team != before;
        const bool firstOne = one && meanOne_ < 0.0;
        mean = mean < 0.0 ? seconds : 0.5 * mean + 0.5 * seconds;
        if (trying) {
            sinceTry_ = 0;
            tryEvery_ = chosen() == before ? std::min(2 * tryEvery_, kMaxTryEvery) : kFirstTryEvery;
        } else if (firstOne) {
            sinceTry_ = 0;
        } else {
            ++sinceTry_;
        }
    }

    // The team size the recent times favour (all threads until both have been timed).
    [[nodiscard]] int32_t chosen() const {
        if (meanAll_ < 0.0 || meanOne_ < 0.0) return all_;
        return meanAll_ < kAllFaster * meanOne_ ? all_ : 1;
    }

  private:
    static constexpr int32_t kFirstTryEvery = 8;
    static constexpr int32_t kMaxTryEvery = 128;
    // All threads are chosen when their mean time is below this fraction of one thread's (on a quiet
    // machine it is about 0.55 with 2 threads).
    static constexpr double kAllFaster = 0.8;
    // All threads count as getting their cores from this share of the team's wall time on (running mean).
    static constexpr double kQuietShare = 0.9;
    int32_t all_ = 1;
    double meanShare_ = -1.0;                 // all threads' CPU share; < 0: not measured yet
    double meanAll_ = -1.0, meanOne_ = -1.0;  // seconds per run; < 0: not timed yet
    int32_t sinceTry_ = 0, tryEvery_ = kFirstTryEvery;
};

// The CPU time the threads of the current team (omp_get_max_threads()) have used so far, summed: the
// difference over a run, divided by its wall time and the team size, is the share TeamChooser::record takes.
// The pool's threads run every region of a team of that size, so they are the threads of the run.
inline double teamCpuSeconds() {
    double sum = 0.0;
#pragma omp parallel reduction(+ : sum)
    {
        timespec now{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
        sum += static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
    }
    return sum;
}

}  // namespace deformkit::uvwarp::detail
