#include "vc/server/backend.h"

#include <cmath>
#include <string>

#include "vc/scene/voxel_scene.h"

namespace vc::server {

Status ValidateEvaluateJob(const wire::EvaluateJobOptions& o) {
  if (o.viewpoints.empty()) {
    return InvalidArgumentError("no viewpoint to evaluate; give at least one (e.g. --viewpoints stations.csv)");
  }
  for (size_t i = 0; i < o.viewpoints.size(); ++i) {
    if (!o.viewpoints[i].allFinite()) {
      return InvalidArgumentError("viewpoint " + std::to_string(i) + " has a non-finite coordinate");
    }
  }
  const double r = o.voxelize.resolution_m;
  if (!std::isfinite(r) || r < 0) {
    return InvalidArgumentError("resolution_m must be a finite number >= 0 (0 = the scene's default), got " +
                                std::to_string(r));
  }
  if (o.voxelize.memory_budget_bytes == 0) return InvalidArgumentError("memory_budget_bytes must be > 0");
  if (o.evaluate.threads < 0) return InvalidArgumentError("threads must be >= 0");
  return o.evaluate.scanner.Validate();
}

Result<Evaluation> RunEvaluation(const SceneInput& input, const wire::EvaluateJobOptions& options,
                                 const JobContext& ctx) {
  VC_ASSIGN_OR_RETURN(VoxelScene scene, Voxelize(input, options.voxelize, ctx));
  return Evaluate(scene, options.viewpoints, options.evaluate, ctx);
}

Backend Backend::Default() {
  Backend b;
  b.read_scene = [](std::string_view bytes, std::string_view source, const ReadOptions& o) {
    return ReadScene(bytes, source, o);
  };
  b.plan = [](const SceneInput& in, const PlanOptions& o, const JobContext& ctx, const PlanCallbacks& cb) {
    return Plan(in, o, ctx, cb);
  };
  b.evaluate = RunEvaluation;
  return b;
}

}  // namespace vc::server
