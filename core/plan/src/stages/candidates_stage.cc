#include <cmath>
#include <string>
#include <utility>

#include "format.h"
#include "vc/plan/candidates.h"
#include "vc/plan/stages.h"

namespace vc::planner {
namespace {

// The user's candidates, checked: in range, and not inside an occupied voxel.
Result<CandidatesOutput> UserCandidates(const VoxelScene& scene, const std::vector<WorldPoint>& user) {
  for (size_t i = 0; i < user.size(); ++i) {
    const WorldPoint& p = user[i];
    if (!ViewpointInRange(p, scene.resolution_m)) {
      return InvalidArgumentError("candidates[" + std::to_string(i) + "] (" + Num(p.x()) + ", " + Num(p.y()) + ", " +
                                  Num(p.z()) + ") is more than " + Num(kMaxViewpointIndex * scene.resolution_m) +
                                  " m from the origin along an axis; use coordinates in the scene's frame");
    }
    if (scene.grid.Occupied(scene.grid.WorldToIndex(p))) {
      return InvalidArgumentError("candidates[" + std::to_string(i) + "] (" + Num(p.x()) + ", " + Num(p.y()) + ", " +
                                  Num(p.z()) + ") lies inside an occupied voxel");
    }
  }
  CandidatesOutput out;
  out.positions = user;
  out.floor_z_m.assign(out.positions.size(), std::nan(""));
  return out;
}

// The generated grid; FAILED_PRECONDITION when no floor is found or no candidate survives.
Result<CandidatesOutput> GridCandidates(const VoxelScene& scene, const PlanOptions& options, const JobContext& ctx) {
  const CandidateOptions cand_options{options.grid_spacing_m, options.tripod_height_m, options.clearance_m};
  VC_ASSIGN_OR_RETURN(CandidateGrid grid, GenerateCandidates(scene, cand_options, ctx));
  CandidatesOutput out;
  for (const FloorLevel& l : grid.levels) out.floor_levels_m.push_back(l.z_m);
  out.grid_cells = grid.cells;
  out.cells_without_floor = grid.rejected_no_floor;
  out.cells_failing_clearance = grid.rejected_clearance;
  if (grid.positions.empty()) {
    if (grid.levels.empty()) {
      return FailedPreconditionError("no floor found: no occupied voxel has tripod_height_m + clearance_m = " +
                                     Num(options.tripod_height_m + options.clearance_m) +
                                     " m of free space above it; lower them or pass candidates");
    }
    std::string levels;
    for (double z : out.floor_levels_m) levels += (levels.empty() ? "" : ", ") + Num(z);
    return FailedPreconditionError("no candidate survived: of " + std::to_string(grid.cells) + " grid cells, " +
                                   std::to_string(grid.rejected_no_floor) +
                                   " had no floor below (floor levels at z = " + levels + " m) and " +
                                   std::to_string(grid.rejected_clearance) +
                                   " had occupied voxels within clearance_m = " + Num(options.clearance_m) +
                                   " m; lower clearance_m or grid_spacing_m, or pass candidates");
  }
  if (grid.positions.size() < 5) {
    out.warnings.push_back("only " + std::to_string(grid.positions.size()) +
                           " candidates survived the clearance filter (" + std::to_string(grid.rejected_clearance) +
                           " cells with floor failed clearance_m = " + Num(options.clearance_m) + " m, " +
                           std::to_string(grid.rejected_no_floor) +
                           " had no floor below) — lower clearance_m or grid_spacing_m, or check the floor estimate");
  }
  out.positions = std::move(grid.positions);
  out.floor_z_m = std::move(grid.floor_z_m);
  return out;
}

}  // namespace

Result<CandidatesOutput> RunCandidatesStage(const CandidatesInput& in, const PlanOptions& options,
                                            const JobContext& ctx) {
  if (!options.candidates.empty()) return UserCandidates(in.scene, options.candidates);
  return GridCandidates(in.scene, options, ctx);
}

}  // namespace vc::planner
