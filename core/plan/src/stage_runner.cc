#include "vc/plan/stage_runner.h"

#include <algorithm>
#include <string>

namespace vc::planner {

JobContext StageContext(const JobContext& ctx, Stage stage, double lo, double hi) {
  JobContext sub;
  sub.cancel = ctx.cancel;
  if (ctx.progress) {
    sub.progress = [&ctx, stage, lo, hi](const ProgressEvent& e) {
      ProgressEvent scaled = e;  // the counts describe the step itself
      scaled.stage = stage;
      scaled.fraction = lo + (hi - lo) * std::clamp(e.fraction, 0.0, 1.0);
      ctx.progress(scaled);
    };
  }
  return sub;
}

JobContext ProgressRange(const JobContext& ctx, double lo, double hi) {
  JobContext sub;
  sub.cancel = ctx.cancel;
  if (ctx.progress) {
    sub.progress = [&ctx, lo, hi](const ProgressEvent& e) {
      ProgressEvent scaled = e;
      scaled.fraction = lo + (hi - lo) * std::clamp(e.fraction, 0.0, 1.0);
      ctx.progress(scaled);
    };
  }
  return sub;
}

double StageRunner::elapsed_seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

Status StageRunner::Begin(Stage stage) const {
  ctx_.Report(stage, 0.0);
  return ctx_.CheckCancelled(std::string(StageName(stage)).c_str());
}

void StageRunner::End(Stage stage, Clock::time_point begin, uint64_t peak_rss_bytes) {
  ctx_.Report(stage, 1.0);
  timings_.push_back({stage, std::chrono::duration<double>(Clock::now() - begin).count(), peak_rss_bytes});
}

}  // namespace vc::planner
