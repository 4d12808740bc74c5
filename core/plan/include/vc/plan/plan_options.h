// PlanOptions: every parameter of a plan, declared once in VC_PLAN_PARAMETERS (vc/base/parameter.h
// explains the table and the places derived from it: validation, the proto conversion, vc-client's
// flags, plan.json). docs/PLANNING.md, "Parameters", has one line per row.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/parameter.h"
#include "vc/base/status.h"
#include "vc/plan/candidates.h"
#include "vc/plan/keep_out.h"
#include "vc/plan/selector.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"

// X(type, name, default, unit, flag, check, help). Greedy selection's rows (max_stations,
// min_marginal_gain_voxels, target_coverage, consolidate) are VC_GREEDY_PARAMETERS (selector.h),
// which GreedyOptions is declared from. Notes on some rows:
// - doorway_candidates: candidates in narrow passages (vc/plan/candidates.h; docs/PLANNING.md,
//   "Doorway candidates"); on by default since issue 36, so that the exact selector reaches the
//   optimum of rooms around a hall (a station just inside each door).
// - ground: the candidates' ground model, floor levels or a terrain height field, or auto per site
//   (vc/plan/candidates.h; docs/PLANNING.md, "Terrain").
// - solver / solve_seconds: greedy, the exact integer program (CBC) with a time limit, or auto
//   (the default: the integer program within the limit, keeping greedy's plan unless it finds a
//   better one; docs/PLANNING.md, "Exact selection").
// - local_candidates: solve, add a sub-grid of candidates around each chosen station, solve again
//   over all, while the plan improves (vc/plan/local_refinement.h; docs/PLANNING.md).
// - coarse_above_candidates: coarse-then-fine candidates (docs/PLANNING.md, "Coarse then fine
//   candidates"): when the grid gives more candidates than this and neither user candidates nor
//   local_candidates are given, the plan runs on a grid of kCoarseGridFactor x grid_spacing_m, then
//   one local-candidates round adds the grid_spacing_m positions around each pick.
// - refine: proximity refinement (ALGORITHM.md s.7.4), each station to the best of a sub-grid.
// - reduce / reduce_to: reduction (s.7.5) removes zero-loss stations; with reduce_to > 0 it keeps
//   removing the cheapest single or pair until at most reduce_to stations remain.
// - min_overlap: registration (vc/plan/scan_graph.h): selection, consolidation, refinement and
//   reduction keep the stations' scan graph connected at this overlap.
// - setup_seconds, scan_seconds, walk_speed_mps: the field time (route.h): per station set-up and
//   scan, plus the walking route's length at this speed.
// - walk_max_step_m: the walking route's RouteOptions::max_step_m (route.h).
// - sparse_set_gain: the visibility sets' form (vc/visibility/voxel_set.h): a set goes sparse
//   (Roaring) when that is at least this many times smaller than its dense bitset; no indoor scene
//   of ours gains 4 x (docs/BENCHMARKS.md), a large site with a range limit gains 9-36 x. The
//   form never changes the plan, only its memory and time.
#define VC_PLAN_PARAMETERS(X)                                                                                         \
  X(double, resolution_m, 0.0, "m", "resolution", kNonNegative,                                                       \
    "working resolution (0 = the octree's own, or 0.1 m for clouds)")                                                 \
  X(uint64_t, memory_budget_bytes, ::vc::kDefaultMemoryBudgetBytes, "bytes", "memory-budget-bytes", kPositive,        \
    "memory budget of the job (capped by the server's --max-memory-budget-bytes)")                                    \
  X(::vc::SelectionTest, selection_test, ::vc::SelectionTest::kSurfaceVisibility, "", "test", kAny,                   \
    "selection test: surface, compatibility, or subvoxel (point clouds only; docs/VISIBILITY.md)")                    \
  X(double, grid_spacing_m, 1.0, "m", "grid-spacing", kPositive, "candidate grid spacing")                            \
  X(double, tripod_height_m, 1.5, "m", "tripod-height", kPositive, "scanner height above the floor")                  \
  X(double, clearance_m, 0.2, "m", "clearance", kNonNegative, "free space required around a candidate")               \
  X(bool, doorway_candidates, true, "", "doorway-candidates", kAny,                                                   \
    "also candidates in doorways and narrow passages, on a finer grid")                                               \
  X(::vc::GroundModel, ground, ::vc::GroundModel::kAuto, "", "ground", kAny,                                          \
    "ground model: floors (a few flat levels), terrain (a walkable height field) or auto (per site)")                 \
  VC_GREEDY_PARAMETERS(X)                                                                                             \
  X(::vc::SelectionSolver, solver, ::vc::SelectionSolver::kAuto, "", "solver", kAny,                                  \
    "station selection: greedy, exact (integer program, proven gap) or auto")                                         \
  X(double, solve_seconds, 20.0, "s", "solve-seconds", kPositive, "time limit of the exact solver")                   \
  X(bool, local_candidates, false, "", "local-candidates", kAny,                                                      \
    "after selection, add candidates around each station and select again while it improves")                         \
  X(double, local_candidates_radius_m, 0.5, "m", "local-candidates-radius", kPositive,                                \
    "half-width of the sub-grid around each station")                                                                 \
  X(double, local_candidates_step_m, 0.25, "m", "local-candidates-step", kPositive, "sub-grid step")                  \
  X(int32_t, local_candidates_rounds, 4, "rounds", "local-candidates-rounds", kPositive,                              \
    "selections after the first, at most")                                                                            \
  X(int32_t, coarse_above_candidates, 4000, "candidates", "coarse-above-candidates", kNonNegative,                    \
    "above this many grid candidates, plan on a 2x grid, then add grid positions around the picks (0 = never)")       \
  X(bool, refine, false, "", "refine", kAny, "refine each station on a local sub-grid")                               \
  X(double, refine_radius_m, 0.5, "m", "refine-radius", kPositive, "refinement radius")                               \
  X(double, refine_step_m, 0.25, "m", "refine-step", kPositive, "refinement step")                                    \
  X(bool, reduce, true, "", "reduce", kAny, "remove redundant stations")                                              \
  X(int32_t, reduce_to, 0, "stations", "reduce-to", kNonNegative,                                                     \
    "reduce to at most this many stations (0 = zero-loss removals only)")                                             \
  X(int32_t, threads, 0, "threads", "threads", kNonNegative, "threads for the job (0 = all, or the server's share)")  \
  X(double, sparse_set_gain, 4.0, "x", "sparse-set-gain", kNonNegative,                                               \
    "keep a candidate's visibility set as a Roaring bitmap when that is this many times smaller (0 = always dense)")  \
  X(double, min_overlap, 0.0, "fraction", "min-overlap", kUnitInterval,                                               \
    "keep the scan graph connected at this overlap (0 = off; 0.3 for target-less registration)")                      \
  X(double, setup_seconds, 120.0, "s", "setup-seconds", kNonNegative, "field time to set up the scanner per station") \
  X(double, scan_seconds, 0.0, "s", "scan-seconds", kNonNegative,                                                     \
    "field time of one scan (0 = the scanner preset's scan time)")                                                    \
  X(double, walk_speed_mps, 1.0, "m/s", "walk-speed", kPositive, "walking speed between stations, carrying the kit")  \
  X(double, walk_max_step_m, 0.25, "m", "walk-max-step", kNonNegative,                                                \
    "largest rise the walking route takes in one step: stairs, sills, ramps")

