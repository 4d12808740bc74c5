#include "vc/plan/selector.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "vc/plan/greedy.h"
#include "vc/plan/stage_runner.h"

namespace vc {

std::string_view StopReasonName(StopReason reason) {
  switch (reason) {
    case StopReason::kExhausted:
      return "exhausted";
    case StopReason::kTargetReached:
      return "target_reached";
    case StopReason::kMaxStations:
      return "max_stations";
    case StopReason::kMinGain:
      return "min_gain";
    case StopReason::kGainRule:
      return "gain_rule";
  }
  return "unknown";
}

std::string_view SelectionSolverName(SelectionSolver solver) {
  switch (solver) {
    case SelectionSolver::kGreedy:
      return "greedy";
    case SelectionSolver::kExact:
      return "exact";
    case SelectionSolver::kAuto:
      return "auto";
  }
  return "unknown";
}

}  // namespace vc

namespace vc::planner {

Result<Selection> GreedySelector::Select(const std::vector<VoxelSet>& sets, int fixed, const JobContext& ctx) const {
  const auto start = std::chrono::steady_clock::now();
  GreedyOptions options = options_;
  options.fixed = fixed;
  VC_ASSIGN_OR_RETURN(GreedyResult greedy, SelectGreedy(sets, options, ctx));
  Selection out;
  out.stop = greedy.stop;
  out.coverable = greedy.coverable;
  out.covered = greedy.covered;
  out.connectors = greedy.connectors;
  out.new_groups = greedy.new_groups;
  for (const GreedyPick& pick : greedy.picks) out.picks.push_back(pick.candidate);
  out.first_pass_picks = static_cast<int>(out.picks.size()) - fixed;
  if (options.consolidate) {
    // Consolidation's progress continues from the coverage greedy's last report showed.
    const double reached = out.coverable > 0 ? std::min(1.0, double(out.covered) / double(out.coverable)) : 1.0;
    VC_ASSIGN_OR_RETURN(ConsolidateResult merged,
                        ConsolidatePicks(sets, std::move(out.picks), options, ProgressRange(ctx, reached, 1.0)));
    out.picks = std::move(merged.picks);
    out.saved_by_improvement = merged.dropped + merged.merged;
    out.consolidation_stopped = merged.budget_reached;
  }
  out.optimality.stations = static_cast<int>(out.picks.size());
  out.optimality.gap = out.picks.empty() ? 0.0 : 1.0;
  out.optimality.before = {static_cast<int>(sets.size()), static_cast<int>(out.coverable), 0};
  out.optimality.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace vc::planner
