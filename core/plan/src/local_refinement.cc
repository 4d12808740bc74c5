#include "vc/plan/local_refinement.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

namespace vc::planner {
namespace {

// Whether a selection reaches target_coverage of its coverable voxels (greedy's own test).
bool Reaches(const Selection& s, double target_coverage) {
  return s.coverable == 0 || double(s.covered) >= target_coverage * double(s.coverable);
}

// Whether the solve `b` improves on `a`: reaching the target beats not reaching it; among plans
// that reach it, fewer stations, or as many covering more; among plans that do not (max_stations,
// min_marginal_gain_voxels), more covered, or as much with fewer stations.
bool Better(const Selection& b, const Selection& a, double target_coverage) {
  const bool rb = Reaches(b, target_coverage), ra = Reaches(a, target_coverage);
  if (rb != ra) return rb;
  if (rb) {
    if (b.picks.size() != a.picks.size()) return b.picks.size() < a.picks.size();
    return b.covered > a.covered;
  }
  if (b.covered != a.covered) return b.covered > a.covered;
  return b.picks.size() < a.picks.size();
}

// Whether `p` is within half a step of one of `positions` in x and y and at the same height.
bool Known(const std::vector<WorldPoint>& positions, const WorldPoint& p, double step_m) {
  for (const WorldPoint& q : positions) {
    if (std::abs(q.x() - p.x()) < step_m / 2 && std::abs(q.y() - p.y()) < step_m / 2 &&
        std::abs(q.z() - p.z()) < step_m / 2) {
      return true;
    }
  }
  return false;
}

// Whether the neighbourhood rule lets a position `p` get a set (LocalRefinementOptions::
// neighbourhood_m): the candidates within neighbourhood_m of it (in x, y and z; on the coarse grid,
// the corners of its cell) see at least min_neighbourhood_gain_voxels voxels `covered` leaves out.
bool WorthASet(const CandidateSets& c, const WorldPoint& p, const VoxelSet& covered,
               const LocalRefinementOptions& options) {
  const double reach = options.neighbourhood_m + 1e-6;
  VoxelSet hood(covered.size());
  for (size_t j = 0; j < c.positions.size(); ++j) {
    const WorldPoint& q = c.positions[j];
    if (std::abs(q.x() - p.x()) > reach || std::abs(q.y() - p.y()) > reach || std::abs(q.z() - p.z()) > reach) {
      continue;
    }
    hood.Union(c.sets[j]);
  }
  hood.Subtract(covered);
  return hood.count() >= std::max<uint64_t>(1, options.min_neighbourhood_gain_voxels);
}

}  // namespace

Result<LocalRefinementResult> RefineLocally(const Selector& selector, const VoxelScene& scene, CandidateSets in,
                                            int fixed, const CandidateOptions& candidate_options,
                                            const VisibilityFn& visibility, const LocalRefinementOptions& options,
                                            const JobContext& ctx) {
  if (!(options.step_m > 0) || !(options.radius_m >= options.step_m) || !std::isfinite(options.radius_m) ||
      options.max_rounds < 0) {
    return InvalidArgumentError("local refinement needs 0 < step_m <= radius_m (finite) and max_rounds >= 0");
  }
  if (!(options.neighbourhood_m >= 0) || !std::isfinite(options.neighbourhood_m)) {
    return InvalidArgumentError("local refinement needs a finite neighbourhood_m >= 0 (0 = every position)");
  }
  if (in.positions.size() != in.sets.size() || in.positions.size() != in.floor_z_m.size()) {
    return InvalidArgumentError("local refinement: " + std::to_string(in.positions.size()) + " positions, " +
                                std::to_string(in.floor_z_m.size()) + " floors and " + std::to_string(in.sets.size()) +
                                " sets; they must match");
  }
  LocalRefinementResult out;
  out.candidates = std::move(in);
  VC_ASSIGN_OR_RETURN(out.selection, selector.Select(out.candidates.sets, fixed, ctx));
  out.stations_per_solve.push_back(static_cast<int>(out.selection.picks.size()));
  out.covered_per_solve.push_back(out.selection.covered);
  const int n = static_cast<int>(std::floor(options.radius_m / options.step_m + 1e-9));
  for (int round = 0; round < options.max_rounds; ++round) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("local refinement"));
    std::vector<WorldPoint> added;
    std::vector<double> added_floor;
    // The neighbourhood rule, where the solve stopped short of the target (the round is for coverage;
    // a solve reaching it may still give way to one of fewer stations, so every position gets a set).
    const bool by_neighbourhood = options.neighbourhood_m > 0 && !Reaches(out.selection, options.target_coverage);
    out.neighbourhood_rounds += by_neighbourhood;
    std::vector<WorldPoint> passed_over;  // by the rule this round
    VoxelSet covered;                     // by the solve's picks
    if (by_neighbourhood && !out.candidates.sets.empty()) {
      covered = VoxelSet(out.candidates.sets.front().size());
      for (int pick : out.selection.picks) covered.Union(out.candidates.sets[static_cast<size_t>(pick)]);
    }
    for (size_t k = static_cast<size_t>(fixed); k < out.selection.picks.size(); ++k) {
      const int pick = out.selection.picks[k];
      const WorldPoint& s = out.candidates.positions[pick];
      const double floor_z = out.candidates.floor_z_m[pick];
      if (!std::isfinite(floor_z)) continue;
      const double height = s.z() - floor_z;
      // The candidate stage's checks at this station's own height (with several tripod heights, a
      // high station's column must be free up to its height, not the lowest one's).
      CandidateOptions at_height = candidate_options;
      at_height.tripod_height_m = height;
      at_height.tripod_heights_m.clear();
      for (int iy = -n; iy <= n; ++iy) {
        for (int ix = -n; ix <= n; ++ix) {
          if (ix == 0 && iy == 0) continue;
          const double x = s.x() + ix * options.step_m, y = s.y() + iy * options.step_m;
          const std::optional<double> top = MovedStationFloor(scene.grid, s, floor_z, x, y, at_height);
          if (!top) continue;
          const WorldPoint p(x, y, *top + height);
          if (!HasClearance(scene.grid, p, candidate_options.clearance_m)) continue;
          if (KeepOutZoneContaining(options.keep_out, p) >= 0) continue;
          if (Known(out.candidates.positions, p, options.step_m) || Known(added, p, options.step_m)) continue;
          if (Known(passed_over, p, options.step_m)) continue;
          if (by_neighbourhood && !WorthASet(out.candidates, p, covered, options)) {
            passed_over.push_back(p);  // once, though several picks' sub-grids reach it
            continue;
          }
          added.push_back(p);
          added_floor.push_back(*top);
        }
      }
    }
    out.passed_over += static_cast<int>(passed_over.size());
    if (static_cast<uint64_t>(out.added) + added.size() > options.max_added) {
      out.limited = true;
      added.resize(options.max_added - static_cast<uint64_t>(out.added));
      added_floor.resize(added.size());
    }
    if (added.empty()) break;
    VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> sets, visibility(added));
    if (sets.size() != added.size()) {
      return InternalError("local refinement: the visibility callback returned " + std::to_string(sets.size()) +
                           " sets for " + std::to_string(added.size()) + " positions");
    }
    for (size_t i = 0; i < added.size(); ++i) {
      out.candidates.positions.push_back(added[i]);
      out.candidates.floor_z_m.push_back(added_floor[i]);
      out.candidates.sets.push_back(std::move(sets[i]));
    }
    out.added += static_cast<int>(added.size());
    ++out.rounds;
    VC_ASSIGN_OR_RETURN(Selection next, selector.Select(out.candidates.sets, fixed, ctx));
    out.stations_per_solve.push_back(static_cast<int>(next.picks.size()));
    out.covered_per_solve.push_back(next.covered);
    // Both over the grown sets: where the added positions' sets are kept whole (coarse then fine)
    // they may see voxels no earlier set did, and the kept plan's share is of those too.
    out.selection.coverable = next.coverable;
    if (!Better(next, out.selection, options.target_coverage)) break;
    out.selection = std::move(next);
  }
  return out;
}

}  // namespace vc::planner
