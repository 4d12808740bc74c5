// Exact station selection: the station problem as an integer program solved with COIN-OR CBC
// (docs/PLANNING.md, "Exact selection"; issue 21).
//
// Minimise the number of stations such that the covered weight reaches the target:
//   min sum_c x_c  s.t.  y_k <= sum_{c sees k} x_c,  sum_k w_k y_k >= T,  x binary, y in [0, 1],
// where k runs over voxel classes of weight w_k and T is the smallest voxel count whose fraction
// of the coverable voxels reaches target_coverage (the greedy's own test). At full coverage the
// y variables go and each class gets a set-cover row sum_{c sees k} x_c >= 1. With max_stations > 0
// the objective is the covered weight instead, capped at T (max sum_k w_k y_k - eps sum_c x_c with
// sum_k w_k y_k <= T and sum_c x_c <= max_stations; the eps term prefers fewer stations among
// plans of equal coverage).
//
// The model is made small first (the sizes before and after are reported in Optimality):
// voxels seen by exactly the same candidates become one class weighted by its voxel count
// (partition refinement, exact); a candidate whose classes are a subset of another's is dropped
// (either can stand in for it: neither the station count nor the covered weight gets worse); at
// full coverage a candidate that is the only view of some class is fixed to 1 and taken out,
// with the classes it covers. Repeated until nothing changes, then classes merged again.
//
// The greedy plan (GreedySelector with the same options) is the warm start and the floor: the
// result is never worse than greedy in the objective. The solve is bounded by time_limit_s and
// cancellable through ctx (a CbcEventHandler polls ctx.CheckCancelled between nodes); on the
// limit the best plan found comes back with its bound (status kFeasible). If the model's
// estimated memory exceeds memory_budget_bytes, no ILP is built: greedy plus a swap local search
// (drop a pick, 2-for-1 and 1-for-1 exchanges that keep the covered weight) runs instead, with a
// note saying so (or, without swap_search, the greedy plan itself). Below full coverage the size
// is first estimated before any class is built, from one pass over the sets (a hash per voxel of
// the candidates that see it: the distinct hashes count the classes and non-zeros from below; the
// reduction's domination is not foreseen), so a model that will be refused costs no reduction.
// Where no LP bound is at hand (over the budget; the root LP cut off) the bound is the best of the
// counting bound and the Lagrangian bound (lagrangian_bound.h) over the reduced classes or, over
// the budget, over the voxels seen by the fewest candidates with the rest counted as covered
// (status kFeasible); none with max_stations (kHeuristic).
//
// With min_overlap > 0 (registration, scan_graph.h) the plan must be connected: a single-commodity
// flow over the candidates' scan-graph arcs (Dehbi et al. 2021) from one root station, which every
// chosen station consumes one unit of; the reduction then only merges classes (a dominated
// candidate may be a needed link), and fixed stations are columns fixed to 1. When no connected
// plan reaches the target, the greedy plan comes back (status kHeuristic, with a note).
// min_marginal_gain_voxels is a greedy stopping rule and is ignored.
//
// Thread-safe: immutable after construction; CBC state lives inside Select.
#pragma once

#include <cstdint>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/selector.h"
#include "vc/visibility/visibility.h"

namespace vc::planner {

struct ExactSelectorOptions {
  GreedyOptions greedy;      // the warm start's options; max_stations and target_coverage define the ILP
  double time_limit_s = 20;  // CBC's time limit, in seconds (> 0)
  // The integer program may use about this many bytes (estimated from its non-zeros, rows and
  // columns); above it, the swap local search runs instead.
  uint64_t memory_budget_bytes = uint64_t{1} << 30;
  // Over the memory budget: true = the swap local search (solver "greedy+swap"), false = the
  // greedy plan as it is (solver "greedy"; SelectionSolver::kAuto).
  bool swap_search = true;
  // Keep greedy's plan (its picks, order, covered count and stop reason) unless the integer program
  // finds a strictly better one: fewer stations reaching the target (max_stations: more covered,
  // or as many with fewer stations), or a connected one where greedy's is not. The optimality
  // figures are the solver's either way. SelectionSolver::kAuto sets it, so a plan whose greedy
  // selection is already optimal stays exactly what greedy planned. With it (the station count as
  // objective, no min_overlap) the counting and Lagrangian bounds come first: greedy's plan at the
  // bound, or the swap local search from it (up to a quarter of time_limit_s) reaching the bound,
  // or else the Lagrangian heuristic's plan (lagrangian_bound.h, primal_plans) at the bound, made no
  // thinner by 1-for-1 exchanges that cover more, is proven optimal without the integer program (a
  // note says so); otherwise CBC runs as before.
  bool prefer_greedy = false;
};

// The ILP above, warm-started from greedy. The picks: the fixed stations in order, then the
// chosen candidates re-sorted by marginal gain among the chosen (greedy order over them, ties to
// the lowest index); with prefer_greedy and no strictly better plan, greedy's picks as they were. stop: kTargetReached
// (or kExhausted at full coverage) when the target is reached, else kMaxStations. first_pass_picks and
// saved_by_improvement are the greedy warm start's. INVALID_ARGUMENT for sets of different sizes, fixed out of range or
// time_limit_s <= 0; CANCELLED / DEADLINE_EXCEEDED from ctx, also while CBC runs; INTERNAL if CBC fails.
class ExactSelector final : public Selector {
 public:
  explicit ExactSelector(const ExactSelectorOptions& options) : options_(options) {}
  using Selector::Select;
  [[nodiscard]] Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed,
                                         const JobContext& ctx) const override;

 private:
  ExactSelectorOptions options_;
};

}  // namespace vc::planner
