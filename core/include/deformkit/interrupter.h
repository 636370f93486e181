#pragma once

#include <cstdint>
#include <string_view>

#include "deformkit/error.h"

namespace deformkit {

// Progress and cancellation of a long library job (a shot of UV-warp tiles, a farm task), in the style of
// OpenVDB's interrupter. A job calls start() once, wasInterrupted() after every unit of work, and end() once
// (also when it fails), all from the thread that called the job. A host derives from it to draw a progress
// bar or to let a user cancel; the default does neither.
class Interrupter {
  public:
    virtual ~Interrupter() = default;

    // The job `name` ("uvwarp") begins with `total` units of work.
    virtual void start(std::string_view name, int64_t total) {
        (void)name;
        (void)total;
    }
    // The job ended, finished, cancelled or failed.
    virtual void end() {}
    // `done` of the job's `total` units are finished; `unit` says what the last one was ("tile 1001 frame
    // 12 written"). Returning true cancels the job: it stops before its next unit and throws Cancelled.
    virtual bool wasInterrupted(int64_t done, int64_t total, std::string_view unit) {
        (void)done;
        (void)total;
        (void)unit;
        return false;
    }
};

// A job's start() and end() around a scope: start() at construction, end() when the scope is left
// (finished, cancelled or failed). Both are skipped for a null interrupter.
class InterrupterScope {
  public:
    InterrupterScope(Interrupter* interrupter, std::string_view name, int64_t total)
        : interrupter_(interrupter) {
        if (interrupter_) interrupter_->start(name, total);
    }
    ~InterrupterScope() {
        if (interrupter_) interrupter_->end();
    }
    InterrupterScope(const InterrupterScope&) = delete;
    InterrupterScope& operator=(const InterrupterScope&) = delete;

  private:
    Interrupter* interrupter_;
};

// A job stopped because its Interrupter asked it to. Every output it wrote is complete (outputs are written
// atomically), so a rerun resumes where it stopped.
class Cancelled : public Error {
  public:
    using Error::Error;
};

}  // namespace deformkit
