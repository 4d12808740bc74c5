// vc::Plan: the stages of stages.h run in order through one StageRunner, and PlanResult assembled
// from their outputs. What lies between two stages (the coverable count, the final stations'
// gains in greedy order, the warnings) is assembled here, in the order the stages produce it.
#include "vc/plan/planner.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "format.h"
#include "vc/plan/selector.h"
#include "vc/plan/stage_runner.h"
#include "vc/plan/stages.h"
#include "vc/visibility/scanner_presets.h"

namespace vc {

namespace {

using planner::Num;

using planner::Percent;

// The final stations among `stations` (those in `keep`, in greedy order) with their gains and
// cumulative coverage of `coverable_voxels`, and the voxels they cover together.
struct FinalStations {
  std::vector<PlannedStation> stations;
  uint64_t covered_voxels = 0;
};
FinalStations AssembleFinalStations(const planner::Stations& stations, const std::vector<int>& keep,
                                    uint64_t coverable_voxels) {
  FinalStations out;
  VoxelSet covered(stations.empty() ? 0 : stations.sets[0].size());
  for (int k : keep) {
    PlannedStation ps;
    ps.position = stations.positions[k];
    ps.visible_voxels = stations.sets[k].count();
    ps.marginal_gain = ps.visible_voxels - stations.sets[k].CountAnd(covered);
    covered.Union(stations.sets[k]);
    out.covered_voxels += ps.marginal_gain;
    ps.cumulative_coverage = coverable_voxels ? double(out.covered_voxels) / coverable_voxels : 0.0;
    ps.candidate_index = stations.candidate[k];
    ps.fixed = k < static_cast<int>(stations.fixed.size()) && stations.fixed[k];
    out.stations.push_back(ps);
  }
  return out;
}

// A warning when a tenth or more of the `occupied` voxels is visible from no candidate, with what
// may reach them under the candidates' ground model.
std::optional<std::string> UncoverableWarning(uint64_t occupied, uint64_t coverable, GroundModel ground) {
  const double uncoverable = occupied ? double(occupied - coverable) / occupied : 0.0;
  if (uncoverable < 0.10) return std::nullopt;
  std::string remedy;
  switch (ground) {
    case GroundModel::kFloors:
      remedy = "a finer grid_spacing_m, other floor levels or user candidates may reach them";
      break;
    case GroundModel::kTerrain:
      remedy =
          "candidates stand only on the terrain's walkable ground (ground = terrain), so roofs, upper storeys "
          "and ground it does not link are reached only by user candidates there or ground = floors; a finer "
          "grid_spacing_m may reach the rest";
      break;
    case GroundModel::kAuto:
      remedy = "user candidates nearer to them may reach them";
      break;
  }
  return Percent(uncoverable) + " of occupied voxels (" + std::to_string(occupied - coverable) +
         ") are visible from no candidate and cannot be covered — " + remedy;
}

// A warning when selection stopped on max_stations or min_marginal_gain_voxels.
std::optional<std::string> StopWarning(const planner::Selection& selection, const PlanOptions& options) {
  const double covered = selection.coverable ? double(selection.covered) / selection.coverable : 0.0;
  if (selection.stop == StopReason::kMaxStations) {
    return "stopped at max_stations = " + std::to_string(options.max_stations) + " with " + Percent(covered) +
           " of coverable voxels covered — raise max_stations for more";
  }
  if (selection.stop == StopReason::kMinGain) {
    return "stopped because no station would add min_marginal_gain_voxels = " +
           std::to_string(options.min_marginal_gain_voxels) + " voxels; " + Percent(covered) +
           " of coverable voxels covered";
  }
  return std::nullopt;
}

// A warning when registration is asked for and the final stations' scan graph is not connected.
std::optional<std::string> ScanGraphWarning(const ScanGraph& graph) {
  if (graph.min_overlap <= 0 || graph.connected) return std::nullopt;
  std::string groups;
  for (const std::vector<int>& g : graph.components) {
    groups += groups.empty() ? "[" : ", [";
    for (size_t k = 0; k < g.size(); ++k) {
      if (k > 0) groups += ' ';
      groups += std::to_string(g[k] + 1);
    }
    groups += "]";
  }
  return "the stations form " + std::to_string(graph.components.size()) + " groups (" + groups +
         ", numbered as on heatmap.png) that no chain of candidates links at min_overlap = " + Num(graph.min_overlap) +
         ": their scans will not register to each other without targets — add candidates between the groups "
         "(a finer grid_spacing_m, user candidates), or lower min_overlap";
}

// The selection's per-k bound (SelectionOutput::best_coverage) on the plan's curve where it bounds
// the plan's prefixes: it is over the selection's candidates and coverable voxels, so it holds while
// the final stations are among them (not after refinement, which moves them and grows the coverable
// set) and the fixed stations lead the plan, as the bound counts them.
void AddBestCoverageWhereValid(PlanResult& result, const std::vector<std::optional<BestCoverage>>& best,
                               const PlanOptions& options) {
  const size_t n_fixed = options.fixed_stations.size();
  const auto is_fixed = [](const PlannedStation& s) { return s.fixed; };
  const bool fixed_lead =
      std::count_if(result.stations.begin(), result.stations.end(), is_fixed) == static_cast<std::ptrdiff_t>(n_fixed) &&
      std::all_of(result.stations.begin(), result.stations.begin() + std::min(n_fixed, result.stations.size()),
                  is_fixed);
  if (!options.refine && fixed_lead) AddBestCoverage(result.coverage_curve, best);
}

// The candidate stage's figures in the result.
void TakeCandidateFigures(const planner::CandidatesOutput& candidates, PlanResult& result) {
  result.candidate_count = candidates.positions.size();
  result.floor_levels_m = candidates.floor_levels_m;
  result.ground = candidates.ground;
  result.grid_cells = candidates.grid_cells;
  result.cells_without_floor = candidates.cells_without_floor;
  result.cells_failing_clearance = candidates.cells_failing_clearance;
}

// The visibility stage's context: `ctx`, and with coarse then fine each progress event without a
// message of its own says that this is the coarse round (the fine round's say "local candidates").
JobContext VisibilityContext(const JobContext& ctx, const planner::CandidatesOutput& candidates) {
  if (!candidates.coarse || !ctx.progress) return ctx;
  const std::string note = "coarse then fine: the " + Num(candidates.coarse->coarse_spacing_m) +
                           " m grid first, then " + Num(candidates.coarse->fine_spacing_m) + " m around its picks";
  JobContext out{ctx.cancel, {}};
  out.progress = [progress = ctx.progress, note](const ProgressEvent& e) {
    ProgressEvent noted = e;
    if (noted.message.empty()) noted.message = note;
    progress(noted);
  };
  return out;
}

// The selection stage's figures, notes and warnings into `result` (`selected`'s warnings moved).
void TakeSelectionFigures(planner::SelectionOutput& selected, const planner::CandidatesOutput& candidates,
                          const PlanOptions& options, PlanResult& result) {
  result.stop_reason = selected.selection.stop;
  result.greedy_stations = selected.selection.first_pass_picks;
  result.consolidated = selected.selection.saved_by_improvement;
  result.connecting_stations = selected.selection.connectors;
  result.optimality = selected.selection.optimality;
  result.optimality.local_candidates.coarse_to_fine =
      planner::CoarseToFineNote(candidates, options.coarse_above_candidates) +
      result.optimality.local_candidates.coarse_to_fine;  // the fine round's neighbourhood rule, if it ran
  if (!result.optimality.note.empty()) result.warnings.push_back(result.optimality.note);
  // (the fan-out's warnings about a replica or the peers' addresses may repeat the visibility stage's)
  for (std::string& w : selected.warnings) {
    if (std::find(result.warnings.begin(), result.warnings.end(), w) == result.warnings.end()) {
      result.warnings.push_back(std::move(w));
    }
  }
  result.distribution.Add(selected.distribution);
}

// The route stage's route (or why there is none) into `result` (the route's warnings moved).
void TakeRoute(planner::RouteOutput& routed, const PlanOptions& local_options, PlanResult& result) {
  std::optional<planner::Route>& route = routed.route;
  if (route) {
    result.route = {route->order,     route->legs_m, route->length_m,
                    route->polylines, route->parts,  local_options.route_start};
    for (std::string& w : route->warnings) result.warnings.push_back(std::move(w));
  } else {
    result.warnings.push_back("no walking route: " + routed.unrouted_reason);
  }
}

}  // namespace

FieldTime ComputeFieldTime(size_t stations, double walk_m, const PlanOptions& options) {
  FieldTime t;
  t.scan_seconds_per_station = options.scan_seconds;
  if (t.scan_seconds_per_station <= 0) {
    if (const ScannerPreset* preset = FindScannerPreset(options.scanner.name)) {
      t.scan_seconds_per_station = preset->scan_time_s;
    }
  }
  t.setup_s = static_cast<double>(stations) * options.setup_seconds;
  t.scan_s = static_cast<double>(stations) * t.scan_seconds_per_station;
  t.walk_s = walk_m / options.walk_speed_mps;
  t.total_s = t.setup_s + t.scan_s + t.walk_s;
  return t;
}

Result<PlanResult> Plan(const SceneInput& input, const PlanOptions& options, const JobContext& ctx,
                        const PlanCallbacks& callbacks) {
  VC_RETURN_IF_ERROR(options.Validate());
  planner::StageRunner runner(ctx);
  PlanResult result;
  result.options = options;

  VC_ASSIGN_OR_RETURN(planner::VoxelizeOutput voxelized, runner.Run(Stage::kVoxelize, [&](const JobContext& c) {
    return planner::RunVoxelizeStage({input}, options, c);
  }));
  const VoxelScene& scene = voxelized.scene;
  const std::span<const SurfacePatch> patches = voxelized.surface_patches;
  result.selection_test = voxelized.selection_test;
  // The stages work in the scene's local frame (SceneInput::frame_origin_m, which Voxelize copies into
  // the scene); result.options stays as given, in the input's frame. They run the test that can run
  // (VoxelizeOutput::selection_test).
  PlanOptions local_options = InLocalFrame(options, input.frame_origin_m);
  local_options.selection_test = voxelized.selection_test;
  result.frame_origin_m = input.frame_origin_m;
  result.resolution_m = scene.resolution_m;
  result.occupied_voxels = scene.occupied.size();

  VC_ASSIGN_OR_RETURN(planner::CandidatesOutput candidates, runner.Run(Stage::kCandidates, [&](const JobContext& c) {
    return planner::RunCandidatesStage({scene}, local_options, c);
  }));
  TakeCandidateFigures(candidates, result);
  result.warnings = std::move(voxelized.warnings);
  result.warnings.insert(result.warnings.end(), candidates.warnings.begin(), candidates.warnings.end());
  // Coarse then fine (docs/PLANNING.md): the coarse grid, then the fine positions around its picks.
  if (candidates.coarse) local_options = planner::CoarseToFineOptions(local_options);

  if (local_options.sparse_set_gain <= 0) {  // sparse sets are checked as they are computed
    VC_RETURN_IF_ERROR(planner::CheckVisibilitySetBudget(
        candidates.positions.size() + local_options.fixed_stations.size(), result.occupied_voxels,
        local_options.memory_budget_bytes, "visibility counts"));
  }
  VC_ASSIGN_OR_RETURN(planner::VisibilityOutput visibility, runner.Run(Stage::kVisibility, [&](const JobContext& c) {
    return planner::RunVisibilityStage(
        {scene, candidates.positions, candidates.floor_z_m, local_options.fixed_stations, callbacks, patches},
        local_options, VisibilityContext(c, candidates));
  }));
  result.heat_map = std::move(visibility.heat_map);
  result.distribution = visibility.distribution;
  for (std::string& w : visibility.warnings) result.warnings.push_back(std::move(w));

  const std::unique_ptr<planner::Selector> selector = planner::SelectorFor(local_options, scene.resolution_m);
  VC_ASSIGN_OR_RETURN(planner::SelectionOutput selected, runner.Run(Stage::kSelection, [&](const JobContext& c) {
    return planner::RunSelectionStage({scene, *selector, std::move(visibility.sets), std::move(visibility.fixed_sets),
                                       candidates.positions, candidates.floor_z_m, result.heat_map.visible_voxels,
                                       callbacks, patches, candidates.ground.model, candidates.coarse.has_value()},
                                      local_options, c);
  }));
  TakeSelectionFigures(selected, candidates, options, result);
  const std::vector<std::optional<BestCoverage>> best_coverage = std::move(selected.best_coverage);
  planner::Stations stations = std::move(selected.stations);
  VoxelSet coverable = std::move(selected.coverable);

  if (local_options.refine && !stations.empty()) {
    VC_ASSIGN_OR_RETURN(planner::RefineOutput refined, runner.Run(Stage::kRefine, [&](const JobContext& c) {
      return planner::RunRefineStage(
          {scene, std::move(stations), std::move(coverable), patches, candidates.ground.model}, local_options, c);
    }));
    stations = std::move(refined.stations);
    coverable = std::move(refined.coverable);
  }
  result.coverable_voxels = coverable.count();
  if (auto w = UncoverableWarning(result.occupied_voxels, result.coverable_voxels, result.ground.model))
    result.warnings.push_back(*w);
  {
    std::vector<WorldPoint> seeing = candidates.positions;
    seeing.insert(seeing.end(), stations.positions.begin(), stations.positions.end());
    VC_ASSIGN_OR_RETURN(result.unseen_causes, CountUnseenCauses({scene, coverable, seeing, result.floor_levels_m,
                                                                 local_options.keep_out, local_options.scanner},
                                                                local_options.threads, ctx));
  }

  planner::ReductionOutput reduced = planner::KeepAllStations(stations.size());
  if (local_options.reduce && !stations.empty()) {
    VC_ASSIGN_OR_RETURN(reduced, runner.Run(Stage::kReduction, [&](const JobContext& c) {
      return planner::RunReductionStage({scene, stations, callbacks.face_values}, local_options, c);
    }));
  }
  result.reduction = std::move(reduced.reduction);
  result.distribution.Add(reduced.distribution);
  for (std::string& w : reduced.warnings) result.warnings.push_back(std::move(w));

  FinalStations final_stations = AssembleFinalStations(stations, reduced.keep, result.coverable_voxels);
  std::vector<double> final_floor_z;
  for (int k : reduced.keep) final_floor_z.push_back(stations.floor_z_m[k]);
  result.stations = std::move(final_stations.stations);
  for (size_t k = 0; k < result.stations.size(); ++k) {
    PlannedStation& s = result.stations[k];
    s.floor_z_m = std::isnan(final_floor_z[k]) ? planner::FloorBelow(scene.grid, s.position) : final_floor_z[k];
  }
  result.covered_voxels = final_stations.covered_voxels;
  {
    std::vector<VoxelSet> final_sets;
    for (int k : reduced.keep) final_sets.push_back(std::move(stations.sets[k]));
    result.scan_graph =
        planner::BuildScanGraph(planner::OverlapMatrix(final_sets, local_options.threads), local_options.min_overlap);
  }
  if (auto w = ScanGraphWarning(result.scan_graph)) result.warnings.push_back(*w);
  if (callbacks.on_final_stations) callbacks.on_final_stations(result.stations);
  if (auto w = StopWarning(selected.selection, local_options)) result.warnings.push_back(*w);

  std::vector<WorldPoint> final_positions;
  for (const PlannedStation& ps : result.stations) final_positions.push_back(ps.position);
  VC_ASSIGN_OR_RETURN(planner::EvaluationOutput evaluated, runner.Run(Stage::kEvaluation, [&](const JobContext& c) {
    return planner::RunEvaluationStage({scene, final_positions, std::move(reduced.evaluation)}, local_options, c);
  }));
  result.evaluation = std::move(evaluated.evaluation);
  for (std::string& w : evaluated.warnings) result.warnings.push_back(std::move(w));
  for (size_t k = 0; k < result.stations.size() && k < result.evaluation.per_viewpoint.size(); ++k) {
    result.stations[k].global_visibility = result.evaluation.per_viewpoint[k].global_visibility;
  }
  result.voxel_centers = std::move(evaluated.voxel_centers);

  VC_ASSIGN_OR_RETURN(planner::RouteOutput routed, runner.Run(Stage::kRoute, [&](const JobContext& c) {
    return planner::RunRouteStage({input, scene, final_positions, final_floor_z, result.floor_levels_m}, local_options,
                                  c);
  }));
  TakeRoute(routed, local_options, result);
  result.field_time = ComputeFieldTime(result.stations.size(), result.route.length_m, local_options);
  std::vector<uint64_t> gains;
  for (const PlannedStation& s : result.stations) gains.push_back(s.marginal_gain);
  result.coverage_curve = CoverageCurve(gains, result.occupied_voxels, result.coverable_voxels,
                                        local_options.setup_seconds + result.field_time.scan_seconds_per_station);
  AddBestCoverageWhereValid(result, best_coverage, local_options);
  result.timings = runner.timings();
  result.total_seconds = runner.elapsed_seconds();
  return result;
}

}  // namespace vc
