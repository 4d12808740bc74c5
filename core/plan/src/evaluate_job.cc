#include "vc/plan/evaluate_job.h"

#include <string>
#include <vector>

#include "vc/plan/stages.h"

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

namespace {

// The viewpoints' sets under options.test; sets result->selection_test and its warning.
Result<std::vector<VoxelSet>> SeenSets(const SceneInput& input, const VoxelScene& scene,
                                       const std::vector<WorldPoint>& local_viewpoints,
                                       const EvaluateJobOptions& options, const JobContext& ctx,
                                       EvaluateJobResult* result) {
  VisibilitySetsOptions set_options;
  set_options.test = options.test;
  set_options.threads = options.threads;
  set_options.scanner = options.scanner;
  std::vector<SurfacePatch> patches;
  if (options.test == SelectionTest::kSubvoxel) {
    if (planner::HasSurfacePoints(input)) {
      patches = ComputeSurfacePatches(scene, input.points);
      set_options.surface_patches = patches;
    } else {
      set_options.test = SelectionTest::kSurfaceVisibility;
      result->warnings.push_back(planner::NoSurfacePointsNote(input) + ": the seen sets are the surface test's");
    }
  }
  result->selection_test = set_options.test;
  return ComputeVisibilitySets(scene, local_viewpoints, set_options, ctx);
}

}  // namespace

Result<EvaluateJobResult> RunEvaluation(const SceneInput& input, const EvaluateJobOptions& options,
                                        const JobContext& ctx) {
  VC_RETURN_IF_ERROR(options.Validate());
  VC_ASSIGN_OR_RETURN(VoxelScene scene, Voxelize(input, options.voxelize_options(), ctx));
  std::vector<WorldPoint> local_viewpoints = options.viewpoints;
  for (WorldPoint& p : local_viewpoints) p -= input.frame_origin_m;
  if (options.export_sets) {
    VC_RETURN_IF_ERROR(planner::CheckVisibilitySetBudget(local_viewpoints.size(), scene.occupied.size(),
                                                         options.memory_budget_bytes, "the seen sets (--export-sets)"));
  }
  EvaluateJobResult result;
  VC_ASSIGN_OR_RETURN(result.evaluation, Evaluate(scene, local_viewpoints, options.evaluate_options(), ctx));
  result.viewpoints = options.viewpoints;
  result.voxel_centers.reserve(scene.occupied.size());
  for (size_t id = 0; id < scene.occupied.size(); ++id) result.voxel_centers.push_back(scene.Center(id));
  result.frame_origin_m = scene.frame_origin_m;
  if (options.export_sets) {
    VC_ASSIGN_OR_RETURN(result.seen_sets, SeenSets(input, scene, local_viewpoints, options, ctx, &result));
  }
  return result;
}

}  // namespace vc
