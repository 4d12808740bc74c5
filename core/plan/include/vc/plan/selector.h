// Station selection behind one interface (ALGORITHM.md s.7.3; docs/PLANNING.md, "Pipeline").
//
// The selection stage hands a Selector the candidates' visibility sets and gets back the picks
// (candidate indices, in pick order) and why it stopped. GreedySelector: lazy greedy maximum
// coverage (greedy.h, CELF), then consolidation of the picks; ExactSelector (exact_selector.h): the
// integer program over the same sets, warm-started from greedy. Selectors are immutable after
// construction, so Select is thread-safe; the sets are only read.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/visibility/visibility.h"

namespace vc {

// Why station selection stopped.
enum class StopReason : uint8_t {
  kExhausted,      // every coverable voxel is covered (or nothing was coverable)
  kTargetReached,  // target_coverage reached
  kMaxStations,    // max_stations picks made
  kMinGain,        // best marginal gain below min_marginal_gain
};
// "exhausted", "target_reached", "max_stations", "min_gain".
std::string_view StopReasonName(StopReason reason);

// Which selector a plan uses (PlanOptions::solver; docs/PLANNING.md, "Exact selection").
enum class SelectionSolver : uint8_t {
  kGreedy,  // GreedySelector: lazy greedy, then consolidation
  kExact,   // ExactSelector: the integer program (CBC), greedy + swaps over the memory budget
  kAuto,    // the default: ExactSelector keeping greedy's plan unless it finds a strictly better one
};
// "greedy", "exact", "auto".
std::string_view SelectionSolverName(SelectionSolver solver);

}  // namespace vc

namespace vc::planner {

// How a selection's station count relates to the optimum over the same candidates (plan.json
// `optimality`; docs/PLANNING.md, "Exact selection").
enum class OptimalityStatus : uint8_t {
  kHeuristic,  // no bound was proven (greedy, or the swap local search)
  kFeasible,   // a solver's incumbent with a proven bound that may be below it (time limit)
  kOptimal,    // proven optimal over the candidates given
};
// "heuristic", "feasible", "optimal".
std::string_view OptimalityStatusName(OptimalityStatus status);

// The size of the integer program (after the model reduction) or, in `before`, of the input.
struct ModelSize {
  int candidates = 0;     // candidate columns (fixed stations included in `before`)
  int voxel_classes = 0;  // voxel classes (`before`: coverable voxels, one class each)
  int rows = 0;           // constraint rows (0 in `before`)
};

// The local-candidates loop (PlanOptions::local_candidates; vc/plan/local_refinement.h), when it ran.
struct LocalCandidatesReport {
  int rounds = 0;                           // selections after the first
  int added = 0;                            // positions added over all rounds
  std::vector<int> stations_per_solve;      // the first selection's first; empty when the loop did not run
  std::vector<uint64_t> covered_per_solve;  // voxels, per selection
};

struct Optimality {
  std::string solver = "greedy";  // "greedy", "exact", or "greedy+swap" (exact's fallback)
  OptimalityStatus status = OptimalityStatus::kHeuristic;
  int stations = 0;        // stations selected (fixed ones included)
  double lower_bound = 0;  // proven lower bound on the stations (0 when none is proven)
  // (stations - lower_bound) / stations; 1 when no bound is proven (0 stations: 0). With
  // max_stations the objective is coverage: lower_bound = stations and gap is the coverage gap
  // (covered_bound - covered) / covered_bound.
  double gap = 1;
  uint64_t covered_bound = 0;              // proven upper bound on the covered voxels (max_stations mode; else 0)
  double seconds = 0;                      // wall time of the whole Select, in seconds
  ModelSize before;                        // the input: candidates and coverable voxels
  ModelSize model;                         // the integer program solved (after the model reduction)
  int forced = 0;                          // candidates fixed to 1 as the only view of some voxel
  int dominated = 0;                       // candidates dropped as dominated by another
  std::string note;                        // why a fallback was taken, or empty
  LocalCandidatesReport local_candidates;  // the local-candidates loop (seconds then covers all its solves)
};

// What a selector chose over one vector of visibility sets.
struct Selection {
  std::vector<int> picks;                    // candidate indices (into the sets), in pick order
  StopReason stop = StopReason::kExhausted;  // why the first pass stopped
  uint64_t coverable = 0;                    // |union of all sets|, in voxels
  uint64_t covered = 0;                      // voxels the first pass covered when it stopped
  int first_pass_picks = 0;                  // picks before any improvement pass (greedy picks, fixed excluded)
  int saved_by_improvement = 0;              // picks the improvement pass saved (consolidation)
  int connectors = 0;                        // first-pass picks made to link the scan graph (min_overlap)
  int new_groups = 0;                        // times the first pass found no chain to a gaining candidate
  Optimality optimality;                     // how far from the optimum (greedy: heuristic, no bound)
};

// Chooses stations among candidates from their visibility sets.
class Selector {
 public:
  virtual ~Selector() = default;
  // Picks among `sets` (all of one size), the first `fixed` of which are stations already placed:
  // they are the first picks, in order, and stay picked. INVALID_ARGUMENT for sets of different
  // sizes or fixed outside [0, |sets|]; CANCELLED / DEADLINE_EXCEEDED from ctx. Progress is
  // reported as Stage::kSelection.
  [[nodiscard]] virtual Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed,
                                                 const JobContext& ctx) const = 0;
  // Select without fixed stations.
  [[nodiscard]] Result<Selection> Select(const std::vector<VoxelSet>& sets, const JobContext& ctx) const {
    return Select(sets, 0, ctx);
  }
};

struct GreedySelectorOptions {
  int max_stations = 0;                   // at most this many greedy picks; 0 = no limit
  uint64_t min_marginal_gain_voxels = 1;  // stop when the best gain is below this (voxels)
  double target_coverage = 1.0;           // stop at this fraction of coverable voxels, in (0, 1]
  bool consolidate = true;                // run ConsolidatePicks on the greedy picks
  double min_overlap = 0;                 // > 0: keep the picks' scan graph connected (greedy.h)
};

// Lazy greedy (SelectGreedy with lazy = true), then, if enabled, ConsolidatePicks.
class GreedySelector final : public Selector {
 public:
  explicit GreedySelector(const GreedySelectorOptions& options) : options_(options) {}
  using Selector::Select;
  // The fixed stations, then the greedy picks, consolidated (fixed stations kept); stop, coverable
  // and covered are the greedy pass's (covered includes what the fixed stations cover).
  [[nodiscard]] Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed,
                                         const JobContext& ctx) const override;

 private:
  GreedySelectorOptions options_;
};

}  // namespace vc::planner
