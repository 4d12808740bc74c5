#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cover_model.h"
#include "format.h"
#include "vc/plan/candidates.h"
#include "vc/plan/exact_selector.h"
#include "vc/plan/greedy.h"
#include "vc/plan/k_coverage_bound.h"
#include "vc/plan/keep_out.h"
#include "vc/plan/local_refinement.h"
#include "vc/plan/planner.h"
#include "vc/plan/stages.h"

namespace vc::planner {
namespace {

using Clock = std::chrono::steady_clock;

// The exact selector for the solves of the local-candidates loop: each gets what is left of one
// time limit, so options.solve_seconds bounds the whole selection stage, as it does without the loop.
class SharedDeadlineSelector final : public Selector {
 public:
  SharedDeadlineSelector(const ExactSelectorOptions& options, Clock::time_point deadline)
      : options_(options), deadline_(deadline) {}
  using Selector::Select;
  [[nodiscard]] Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed,
                                         const JobContext& ctx) const override {
    ExactSelectorOptions o = options_;
    // A solve past the deadline still returns a plan (greedy's, with the bounds of the root LP
    // CBC reaches in its first moments); 0.05 s is what it is given then.
    o.time_limit_s = std::max(0.05, std::chrono::duration<double>(deadline_ - Clock::now()).count());
    return ExactSelector(o).Select(sets, fixed, ctx);
  }

