#include "vc/plan/stages.h"

namespace vc::planner {

Result<VoxelizeOutput> RunVoxelizeStage(const VoxelizeInput& in, const PlanOptions& options, const JobContext& ctx) {
  VC_ASSIGN_OR_RETURN(VoxelScene scene, Voxelize(in.input, {options.resolution_m, options.memory_budget_bytes}, ctx));
  return VoxelizeOutput{std::move(scene)};
}

}  // namespace vc::planner
