// Pacing of progress reports from loops whose items are cheap but whose passes may run for minutes
// (consolidation, the voxel classes, the model reduction): a report is due at most once per
// interval of a steady clock, never per item, and the time left is estimated from the rate so far.
// Not thread-safe: one pacer per loop.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace vc::planner::internal {

class ProgressPacer {
 public:
  using Clock = std::chrono::steady_clock;
  // Reports due every `interval` (default one second), the first at once.
  explicit ProgressPacer(Clock::duration interval = std::chrono::seconds(1))
      : interval_(interval), start_(Clock::now()), last_(start_ - interval) {}
  // Whether a report is due now; if so, the next one is due one interval later.
  bool Due() {
    const Clock::time_point now = Clock::now();
    if (now - last_ < interval_) return false;
    last_ = now;
    return true;
  }
  // Restarts the rate measurement (a new pass over `total` items begins).
  void Restart() { start_ = Clock::now(); }
  // "~40 s left" at the rate since the last Restart, for `done` of `total` items; empty before
  // anything was done.
  std::string TimeLeft(uint64_t done, uint64_t total) const {
    if (done == 0 || done >= total) return {};
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - start_).count();
    const double left_s = elapsed_s * double(total - done) / double(done);
    char text[48];
    if (left_s < 120) {
      std::snprintf(text, sizeof text, "~%.0f s left", left_s);
    } else {
      std::snprintf(text, sizeof text, "~%.0f min left", left_s / 60);
    }
    return text;
  }

 private:
  Clock::duration interval_;
  Clock::time_point start_, last_;
};

}  // namespace vc::planner::internal
