// The station planner (ALGORITHM.md section 7; paper section 3): candidates on the operating plane,
// visibility counts (the heat map), selection (a Selector: lazy greedy, then consolidation),
// optional proximity refinement, reduction, and evaluation, as one cancellable pipeline reporting
// progress per stage. The stages are stages.h's functions, run by one StageRunner (stage_runner.h).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/plan/coverage_curve.h"
#include "vc/plan/plan_options.h"
#include "vc/plan/scan_graph.h"
#include "vc/plan/selector.h"
#include "vc/plan/stage_runner.h"
#include "vc/plan/unseen_causes.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"

namespace vc {

struct PlannedStation {
  WorldPoint position;
  uint64_t visible_voxels = 0;     // voxels passing the selection test from here
  uint64_t marginal_gain = 0;      // new voxels when picked (greedy order)
  double cumulative_coverage = 0;  // covered / coverable after this pick
  double global_visibility = 0;    // G of this station alone
  int candidate_index = -1;        // index into PlanResult::candidates, or -1 if refined off-grid or fixed
  bool fixed = false;              // one of PlanOptions::fixed_stations (placed first, never removed)
  // Top of the floor the station stands over (m, local frame): its candidate's floor, else the
  // highest standing surface below it (planner::FloorBelow); NaN when nothing lies below it.
  double floor_z_m = std::numeric_limits<double>::quiet_NaN();
};

struct HeatMap {
  // Candidates with their visibility count (Fig. 10); cells without a candidate are absent.
  std::vector<WorldPoint> positions;
  std::vector<uint64_t> visible_voxels;
  // Per candidate: the top of the floor under it (m), NaN for user candidates; may be empty (then
  // the heat map groups candidates by their own z).
  std::vector<double> floor_z_m;
  double grid_spacing_m = 0;
};

struct Reduction {
  // |P| x |P|, row-major: diagonal = G(P) - G(P - {i}); off-diagonal = G(P) - G(P - {i, j}).
  std::vector<double> matrix;
  int size = 0;
  // Stations removed, as positions in the greedy order (before removal).
  std::vector<int> removed;
  double global_visibility_before = 0;
  double global_visibility_after = 0;
  // P: the stations the matrix is about (greedy order, after refinement), local frame (m).
  std::vector<WorldPoint> positions;
};

// The walking route through a plan's final stations (docs/PLANNING.md, "The walking route and the
// field time"; vc/plan/route.h has the rules).
struct WalkingRoute {
  std::vector<int> order;  // indices into PlanResult::stations, each once, in visiting order
  // Per entry of order: the walk arriving there (m); the first from `start`, 0 without one; NaN
  // where no walkable path links the station to the one before it (a new part of the route).
  std::vector<double> legs_m;
  double length_m = 0;  // sum of the finite legs
  // Per entry of order: the leg's path over the standing surfaces, (x, y, z of the floor) in m,
  // from the previous station's floor (or the start) to this one's; empty for a NaN leg and for
  // the first entry without a start.
  std::vector<std::vector<WorldPoint>> polylines;
  int parts = 0;                    // groups of stations no walkable path links (1 = one walk)
  std::optional<WorldPoint> start;  // PlanOptions::route_start, if given
};

// The time a crew needs in the field for a plan (docs/PLANNING.md, "The walking route and the
// field time"), in seconds: every station set up and scanned, and the route walked.
struct FieldTime {
  double setup_s = 0;                   // stations x PlanOptions::setup_seconds
  double scan_s = 0;                    // stations x scan_seconds_per_station
  double walk_s = 0;                    // the route's walkable length / PlanOptions::walk_speed_mps
  double total_s = 0;                   // their sum
  double scan_seconds_per_station = 0;  // PlanOptions::scan_seconds, or the scanner preset's scan time, or 0
};
// The field time of `stations` stations and a walk of `walk_m` metres under `options`.
FieldTime ComputeFieldTime(size_t stations, double walk_m, const PlanOptions& options);

// How a plan's visibility stage and its reduction's evaluation of the stations were spread over
// vc-server replicas (docs/DEPLOY.md, "Scaling out"). All zero for a plan computed in one process.
struct Distribution {
  int replicas = 0;              // replicas that computed a shard (this one included; the larger stage's count)
  int shards = 0;                // shards of candidates (visibility) and of stations (reduction)
  int retried = 0;               // shard attempts started again elsewhere (failed, refused or slow)
  uint64_t bytes_exchanged = 0;  // bytes sent to and received from peers (scenes, requests, sets, values)
  // Adds another stage's figures.
  void Add(const Distribution& o) {
    replicas = std::max(replicas, o.replicas);
    shards += o.shards;
    retried += o.retried;
    bytes_exchanged += o.bytes_exchanged;
  }
};

// The visibility sets of `viewpoints`, computed elsewhere than ComputeVisibilitySets (vc-server
// fans them out over its peers): must return exactly what ComputeVisibilitySets(scene, viewpoints,
// options, ctx) returns, with how it was spread and any warnings for PlanResult::warnings. `what`
// names the call for logs and warnings: "the visibility stage", or the selection stage's local
// candidates ("the fine round's sets" of coarse-then-fine candidates, "the local candidates' sets").
struct DistributedSets {
  std::vector<VoxelSet> sets;
  Distribution distribution;
  std::vector<std::string> warnings;
};
using VisibilitySetsFn = std::function<Result<DistributedSets>(
    const VoxelScene& scene, const std::vector<WorldPoint>& viewpoints, const VisibilitySetsOptions& options,
    const JobContext& ctx, const char* what)>;

// The reduction's per-station evaluation, by its caller (across replicas): for each station its
// faces with V > 0, exactly as vc::Evaluate with keep_sparse_per_viewpoint_values gives them.
// Asked for the join state (EvaluateOptions::keep_sparse_join_state), also each station's figures
// and its values' join state, exactly as Evaluate gives them, when every replica gave them (an
// older one does not): `figures` then holds one per station, else it is empty.
struct DistributedFaceValues {
  std::vector<SparseFaceValues> values;
  std::vector<VisibilityFigures> figures;
  Distribution distribution;
  std::vector<std::string> warnings;
};
using FaceValuesFn =
    std::function<Result<DistributedFaceValues>(const VoxelScene& scene, const std::vector<WorldPoint>& stations,
                                                const EvaluateOptions& options, const JobContext& ctx)>;

// Every position here (stations, heat map, reduction, voxel centres, route; floor levels and
// floor_z_m as heights) is in the scene's local frame: add frame_origin_m for the input's own frame,
// as every writer does (vc/report/plan_report.h, vc/wire/convert.h). `options` is as given, in the
// input's frame.
struct PlanResult {
  PlanOptions options;
  // Where the local frame's origin lies in the input's frame, m (VoxelScene::frame_origin_m).
  WorldPoint frame_origin_m = WorldPoint::Zero();
  double resolution_m = 0;
  SelectionTest selection_test = SelectionTest::kSurfaceVisibility;  // the test that ran
  std::vector<PlannedStation> stations;                              // final stations, in greedy order
  HeatMap heat_map;
  Reduction reduction;
  uint64_t candidate_count = 0;
  // Generated grid: cells examined (per floor level), those with no floor below, and those whose
  // candidate failed the clearance (0 with user candidates).
  uint64_t grid_cells = 0;
  uint64_t cells_without_floor = 0;
  uint64_t cells_failing_clearance = 0;
  uint64_t occupied_voxels = 0;
  uint64_t coverable_voxels = 0;
  uint64_t covered_voxels = 0;
  // Why the occupied voxels outside the coverable ones are seen by no candidate (unseen_causes.h).
  UnseenCauses unseen_causes;
  Evaluation evaluation;             // of the final stations at the working resolution (with face values)
  std::vector<StageTiming> timings;  // the stages that ran, in order
  double total_seconds = 0;          // the whole plan, from validation to the evaluation
  std::vector<std::string> warnings;
  // Floor levels found for the operating plane (top of the floor, m), ascending; empty with
  // user-supplied candidates.
  std::vector<double> floor_levels_m;
  // The candidates' ground model (floors or terrain) and why (docs/PLANNING.md, "Terrain"); model
  // kAuto with user-supplied candidates.
  planner::GroundChoice ground;
  // Why selection stopped (StopReasonName: "exhausted", "target_reached", "max_stations", "min_gain",
  // "gain_rule").
  StopReason stop_reason = StopReason::kExhausted;
  // Greedy picks (fixed stations not counted), and how many of them consolidation saved.
  int greedy_stations = 0;
  int consolidated = 0;
  // Occupied voxel centres (local frame, m) in id order, for visibility.ply.
  std::vector<WorldPoint> voxel_centers;
  // Registration: the final stations' scan graph (indices into stations) at options.min_overlap,
  // and how many stations selection picked only to link it.
  ScanGraph scan_graph;
  int connecting_stations = 0;
  WalkingRoute route;
  FieldTime field_time;
  // The coverage curve of the final stations (vc/plan/coverage_curve.h): one point per station, in
  // the order of stations; the last point is the plan's own coverage.
  std::vector<CoveragePoint> coverage_curve;
  // How the selection's station count relates to the optimum over the candidates (docs/PLANNING.md,
  // "Exact selection"): the selection stage's, before refinement and reduction.
  planner::Optimality optimality;
  // The visibility stage and the reduction across replicas (PlanCallbacks::visibility_sets,
  // face_values); zero when local.
  Distribution distribution;
};

// What a plan reports while it runs, for streaming, and the one piece of work it may hand to its
// caller; every member optional, called on the thread that runs Plan.
struct PlanCallbacks {
  // Once, when the visibility stage has counted every candidate (the heat map is final then:
  // refinement's trial positions are not candidates).
  std::function<void(const HeatMap&)> on_heat_map;
  // Provisional: each station as selection picks it (greedy order, after consolidation; the fixed
  // stations first, with fixed = true), before refinement and reduction may move or remove it
  // (never a fixed one); global_visibility is still 0.
  std::function<void(const PlannedStation&, int index)> on_station;
  // Once, after refinement and reduction: the final stations, in the order of PlanResult::stations
  // (marginal gain and coverage final; global_visibility still 0 until the evaluation).
  std::function<void(const std::vector<PlannedStation>&)> on_final_stations;
  // The visibility stage's sets (fixed stations first, then the candidates), when set: vc-server
  // fans them out over its peers. Unset: ComputeVisibilitySets in this process.
  VisibilitySetsFn visibility_sets;
  // When set, the reduction asks it for its stations' face values (all stations in one call)
  // instead of evaluating them itself; the same contract as visibility_sets.
  FaceValuesFn face_values;
};

// Runs the whole pipeline on an already-read input. INVALID_ARGUMENT for bad options,
// FAILED_PRECONDITION when no candidate survives, RESOURCE_EXHAUSTED over budget, CANCELLED /
// DEADLINE_EXCEEDED from ctx.
Result<PlanResult> Plan(const SceneInput& input, const PlanOptions& options, const JobContext& ctx = {},
                        const PlanCallbacks& callbacks = {});

}  // namespace vc
