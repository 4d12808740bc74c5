#include "vc/plan/evaluate_job.h"

#include <string>
#include <vector>

namespace vc {

Status EvaluateJobOptions::Validate(const FieldNamer& namer) const {
  if (viewpoints.empty()) {
    return InvalidArgumentError("no viewpoint to evaluate; give at least one (e.g. --viewpoints stations.csv)");
  }
  for (size_t i = 0; i < viewpoints.size(); ++i) {
    if (!viewpoints[i].allFinite()) {
      return InvalidArgumentError("viewpoint " + std::to_string(i) + " has a non-finite coordinate");
    }
  }
#define VC_CHECK_ROW(type, row, ...) \
  VC_RETURN_IF_ERROR(CheckNamedParameter(VC_PARAMETER_INFO(type, row, __VA_ARGS__), row, namer));
  VC_EVALUATE_PARAMETERS(VC_CHECK_ROW)
#undef VC_CHECK_ROW
  VC_RETURN_IF_ERROR(scanner.Validate(namer));
  if (scanner.HasHorizontalFieldOfView()) {
    return InvalidArgumentError(NameOf(namer, "scanner.hfov_deg") + " is " + std::to_string(scanner.hfov_deg) +
                                " deg, but evaluated viewpoints carry no heading; leave hfov_deg at 360");
  }
  return Status::Ok();
}

VoxelizeOptions EvaluateJobOptions::voxelize_options() const { return {resolution_m, memory_budget_bytes}; }

EvaluateOptions EvaluateJobOptions::evaluate_options() const {
  EvaluateOptions o;
  o.scanner = scanner;
  o.faces = faces;
  o.threads = threads;
  o.sample_faces = sample_faces;
  o.seed = seed;
  o.keep_face_values = sample_faces == 0;
  return o;
}

Result<EvaluateJobResult> RunEvaluation(const SceneInput& input, const EvaluateJobOptions& options,
                                        const JobContext& ctx) {
  VC_RETURN_IF_ERROR(options.Validate());
  VC_ASSIGN_OR_RETURN(VoxelScene scene, Voxelize(input, options.voxelize_options(), ctx));
  std::vector<WorldPoint> local_viewpoints = options.viewpoints;
  for (WorldPoint& p : local_viewpoints) p -= input.frame_origin_m;
  EvaluateJobResult result;
  VC_ASSIGN_OR_RETURN(result.evaluation, Evaluate(scene, local_viewpoints, options.evaluate_options(), ctx));
  result.viewpoints = options.viewpoints;
  result.voxel_centers.reserve(scene.occupied.size());
  for (size_t id = 0; id < scene.occupied.size(); ++id) result.voxel_centers.push_back(scene.Center(id));
  result.frame_origin_m = scene.frame_origin_m;
  return result;
}

}  // namespace vc
