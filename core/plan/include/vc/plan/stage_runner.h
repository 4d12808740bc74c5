// One runner for the planning stages (docs/PLANNING.md, "Pipeline").
//
// Every stage of a plan is begun, observed, interrupted and timed the same way, so that no stage
// does it by hand: StageRunner::Run reports the stage at 0, stops with CANCELLED /
// DEADLINE_EXCEEDED naming the stage (StageName) if the job was cancelled before it starts, runs
// the stage with a JobContext whose progress is relabelled to the stage and mapped into [0, 1],
// reports 1 when it succeeded, and records its wall time. A stage that splits its own work maps
// the parts into sub-ranges with ProgressRange. Stages are keyed by vc::Stage, never by a string.
// Each stage's peak resident memory is measured by a ResidentPeakMeter (vc/base/resident_memory.h):
// exact where the stage raised the process's peak (VmHWM), sampled every 10 ms otherwise; process-
// wide, so with several jobs in one process a stage's peak includes what the others hold.
// Thread-compatible: one runner per plan, used from the thread that runs the plan; the contexts it
// hands out forward progress from any thread (the caller's callback must be thread-safe anyway).
#pragma once

#include <chrono>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/resident_memory.h"
#include "vc/base/status.h"

namespace vc {

// How long one stage of a plan took, and the memory the process held at most meanwhile.
struct StageTiming {
  Stage stage = Stage::kUnspecified;
  double seconds = 0;           // wall time from the stage's begin to its end
  uint64_t peak_rss_bytes = 0;  // the process's peak resident memory during the stage, bytes; 0: not measured
};

}  // namespace vc

namespace vc::planner {

// A context sharing ctx's cancel token whose progress reports are relabelled to `stage` and whose
// fractions are clamped to [0, 1] and mapped into [lo, hi]. Must not outlive ctx.
[[nodiscard]] JobContext StageContext(const JobContext& ctx, Stage stage, double lo = 0.0, double hi = 1.0);

// A context for part of a stage: ctx's reports keep their stage, fractions clamped to [0, 1] and
// mapped into [lo, hi]. Must not outlive ctx.
[[nodiscard]] JobContext ProgressRange(const JobContext& ctx, double lo, double hi);

// Runs the stages of one plan in order and times them.
class StageRunner {
 public:
  // Starts the clock of the whole job. ctx must outlive the runner.
  explicit StageRunner(const JobContext& ctx) : ctx_(ctx), start_(Clock::now()) {}

  // Runs fn(stage_ctx) as `stage`: begin report, cancellation check, fn, end report, timing and peak memory.
  // fn returns a Result<T>; its error is returned as it is (no end report, no timing).
  template <typename Fn>
  [[nodiscard]] std::invoke_result_t<Fn&, const JobContext&> Run(Stage stage, Fn&& fn) {
    VC_RETURN_IF_ERROR(Begin(stage));
    ResidentPeakMeter memory;
    const Clock::time_point begin = Clock::now();
    auto out = fn(StageContext(ctx_, stage));
    if (out.ok()) End(stage, begin, memory.Stop());
    return out;
  }

  // The stages that completed, in the order they ran.
  [[nodiscard]] const std::vector<StageTiming>& timings() const { return timings_; }
  // Seconds since the runner was constructed.
  [[nodiscard]] double elapsed_seconds() const;

 private:
  using Clock = std::chrono::steady_clock;
  // Reports `stage` at 0; CANCELLED / DEADLINE_EXCEEDED naming the stage if the job was stopped.
  Status Begin(Stage stage) const;
  // Reports `stage` at 1 and records its time since `begin` and its peak resident memory.
  void End(Stage stage, Clock::time_point begin, uint64_t peak_rss_bytes);

  const JobContext& ctx_;
  Clock::time_point start_;
  std::vector<StageTiming> timings_;
};

}  // namespace vc::planner
