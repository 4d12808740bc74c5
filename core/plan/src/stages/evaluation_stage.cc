#include <mutex>
#include <string>
#include <utility>

#include "format.h"
#include "progress_pacer.h"
#include "vc/base/parallel.h"
#include "vc/plan/stages.h"

namespace vc::planner {

EvaluateOptions StationEvaluateOptions(const PlanOptions& options) {
  EvaluateOptions eval_options;
  eval_options.scanner = options.scanner;
  eval_options.threads = options.threads;
  eval_options.keep_face_values = true;
  return eval_options;
}

uint64_t EvaluationStageBytes(uint64_t voxels, uint64_t stations, int threads) {
  const uint64_t own =
      EvaluateWorkingBytes(voxels) + voxels * (sizeof(int32_t) + kFacesPerVoxel * sizeof(float) + sizeof(WorldPoint));
  // vc::Evaluate gives each extra thread its own best values and sole viewers while they take at
  // most 256 MiB in all (kEvaluateExtraWorkBytes in evaluate.cc); charged whenever they may.
  const uint64_t workers = static_cast<uint64_t>(ResolveThreads(threads, std::max<uint64_t>(stations, 1)));
  const uint64_t extra =
      (workers - 1) * voxels * (kFacesPerVoxel * (sizeof(double) + sizeof(uint8_t)) + sizeof(int32_t));
  return own + (extra <= (uint64_t{256} << 20) ? extra : 0);
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
    const uint64_t need = EvaluationStageBytes(n_voxels, in.positions.size(), options.threads);
    if (need > options.memory_budget_bytes) {  // refused before anything is allocated
      return ResourceExhaustedError("evaluation: evaluating the " + std::to_string(in.positions.size()) +
                                    " final stations on " + std::to_string(n_voxels) + " voxels takes " +
                                    std::to_string(need) + " bytes, over the memory budget (" +
                                    std::to_string(options.memory_budget_bytes) + " bytes); a memory budget of " +
                                    Num(need / 1048576.0) + " MiB or more (--memory-budget-bytes " +
                                    std::to_string(need) + ") plans it, or a coarser resolution_m has fewer voxels");
    }
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
