#include "vc/plan/stages.h"

namespace vc::planner {

bool HasSurfacePoints(const SceneInput& input) {
  return !input.is_octree() && input.format != InputFormat::kVoxelStream && !input.points.empty();
}

std::string NoSurfacePointsNote(const SceneInput& input) {
  return std::string("the subvoxel test needs the input's points, and this ") +
         (input.is_octree() ? "octree" : "compact (vc-voxels) upload") + " has none";
}

Result<VoxelizeOutput> RunVoxelizeStage(const VoxelizeInput& in, const PlanOptions& options, const JobContext& ctx) {
  VC_ASSIGN_OR_RETURN(VoxelScene scene, Voxelize(in.input, {options.resolution_m, options.memory_budget_bytes}, ctx));
  VoxelizeOutput out{std::move(scene), {}, options.selection_test, {}};
  if (options.selection_test != SelectionTest::kSubvoxel) return out;
  if (HasSurfacePoints(in.input)) {
    out.surface_patches = ComputeSurfacePatches(out.scene, in.input.points);
  } else {
    out.selection_test = SelectionTest::kSurfaceVisibility;
    out.warnings.push_back(NoSurfacePointsNote(in.input) +
                           ": the plan ran the surface test instead (give a point cloud, uploaded with "
                           "--raw-upload, for the subvoxel test)");
  }
  return out;
}

}  // namespace vc::planner
