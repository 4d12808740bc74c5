// Cancellation and progress reporting for long-running core work.
//
// A CancelToken is shared between the caller (e.g. an RPC whose client went away) and the core
// loop, which polls it often enough that a cancelled job stops within about a second. Progress is a
// plain callback; the core calls it from worker threads, at most a few hundred times per stage, so
// the callback must be thread-safe and cheap (the server forwards it to a queue).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "vc/base/status.h"

namespace vc {

// Thread-safe. Cancelled once Cancel() was called or the deadline (if any) passed.
class CancelToken {
 public:
  CancelToken() = default;
  void Cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  void SetDeadline(std::chrono::steady_clock::time_point deadline) { deadline_ = deadline; }
  bool cancelled() const;
  // OK, or CANCELLED / DEADLINE_EXCEEDED naming `what` was interrupted.
  Status Check(const char* what) const;

 private:
  std::atomic<bool> cancelled_{false};
  std::optional<std::chrono::steady_clock::time_point> deadline_;
};

// The stages of a job, in the order a plan runs them. An Evaluate job runs kRead, kVoxelize and
// kEvaluation. The names (StageName) appear in progress lines, logs and plan.json's timings.
enum class Stage : uint8_t {
  kUnspecified = 0,
  kRead,        // parse the uploaded bytes
  kVoxelize,    // points or octree leaves to the working voxel grid
  kCandidates,  // candidate tripod positions on the operating plane
  kVisibility,  // each candidate's visibility set (the heat map)
  kSelection,   // choose stations (Selector: lazy greedy, then consolidation)
  kRefine,      // move each station to the best position of a sub-grid around it
  kReduction,   // remove redundant stations (the reduction matrix)
  kEvaluation,  // V of every face from the final stations, and G
  kRoute,       // the walking route through the final stations
};
inline constexpr Stage kAllStages[] = {Stage::kRead,       Stage::kVoxelize,   Stage::kCandidates,
                                       Stage::kVisibility, Stage::kSelection,  Stage::kRefine,
                                       Stage::kReduction,  Stage::kEvaluation, Stage::kRoute};
// "read", "voxelize", "candidates", "visibility", "selection", "refine", "reduction", "evaluation",
// "route"; "unspecified" for kUnspecified.
std::string_view StageName(Stage stage);

// One progress report: `fraction` of `stage` done, in [0,1], and an optional human-readable note.
struct ProgressEvent {
  Stage stage = Stage::kUnspecified;
  double fraction = 0.0;
  std::string message;
  // What was counted, when the work is countable: `done` of `total` `unit`s (e.g. 412 of 858
  // "candidates"); total 0 when the total is not known in advance (selection: stations picked so
  // far); unit empty when nothing was counted. A client derives the rate and the time left from it.
  uint64_t done = 0;
  uint64_t total = 0;
  std::string unit;
};

using ProgressFn = std::function<void(const ProgressEvent&)>;

// What long-running core calls take to be interruptible and observable. Both members optional.
struct JobContext {
  const CancelToken* cancel = nullptr;
  ProgressFn progress;

  Status CheckCancelled(const char* what) const { return cancel ? cancel->Check(what) : Status::Ok(); }
  void Report(Stage stage, double fraction, std::string message = {}) const {
    if (progress) progress(ProgressEvent{stage, fraction, std::move(message), 0, 0, {}});
  }
  // `done` of `total` `unit`s, the fraction done / total (0 when total is 0).
  void ReportCount(Stage stage, uint64_t done, uint64_t total, std::string unit, std::string message = {}) const {
    if (!progress) return;
    const double fraction = total > 0 ? double(std::min(done, total)) / double(total) : 0.0;
    progress(ProgressEvent{stage, fraction, std::move(message), done, total, std::move(unit)});
  }
};

}  // namespace vc
