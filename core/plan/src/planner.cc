#include "vc/plan/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

#include "vc/plan/candidates.h"
#include "vc/plan/greedy.h"
#include "vc/plan/reduction.h"

namespace vc {

namespace {

using Clock = std::chrono::steady_clock;

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

std::string Percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f %%", 100.0 * fraction);
  return buf;
}

// A JobContext whose progress reports are relabelled to `stage` and mapped into [lo, hi].
JobContext StageContext(const JobContext& ctx, Stage stage, double lo = 0.0, double hi = 1.0) {
  JobContext sub;
  sub.cancel = ctx.cancel;
  if (ctx.progress) {
    sub.progress = [&ctx, stage, lo, hi](const ProgressEvent& e) {
      ctx.Report(stage, lo + (hi - lo) * std::clamp(e.fraction, 0.0, 1.0), e.message);
    };
  }
  return sub;
}

// Reports the start of a stage and stops if the job was cancelled meanwhile.
Status BeginStage(const JobContext& ctx, Stage stage) {
  ctx.Report(stage, 0.0);
  return ctx.CheckCancelled(std::string(StageName(stage)).c_str());
}

// Times the stages of one plan.
class StageTimer {
 public:
  explicit StageTimer(PlanResult* out) : out_(out), start_(Clock::now()), stage_start_(start_) {}
  void End(Stage stage) {
    const auto now = Clock::now();
    out_->timings.push_back({stage, std::chrono::duration<double>(now - stage_start_).count()});
    stage_start_ = now;
  }
  void Total() { out_->total_seconds = std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  PlanResult* out_;
  Clock::time_point start_, stage_start_;
};

// Bytes of `count` visibility sets over `voxels` voxels.
uint64_t SetBytes(uint64_t count, uint64_t voxels) { return count * ((voxels + 63) / 64) * 8; }

Status CheckSetBudget(uint64_t count, uint64_t voxels, uint64_t budget, const char* what) {
  const uint64_t need = SetBytes(count, voxels);
  if (need > budget / 2) {
    return ResourceExhaustedError(std::string(what) + ": " + std::to_string(count) + " positions x " +
                                  std::to_string(voxels) + " occupied voxels need " +
                                  Num(need / 1073741824.0) + " GiB of visibility sets (budget " +
                                  Num(budget / 1073741824.0) +
                                  " GiB); raise grid_spacing_m or resolution_m");
  }
  return Status::Ok();
}

}  // namespace


Result<PlanResult> Plan(const SceneInput& input, const PlanOptions& options, const JobContext& ctx,
                        const PlanCallbacks& callbacks) {
  VC_RETURN_IF_ERROR(options.Validate());
  PlanResult result;
  result.options = options;
  result.selection_test = options.selection_test;
  StageTimer timer(&result);

  // 1. Voxelize.
  VC_RETURN_IF_ERROR(BeginStage(ctx, Stage::kVoxelize));
  VC_ASSIGN_OR_RETURN(VoxelScene scene, Voxelize(input, {options.resolution_m, options.memory_budget_bytes},
                                                 StageContext(ctx, Stage::kVoxelize)));
  result.resolution_m = scene.resolution_m;
  const uint64_t n_voxels = scene.occupied.size();
  result.occupied_voxels = n_voxels;
  ctx.Report(Stage::kVoxelize, 1.0);
  timer.End(Stage::kVoxelize);

  // 2. Candidates on the operating plane (or the user's).
  VC_RETURN_IF_ERROR(BeginStage(ctx, Stage::kCandidates));
  const planner::CandidateOptions cand_options{options.grid_spacing_m, options.tripod_height_m, options.clearance_m};
  std::vector<WorldPoint> candidates;
  std::vector<double> floor_z;  // per candidate; NaN for user candidates
  const bool user_candidates = !options.candidates.empty();
  if (user_candidates) {
    for (size_t i = 0; i < options.candidates.size(); ++i) {
      const WorldPoint& p = options.candidates[i];
      if (!ViewpointInRange(p, scene.resolution_m)) {
        return InvalidArgumentError("candidates[" + std::to_string(i) + "] (" + Num(p.x()) + ", " + Num(p.y()) + ", " +
                                    Num(p.z()) + ") is more than " + Num(kMaxViewpointIndex * scene.resolution_m) +
                                    " m from the origin along an axis; use coordinates in the scene's frame");
      }
      if (scene.grid.Occupied(scene.grid.WorldToIndex(p))) {
        return InvalidArgumentError("candidates[" + std::to_string(i) + "] (" + Num(p.x()) + ", " + Num(p.y()) +
                                    ", " + Num(p.z()) + ") lies inside an occupied voxel");
      }
    }
    candidates = options.candidates;
    floor_z.assign(candidates.size(), std::nan(""));
  } else {
    VC_ASSIGN_OR_RETURN(planner::CandidateGrid grid,
                        planner::GenerateCandidates(scene, cand_options, StageContext(ctx, Stage::kCandidates)));
    for (const planner::FloorLevel& l : grid.levels) result.floor_levels_m.push_back(l.z_m);
    result.grid_cells = grid.cells;
    result.cells_without_floor = grid.rejected_no_floor;
    result.cells_failing_clearance = grid.rejected_clearance;
    if (grid.positions.empty()) {
      if (grid.levels.empty()) {
        return FailedPreconditionError(
            "no floor found: no occupied voxel has tripod_height_m + clearance_m = " +
            Num(options.tripod_height_m + options.clearance_m) +
            " m of free space above it; lower them or pass candidates");
      }
      std::string levels;
      for (double z : result.floor_levels_m) levels += (levels.empty() ? "" : ", ") + Num(z);
      return FailedPreconditionError(
          "no candidate survived: of " + std::to_string(grid.cells) + " grid cells, " +
          std::to_string(grid.rejected_no_floor) + " had no floor below (floor levels at z = " + levels +
          " m) and " + std::to_string(grid.rejected_clearance) + " had occupied voxels within clearance_m = " +
          Num(options.clearance_m) + " m; lower clearance_m or grid_spacing_m, or pass candidates");
    }
    if (grid.positions.size() < 5) {
      result.warnings.push_back("only " + std::to_string(grid.positions.size()) + " candidates survived the clearance filter (" +
                                std::to_string(grid.rejected_clearance) + " cells with floor failed clearance_m = " +
                                Num(options.clearance_m) + " m, " + std::to_string(grid.rejected_no_floor) +
                                " had no floor below) — lower clearance_m or grid_spacing_m, or check the floor estimate");
    }
    candidates = std::move(grid.positions);
    floor_z = std::move(grid.floor_z_m);
  }
  result.candidate_count = candidates.size();
  ctx.Report(Stage::kCandidates, 1.0);
  timer.End(Stage::kCandidates);

  // 3. Visibility sets and the heat map.
  VC_RETURN_IF_ERROR(CheckSetBudget(candidates.size(), n_voxels, options.memory_budget_bytes, "visibility counts"));
  VC_RETURN_IF_ERROR(BeginStage(ctx, Stage::kVisibility));
  const VisibilitySetsOptions set_options{options.selection_test, options.threads};
  VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> sets,
                      ComputeVisibilitySets(scene, candidates, set_options, StageContext(ctx, Stage::kVisibility)));
  result.heat_map.positions = candidates;
  result.heat_map.grid_spacing_m = options.grid_spacing_m;
  result.heat_map.visible_voxels.reserve(sets.size());
  for (const VoxelSet& s : sets) result.heat_map.visible_voxels.push_back(planner::CountBits(s));
  if (callbacks.on_heat_map) callbacks.on_heat_map(result.heat_map);
  ctx.Report(Stage::kVisibility, 1.0);
  timer.End(Stage::kVisibility);

