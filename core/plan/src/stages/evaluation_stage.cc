#include <string>
#include <utility>

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
    VC_ASSIGN_OR_RETURN(out.evaluation, Evaluate(in.scene, in.positions, StationEvaluateOptions(options), ctx));
  }
  out.voxel_centers.reserve(n_voxels);
  for (size_t i = 0; i < n_voxels; ++i) out.voxel_centers.push_back(in.scene.Center(i));
  return out;
}

}  // namespace vc::planner
