// The best k-station coverage and an upper bound on it, for each k (issue 36; docs/PLANNING.md,
// "The coverage curve"): how much any k candidates can cover at most, and the most found.
//
// The problem (maximum k-coverage over voxel classes, as the exact selector's reduced model):
// classes i of weight w_i, each seen by the columns S_i; choose k columns covering the most weight.
// Upper bound, the Lagrangian relaxation of the rows y_i <= sum_{j sees i} x_j with u_i in [0, w_i]:
//   UB_k(u) = sum_i (w_i - u_i) + (the sum of the k largest prices p_j = sum_{i seen by j} u_i),
// valid for every such u. Three kinds of u are tried:
// - from greedy's prefixes P (pure maximum-coverage greedy, run here): u_i = 0 on the classes P
//   covers and w_i elsewhere gives UB_k = f(P) + the k largest marginal gains over P (the
//   submodular bound; Leskovec et al. 2007); every prefix, every k, in one greedy pass;
// - subgradient steps from the best of those (and from k - 1's multipliers): u_i = w_i v_i, v_i
//   moves by -step (c_i - 1) (c_i: how many of the k dearest columns see i) with Polyak's step
//   lambda (UB - best) / sum_i w_i (c_i - 1)^2, clamped to [0, 1]; lambda halves after `patience`
//   steps without a better UB;
// - greedy's guarantee: greedy's own first k picks cover at least (1 - (1 - 1/k)^k) of the optimum
//   (Nemhauser, Wolsey & Fisher 1978). It holds for the greedy run here, not for a plan whose
//   stations were reordered, consolidated or reduced, so only this greedy's prefix is used.
// Each UB_k is capped by the total weight and by UB_{k+1} (OPT_k <= OPT_{k+1}), and rounded down
// after a tolerance above the sums' rounding error.
// Best: greedy's prefix, and where the model is small (at most exact_max_columns columns and
// exact_max_pairs (class, column) pairs) a branch and bound over the columns per k (bound: what
// is covered + the k - d largest marginal gains of the columns still allowed), optimal when it
// finishes within exact_max_nodes nodes. A k is `optimal` when best reaches the bound.
// Budgets: subgradient steps stop after max_pair_visits (class, column) pairs in all and at the
// deadline; the search after its nodes and at the deadline. Any stop leaves valid bounds.
// Thread-safe (no state between calls).
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

namespace vc::planner {

// A weighted maximum-coverage problem over voxel classes; columns are candidates 0..columns-1.
struct KCoverageProblem {
  std::vector<uint64_t> weight;           // per class, in voxels (> 0)
  std::vector<std::vector<int>> seen_by;  // per class: the columns that see it (each in [0, columns), no repeats)
  int columns = 0;
};

struct KCoverageOptions {
  int max_k = 0;                                                  // k = 1..max_k (at most the columns)
  int max_iterations_per_k = 40;                                  // subgradient steps per k, at most
  int patience = 5;                                               // steps without a better UB before lambda halves
  uint64_t max_pair_visits = uint64_t{1} << 27;                   // subgradient steps in all, in (class, column) pairs
  int exact_max_columns = 40;                                     // the exact search only on models this small...
  uint64_t exact_max_pairs = 20000;                               // ...in (class, column) pairs
  uint64_t exact_max_nodes = 200000;                              // per k
  std::optional<std::chrono::steady_clock::time_point> deadline;  // none: the budgets alone
};

// What k columns can cover, in voxels.
struct KCoverage {
  uint64_t upper_bound = 0;  // no k columns cover more
  uint64_t best = 0;         // k columns found covering this much (greedy's or the exact search's)
  bool optimal = false;      // best == upper_bound: proven the most k columns can cover
};

// One entry per k = 1..min(max_k, columns); empty when max_k < 1 or there are no columns.
[[nodiscard]] std::vector<KCoverage> KCoverageBounds(const KCoverageProblem& problem, const KCoverageOptions& options);

}  // namespace vc::planner
