// A lower bound on the fewest candidates of a weighted covering problem, full or partial, by
// Lagrangian relaxation and subgradient optimisation (issue 36; docs/PLANNING.md, "Exact selection").
//
// The problem (the exact selector's integer program over its reduced voxel classes,
// exact_selector.h): classes k of weight w_k, each seen by the candidates S_k; choose the fewest
// candidates whose classes weigh at least `need`:
//   min sum_j x_j  s.t.  y_k <= sum_{j in S_k} x_j,  sum_k w_k y_k >= need,  x binary, y in [0, 1].
// At need = sum_k w_k every y_k is 1 and this is the set-covering problem (Beasley 1990).
// Relaxing the rows y_k <= sum x_j with multipliers u_k >= 0 leaves two problems solved exactly:
//   L(u) = sum_j min(0, 1 - sum_{k seen by j} u_k) + min { sum_k u_k y_k : sum_k w_k y_k >= need, y in [0, 1] },
// the second a fractional knapsack (classes by u_k / w_k ascending, the last one split). For every
// u >= 0, L(u) <= the LP optimum <= the integer optimum (weak duality), so the bound is
// ceil(max L(u) - tolerance), with a tolerance above the rounding error of the sums (long double).
// The multipliers move along the subgradient g_k = y_k - sum_{j in S_k} x_j (components with
// u_k = 0 and g_k < 0 set to 0) with the step of Beasley 1990, lambda (UB - L(u)) / |g|^2 (UB: an
// upper bound on the optimum, e.g. greedy's count; lambda starts at 2 and halves after `patience`
// iterations without a better L), taken in the metric scaled by the class weights (u_k moves by
// step * w_k * g_k, |g|^2 = sum w_k g_k^2): classes of one voxel and of thousands then move at one
// price per voxel.
//
// Cores (issue 36): the steps run first over the classes at most first_core_seers candidates see,
// then over those at most twice as many see, and so on until every class is in. A class outside the
// core keeps u_k = 0: it is free in the knapsack and in no candidate's price, so L(u) over the core
// is L(u) of the whole problem (every core's L is a valid bound) and each core's multipliers start
// the next. The first core starts at Beasley's u_k = w_k / (the widest core candidate that sees k),
// where every reduced cost is >= 0. Why: a partial cover leaves the slack to the classes many
// candidates see, so the rare classes carry the bound, and a core of them costs a fraction of the
// pairs: on geb079 (398 candidates, 99,863 classes, 5.4 M pairs) the classes at most 16 see hold
// 0.2 M pairs and the bound reaches 46 where 49 steps over every class reached 33
// (docs/PLANNING.md, "The Lagrangian bound over cores").
//
// Cost: each step visits every (class, candidate) pair of the core once (a candidate's price, in
// double with a proven error allowance), the pairs of the candidates with reduced cost < 0 once
// (the subgradient), and finds the knapsack's cheapest classes by a weighted quickselect (linear).
// Each core stops after max_iterations steps or when lambda falls below min_step_scale; the whole
// stops when the bound reaches UB or before max_pair_visits pairs would be exceeded. No clocks and
// one thread: the same input gives the same bound on any machine.
//
// Plans (primal_plans; issue 36, the Lagrangian heuristic of Beasley 1990 and Caprara, Fischetti &
// Toth 1999): at each step whose L(u) is the best of its core so far the multipliers are turned into
// a plan. From no column, add the column of the lowest score, gamma_j / mu_j when gamma_j > 0 and
// gamma_j mu_j otherwise, where gamma_j = 1 - (u_k of the classes j would newly cover) is its
// reduced cost over what is still uncovered and mu_j the weight it would newly cover, capped at what
// `need` still lacks (ties: the lower column), until the plan covers `need`; then drop, in order of
// decreasing reduced cost 1 - sum_{k seen by j} u_k (ties: the higher column), every column the others
// cover `need` without. The plan with the fewest columns is kept (the first found among equals); the
// whole stops once the bound reaches its size (then both are optimal). Each plan visits every
// (class, column) pair about twice; they count against max_plan_pair_visits, not max_pair_visits,
// so the bound and its steps are those of the run without plans (it only stops sooner).
// Thread-safe (no state between calls).
#pragma once

#include <cstdint>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"

namespace vc::planner {

// A weighted covering problem over voxel classes; columns are candidates 0..columns-1.
struct CoverProblem {
  std::vector<uint64_t> weight;           // per class, in voxels (> 0)
  std::vector<std::vector<int>> seen_by;  // per class: the columns that see it (each in [0, columns))
  int columns = 0;                        // candidate columns
  uint64_t need = 0;                      // weight the chosen columns must cover, in voxels (<= sum of weight)
};

struct LagrangianOptions {
  int upper_bound = 0;           // stations of a known plan (> 0), scales the step; 0 = the column count
  int max_iterations = 300;      // subgradient iterations per core, at most
  int patience = 20;             // iterations without a better L(u) before lambda halves
  int first_core_seers = 16;     // the first core: the classes at most this many columns see (below 1: 1)
  double min_step_scale = 1e-3;  // stop once lambda falls below this
  uint64_t max_pair_visits = uint64_t{2} << 30;       // stop once this many (class, column) pairs were visited
  bool primal_plans = false;                          // also turn the multipliers into plans (above)
  uint64_t max_plan_pair_visits = uint64_t{1} << 30;  // no further plan once the plans visited this many pairs
};

struct LagrangianBound {
  int bound = 0;             // proven lower bound on the optimum, in stations (0 when need is 0)
  double relaxation = 0;     // the best L(u) found, in stations (bound = ceil of it, less the tolerance)
  int counting_bound = 0;    // ceil(need / W), the start's bound, for comparison
  int iterations = 0;        // subgradient iterations run, over all cores
  uint64_t pair_visits = 0;  // (class, column) pairs visited
  // With primal_plans: the plan of the fewest columns found (ascending; its classes weigh at least
  // need; empty only when need is 0: with no step run, one plan from the start's multipliers), the
  // plans made and the pairs they visited.
  std::vector<int> plan;
  int plans = 0;
  uint64_t plan_pair_visits = 0;
};

// The bound above (and, with primal_plans, a plan). INVALID_ARGUMENT for a class weight of 0, a column out of range, or
// need above the weight of the classes some column sees (no plan reaches it); CANCELLED / DEADLINE_EXCEEDED from ctx
// (polled every iteration).
[[nodiscard]] Result<LagrangianBound> ComputeLagrangianBound(const CoverProblem& problem,
                                                             const LagrangianOptions& options = {},
                                                             const JobContext& ctx = {});

}  // namespace vc::planner