 private:
  ExactSelectorOptions options_;
  Clock::time_point deadline_;
};

ExactSelectorOptions ExactOptionsFor(const PlanOptions& options, double resolution_m) {
  ExactSelectorOptions exact;
  exact.greedy = SelectorOptionsFor(options, resolution_m);
  exact.time_limit_s = options.solve_seconds;
  exact.memory_budget_bytes = options.memory_budget_bytes / 2;
  exact.swap_search = options.solver == SelectionSolver::kExact;
  exact.prefer_greedy = options.solver == SelectionSolver::kAuto;
  return exact;
}

// RefineLocally with the stage's selector over the fixed stations and the candidates (`sets`,
// consumed), with the added positions' sets cut to the coverable set of the first selection (but
// with in.keep_added_sets_whole) and
// as many of them as the memory budget holds beside the sets already held.
Result<LocalRefinementResult> SelectWithLocalCandidates(const SelectionInput& in, std::vector<VoxelSet> sets, int fixed,
                                                        const PlanOptions& options, const JobContext& ctx,
                                                        SelectionOutput& out_spread) {
  const Clock::time_point start = Clock::now();
  CandidateSets all;
  all.positions = options.fixed_stations;
  all.floor_z_m.assign(options.fixed_stations.size(), std::nan(""));
  all.positions.insert(all.positions.end(), in.candidates.begin(), in.candidates.end());
  all.floor_z_m.insert(all.floor_z_m.end(), in.floor_z_m.begin(), in.floor_z_m.end());
  const size_t n_voxels = in.scene.occupied.size();
  VoxelSet coverable(n_voxels);
  for (const VoxelSet& s : sets) UnionInto(coverable, s);
  all.sets = std::move(sets);

  const VisibilitySetsOptions set_options = VisibilitySetsOptionsFor(options, in.surface_patches);
  // The added positions' sets as the visibility stage's (through in.callbacks.visibility_sets when
  // set: vc-server fans them out over its peers), their progress counted in the selection stage
  // (ctx is the stage's: StageContext sets the stage) under the loop's own line (fr_campus's 820
  // fine positions at 0.2 m take a minute).
  const char* what = in.keep_added_sets_whole ? "the fine round's sets" : "the local candidates' sets";
  const VisibilityFn visibility = [&](const std::vector<WorldPoint>& positions) -> Result<std::vector<VoxelSet>> {
    const std::string line = "local candidates: visibility of " + std::to_string(positions.size()) + " positions";
    ctx.Report(Stage::kSelection, 0.0, line);
    JobContext sets_ctx{ctx.cancel, {}};
    if (ctx.progress) {
      sets_ctx.progress = [&ctx, line](const ProgressEvent& e) {
        ProgressEvent under_line = e;
        under_line.message = line;
        ctx.progress(under_line);
      };
    }
    VC_ASSIGN_OR_RETURN(DistributedSets d, VisibilitySetsOf(in.callbacks.visibility_sets, in.scene, positions,
                                                            set_options, in.surface_patches, sets_ctx, what));
    out_spread.distribution.Add(d.distribution);
    for (std::string& w : d.warnings) out_spread.warnings.push_back(std::move(w));
    if (!in.keep_added_sets_whole) {
      for (VoxelSet& s : d.sets) s.Intersect(coverable);
    }
    return std::move(d.sets);
  };

  const std::vector<double> heights = options.TripodHeights();
  CandidateOptions cand_options = CandidateOptionsFor(options);
  cand_options.tripod_height_m = *std::min_element(heights.begin(), heights.end());
  cand_options.doorway_candidates = false;
  cand_options.ground = in.ground;
  LocalRefinementOptions local{options.local_candidates_radius_m, options.local_candidates_step_m,
                               options.local_candidates_rounds, options.keep_out};
  local.target_coverage = options.target_coverage;
  // The visibility sets may take half the budget (CheckVisibilitySetBudget); what is left of it
  // after the sets held bounds the positions added.
  const uint64_t set_bytes = std::max<uint64_t>(8, (n_voxels + 63) / 64 * 8);
  const uint64_t fit = options.memory_budget_bytes / 2 / set_bytes;
  local.max_added = fit > all.positions.size() ? fit - all.positions.size() : 0;
  if (in.keep_added_sets_whole) {  // coarse then fine: sets only where the neighbourhood can gain
    local.neighbourhood_m = options.local_candidates_step_m;  // the coarse cell's corners
    // the selector's own smallest pick (its gain rule, min_marginal_gain_voxels): fewer cannot be picked
    local.min_neighbourhood_gain_voxels = SmallestGainPickedVoxels(SelectorOptionsFor(options, in.scene.resolution_m));
  }

  VC_ASSIGN_OR_RETURN(LocalRefinementResult out, RefineLocally(in.selector, in.scene, std::move(all), fixed,
                                                               cand_options, visibility, local, ctx));
  LocalCandidatesReport& report = out.selection.optimality.local_candidates;
  report.rounds = out.rounds;
  report.added = out.added;
  report.stations_per_solve = out.stations_per_solve;
  report.covered_per_solve = out.covered_per_solve;
  if (out.neighbourhood_rounds > 0) {  // one round (coarse then fine): N and M count distinct positions
    report.coarse_to_fine = "; " + std::to_string(out.passed_over) + " of " +
                            std::to_string(out.added + out.passed_over) +
                            " fine positions passed over (the candidates within " + Num(local.neighbourhood_m) +
                            " m of each see fewer than " + std::to_string(local.min_neighbourhood_gain_voxels) +
                            " voxels the coarse picks leave uncovered, the selector's smallest gain)";
  }
  out.selection.optimality.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace

#define VC_COPY_ROW(type, name, ...) out.name = options.name;

GreedyOptions SelectorOptionsFor(const PlanOptions& options, double resolution_m) {
  GreedyOptions out;
  VC_GREEDY_PARAMETERS(VC_COPY_ROW)
  out.min_overlap = options.min_overlap;
  out.surface_voxels_per_m2 = resolution_m > 0 ? 1.0 / (resolution_m * resolution_m) : 0.0;
  out.station_seconds = options.setup_seconds + ComputeFieldTime(1, 0.0, options).scan_seconds_per_station;
  return out;
}

#undef VC_COPY_ROW

std::unique_ptr<Selector> SelectorFor(const PlanOptions& options, double resolution_m) {
  if (options.solver == SelectionSolver::kGreedy) {
    return std::make_unique<GreedySelector>(SelectorOptionsFor(options, resolution_m));
  }
  if (options.local_candidates) {
    return std::make_unique<SharedDeadlineSelector>(
        ExactOptionsFor(options, resolution_m),
        Clock::now() +
            std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.solve_seconds)));
  }
  return std::make_unique<ExactSelector>(ExactOptionsFor(options, resolution_m));
}

