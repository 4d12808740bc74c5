#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "vc/plan/exact_selector.h"
#include "vc/plan/greedy.h"
#include "vc/plan/stages.h"

namespace vc::planner {

GreedySelectorOptions SelectorOptionsFor(const PlanOptions& options) {
  GreedySelectorOptions out;
  out.max_stations = options.max_stations;
  out.min_marginal_gain_voxels = options.min_marginal_gain_voxels;
  out.target_coverage = options.target_coverage;
  out.consolidate = options.consolidate;
  out.min_overlap = options.min_overlap;
  return out;
}

std::unique_ptr<Selector> SelectorFor(const PlanOptions& options) {
  if (options.solver == SelectionSolver::kGreedy) return std::make_unique<GreedySelector>(SelectorOptionsFor(options));
  ExactSelectorOptions exact;
  exact.greedy = SelectorOptionsFor(options);
  exact.time_limit_s = options.solve_seconds;
  exact.memory_budget_bytes = options.memory_budget_bytes / 2;
  exact.swap_search = options.solver == SelectionSolver::kExact;
  return std::make_unique<ExactSelector>(exact);
}

Result<SelectionOutput> RunSelectionStage(SelectionInput in, const PlanOptions& options, const JobContext& ctx) {
  SelectionOutput out;
  // The fixed stations' sets first: the selector starts with them picked.
  const int fixed = static_cast<int>(in.fixed_sets.size());
  std::vector<VoxelSet> sets = std::move(in.fixed_sets);
  sets.reserve(sets.size() + in.sets.size());
  for (VoxelSet& s : in.sets) sets.push_back(std::move(s));
  in.sets.clear();
  VC_ASSIGN_OR_RETURN(out.selection, in.selector.Select(sets, fixed, ctx));
  const size_t n_voxels = sets.empty() ? 0 : sets[0].size();
  out.coverable = VoxelSet(n_voxels);
  for (const VoxelSet& s : sets) UnionInto(out.coverable, s);
  // The picks as stations, each reported (provisionally) with its gain in pick order.
  Stations& st = out.stations;
  VoxelSet so_far(n_voxels);
  uint64_t covered_so_far = 0;
  const uint64_t coverable = out.selection.coverable;
  for (size_t k = 0; k < out.selection.picks.size(); ++k) {
    const int pick = out.selection.picks[k];
    const bool is_fixed = pick < fixed;
    const int c = is_fixed ? -1 : pick - fixed;  // candidate index
    const WorldPoint& position = is_fixed ? options.fixed_stations[pick] : in.candidates[c];
    const uint64_t visible = is_fixed ? CountBits(sets[pick]) : in.visible_voxels[c];
    st.positions.push_back(position);
    st.floor_z_m.push_back(is_fixed ? std::nan("") : in.floor_z_m[c]);
    st.candidate.push_back(c);
    st.sets.push_back(sets[pick]);
    st.fixed.push_back(is_fixed);
    const uint64_t gain = visible - CountAnd(sets[pick], so_far);
    UnionInto(so_far, sets[pick]);
    covered_so_far += gain;
    if (in.callbacks.on_station) {
      PlannedStation ps;
      ps.position = position;
      ps.visible_voxels = visible;
      ps.marginal_gain = gain;
      ps.cumulative_coverage = coverable ? double(covered_so_far) / coverable : 0.0;
      ps.candidate_index = c;
      ps.fixed = is_fixed;
      in.callbacks.on_station(ps, static_cast<int>(k));
    }
  }
  sets.clear();
  sets.shrink_to_fit();
  return out;
}

}  // namespace vc::planner
