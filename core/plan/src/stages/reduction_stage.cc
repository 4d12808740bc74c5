#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>

#include "vc/plan/reduction.h"
#include "vc/plan/scan_graph.h"
#include "vc/plan/stage_runner.h"
#include "vc/plan/stages.h"

namespace vc::planner {

ReductionOutput KeepAllStations(size_t count) {
  ReductionOutput out;
  out.keep.resize(count);
  for (size_t k = 0; k < count; ++k) out.keep[k] = static_cast<int>(k);
  return out;
}

// Reduction on every station's V of every face. One Evaluate of all stations keeps them when
// they fit the cache budget (and is the final evaluation if nothing is removed); otherwise each
// station is evaluated alone, as often as the reduction needs.
Result<ReductionOutput> RunReductionStage(const ReductionInput& in, const PlanOptions& options, const JobContext& ctx) {
  const std::vector<WorldPoint>& stations = in.stations.positions;
  const EvaluateOptions eval_options = StationEvaluateOptions(options);
  const uint64_t faces_total = in.scene.occupied.size() * kFacesPerVoxel;
  const uint64_t cache_budget = std::min<uint64_t>(options.memory_budget_bytes / 4, uint64_t{1} << 30);
  const bool batch = stations.size() * faces_total * sizeof(float) <= cache_budget;
  std::optional<Evaluation> all_evaluation;
  StationFaceValuesFn values;
  if (batch) {
    EvaluateOptions batch_options = eval_options;
    batch_options.keep_per_viewpoint_values = true;
    VC_ASSIGN_OR_RETURN(all_evaluation, Evaluate(in.scene, stations, batch_options, ProgressRange(ctx, 0.0, 0.9)));
    values = [&](int s, const JobContext&) -> Result<std::vector<float>> {
      return std::move(all_evaluation->per_viewpoint_face_values[s]);  // read once: RunReduction caches
    };
  } else {
    EvaluateOptions single_options = eval_options;
    single_options.keep_face_values = false;
    single_options.keep_per_viewpoint_values = true;
    // single_options by value: this block ends before RunReduction calls `values`.
    values = [&in, &stations, single_options](int s, const JobContext& sub) -> Result<std::vector<float>> {
      VC_ASSIGN_OR_RETURN(Evaluation e, Evaluate(in.scene, {stations[s]}, single_options, sub));
      return std::move(e.per_viewpoint_face_values[0]);
    };
  }
  ReductionRunOptions red_options;
  red_options.reduce_to = options.reduce_to;
  red_options.threads = options.threads;
  red_options.cache_budget_bytes = cache_budget;
  red_options.fixed = in.stations.fixed;
  // Registration: no removal may split the stations' scan graph into more groups.
  OverlapMatrix overlaps;
  int groups = 0;
  if (options.min_overlap > 0) {
    overlaps = OverlapMatrix(in.stations.sets);
    std::vector<int> all(stations.size());
    for (size_t k = 0; k < stations.size(); ++k) all[k] = static_cast<int>(k);
    groups = CountComponents(overlaps, all, options.min_overlap);
    red_options.keeps = [&](const std::vector<int>& remaining) {
      return CountComponents(overlaps, remaining, options.min_overlap) <= groups;
    };
  }
  VC_ASSIGN_OR_RETURN(ReductionRun run, RunReduction(static_cast<int>(stations.size()), faces_total, values,
                                                     red_options, ProgressRange(ctx, batch ? 0.9 : 0.0, 1.0)));
  if (all_evaluation) all_evaluation->per_viewpoint_face_values.clear();
  ReductionOutput out;
  Reduction& reduction = out.reduction;
  reduction.size = run.initial.size;
  reduction.matrix = run.initial.loss;
  reduction.removed = run.removed;
  std::sort(reduction.removed.begin(), reduction.removed.end());
  reduction.global_visibility_before = run.global_visibility_before;
  reduction.global_visibility_after = run.global_visibility_after;
  reduction.positions = stations;
  for (size_t k = 0; k < stations.size(); ++k) {
    if (!std::binary_search(reduction.removed.begin(), reduction.removed.end(), static_cast<int>(k))) {
      out.keep.push_back(static_cast<int>(k));
    }
  }
  if (run.removed.empty()) out.evaluation = std::move(all_evaluation);
  return out;
}

}  // namespace vc::planner
