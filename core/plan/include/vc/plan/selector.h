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

#include "vc/base/parameter.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/visibility/visibility.h"

namespace vc {

// Why station selection stopped.
enum class StopReason : uint8_t {
  kExhausted,      // every coverable voxel is covered (or nothing was coverable)
  kTargetReached,  // target_coverage reached
  kMaxStations,    // max_stations picks made
  kMinGain,        // best marginal gain below min_marginal_gain_voxels
  kGainRule,       // best marginal gain below min_gain_voxels_per_minute x the station's set-up and scan minutes
};
// "exhausted", "target_reached", "max_stations", "min_gain", "gain_rule".
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
  // Why the loop ran as the fine round of coarse-then-fine candidates (PlanOptions::
  // coarse_above_candidates; CoarseToFineNote in stages.h); empty when it did not.
  std::string coarse_to_fine;
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
  bool consolidation_stopped = false;        // consolidation stopped at its time budget (greedy.h)
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

// Greedy selection's plan parameters (vc/base/parameter.h): X(type, name, default, unit, flag, check,
// help). VC_PLAN_PARAMETERS splices these rows in, so a greedy parameter is declared here once and
// reaches PlanOptions, its flag, its proto field's conversion, plan.json and GreedyOptions. Notes:
// - target_coverage: the default 0.99 stops chasing the last voxels of scan noise: on geb079, 1.0
//   puts a station on every one of the 123 candidates, 0.99 needs 69 and 0.95 needs 37.
// - min_gain_voxels_per_minute: the gain rule (docs/PLANNING.md, "The gain rule"): stop before a
//   station whose gain is below this many voxels per minute of its set-up and scan time
//   (GreedyOptions::station_seconds); walking is not counted (the route is planned afterwards).
//   The first station is always placed. With min_overlap, the rule reads the linked candidates'
//   gains; the chains of connecting stations are picked as before.
//   The exact solver then seeks the fewest stations covering what greedy covered when it stopped.
// - min_gain_m2_per_minute: the same rule in square metres of surface (docs/PLANNING.md, "The gain
//   rule"): a gain of g voxels is g x resolution^2 m^2 (GreedyOptions::surface_voxels_per_m2). The
//   voxel rule, when > 0, takes its place; PlanOptions::Validate refuses both > 0.
// - consolidate: after greedy selection, drop picks the others cover and replace two picks by one
//   candidate that sees all they alone covered (coverage never shrinks; docs/PLANNING.md).
#define VC_GREEDY_PARAMETERS(X)                                                                                        \
  X(int32_t, max_stations, 0, "stations", "max-stations", kNonNegative, "at most this many stations (0 = no limit)")   \
  X(uint64_t, min_marginal_gain_voxels, 1, "voxels", "min-gain", kAny, "stop when the best station adds fewer voxels") \
  X(double, target_coverage, 0.99, "fraction", "target-coverage", kFraction,                                           \
    "stop at this covered fraction of the coverable voxels")                                                           \
  X(double, min_gain_voxels_per_minute, 0.0, "voxels/min", "min-gain-voxels-per-minute", kNonNegative,                 \
    "stop when the best station adds fewer voxels per minute of its set-up and scan (0 = off)")                        \
  X(double, min_gain_m2_per_minute, 0.5, "m2/min", "min-gain-m2-per-minute", kNonNegative,                             \
    "stop when the best station adds less surface per minute of its set-up and scan (0 = off)")                        \
  X(bool, consolidate, true, "", "consolidate", kAny, "drop covered picks and merge pairs after greedy")

// The options of greedy selection: of GreedySelector, SelectGreedy and ConsolidatePicks (greedy.h).
// The rows above, with the plan's defaults (max_stations: greedy picks, fixed stations not
// counted; consolidate: GreedySelector only), then what is not a row of its own here. A default
// GreedyOptions stops at the plan's target_coverage, 0.99, not at full coverage: set 1.0 to cover
// every coverable voxel.
struct GreedyOptions {
  VC_GREEDY_PARAMETERS(VC_DECLARE_PARAMETER)
  // Registration (scan_graph.h; the plan row min_overlap, which the later stages use too): when
  // > 0, the picks must form a connected scan graph at this overlap. After the first pick (or the
  // fixed stations) only candidates with an edge to a picked station compete. When none of them
  // gains min_marginal_gain_voxels but another candidate would, the shortest chain of candidates
  // (fewest, by breadth-first search over edges) from the picks to the nearest such candidates is
  // added, its links as connecting stations, then the one with the largest gain at that depth
  // (lowest index on ties). When no chain reaches any gaining candidate, the best of them starts a
  // new group (GreedyResult::new_groups; the plan reports the groups). At the end, groups the fixed
  // stations left apart are joined the same way when a chain exists (unless max_stations stopped
  // the picks). Consolidation keeps the number of groups. 0 = off: the plain greedy.
  double min_overlap = 0;
  // Set-up and scan time of one station, s: the gain rule's cost (PlanOptions::setup_seconds plus
  // the scan time, FieldTime::scan_seconds_per_station). 0: the gain rule never stops.
  double station_seconds = 0;
  // Surface voxels per m^2 (1 / resolution^2, the planner sets it): min_gain_m2_per_minute's
  // conversion. 0: the area rule never stops.
  double surface_voxels_per_m2 = 0;
  // CELF lazy evaluation (true) or the plain recount of every candidate per round (false).
  bool lazy = true;
  // The first `fixed` sets are stations already placed: picked first, in order (whatever their
  // gain), never dropped or replaced; the stopping rules then apply to what they cover.
  // GreedySelector::Select sets it from its argument.
  int fixed = 0;
  // Consolidation's time budget, s of wall time (0 = none): when it runs out, consolidation stops
  // looking for a change and keeps the picks of the changes made so far (each keeps the coverage;
  // ConsolidateResult::budget_reached, Selection::consolidation_stopped). Drops and merges are found
  // in pick order, so a stop keeps the early ones. Small sites finish in well under a second.
  double consolidate_budget_s = 60;
};

// SelectGreedy (lazy unless options.lazy is false), then, with options.consolidate, ConsolidatePicks.
class GreedySelector final : public Selector {
 public:
  explicit GreedySelector(const GreedyOptions& options) : options_(options) {}
  using Selector::Select;
  // The fixed stations, then the greedy picks, consolidated (fixed stations kept); stop, coverable
  // and covered are the greedy pass's (covered includes what the fixed stations cover).
  [[nodiscard]] Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed,
                                         const JobContext& ctx) const override;

 private:
  GreedyOptions options_;
};

}  // namespace vc::planner
