#include <mutex>
#include <string>
#include <utility>

#include "progress_pacer.h"
#include "vc/plan/stages.h"

namespace vc::planner {

EvaluateOptions StationEvaluateOptions(const PlanOptions& options) {
  EvaluateOptions eval_options;
  eval_options.scanner = options.scanner;
  eval_options.threads = options.threads;
  eval_options.keep_face_values = true;
  return eval_options;
}

Result<EvaluationOutput> RunEvaluationStage(EvaluationInput in, const PlanOptions& options, const JobContext& ctx) {
  const size_t n_voxels = in.scene.occupied.size();
  EvaluationOutput out;
  if (in.positions.empty()) {
    out.warnings.push_back("no station was selected: no candidate sees any occupied voxel by the " +
                           std::string(SelectionTestName(options.selection_test)) + " test");
    out.evaluation.resolution_m = in.scene.resolution_m;
    out.evaluation.faces_total = n_voxels * kFacesPerVoxel;
    out.evaluation.best_face_values.assign(n_voxels, {});
    out.evaluation.sole_viewer.assign(n_voxels, kNoViewer);
  } else if (in.reusable) {
    out.evaluation = std::move(*in.reusable);  // same stations, nothing was removed
  } else {
    // Evaluate reports stations evaluated; each report gets the time left at the rate so far
    // (none before the first station), at most once a second besides the last.
    JobContext sub = ctx;
    internal::ProgressPacer pacer;
    std::mutex pacer_mutex;
    if (ctx.progress) {
      sub.progress = [&](const ProgressEvent& e) {
        std::lock_guard<std::mutex> lock(pacer_mutex);
        if (!(pacer.Due() || e.done >= e.total)) return;
        ProgressEvent paced = e;
        if (paced.message.empty()) paced.message = pacer.TimeLeft(e.done, e.total);
        ctx.progress(paced);
      };
    }
    VC_ASSIGN_OR_RETURN(out.evaluation, Evaluate(in.scene, in.positions, StationEvaluateOptions(options), sub));
  }
  out.voxel_centers.reserve(n_voxels);
  for (size_t i = 0; i < n_voxels; ++i) out.voxel_centers.push_back(in.scene.Center(i));
  return out;
}

}  // namespace vc::planner