namespace vc {

struct PlanOptions {
  VC_PLAN_PARAMETERS(VC_DECLARE_PARAMETER)
  // The scanner (VC_SCANNER_PARAMETERS); plan.json and the proto nest it as "scanner".
  ScannerModel scanner;
  // Positions below are in the input's own frame (docs/PLANNING.md, "Outputs in the input's
  // frame"); Plan moves them to the scene's local frame (InLocalFrame) once it has voxelised.
  // User-supplied candidates (m). When non-empty, replaces the generated grid.
  std::vector<WorldPoint> candidates;
  // Several instrument heights above the floor (m): when non-empty, replaces tripod_height_m and
  // the grid gets a candidate at each height per cell.
  std::vector<double> tripod_heights_m;
  // Places no station may stand in.
  std::vector<KeepOutZone> keep_out;
  // Stations already placed (m): picked first, never removed; the plan adds to them.
  std::vector<WorldPoint> fixed_stations;
  // Where the walking route starts (m; z picks the floor level nearest it, NaN = the lowest), if set.
  std::optional<WorldPoint> route_start;

  // The instrument heights candidates stand at: tripod_heights_m, or {tripod_height_m}.
  [[nodiscard]] std::vector<double> TripodHeights() const;

  // INVALID_ARGUMENT naming the first bad parameter: a row's check (non-finite, negative, zero,
  // out of range), the scanner's, a scanner hfov_deg below 360 (stations have no heading), a
  // non-finite candidate, clearance_m >= tripod_height_m (or a
  // tripod_heights_m entry), refine_step_m > refine_radius_m with refine on (local_candidates_step_m
  // > local_candidates_radius_m with local_candidates on), a bad keep-out zone, a
  // non-finite fixed station or one inside a keep-out zone, a route_start with a non-finite x or y
  // or an infinite z. A fixed station inside a zone is named after the zone ("keep_out[1]:
  // fixed_stations[0] (x, y, z) lies inside this zone"), min_gain_voxels_per_minute and
  // min_gain_m2_per_minute both > 0 (named together). Fields are named as `namer` shows them
  // (vc/base/parameter.h; empty: by their paths, "scanner.max_range_m", "keep_out[0]").
  Status Validate(const FieldNamer& namer = {}) const;
};

// The gain rule a plan runs with (docs/PLANNING.md, "The gain rule"), when one is on.
struct GainRule {
  std::string_view parameter;    // "min_gain_m2_per_minute" or "min_gain_voxels_per_minute"
  double value = 0;              // the parameter's value, in its unit (m2/min or voxels/min)
  double voxels_per_minute = 0;  // the same rule in voxels: value x 1 / resolution^2 for m2/min
};

// The gain rule of `options` at `resolution_m` (the voxel rule when > 0, else the area rule), or
// nullopt when both are 0 or resolution_m is not > 0 for the area rule.
[[nodiscard]] std::optional<GainRule> GainRuleOf(const PlanOptions& options, double resolution_m);

// `options` with every position (candidates, keep-out zones, fixed stations, route start) moved
// from the input's frame to the local frame whose origin lies at `frame_origin_m` in the input's
// frame (VoxelScene::frame_origin_m): each less that origin. A zero origin changes nothing.
[[nodiscard]] PlanOptions InLocalFrame(PlanOptions options, const WorldPoint& frame_origin_m);

}  // namespace vc
