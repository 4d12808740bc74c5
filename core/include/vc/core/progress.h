// Cancellation and progress reporting for long-running core work.
//
// A CancelToken is shared between the caller (e.g. an RPC whose client went away) and the core
// loop, which polls it often enough that a cancelled job stops within about a second. Progress is a
// plain callback; the core calls it from worker threads, at most a few hundred times per stage, so
// the callback must be thread-safe and cheap (the server forwards it to a queue).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "vc/core/status.h"

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

// One progress report: `stage` (e.g. "compatibility"), fraction of that stage done in [0,1].
struct ProgressEvent {
  std::string stage;
  double fraction = 0.0;
  std::string message;
};

using ProgressFn = std::function<void(const ProgressEvent&)>;

// What long-running core calls take to be interruptible and observable. Both members optional.
struct JobContext {
  const CancelToken* cancel = nullptr;
  ProgressFn progress;

  Status CheckCancelled(const char* what) const {
    return cancel ? cancel->Check(what) : Status::Ok();
  }
  void Report(const std::string& stage, double fraction, std::string message = {}) const {
    if (progress) progress(ProgressEvent{stage, fraction, std::move(message)});
  }
};

}  // namespace vc
