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

VisibilitySetsOptions VisibilitySetsOptionsFor(const PlanOptions& options,
                                               std::span<const SurfacePatch> surface_patches) {
  VisibilitySetsOptions set_options;
  set_options.test = options.selection_test;
  set_options.surface_patches = surface_patches;
  set_options.threads = options.threads;
  set_options.scanner = options.scanner;
  set_options.compact_gain = options.sparse_set_gain;
  // Sparse sets: their size is known only once computed, so the budget is checked as they are
  // (CheckVisibilitySetBudget checks dense ones before).
  if (options.sparse_set_gain > 0) {
    set_options.max_set_bytes = options.memory_budget_bytes / 2;
    set_options.batch_bytes = std::min<uint64_t>(set_options.batch_bytes, options.memory_budget_bytes / 8);
  }
  return set_options;
}

Result<DistributedSets> VisibilitySetsOf(const VisibilitySetsFn& visibility_sets, const VoxelScene& scene,
                                         const std::vector<WorldPoint>& positions,
                                         const VisibilitySetsOptions& set_options,
                                         std::span<const SurfacePatch> surface_patches, const JobContext& ctx,
                                         const char* what) {
  if (!visibility_sets || !surface_patches.empty()) {
    VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> sets, ComputeVisibilitySets(scene, positions, set_options, ctx));
    return DistributedSets{std::move(sets), {}, {}};
  }
  VC_ASSIGN_OR_RETURN(DistributedSets d, visibility_sets(scene, positions, set_options, ctx, what));
  if (d.sets.size() != positions.size()) {
    return InternalError("the distributed visibility sets were " + std::to_string(d.sets.size()) + " for " +
                         std::to_string(positions.size()) + " positions");
  }
  for (const VoxelSet& set : d.sets) {
    if (set.size() != scene.occupied.size()) {
      return InternalError("a distributed visibility set held " + std::to_string(set.size()) +
                           " voxels for a scene of " + std::to_string(scene.occupied.size()));
    }
  }
  return d;
}

Result<VisibilityOutput> RunVisibilityStage(const VisibilityInput& in, const PlanOptions& options,
                                            const JobContext& ctx) {
  const VisibilitySetsOptions set_options = VisibilitySetsOptionsFor(options, in.surface_patches);
  VisibilityOutput out;
  // One pass over the fixed stations and the candidates; the fixed stations' sets come first.
  std::vector<WorldPoint> all = in.fixed_stations;
  all.insert(all.end(), in.candidates.begin(), in.candidates.end());
  VC_ASSIGN_OR_RETURN(DistributedSets d, VisibilitySetsOf(in.callbacks.visibility_sets, in.scene, all, set_options,
                                                          in.surface_patches, ctx, "the visibility stage"));
  out.sets = std::move(d.sets);
  out.distribution = d.distribution;
  out.warnings = std::move(d.warnings);
  if (!in.fixed_stations.empty()) {
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