  // 4. Greedy selection.
  VC_RETURN_IF_ERROR(BeginStage(ctx, Stage::kSelection));
  planner::GreedyOptions greedy_options;
  greedy_options.max_stations = options.max_stations;
  greedy_options.min_marginal_gain = options.min_marginal_gain_voxels;
  greedy_options.target_coverage = options.target_coverage;
  VC_ASSIGN_OR_RETURN(planner::GreedyResult greedy, planner::SelectGreedy(sets, greedy_options, StageContext(ctx, Stage::kSelection)));
  result.stop_reason = greedy.stop;
  VoxelSet coverable(n_voxels);
  for (const VoxelSet& s : sets) planner::UnionInto(coverable, s);
  std::vector<int> picks;
  for (const planner::GreedyPick& pick : greedy.picks) picks.push_back(pick.candidate);
  result.greedy_stations = static_cast<int>(picks.size());
  if (options.consolidate) {
    VC_ASSIGN_OR_RETURN(planner::ConsolidateResult merged,
                        planner::ConsolidatePicks(sets, std::move(picks), StageContext(ctx, Stage::kSelection)));
    picks = std::move(merged.picks);
    result.consolidated = merged.dropped + merged.merged;
  }
  std::vector<WorldPoint> stations;
  std::vector<double> station_floor;
  std::vector<int> station_candidate;
  std::vector<VoxelSet> station_sets;
  {
    VoxelSet so_far(n_voxels);
    uint64_t covered_so_far = 0;
    for (size_t k = 0; k < picks.size(); ++k) {
      const int c = picks[k];
      stations.push_back(candidates[c]);
      station_floor.push_back(floor_z[c]);
      station_candidate.push_back(c);
      station_sets.push_back(sets[c]);
      const uint64_t gain = result.heat_map.visible_voxels[c] - planner::CountAnd(sets[c], so_far);
      planner::UnionInto(so_far, sets[c]);
      covered_so_far += gain;
      if (callbacks.on_station) {
        PlannedStation ps;
        ps.position = candidates[c];
        ps.visible_voxels = result.heat_map.visible_voxels[c];
        ps.marginal_gain = gain;
        ps.cumulative_coverage = greedy.coverable ? double(covered_so_far) / greedy.coverable : 0.0;
        ps.candidate_index = c;
        callbacks.on_station(ps, static_cast<int>(k));
      }
    }
  }
  sets.clear();
  sets.shrink_to_fit();
  ctx.Report(Stage::kSelection, 1.0);
  timer.End(Stage::kSelection);

