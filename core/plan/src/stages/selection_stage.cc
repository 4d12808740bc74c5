#include <utility>

#include "vc/plan/greedy.h"
#include "vc/plan/stages.h"

namespace vc::planner {

GreedySelectorOptions SelectorOptionsFor(const PlanOptions& options) {
  GreedySelectorOptions out;
  out.max_stations = options.max_stations;
  out.min_marginal_gain_voxels = options.min_marginal_gain_voxels;
  out.target_coverage = options.target_coverage;
  out.consolidate = options.consolidate;
  return out;
}

Result<SelectionOutput> RunSelectionStage(SelectionInput in, const PlanOptions&, const JobContext& ctx) {
  SelectionOutput out;
  VC_ASSIGN_OR_RETURN(out.selection, in.selector.Select(in.sets, ctx));
  const size_t n_voxels = in.sets.empty() ? 0 : in.sets[0].size();
  out.coverable = VoxelSet(n_voxels);
  for (const VoxelSet& s : in.sets) UnionInto(out.coverable, s);
  // The picks as stations, each reported (provisionally) with its gain in pick order.
  Stations& st = out.stations;
  VoxelSet so_far(n_voxels);
  uint64_t covered_so_far = 0;
  const uint64_t coverable = out.selection.coverable;
  for (size_t k = 0; k < out.selection.picks.size(); ++k) {
    const int c = out.selection.picks[k];
    st.positions.push_back(in.candidates[c]);
    st.floor_z_m.push_back(in.floor_z_m[c]);
    st.candidate.push_back(c);
    st.sets.push_back(in.sets[c]);
    const uint64_t gain = in.visible_voxels[c] - CountAnd(in.sets[c], so_far);
    UnionInto(so_far, in.sets[c]);
    covered_so_far += gain;
    if (in.callbacks.on_station) {
      PlannedStation ps;
      ps.position = in.candidates[c];
      ps.visible_voxels = in.visible_voxels[c];
      ps.marginal_gain = gain;
      ps.cumulative_coverage = coverable ? double(covered_so_far) / coverable : 0.0;
      ps.candidate_index = c;
      in.callbacks.on_station(ps, static_cast<int>(k));
    }
  }
  in.sets.clear();
  in.sets.shrink_to_fit();
  return out;
}

}  // namespace vc::planner
