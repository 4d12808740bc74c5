// The coverage curve of a plan (docs/PLANNING.md, "The coverage curve"): for k = 1..n, what the
// plan's first k stations (PlanResult::stations order, which is selection order) cover together.
// The curve is nested by construction: the first k stations are the plan for k. Each step is a
// station's marginal gain, so the curve agrees with stations.csv's gain_voxels and
// cumulative_coverage. Per-k optima and bounds are not computed: the exact solver's bound (plan.json
// `optimality`) holds at the target coverage only. Pure functions, thread-safe.
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
};

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
};

// Each of `levels` (fractions in (0, 1]) with the first point of `curve` whose covered voxels reach
// level x coverable (the test greedy selection stops on); `coverable_voxels` as the curve's.
[[nodiscard]] std::vector<CoverageMilestone> CoverageMilestones(const std::vector<CoveragePoint>& curve,
                                                                uint64_t coverable_voxels,
                                                                const std::vector<double>& levels);

}  // namespace vc