  // 5. Proximity refinement: each station to the best position of a sub-grid around it.
  if (options.refine && !stations.empty()) {
    VC_RETURN_IF_ERROR(BeginStage(ctx, Stage::kRefine));
    const int steps = static_cast<int>(std::floor(options.refine_radius_m / options.refine_step_m + 1e-9));
    std::vector<WorldPoint> trial;
    std::vector<int> trial_station;
    for (size_t k = 0; k < stations.size(); ++k) {
      for (int iy = -steps; iy <= steps; ++iy) {
        for (int ix = -steps; ix <= steps; ++ix) {
          if (ix == 0 && iy == 0) continue;
          WorldPoint p = stations[k] + WorldPoint(ix * options.refine_step_m, iy * options.refine_step_m, 0);
          if (!std::isnan(station_floor[k])) {
            std::optional<double> top = planner::FloorTopNear(scene.grid, p.x(), p.y(), station_floor[k], cand_options);
            if (!top) continue;
            p.z() = *top + options.tripod_height_m;
          }
          if (!planner::HasClearance(scene.grid, p, options.clearance_m)) continue;
          trial.push_back(p);
          trial_station.push_back(static_cast<int>(k));
        }
      }
    }
    VC_RETURN_IF_ERROR(CheckSetBudget(trial.size(), n_voxels, options.memory_budget_bytes, "refinement"));
    VC_ASSIGN_OR_RETURN(std::vector<VoxelSet> trial_sets,
                        ComputeVisibilitySets(scene, trial, set_options, StageContext(ctx, Stage::kRefine, 0.0, 0.9)));
    for (const VoxelSet& s : trial_sets) planner::UnionInto(coverable, s);
    size_t t = 0;
    for (size_t k = 0; k < stations.size(); ++k) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("refinement"));
      VoxelSet others(n_voxels);
      for (size_t j = 0; j < stations.size(); ++j) {
        if (j != k) planner::UnionInto(others, station_sets[j]);
      }
      const uint64_t others_count = planner::CountBits(others);
      auto score = [&](const VoxelSet& s) {
        return std::make_pair(others_count + planner::CountBits(s) - planner::CountAnd(others, s), planner::CountBits(s));
      };
      auto best = score(station_sets[k]);
      int best_trial = -1;
      for (; t < trial.size() && trial_station[t] == static_cast<int>(k); ++t) {
        const auto sc = score(trial_sets[t]);
        if (sc > best) {
          best = sc;
          best_trial = static_cast<int>(t);
        }
      }
      if (best_trial >= 0) {
        stations[k] = trial[best_trial];
        if (!std::isnan(station_floor[k])) station_floor[k] = stations[k].z() - options.tripod_height_m;
        station_candidate[k] = -1;
        station_sets[k] = std::move(trial_sets[best_trial]);
      }
    }
    ctx.Report(Stage::kRefine, 1.0);
    timer.End(Stage::kRefine);
  }
  result.coverable_voxels = planner::CountBits(coverable);
  const double uncoverable = n_voxels ? double(n_voxels - result.coverable_voxels) / n_voxels : 0.0;
  if (uncoverable >= 0.10) {
    result.warnings.push_back(Percent(uncoverable) + " of occupied voxels (" +
                              std::to_string(n_voxels - result.coverable_voxels) +
                              ") are visible from no candidate and cannot be covered — a finer grid_spacing_m, "
                              "other floor levels or user candidates may reach them");
  }

  // 6. Reduction (s.7.5) on every station's V of every face. One Evaluate of all stations keeps
  // them when they fit the cache budget (and is the final evaluation if nothing is removed);
  // otherwise each station is evaluated alone, as often as the reduction needs.
  std::vector<int> keep(stations.size());
  for (size_t k = 0; k < keep.size(); ++k) keep[k] = static_cast<int>(k);
  EvaluateOptions eval_options;
  eval_options.scanner = options.scanner;
  eval_options.threads = options.threads;
  eval_options.keep_face_values = true;
  std::optional<Evaluation> all_evaluation;
  if (options.reduce && !stations.empty()) {
    VC_RETURN_IF_ERROR(BeginStage(ctx, Stage::kReduction));
    const uint64_t faces_total = n_voxels * kFacesPerVoxel;
    const uint64_t cache_budget = std::min<uint64_t>(options.memory_budget_bytes / 4, uint64_t{1} << 30);
    const bool batch = stations.size() * faces_total * sizeof(float) <= cache_budget;
    planner::StationFaceValuesFn values;
    if (batch) {
      EvaluateOptions batch_options = eval_options;
      batch_options.keep_per_viewpoint_values = true;
      VC_ASSIGN_OR_RETURN(all_evaluation, Evaluate(scene, stations, batch_options, StageContext(ctx, Stage::kReduction, 0.0, 0.9)));
      values = [&](int s, const JobContext&) -> Result<std::vector<float>> {
        return std::move(all_evaluation->per_viewpoint_face_values[s]);  // read once: RunReduction caches
      };
    } else {
      EvaluateOptions single_options = eval_options;
      single_options.keep_face_values = false;
      single_options.keep_per_viewpoint_values = true;
      values = [&](int s, const JobContext& sub) -> Result<std::vector<float>> {
        VC_ASSIGN_OR_RETURN(Evaluation e, Evaluate(scene, {stations[s]}, single_options, sub));
        return std::move(e.per_viewpoint_face_values[0]);
      };
    }
    planner::ReductionRunOptions red_options;
    red_options.reduce_to = options.reduce_to;
    red_options.threads = options.threads;
    red_options.cache_budget_bytes = cache_budget;
    VC_ASSIGN_OR_RETURN(planner::ReductionRun run,
                        planner::RunReduction(static_cast<int>(stations.size()), faces_total, values, red_options,
                                              StageContext(ctx, Stage::kReduction, batch ? 0.9 : 0.0, 1.0)));
    if (all_evaluation) all_evaluation->per_viewpoint_face_values.clear();
    result.reduction.size = run.initial.size;
    result.reduction.matrix = run.initial.loss;
    result.reduction.removed = run.removed;
    std::sort(result.reduction.removed.begin(), result.reduction.removed.end());
    result.reduction.global_visibility_before = run.global_visibility_before;
    result.reduction.global_visibility_after = run.global_visibility_after;
    result.reduction.positions = stations;
    keep.clear();
    for (size_t k = 0; k < stations.size(); ++k) {
      if (!std::binary_search(result.reduction.removed.begin(), result.reduction.removed.end(), static_cast<int>(k))) {
        keep.push_back(static_cast<int>(k));
      }
    }
    if (!run.removed.empty()) all_evaluation.reset();
    ctx.Report(Stage::kReduction, 1.0);
    timer.End(Stage::kReduction);
  }

  // 7. Final stations: gains and coverage in greedy order, then the evaluation.
  VoxelSet covered(n_voxels);
  uint64_t covered_count = 0;
  std::vector<WorldPoint> final_positions;
  for (int k : keep) {
    PlannedStation ps;
    ps.position = stations[k];
    ps.visible_voxels = planner::CountBits(station_sets[k]);
    ps.marginal_gain = ps.visible_voxels - planner::CountAnd(station_sets[k], covered);
    planner::UnionInto(covered, station_sets[k]);
    covered_count += ps.marginal_gain;
    ps.cumulative_coverage = result.coverable_voxels ? double(covered_count) / result.coverable_voxels : 0.0;
    ps.candidate_index = station_candidate[k];
    result.stations.push_back(ps);
    final_positions.push_back(ps.position);
  }
  result.covered_voxels = covered_count;
  if (callbacks.on_final_stations) callbacks.on_final_stations(result.stations);
  if (greedy.stop == StopReason::kMaxStations) {
    result.warnings.push_back("stopped at max_stations = " + std::to_string(options.max_stations) + " with " +
                              Percent(greedy.coverable ? double(greedy.covered) / greedy.coverable : 0.0) +
                              " of coverable voxels covered — raise max_stations for more");
  } else if (greedy.stop == StopReason::kMinGain) {
    result.warnings.push_back("stopped because no station would add min_marginal_gain_voxels = " +
                              std::to_string(options.min_marginal_gain_voxels) + " voxels; " +
                              Percent(greedy.coverable ? double(greedy.covered) / greedy.coverable : 0.0) +
                              " of coverable voxels covered");
  }

  VC_RETURN_IF_ERROR(BeginStage(ctx, Stage::kEvaluation));
  if (final_positions.empty()) {
    result.warnings.push_back("no station was selected: no candidate sees any occupied voxel by the " +
                              std::string(SelectionTestName(result.selection_test)) + " test");
    result.evaluation.resolution_m = scene.resolution_m;
    result.evaluation.faces_total = n_voxels * kFacesPerVoxel;
    result.evaluation.best_face_values.assign(n_voxels, {});
  } else if (all_evaluation) {
    result.evaluation = std::move(*all_evaluation);  // same stations, nothing was removed
  } else {
    VC_ASSIGN_OR_RETURN(result.evaluation,
                        Evaluate(scene, final_positions, eval_options, StageContext(ctx, Stage::kEvaluation)));
  }
  for (size_t k = 0; k < result.stations.size() && k < result.evaluation.per_viewpoint.size(); ++k) {
    result.stations[k].global_visibility = result.evaluation.per_viewpoint[k].global_visibility;
  }
  result.voxel_centers.reserve(n_voxels);
  for (size_t i = 0; i < n_voxels; ++i) result.voxel_centers.push_back(scene.Center(i));
  ctx.Report(Stage::kEvaluation, 1.0);
  timer.End(Stage::kEvaluation);
  timer.Total();
  return result;
}

}  // namespace vc