Result<std::vector<std::optional<BestCoverage>>> BestCoverageOf(const std::vector<VoxelSet>& sets, int fixed, int max_k,
                                                                double seconds, uint64_t max_bytes,
                                                                const JobContext& ctx) {
  std::vector<std::optional<BestCoverage>> out;
  if (max_k < 1 || static_cast<int>(sets.size()) <= fixed) return out;
  uint64_t pairs = 0;
  for (const VoxelSet& s : sets) pairs += CountBits(s);
  const uint64_t voxels = sets.front().size();
  if (pairs > kMaxBestCoveragePairs ||
      kBestCoverageBytesPerPair * pairs + kBestCoverageBytesPerVoxel * voxels > max_bytes) {
    return out;
  }
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  const JobContext quiet{ctx.cancel, {}};  // the classes' progress is the exact selector's to report
  VC_ASSIGN_OR_RETURN(internal::Classes cl, internal::BuildClasses(sets, quiet));
  std::vector<std::vector<int>>().swap(cl.sees);  // KCoverageBounds builds its own per column
  KCoverageProblem problem;
  problem.columns = static_cast<int>(sets.size()) - fixed;
  uint64_t given = 0;  // the fixed stations' voxels
  for (size_t i = 0; i < cl.weight.size(); ++i) {
    if (cl.seen_by[i].front() < fixed) {  // ascending: a fixed station sees it
      given += cl.weight[i];
      continue;
    }
    problem.weight.push_back(cl.weight[i]);
    for (int& c : cl.seen_by[i]) c -= fixed;
    problem.seen_by.push_back(std::move(cl.seen_by[i]));
  }
  cl = {};
  KCoverageOptions options;
  options.max_k = max_k - fixed;
  options.deadline = deadline;
  const std::vector<KCoverage> bounds = KCoverageBounds(problem, options);
  out.assign(static_cast<size_t>(max_k), std::nullopt);
  if (fixed > 0) out[fixed - 1] = BestCoverage{given, given};
  for (size_t k = 0; k < bounds.size(); ++k) {
    out[fixed + k] = BestCoverage{given + bounds[k].upper_bound, given + bounds[k].best};
  }
  return out;
}

void CapBelowTheSelectorsBound(std::vector<std::optional<BestCoverage>>& best, const Selection& selection,
                               const PlanOptions& options) {
  if (options.min_overlap > 0 || options.max_stations > 0 || options.local_candidates) return;
  const double lower_bound = selection.optimality.lower_bound;
  if (!(lower_bound > 0) || selection.coverable == 0) return;
  const uint64_t need = internal::TargetVoxels(options.target_coverage, selection.coverable);
  if (need == 0) return;
  const size_t below = static_cast<size_t>(std::ceil(lower_bound - 1e-9)) - 1;  // k = 1 .. below cover < need
  for (size_t k = 0; k < below && k < best.size(); ++k) {
    if (!best[k]) continue;
    best[k]->upper_bound_voxels = std::min(best[k]->upper_bound_voxels, need - 1);
    best[k]->best_voxels = std::min(best[k]->best_voxels, best[k]->upper_bound_voxels);
  }
}

