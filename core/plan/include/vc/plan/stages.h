// The stages of a plan (docs/PLANNING.md, "Pipeline"), each a function from a typed input to a
// typed output: voxelize -> candidates -> visibility -> selection -> refine -> reduction ->
// evaluation. vc::Plan (planner.h) runs them through one StageRunner (stage_runner.h), which does
// the begin report, the cancellation check, the progress relabelling and the timing, and assembles
// PlanResult from their outputs; the stages themselves only compute. Each takes the context the
// runner gives it (progress already relabelled to the stage) and the plan's options, and returns
// a Result. Inputs hold references to earlier outputs (which must outlive the call) or take over
// what the stage consumes (visibility sets, stations), so that memory is freed where the
// monolithic planner freed it. Thread-compatible: a stage shares nothing between calls.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/candidates.h"
#include "vc/plan/planner.h"
#include "vc/plan/route.h"
#include "vc/plan/selector.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"

namespace vc::planner {

// The stations between selection and the final evaluation, in greedy order, one entry each.
struct Stations {
  std::vector<WorldPoint> positions;  // optical centres, local frame (m)
  std::vector<double> floor_z_m;      // top of the floor below (m); NaN for user candidates
  std::vector<int> candidate;         // index into the candidates; -1 once refined off-grid, or fixed
  std::vector<VoxelSet> sets;         // each station's visibility set (selection test)
  std::vector<bool> fixed;            // a fixed station (options.fixed_stations): never moved or removed
  // Number of stations.
  [[nodiscard]] size_t size() const { return positions.size(); }
  // True when there is no station.
  [[nodiscard]] bool empty() const { return positions.empty(); }
};

// --- Stage::kVoxelize: the input at the working resolution ---
struct VoxelizeInput {
  const SceneInput& input;
};
struct VoxelizeOutput {
  VoxelScene scene;
  // With options.selection_test kSubvoxel and an input of points: one patch per occupied voxel
  // (ComputeSurfacePatches). Empty otherwise.
  std::vector<SurfacePatch> surface_patches;
  // The test the plan runs: options.selection_test, or kSurfaceVisibility for kSubvoxel on an input
  // without points (an octree, a compact vc-voxels upload).
  SelectionTest selection_test = SelectionTest::kSurfaceVisibility;
  std::vector<std::string> warnings;  // for PlanResult::warnings: why the sub-voxel test did not run
};
// Whether `input` carries the points the sub-voxel test needs (not an octree, not a vc-voxels stream).
[[nodiscard]] bool HasSurfacePoints(const SceneInput& input);
// "the subvoxel test needs the input's points, and this octree has none", for an input without them.
[[nodiscard]] std::string NoSurfacePointsNote(const SceneInput& input);
// Voxelize with options.resolution_m and memory_budget_bytes, and the surface patches the sub-voxel
// test needs (a warning, and the surface test, where the input has no points); RESOURCE_EXHAUSTED
// over budget.
[[nodiscard]] Result<VoxelizeOutput> RunVoxelizeStage(const VoxelizeInput& in, const PlanOptions& options,
                                                      const JobContext& ctx);

// --- Stage::kCandidates: tripod positions on the operating plane, or the user's ---
struct CandidatesInput {
  const VoxelScene& scene;
};
struct CandidatesOutput {
  std::vector<WorldPoint> positions;   // local frame (m)
  std::vector<double> floor_z_m;       // per candidate (m); NaN for user candidates
  std::vector<double> floor_levels_m;  // floor levels found (m), ascending; empty for user candidates
  GroundChoice ground;                 // the ground model used and why; kAuto for user candidates
  uint64_t grid_cells = 0;             // grid cells x levels examined
  uint64_t cells_without_floor = 0;
  uint64_t cells_failing_clearance = 0;
  uint64_t in_keep_out = 0;           // candidates dropped because they lie in a keep-out zone
  std::vector<std::string> warnings;  // for PlanResult::warnings, in order
  // Set when the coarse-then-fine path runs (PlanOptions::coarse_above_candidates): the grid at
  // fine_spacing_m gave fine_candidates, more than the threshold, so `positions` (and the counts
  // above) are the grid's at coarse_spacing_m.
  struct CoarseGrid {
    double fine_spacing_m = 0;
    double coarse_spacing_m = 0;
    uint64_t fine_candidates = 0;
  };
  std::optional<CoarseGrid> coarse;
};
// The candidate grid's options (every row of PlanOptions it uses). Refinement and local candidates
// start from them, each with its own height, ground model and no doorway candidates.
[[nodiscard]] CandidateOptions CandidateOptionsFor(const PlanOptions& options);
// Generated candidates at every height of options.TripodHeights(), or the user's; either without
// those in a keep-out zone. INVALID_ARGUMENT for a user candidate or fixed station out of range or
// inside an occupied voxel, or a fixed station outside the scene's bounds (widened by 2 m, naming
// them); a warning for a fixed station without an occupied voxel within 3 m straight below.
// FAILED_PRECONDITION when no floor is found or no candidate survives.
// With options.coarse_above_candidates > 0, no user candidates and local_candidates off: when the
// grid gives more candidates than coarse_above_candidates, the output is the grid at
// kCoarseGridFactor x grid_spacing_m instead (CandidatesOutput::coarse; the full grid when the
// coarse one has no candidate, other errors of the coarse grid end the stage), and a progress line
// says so.
[[nodiscard]] Result<CandidatesOutput> RunCandidatesStage(const CandidatesInput& in, const PlanOptions& options,
                                                          const JobContext& ctx);

// The coarse grid's spacing in units of grid_spacing_m (docs/PLANNING.md, "Coarse then fine
// candidates": 2 halves the time of fr_campus's plan; 3 would leave the fine round 8 positions per
// pick that a pick 3 cells away cannot reach).
inline constexpr double kCoarseGridFactor = 2.0;
// The options the rest of a coarse-then-fine plan runs with: `options` with one local-candidates
// round of grid_spacing_m steps within grid_spacing_m of each pick (the fine grid's 8 positions
// around it).
[[nodiscard]] PlanOptions CoarseToFineOptions(const PlanOptions& options);
// Why the coarse-then-fine path ran (candidates.coarse set) with `threshold`
// (coarse_above_candidates), for plan.json (LocalCandidatesReport::coarse_to_fine); empty when not.
[[nodiscard]] std::string CoarseToFineNote(const CandidatesOutput& candidates, int32_t threshold);

// RESOURCE_EXHAUSTED (naming `what`) when `positions` visibility sets over `voxels` voxels need
// more than half of `budget_bytes`; checked before a stage computes that many sets.
[[nodiscard]] Status CheckVisibilitySetBudget(uint64_t positions, uint64_t voxels, uint64_t budget_bytes,
                                              const char* what);

// --- Stage::kVisibility: each candidate's visibility set and the heat map ---
struct VisibilityInput {
  const VoxelScene& scene;
  const std::vector<WorldPoint>& candidates;
  const std::vector<double>& floor_z_m;           // per candidate (for the heat map)
  const std::vector<WorldPoint>& fixed_stations;  // their sets are computed too, not in the heat map
  const PlanCallbacks& callbacks;                 // on_heat_map is called once, when the heat map is final
  std::span<const SurfacePatch> surface_patches;  // VoxelizeOutput's: the sub-voxel test's patches
};
struct VisibilityOutput {
  std::vector<VoxelSet> sets;         // per candidate
  std::vector<VoxelSet> fixed_sets;   // per fixed station
  HeatMap heat_map;                   // per candidate: |set|
  Distribution distribution;          // from callbacks.visibility_sets; zero when computed here
  std::vector<std::string> warnings;  // from callbacks.visibility_sets
};
// The options the visibility stage computes its sets with (a peer computing a shard of them must
// use the same), with `surface_patches` (VoxelizeOutput's) for the sub-voxel test.
[[nodiscard]] VisibilitySetsOptions VisibilitySetsOptionsFor(const PlanOptions& options,
                                                             std::span<const SurfacePatch> surface_patches = {});
// The sets of `positions` from `visibility_sets` (vc-server fans them out over its peers; `what`
// names the call, VisibilitySetsFn) when it is set and there are no surface patches (peers hold
// none), else ComputeVisibilitySets here; the same sets either way. INTERNAL when the callback
// returns the wrong number or size of sets.
[[nodiscard]] Result<DistributedSets> VisibilitySetsOf(const VisibilitySetsFn& visibility_sets, const VoxelScene& scene,
                                                       const std::vector<WorldPoint>& positions,
                                                       const VisibilitySetsOptions& set_options,
                                                       std::span<const SurfacePatch> surface_patches,
                                                       const JobContext& ctx, const char* what);
// With surface patches (the sub-voxel test) the sets are computed here, never by
// callbacks.visibility_sets: peers hold no patches. CANCELLED / DEADLINE_EXCEEDED from ctx.
[[nodiscard]] Result<VisibilityOutput> RunVisibilityStage(const VisibilityInput& in, const PlanOptions& options,
                                                          const JobContext& ctx);

// --- Stage::kSelection: the Selector's picks as stations ---
struct SelectionInput {
  const VoxelScene& scene;  // for the local-candidates loop's positions and their sets
  const Selector& selector;
  std::vector<VoxelSet> sets;        // per candidate; consumed (freed when done)
  std::vector<VoxelSet> fixed_sets;  // per fixed station (options.fixed_stations); consumed
  const std::vector<WorldPoint>& candidates;
  const std::vector<double>& floor_z_m;           // per candidate
  const std::vector<uint64_t>& visible_voxels;    // per candidate: |set| (the heat map's counts)
  const PlanCallbacks& callbacks;                 // on_station is called per pick, in pick order
  std::span<const SurfacePatch> surface_patches;  // VoxelizeOutput's: the sub-voxel test's patches
  // The candidates' ground model (CandidatesOutput::ground): on kTerrain the local candidates
  // stand on the ground reached on foot from their station (MovedStationFloor).
  GroundModel ground = GroundModel::kAuto;
  // Coarse then fine (CandidatesOutput::coarse): the added positions' sets are kept whole, so the
  // fine round may cover voxels no coarse candidate sees (the coverable set grows).
  bool keep_added_sets_whole = false;
};
struct SelectionOutput {
  Stations stations;    // the fixed stations, then the picks, in pick order
  VoxelSet coverable;   // union of every candidate's and fixed station's set
  Selection selection;  // what the selector reported
  // the local-candidates loop's, when the memory budget cut it short, and its fan-out's
  std::vector<std::string> warnings;
  // How the local-candidates loop's sets were spread over the replicas (VisibilitySetsOf); zero
  // when computed here.
  Distribution distribution;
  // Per k = 1..picks (index k - 1), what any k stations cover at most and the most found, over the
  // candidates and fixed stations selected from (the fixed ones always among the k; none for fewer
  // k); empty where not computed (BestCoverageOf).
  std::vector<std::optional<BestCoverage>> best_coverage;
};
// The per-k bound and best coverage (vc/plan/k_coverage_bound.h) over `sets`, the `fixed` stations'
// first: their voxels count as given and the k - fixed others are chosen among the rest. Empty over
// kMaxBestCoveragePairs (voxel, set) pairs or where the classes could take more than `max_bytes`
// (kBestCoverageBytesPerPair a (voxel, set) pair and kBestCoverageBytesPerVoxel a voxel: the
// classes' seen_by and sees, the problem's copy and the bound's own column lists, 4 bytes a pair
// each with room for their vectors' growth; BuildClasses' id maps; a vector per class, the classes
// at most the voxels); the steps and search stop at `seconds`
// (the bounds stay valid).
inline constexpr uint64_t kMaxBestCoveragePairs = uint64_t{1} << 28;
inline constexpr uint64_t kBestCoverageBytesPerPair = 32;
inline constexpr uint64_t kBestCoverageBytesPerVoxel = 136;
[[nodiscard]] Result<std::vector<std::optional<BestCoverage>>> BestCoverageOf(const std::vector<VoxelSet>& sets,
                                                                              int fixed, int max_k, double seconds,
                                                                              uint64_t max_bytes,
                                                                              const JobContext& ctx);
// The selector's own bound tightens the per-k bound below it: selection.optimality.lower_bound says
// no plan of fewer stations covers the target's voxels (need = the smallest count reaching
// options.target_coverage of selection.coverable), so for k < lower_bound the bound becomes at most
// need - 1 (and best_voxels with it). Only where that bound is about the same problem as the per-k
// bound: any stations among the same sets over the same coverable voxels (not with min_overlap's
// connection, max_stations or local_candidates' extra rounds); nothing without a proven bound.
void CapBelowTheSelectorsBound(std::vector<std::optional<BestCoverage>>& best, const Selection& selection,
                               const PlanOptions& options);
// With options.local_candidates, RefineLocally (local_refinement.h) around the selector: positions
// on a local_candidates_step_m sub-grid around each chosen station (on its floor, with the
// clearance, outside keep-out zones) become candidates, their sets cut to the first coverable set
// (the coverage problem stays the same: voxels only they see raise no target; whole with
// in.keep_added_sets_whole), and selection runs
// again with in.selector over all while it improves. A station at an added position has candidate
// index -1. Positions beyond what half the memory budget holds are not added (a warning says so).
// Errors of the selector (CANCELLED / DEADLINE_EXCEEDED from ctx).
[[nodiscard]] Result<SelectionOutput> RunSelectionStage(SelectionInput in, const PlanOptions& options,
                                                        const JobContext& ctx);

// GreedySelector's options for a plan with `options` over a scene of `resolution_m`: its
// VC_GREEDY_PARAMETERS rows, min_overlap, the station's set-up and scan seconds and the area
// rule's 1 / resolution_m^2 surface voxels per m^2 (0 when resolution_m is not > 0).
[[nodiscard]] GreedyOptions SelectorOptionsFor(const PlanOptions& options, double resolution_m);
// The selector options.solver names: GreedySelector, or ExactSelector with options.solve_seconds
// and half the job's memory budget (the visibility sets hold the rest). With local_candidates its
// solves share options.solve_seconds counted from this call: make it right before the stage.
[[nodiscard]] std::unique_ptr<Selector> SelectorFor(const PlanOptions& options, double resolution_m);

// --- Stage::kRefine: each station to the best position of a sub-grid around it (s.7.4) ---
struct RefineInput {
  const VoxelScene& scene;
  Stations stations;                              // consumed
  VoxelSet coverable;                             // consumed; grows by what the trial positions see
  std::span<const SurfacePatch> surface_patches;  // VoxelizeOutput's: the sub-voxel test's patches
  // The candidates' ground model (CandidatesOutput::ground): on kTerrain a moved station stands on
  // the ground reached on foot from where it was (MovedStationFloor), else on its floor level.
  GroundModel ground = GroundModel::kAuto;
};
struct RefineOutput {
  Stations stations;
  VoxelSet coverable;
};
// RESOURCE_EXHAUSTED when the trial positions' sets exceed the budget; CANCELLED from ctx.
[[nodiscard]] Result<RefineOutput> RunRefineStage(RefineInput in, const PlanOptions& options, const JobContext& ctx);

// --- Stage::kReduction: the reduction matrix and the stations to keep (s.7.5) ---
struct ReductionInput {
  const VoxelScene& scene;
  const Stations& stations;
  const FaceValuesFn& face_values;  // when set, the stations' values come from it (PlanCallbacks)
};
struct ReductionOutput {
  Reduction reduction;    // the matrix, the removed stations and G before and after
  std::vector<int> keep;  // indices into the stations kept, ascending
  // The evaluation of all stations (with face values), when it was computed and nothing was
  // removed, so the evaluation stage reuses it.
  std::optional<Evaluation> evaluation;
  Distribution distribution;          // of the face values, when face_values computed them
  std::vector<std::string> warnings;  // face_values' warnings, for PlanResult::warnings
};
// Stations the reduction evaluates at once (each call of vc::Evaluate pays for the scene's
// lattice and face groups once, ~3 s on a 6.8 M-voxel site).
inline constexpr int kReductionStationsPerBatch = 256;
// What the reduction evaluates stations with (here, and on a peer computing a shard of them):
// StationEvaluateOptions keeping each station's sparse values (faces with V > 0), not the face
// values (the stage keeps those too when one evaluation covers every station).
[[nodiscard]] EvaluateOptions ReductionEvaluateOptions(const PlanOptions& options);
// Every one of `count` stations kept, nothing evaluated: the output when reduction does not run.
[[nodiscard]] ReductionOutput KeepAllStations(size_t count);
// The bytes the reduction's joined evaluation holds at its peak on a scene of `voxels` occupied
// voxels: the evaluation joined so far and the batch being joined into it, each with the join
// state (9 bytes per face), the face values (4 per face) and the sole viewers (4 per voxel).
[[nodiscard]] uint64_t ReductionJoinBytes(uint64_t voxels);
// The bytes of an Evaluate call's working set on a scene of `voxels` voxels, whatever the stations:
// the voxels' lattice indices (12 bytes a voxel), their corners (8 ids of 4 bytes, and about 3
// distinct corners a voxel, each 8 bytes and 4 for its place in the rays' order) and each face's
// best V and perception (9 bytes a face): 134 bytes a voxel.
[[nodiscard]] uint64_t EvaluateWorkingBytes(uint64_t voxels);
// What the reduction holds whatever it keeps: the top-3 table (one FaceTop3, 24 bytes a face,
// vc/plan/reduction.h) and the working set of the Evaluate call of a batch (EvaluateWorkingBytes):
// 278 bytes a voxel.
[[nodiscard]] uint64_t ReductionTableBytes(uint64_t voxels);
// The reduction's shares of the memory budget (docs/PLANNING.md, "Memory, stage by stage"): the
// cache of the stations' values, a quarter (at most 1 GiB, as before); the table and the joined
// evaluation, the other three quarters (the candidates' visibility sets held half of the budget;
// selection frees them before the reduction starts). The table is needed: over the three quarters
// the stage refuses (RESOURCE_EXHAUSTED) before allocating it. The joined evaluation is kept only if
// it fits beside the table; otherwise the evaluation stage evaluates the final stations again (a
// warning says so), which holds less: one evaluation, no join state, no table.
struct ReductionMemory {
  bool table_fits = false;   // table_bytes <= three quarters of the budget
  bool keep_join = false;    // table_bytes + join_bytes <= three quarters of the budget
  uint64_t table_bytes = 0;  // ReductionTableBytes of the scene
  uint64_t join_bytes = 0;   // ReductionJoinBytes of the scene
  uint64_t cache_bytes = 0;  // the cache's share: a quarter of the budget, at most 1 GiB
};
[[nodiscard]] ReductionMemory ReductionMemoryFor(uint64_t voxels, uint64_t memory_budget_bytes);
// The smallest memory budgets that hold the reduction's table (RunReductionStage refuses below it),
// and the table with the joined evaluation, on a scene of `voxels` voxels.
[[nodiscard]] uint64_t ReductionTableBudgetBytes(uint64_t voxels);
[[nodiscard]] uint64_t ReductionJoinBudgetBytes(uint64_t voxels);
// Errors of Evaluate and RunReduction (CANCELLED / DEADLINE_EXCEEDED from ctx); RESOURCE_EXHAUSTED,
// before anything is allocated, when its table does not fit in three quarters of the memory budget.
[[nodiscard]] Result<ReductionOutput> RunReductionStage(const ReductionInput& in, const PlanOptions& options,
                                                        const JobContext& ctx);

// --- Stage::kEvaluation: V of every face from the final stations, and G ---
struct EvaluationInput {
  const VoxelScene& scene;
  const std::vector<WorldPoint>& positions;  // the final stations, local frame (m)
  std::optional<Evaluation> reusable;        // the same stations' evaluation, if one exists
};
struct EvaluationOutput {
  Evaluation evaluation;
  std::vector<WorldPoint> voxel_centers;  // occupied voxel centres (world, m) in id order
  std::vector<std::string> warnings;      // for PlanResult::warnings, in order
};
// The bytes the evaluation stage holds at its peak when it evaluates `stations` final stations on
// a scene of `voxels` voxels with `threads` threads (0 = all): EvaluateWorkingBytes (134 bytes a
// voxel), the sole viewers (4) and the face values out (24), the voxels' centres (24); each extra
// thread's best values and sole viewers (58 bytes a voxel) while they stay within the 256 MiB
// vc::Evaluate allows them. Charged to the whole budget (no other stage's structure is held then).
[[nodiscard]] uint64_t EvaluationStageBytes(uint64_t voxels, uint64_t stations, int threads);
// Errors of Evaluate (CANCELLED / DEADLINE_EXCEEDED from ctx); RESOURCE_EXHAUSTED, before anything
// is allocated, when the stage must evaluate and EvaluationStageBytes exceeds the memory budget.
[[nodiscard]] Result<EvaluationOutput> RunEvaluationStage(EvaluationInput in, const PlanOptions& options,
                                                          const JobContext& ctx);

// --- Stage::kRoute: the walking route through the final stations (route.h) ---
struct RouteInput {
  const SceneInput& input;  // an octree's free space tells where the scan saw
  const VoxelScene& scene;
  const std::vector<WorldPoint>& stations;    // the final stations, local frame (m)
  const std::vector<double>& floor_z_m;       // per station: its floor (m), NaN when unknown
  const std::vector<double>& floor_levels_m;  // the candidates' floor levels, ascending
};
struct RouteOutput {
  std::optional<Route> route;   // none when its walk graph exceeds a quarter of the memory budget
  std::string unrouted_reason;  // why there is none (the walk graph's RESOURCE_EXHAUSTED message)
};
// PlanRoute with the planner's settings: headroom = the lowest tripod height + clearance_m (where
// candidates stand), clearance_m, unseen floor within 1.5 m of a seen one, up to 35 % of the
// walking cylinder cluttered, an octree's free space, stations numbered from 1 in warnings, and
// route_start (z NaN: the lowest floor level). CANCELLED / DEADLINE_EXCEEDED from ctx.
[[nodiscard]] Result<RouteOutput> RunRouteStage(const RouteInput& in, const PlanOptions& options,
                                                const JobContext& ctx);

// What reduction and the final evaluation evaluate stations with: the plan's scanner and
// threads, all faces, each face's best V kept.
[[nodiscard]] EvaluateOptions StationEvaluateOptions(const PlanOptions& options);

}  // namespace vc::planner
