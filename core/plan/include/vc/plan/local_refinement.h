// Local candidate refinement around a solution (issue 21, "Candidates where the grid has none"):
// solve, add candidates on a fine sub-grid around each chosen station, solve again over all of
// them, and repeat while the solution improves.
//
// Why a loop around a Selector: the grid decides where a station may stand before anything is
// known about the plan, and the best position of a station is often between grid points (a doorway,
// the corner of an alcove). Refining each chosen station on its own (proximity refinement, §7.4)
// keeps the picks; re-solving over the enlarged candidate set lets the selector trade stations, so
// a selector that optimises the set (an exact one) can drop one. The loop only needs Select, so any
// Selector works; the visibility sets of new positions come from a callback, so the loop does not
// depend on how the pipeline computes them.
//
// Thread-safety: RefineLocally calls the selector and the callback from the calling thread only.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/candidates.h"
#include "vc/plan/keep_out.h"
#include "vc/plan/selector.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"

namespace vc::planner {

struct LocalRefinementOptions {
  double radius_m = 0.5;              // sub-grid half-width around each chosen station (m)
  double step_m = 0.25;               // sub-grid step (m), in (0, radius_m]
  int max_rounds = 4;                 // solves after the first, at most
  std::vector<KeepOutZone> keep_out;  // no position is added inside these
  double target_coverage = 1.0;       // a solve reaching this fraction of its coverable voxels beats one that does not
  uint64_t max_added = UINT64_MAX;    // positions added over all rounds, at most (the caller's memory budget)
  // > 0 (coarse then fine), in a round after a solve short of target_coverage: a sub-grid position
  // gets a set (and becomes a candidate) only where its neighbourhood can still gain, i.e. the
  // candidates within neighbourhood_m of it (in x, y and z; at neighbourhood_m = step_m on a grid of
  // twice the step through the picks, the corners of its cell) see at least
  // min_neighbourhood_gain_voxels voxels the solve's picks leave uncovered. A heuristic, not a
  // bound: the position is taken to see no more than the candidates around it (docs/PLANNING.md,
  // "Coarse then fine candidates"). After a solve reaching the target (the round can only save
  // stations) and at 0: every position gets a set.
  double neighbourhood_m = 0;
  uint64_t min_neighbourhood_gain_voxels = 1;  // at least 1
};

// Candidates and their sets: positions[i] sees sets[i]; floor_z_m[i] is the top of its floor (m,
// NaN when unknown: no sub-grid is placed around it).
struct CandidateSets {
  std::vector<WorldPoint> positions;
  std::vector<double> floor_z_m;
  std::vector<VoxelSet> sets;
};

// The visibility sets of `positions` (world, m), each of the scene's size; errors pass through.
using VisibilityFn = std::function<Result<std::vector<VoxelSet>>(const std::vector<WorldPoint>&)>;

struct LocalRefinementResult {
  CandidateSets candidates;  // the input's, then the positions the rounds added
  Selection selection;       // the best solve's, over `candidates`
  int rounds = 0;            // solves after the first
  int added = 0;             // positions added over all rounds
  bool limited = false;      // max_added cut a round short (the rounds after it add nothing)
  // The rounds the neighbourhood rule decided, and the positions it passed over in them (their
  // neighbours see fewer than min_neighbourhood_gain_voxels uncovered voxels; not in `added`).
  int neighbourhood_rounds = 0;
  int passed_over = 0;
  // Stations and covered voxels of each solve, the first solve's first.
  std::vector<int> stations_per_solve;
  std::vector<uint64_t> covered_per_solve;
};

// Solves with `selector` over `in`, then, each round, adds around every picked station (beyond the
// `fixed` first ones) the positions of a step_m sub-grid within radius_m (square) that stand on the
// station's floor (MovedStationFloor: the floor level's band, or on terrain (candidate_options.ground)
// the ground reached on foot; with the station's own height above that floor), with the
// clearance (HasClearance), outside options.keep_out, and are not yet candidates (at most
// options.max_added over all rounds); solves again over all; keeps the new solve if it is better:
// reaching target_coverage beats not reaching it, then fewer stations, or as many covering more
// (short of the target: more covered, then fewer stations). With options.neighbourhood_m > 0 and a
// solve short of the target only the positions whose neighbourhood can still gain are added
// (LocalRefinementOptions). Stops after a round without
// improvement, without new positions, or after max_rounds. INVALID_ARGUMENT for bad options or inputs of different
// lengths; the selector's and the callback's errors pass through; CANCELLED / DEADLINE_EXCEEDED from ctx.
Result<LocalRefinementResult> RefineLocally(const Selector& selector, const VoxelScene& scene, CandidateSets in,
                                            int fixed, const CandidateOptions& candidate_options,
                                            const VisibilityFn& visibility, const LocalRefinementOptions& options,
                                            const JobContext& ctx = {});

}  // namespace vc::planner
