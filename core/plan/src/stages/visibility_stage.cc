#include <iterator>
#include <string>
#include <vector>

#include "format.h"
#include "vc/plan/greedy.h"
#include "vc/plan/stages.h"

namespace vc::planner {

Status CheckVisibilitySetBudget(uint64_t positions, uint64_t voxels, uint64_t budget_bytes, const char* what) {
  const uint64_t need = positions * ((voxels + 63) / 64) * 8;
  if (need > budget_bytes / 2) {
    return ResourceExhaustedError(std::string(what) + ": " + std::to_string(positions) + " positions x " +
                                  std::to_string(voxels) + " occupied voxels need " + Num(need / 1073741824.0) +
                                  " GiB of visibility sets (budget " + Num(budget_bytes / 1073741824.0) +
                                  " GiB); raise grid_spacing_m or resolution_m");
  }
  return Status::Ok();
}

Result<VisibilityOutput> RunVisibilityStage(const VisibilityInput& in, const PlanOptions& options,
                                            const JobContext& ctx) {
  VisibilitySetsOptions set_options{options.selection_test, options.threads};
  set_options.scanner = options.scanner;
  VisibilityOutput out;
  if (in.fixed_stations.empty()) {
    VC_ASSIGN_OR_RETURN(out.sets, ComputeVisibilitySets(in.scene, in.candidates, set_options, ctx));
  } else {
    // One pass over the fixed stations and the candidates; the fixed stations' sets come first.
    std::vector<WorldPoint> all = in.fixed_stations;
    all.insert(all.end(), in.candidates.begin(), in.candidates.end());
    VC_ASSIGN_OR_RETURN(out.sets, ComputeVisibilitySets(in.scene, all, set_options, ctx));
    const auto split = out.sets.begin() + static_cast<std::ptrdiff_t>(in.fixed_stations.size());
    out.fixed_sets.assign(std::make_move_iterator(out.sets.begin()), std::make_move_iterator(split));
    out.sets.erase(out.sets.begin(), split);
  }
  out.heat_map.positions = in.candidates;
  out.heat_map.floor_z_m = in.floor_z_m;
  out.heat_map.grid_spacing_m = options.grid_spacing_m;
  out.heat_map.visible_voxels.reserve(out.sets.size());
  for (const VoxelSet& s : out.sets) out.heat_map.visible_voxels.push_back(CountBits(s));
  if (in.callbacks.on_heat_map) in.callbacks.on_heat_map(out.heat_map);
  return out;
}

}  // namespace vc::planner
