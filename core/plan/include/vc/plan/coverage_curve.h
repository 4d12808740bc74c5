// The coverage curve of a plan (docs/PLANNING.md, "The coverage curve"): for k = 1..n, what the
// plan's first k stations (PlanResult::stations order, which is selection order) cover together.
// The curve is nested by construction: the first k stations are the plan for k. Each step is a
// station's marginal gain, so the curve agrees with stations.csv's gain_voxels and
// cumulative_coverage. Where the selection computed them (vc/plan/k_coverage_bound.h), each point
// also says how much any k stations could cover at most and the most found for k (AddBestCoverage).
// Pure functions, thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace vc {

// One point of the curve: the plan's first `stations` stations.
struct CoveragePoint {
  int stations = 0;               // k, from 1
  uint64_t covered_voxels = 0;    // voxels the first k stations see together (sum of their gains)
  double coverable_fraction = 0;  // covered_voxels / the coverable voxels (0 when none)
  double scene_fraction = 0;      // covered_voxels / the occupied voxels of the whole scene (0 when none)
  double setup_scan_s = 0;        // field time to set up and scan k stations, s (walking not included)
  // No k stations (the fixed ones among them, over the selection's candidates) cover more voxels;
  // absent where not computed (docs/PLANNING.md, "The coverage curve").
  std::optional<uint64_t> best_voxels_upper_bound;
  std::optional<uint64_t> best_voxels;  // the most k stations were found to cover (>= covered_voxels)
  bool best_voxels_optimal = false;     // best_voxels == best_voxels_upper_bound: proven the best
};

// Per k (from 1) what any k stations can cover at most and the most found, in voxels.
struct BestCoverage {
  uint64_t upper_bound_voxels = 0;
  uint64_t best_voxels = 0;
};
// Sets each point's best_voxels_upper_bound and best_voxels from `best` (index k - 1; points past
// its end are left without), best_voxels at least the point's own covered_voxels, and
// best_voxels_optimal where the two meet.
void AddBestCoverage(std::vector<CoveragePoint>& curve, const std::vector<std::optional<BestCoverage>>& best);

// The curve of stations with these marginal gains (voxels, in plan order), over `occupied` and
// `coverable` voxels, each station costing `station_seconds` of set-up and scan: one point per station.
[[nodiscard]] std::vector<CoveragePoint> CoverageCurve(const std::vector<uint64_t>& marginal_gains_voxels,
                                                       uint64_t occupied_voxels, uint64_t coverable_voxels,
                                                       double station_seconds);

// The coverage levels a crew reads (fractions of the coverable voxels): 80, 90, 95 and 99 %.
inline constexpr double kCoverageMilestones[] = {0.80, 0.90, 0.95, 0.99};

// A level of the coverable voxels and the first point of the curve reaching it.
struct CoverageMilestone {
  double coverable_fraction = 0;         // the level
  std::optional<CoveragePoint> reached;  // the fewest leading stations reaching it; nullopt if the plan never does
  // The smallest k whose best_voxels_upper_bound reaches the level: no plan of fewer stations does;
  // absent when the curve carries no bound reaching it.
  std::optional<int> fewest_possible_stations;
};

// Each of `levels` (fractions in (0, 1]) with the first point of `curve` whose covered voxels reach
// level x coverable (the test greedy selection stops on), and the smallest k whose bound reaches it;
// `coverable_voxels` as the curve's. A point without a bound counts as reaching no level: the curve
// has none only below the plan's fixed stations (no plan has fewer stations than those), or none.
[[nodiscard]] std::vector<CoverageMilestone> CoverageMilestones(const std::vector<CoveragePoint>& curve,
                                                                uint64_t coverable_voxels,
                                                                const std::vector<double>& levels);

}  // namespace vc
