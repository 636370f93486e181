#pragma once

#include <chrono>
#include <cstdint>
#include <ostream>
#include <string_view>

#include "deformkit/interrupter.h"

namespace deformkit::harness {

// A library job's progress as one line redrawn in place ("uvwarp [####----] 12/48  tile 1001 frame 12
// written  elapsed 0:41  ETA 2:03"), for a person watching a terminal. The ETA extrapolates the time per
// unit done so far. Never cancels.
class ProgressBar final : public Interrupter {
  public:
    explicit ProgressBar(std::ostream& out) : out_(out) {}

    void start(std::string_view name, int64_t total) override;
    void end() override;
    bool wasInterrupted(int64_t done, int64_t total, std::string_view unit) override;

  private:
    std::ostream& out_;
    std::string name_;
    std::chrono::steady_clock::time_point start_;
    bool drawn_ = false;
};

}  // namespace deformkit::harness
