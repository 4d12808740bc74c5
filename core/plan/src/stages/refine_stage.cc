#include <cmath>
#include <optional>
#include <type_traits>
#include <utility>

#include "vc/plan/candidates.h"
#include "vc/plan/greedy.h"
#include "vc/plan/keep_out.h"
#include "vc/plan/scan_graph.h"
#include "vc/plan/stage_runner.h"
#include "vc/plan/stages.h"

namespace vc::planner {
namespace {

// Positions of the sub-grids around the stations, grouped by station in station order.
struct TrialPositions {
  std::vector<WorldPoint> positions;  // world frame (m)
  std::vector<int> station;           // per position: the station it may replace
};

// The tripod height of station k: the one of options.TripodHeights() closest to its height above
// its floor.
double StationHeight(const Stations& stations, size_t k, const std::vector<double>& heights) {
  const double above = stations.positions[k].z() - stations.floor_z_m[k];
  double best = heights[0];
  for (double h : heights) {
    if (std::fabs(h - above) < std::fabs(best - above)) best = h;
  }
  return best;
}

// Every sub-grid point within options.refine_radius_m of a station (not the station itself, and
// not a fixed station), moved onto the floor near the station's (on terrain, `ground`, the ground
// reached on foot: MovedStationFloor) at the station's tripod height, and kept if it has the
// clearance and lies in no keep-out zone.
TrialPositions TrialsAround(const OccupancyGrid& grid, const Stations& stations, GroundModel ground,
                            const PlanOptions& options) {
  const std::vector<double> heights = options.TripodHeights();
  const int steps = static_cast<int>(std::floor(options.refine_radius_m / options.refine_step_m + 1e-9));
  TrialPositions trials;
  for (size_t k = 0; k < stations.size(); ++k) {
    if (stations.fixed[k]) continue;
    const double height = std::isnan(stations.floor_z_m[k]) ? 0.0 : StationHeight(stations, k, heights);
    CandidateOptions cand_options = CandidateOptionsFor(options);
    cand_options.tripod_height_m = height;
    cand_options.tripod_heights_m = {};
    cand_options.doorway_candidates = false;
    cand_options.ground = ground;
    for (int iy = -steps; iy <= steps; ++iy) {
      for (int ix = -steps; ix <= steps; ++ix) {
        if (ix == 0 && iy == 0) continue;
        WorldPoint p = stations.positions[k] + WorldPoint(ix * options.refine_step_m, iy * options.refine_step_m, 0);
        if (!std::isnan(stations.floor_z_m[k])) {
          std::optional<double> top =
              MovedStationFloor(grid, stations.positions[k], stations.floor_z_m[k], p.x(), p.y(), cand_options);
          if (!top) continue;
          p.z() = *top + height;
        }
        if (!HasClearance(grid, p, options.clearance_m)) continue;
        if (KeepOutZoneContaining(options.keep_out, p) >= 0) continue;
        trials.positions.push_back(p);
        trials.station.push_back(static_cast<int>(k));
      }
    }
  }
  return trials;
}

}  // namespace

Result<RefineOutput> RunRefineStage(RefineInput in, const PlanOptions& options, const JobContext& ctx) {
  const size_t n_voxels = in.scene.occupied.size();
  Stations& stations = in.stations;
  TrialPositions trials = TrialsAround(in.scene.grid, stations, in.ground, options);
  VC_RETURN_IF_ERROR(
      CheckVisibilitySetBudget(trials.positions.size(), n_voxels, options.memory_budget_bytes, "refinement"));
  const VisibilitySetsOptions set_options = VisibilitySetsOptionsFor(options, in.surface_patches);
  VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> trial_sets,
                      ComputeVisibilitySets(in.scene, trials.positions, set_options, ProgressRange(ctx, 0.0, 0.9)));
  for (const VoxelSet& s : trial_sets) UnionInto(in.coverable, s);
  // Registration: a move must not split the stations' scan graph into more groups.
  const bool registration = options.min_overlap > 0;
  std::vector<int> all(stations.size());
  for (size_t k = 0; k < stations.size(); ++k) all[k] = static_cast<int>(k);
  OverlapMatrix overlaps = registration ? OverlapMatrix(stations.sets, options.threads) : OverlapMatrix();
  const int groups = registration ? CountComponents(overlaps, all, options.min_overlap) : 1;
  // Each station in turn moves to its best trial position if that covers more together with the
  // other stations (then sees more alone), and keeps the scan graph's groups; the others stay
  // where they are meanwhile.
  size_t t = 0;
  for (size_t k = 0; k < stations.size(); ++k) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("refinement"));
    VoxelSet others(n_voxels);
    for (size_t j = 0; j < stations.size(); ++j) {
      if (j != k) UnionInto(others, stations.sets[j]);
    }
    const uint64_t others_count = CountBits(others);
    auto score = [&](const VoxelSet& s) {
      return std::make_pair(others_count + CountBits(s) - CountAnd(others, s), CountBits(s));
    };
    const auto current = score(stations.sets[k]);
    std::vector<std::pair<std::remove_const_t<decltype(current)>, int>>
        better;  // trials that beat the station, best first
    for (; t < trials.positions.size() && trials.station[t] == static_cast<int>(k); ++t) {
      const auto sc = score(trial_sets[t]);
      if (sc > current) better.push_back({sc, static_cast<int>(t)});
    }
    std::stable_sort(better.begin(), better.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    int best_trial = -1;
    for (const auto& [sc, trial] : better) {
      if (registration) {
        OverlapMatrix moved = overlaps;
        moved.Replace(static_cast<int>(k), trial_sets[trial], stations.sets);
        if (CountComponents(moved, all, options.min_overlap) > groups) continue;
        overlaps = std::move(moved);
      }
      best_trial = trial;
      break;
    }
    if (best_trial >= 0) {
      const bool on_floor = !std::isnan(stations.floor_z_m[k]);
      const double height = on_floor ? StationHeight(stations, k, options.TripodHeights()) : 0.0;
      stations.positions[k] = trials.positions[best_trial];
      if (on_floor) stations.floor_z_m[k] = stations.positions[k].z() - height;
      stations.candidate[k] = -1;
      stations.sets[k] = std::move(trial_sets[best_trial]);
    }
  }
  return RefineOutput{std::move(in.stations), std::move(in.coverable)};
}

}  // namespace vc::planner