Result<SelectionOutput> RunSelectionStage(SelectionInput in, const PlanOptions& options, const JobContext& ctx) {
  const Clock::time_point start = Clock::now();
  SelectionOutput out;
  // The fixed stations' sets first: the selector starts with them picked.
  const int fixed = static_cast<int>(in.fixed_sets.size());
  const int n_candidates = static_cast<int>(in.sets.size());
  std::vector<VoxelSet> sets = std::move(in.fixed_sets);
  sets.reserve(sets.size() + in.sets.size());
  for (VoxelSet& s : in.sets) sets.push_back(std::move(s));
  in.sets.clear();
  // Positions the local-candidates loop added, after the fixed stations and the candidates.
  std::vector<WorldPoint> added_positions;
  std::vector<double> added_floor_z;
  if (options.local_candidates) {
    VC_ASSIGN_OR_RETURN(LocalRefinementResult local,
                        SelectWithLocalCandidates(in, std::move(sets), fixed, options, ctx, out));
    out.selection = std::move(local.selection);
    if (local.limited) {
      out.warnings.push_back("local candidates: the memory budget holds the visibility sets of " +
                             std::to_string(local.added) +
                             " added positions and no more; raise memory_budget_bytes or lower "
                             "local_candidates_radius_m for the rest");
    }
    sets = std::move(local.candidates.sets);
    const size_t first_added = static_cast<size_t>(fixed + n_candidates);
    added_positions.assign(local.candidates.positions.begin() + static_cast<std::ptrdiff_t>(first_added),
                           local.candidates.positions.end());
    added_floor_z.assign(local.candidates.floor_z_m.begin() + static_cast<std::ptrdiff_t>(first_added),
                         local.candidates.floor_z_m.end());
  } else {
    VC_ASSIGN_OR_RETURN(out.selection, in.selector.Select(sets, fixed, ctx));
  }
  if (out.selection.consolidation_stopped) {
    out.warnings.push_back("consolidation stopped at its time budget of " +
                           std::to_string(std::lround(SelectorOptionsFor(options, 0).consolidate_budget_s)) +
                           " s: the plan keeps the picks it had dropped or merged by then; a few more stations "
                           "might have been saved (docs/PLANNING.md, \"Greedy selection (§7.3) and consolidation\")");
  }
  const size_t n_voxels = sets.empty() ? 0 : sets[0].size();
  out.coverable = VoxelSet(n_voxels);
  for (const VoxelSet& s : sets) UnionInto(out.coverable, s);
  // The picks as stations, each reported (provisionally) with its gain in pick order.
  Stations& st = out.stations;
  VoxelSet so_far(n_voxels);
  uint64_t covered_so_far = 0;
  const uint64_t coverable = out.selection.coverable;
  for (size_t k = 0; k < out.selection.picks.size(); ++k) {
    const int pick = out.selection.picks[k];
    const bool is_fixed = pick < fixed;
    const bool is_added = pick >= fixed + n_candidates;      // a local candidate
    const int c = is_fixed || is_added ? -1 : pick - fixed;  // candidate index
    const int a = pick - fixed - n_candidates;               // index into the added positions
    const WorldPoint& position = is_fixed   ? options.fixed_stations[pick]
                                 : is_added ? added_positions[a]
                                            : in.candidates[c];
    const uint64_t visible = c < 0 ? CountBits(sets[pick]) : in.visible_voxels[c];
    st.positions.push_back(position);
    st.floor_z_m.push_back(is_fixed ? std::nan("") : is_added ? added_floor_z[a] : in.floor_z_m[c]);
    st.candidate.push_back(c);
    st.sets.push_back(sets[pick]);
    st.fixed.push_back(is_fixed);
    const uint64_t gain = visible - CountAnd(sets[pick], so_far);
    UnionInto(so_far, sets[pick]);
    covered_so_far += gain;
    if (in.callbacks.on_station) {
      PlannedStation ps;
      ps.position = position;
      ps.visible_voxels = visible;
      ps.marginal_gain = gain;
      ps.cumulative_coverage = coverable ? double(covered_so_far) / coverable : 0.0;
      ps.candidate_index = c;
      ps.fixed = is_fixed;
      in.callbacks.on_station(ps, static_cast<int>(k));
    }
  }
  // The per-k bound's steps and search in at most a twentieth of the selection's time so far, and
  // at least 0.1 s (docs/PLANNING.md, "The coverage curve"; docs/BENCHMARKS.md measures it); its
  // classes in a quarter of the memory budget, beside the sets (half of it), the exact selector's
  // model freed by now.
  const double selection_s = std::chrono::duration<double>(Clock::now() - start).count();
  VC_ASSIGN_OR_RETURN(out.best_coverage,
                      BestCoverageOf(sets, fixed, static_cast<int>(out.selection.picks.size()),
                                     std::max(0.1, 0.05 * selection_s), options.memory_budget_bytes / 4, ctx));
  CapBelowTheSelectorsBound(out.best_coverage, out.selection, options);
  sets.clear();
  sets.shrink_to_fit();
  return out;
}

}  // namespace vc::planner
