#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>

#include "format.h"
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

uint64_t ReductionJoinBytes(uint64_t voxels) {
  const uint64_t per_voxel = kFacesPerVoxel * (sizeof(double) + sizeof(uint8_t) + sizeof(float)) + sizeof(int32_t);
  return 2 * voxels * per_voxel;
}

uint64_t EvaluateWorkingBytes(uint64_t voxels) {
  const uint64_t per_voxel = sizeof(VoxelIndex) + 8 * sizeof(uint32_t) + 3 * (sizeof(uint64_t) + sizeof(uint32_t)) +
                             kFacesPerVoxel * (sizeof(double) + sizeof(uint8_t));
  return voxels * per_voxel;
}

uint64_t ReductionTableBytes(uint64_t voxels) {
  return voxels * kFacesPerVoxel * sizeof(FaceTop3) + EvaluateWorkingBytes(voxels);
}

ReductionMemory ReductionMemoryFor(uint64_t voxels, uint64_t memory_budget_bytes) {
  ReductionMemory m;
  m.table_bytes = ReductionTableBytes(voxels);
  m.join_bytes = ReductionJoinBytes(voxels);
  const uint64_t three_quarters = memory_budget_bytes / 4 * 3;
  m.table_fits = m.table_bytes <= three_quarters;
  m.keep_join = m.table_bytes + m.join_bytes <= three_quarters;
  m.cache_bytes = std::min<uint64_t>(memory_budget_bytes / 4, uint64_t{1} << 30);
  return m;
}

namespace {
// The smallest budget b with bytes <= b / 4 * 3.
uint64_t BudgetForThreeQuarters(uint64_t bytes) { return (bytes + 2) / 3 * 4; }
}  // namespace

uint64_t ReductionTableBudgetBytes(uint64_t voxels) { return BudgetForThreeQuarters(ReductionTableBytes(voxels)); }

uint64_t ReductionJoinBudgetBytes(uint64_t voxels) {
  return BudgetForThreeQuarters(ReductionTableBytes(voxels) + ReductionJoinBytes(voxels));
}

EvaluateOptions ReductionEvaluateOptions(const PlanOptions& options) {
  EvaluateOptions eval_options = StationEvaluateOptions(options);
  eval_options.keep_face_values = false;
  eval_options.keep_sparse_per_viewpoint_values = true;
  return eval_options;
}

namespace {
// RESOURCE_EXHAUSTED for a reduction whose table does not fit: the figures and what would plan it.
Status TableRefusal(const ReductionMemory& memory, uint64_t voxels, uint64_t memory_budget_bytes) {
  const uint64_t enough = ReductionTableBudgetBytes(voxels);
  return ResourceExhaustedError("reduction: its table of the stations' best face values (" +
                                std::to_string(memory.table_bytes) + " bytes for " + std::to_string(voxels) +
                                " voxels: 24 bytes a face, and an evaluation's working set) does not fit in three "
                                "quarters of the memory budget (" +
                                std::to_string(memory_budget_bytes / 4 * 3) + " bytes); a memory budget of " +
                                Num(enough / 1048576.0) + " MiB or more (--memory-budget-bytes " +
                                std::to_string(enough) +
                                ") plans it, or --no-reduce skips the reduction, or a coarser resolution_m has fewer "
                                "voxels");
}

// The first pass's evaluation of the stations so far (0 .. joined - 1), each batch joined on.
struct JoinedStations {
  std::optional<Evaluation> all;
  size_t joined = 0;

  // Joins `e`, the evaluation of the next `count` of `total` stations; once every one is in there
  // is nothing more to join on, so the join state's memory goes back.
  Status Add(Evaluation e, size_t count, size_t total) {
    if (all) {
      VC_ASSIGN_OR_RETURN(e, JoinEvaluations(std::move(*all), std::move(e)));
    }
    all = std::move(e);
    joined += count;
    if (joined == total) {
      std::vector<double>().swap(all->best_values);
      std::vector<uint8_t>().swap(all->best_perceptions);
    }
    return Status::Ok();
  }
};

// What the reduction keeps of values that came with their join state: V as a float, not the
// double and the perception (9 bytes a face, given back once the batch is joined).
std::vector<SparseFaceValues> WithoutJoinState(std::vector<SparseFaceValues> values) {
  for (SparseFaceValues& v : values) {
    std::vector<double>().swap(v.exact_values);
    std::vector<uint8_t>().swap(v.perceptions);
  }
  return values;
}

// Across replicas the first pass's batch also brings its join state, 9 bytes a face seen beside the
// values' 8, which the cache budget sizes the batch for: so besides the table and the join, 9/8 of
// the cache budget, in three quarters of the budget.
uint64_t PeerJoinStateBytes(const ReductionMemory& m) { return m.cache_bytes / 8 * 9; }
bool PeerJoinFits(const ReductionMemory& m, uint64_t memory_budget_bytes) {
  return m.table_bytes + m.join_bytes + PeerJoinStateBytes(m) <= memory_budget_bytes / 4 * 3;
}
// The smallest budget (to a MiB) at which PeerJoinFits.
uint64_t PeerJoinBudgetBytes(uint64_t voxels) {
  uint64_t budget = ReductionJoinBudgetBytes(voxels);
  while (!PeerJoinFits(ReductionMemoryFor(voxels, budget), budget)) budget += uint64_t{1} << 20;
  return budget;
}

constexpr char kOlderReplicaNote[] =
    "reduction: a replica answered the stations' face values without their perceptions and double-precision V "
    "(most likely a vc-server older than this one), so the evaluation stage evaluates the final stations again; "
    "replicas of this version join them into the final evaluation";

}  // namespace

// Reduction on every station's V of every face it sees. Stations are evaluated a batch at a time
// into sparse values (what each sees), which RunReduction keeps while they fit the cache budget
// (otherwise it asks for them again after each removal). The first pass over all stations also
// keeps the face values the evaluation stage needs, batch by batch, joined (JoinEvaluations) into
// the evaluation of every station: the final evaluation if nothing is removed. That joined
// evaluation is charged to the memory budget beside the table (ReductionMemoryFor: three quarters
// of it); when it does not fit, nothing is joined and the evaluation stage evaluates the final
// stations itself. Across replicas the first pass asks for each station's values with their join
// state (the double-precision V and perception of each face, and the station's figures) and builds
// each batch's evaluation from them (EvaluationOfSparseValues) to join it the same way; a replica
// too old to give them leaves the join out (a note says so).
Result<ReductionOutput> RunReductionStage(const ReductionInput& in, const PlanOptions& options, const JobContext& ctx) {
  const std::vector<WorldPoint>& stations = in.stations.positions;
  const uint64_t faces_total = in.scene.occupied.size() * kFacesPerVoxel;
  const ReductionMemory memory = ReductionMemoryFor(in.scene.occupied.size(), options.memory_budget_bytes);
  if (!memory.table_fits) return TableRefusal(memory, in.scene.occupied.size(), options.memory_budget_bytes);
  JoinedStations joined;
  ReductionOutput out;
  const StationFaceValuesFn values = [&](const std::vector<int>& batch,
                                         const JobContext& sub) -> Result<std::vector<SparseFaceValues>> {
    std::vector<WorldPoint> positions;
    positions.reserve(batch.size());
    for (int s : batch) positions.push_back(stations[s]);
    // The first pass streams the stations in order, so a batch that starts at the next station
    // not joined yet belongs to it (a pass after a removal starts again from the first kept one).
    // Without room for the join state, only a batch of every station is kept (nothing to join).
    // Across replicas the join state comes with every batch, so it must fit even for one.
    const bool join_fits = in.face_values ? PeerJoinFits(memory, options.memory_budget_bytes)
                                          : (memory.keep_join || batch.size() == stations.size());
    const bool first_pass = !batch.empty() && static_cast<size_t>(batch.front()) == joined.joined &&
                            joined.joined < stations.size() && join_fits;
    EvaluateOptions eval_options = ReductionEvaluateOptions(options);
    if (in.face_values) {  // across replicas
      eval_options.keep_sparse_join_state = first_pass;
      VC_ASSIGN_OR_RETURN(DistributedFaceValues d, in.face_values(in.scene, positions, eval_options, sub));
      if (d.values.size() != positions.size()) {
        return InternalError("the distributed reduction returned face values of " + std::to_string(d.values.size()) +
                             " stations for " + std::to_string(positions.size()));
      }
      out.distribution.Add(d.distribution);
      if (first_pass && d.figures.size() != positions.size()) d.warnings.push_back(kOlderReplicaNote);
      for (std::string& w : d.warnings) {  // once each, though every batch asks the replicas again
        if (std::find(out.warnings.begin(), out.warnings.end(), w) == out.warnings.end()) {
          out.warnings.push_back(std::move(w));
        }
      }
      if (first_pass && d.figures.size() == positions.size()) {
        VC_ASSIGN_OR_RETURN(Evaluation e,
                            EvaluationOfSparseValues(in.scene, eval_options.faces, std::move(d.figures), d.values));
        VC_RETURN_IF_ERROR(joined.Add(std::move(e), batch.size(), stations.size()));
      }
      return WithoutJoinState(std::move(d.values));
    }
    eval_options.keep_face_values = first_pass;
    // The join state only where another batch will be joined on (one batch is the whole evaluation).
    eval_options.keep_join_state = first_pass && batch.size() < stations.size();
    VC_ASSIGN_OR_RETURN(Evaluation e, Evaluate(in.scene, positions, eval_options, sub));
    std::vector<SparseFaceValues> batch_values = std::move(e.per_viewpoint_sparse_values);
    e.per_viewpoint_sparse_values.clear();
    if (first_pass) VC_RETURN_IF_ERROR(joined.Add(std::move(e), batch.size(), stations.size()));
    return batch_values;
  };
  ReductionRunOptions red_options;
  red_options.reduce_to = options.reduce_to;
  red_options.threads = options.threads;
  red_options.cache_budget_bytes = memory.cache_bytes;
  // Across replicas, every station in one call: the replicas split it into shards among them.
  red_options.batch_stations = in.face_values ? std::max<int>(1, int(stations.size())) : kReductionStationsPerBatch;
  red_options.fixed = in.stations.fixed;
  // Registration: no removal may split the stations' scan graph into more groups.
  OverlapMatrix overlaps;
  int groups = 0;
  if (options.min_overlap > 0) {
    overlaps = OverlapMatrix(in.stations.sets, options.threads);
    std::vector<int> all(stations.size());
    for (size_t k = 0; k < stations.size(); ++k) all[k] = static_cast<int>(k);
    groups = CountComponents(overlaps, all, options.min_overlap);
    red_options.keeps = [&](const std::vector<int>& remaining) {
      return CountComponents(overlaps, remaining, options.min_overlap) <= groups;
    };
  }
  VC_ASSIGN_OR_RETURN(ReductionRun run,
                      RunReduction(static_cast<int>(stations.size()), faces_total, values, red_options, ctx));
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
  if (run.removed.empty() && joined.joined == stations.size()) out.evaluation = std::move(joined.all);
  if (in.face_values && !PeerJoinFits(memory, options.memory_budget_bytes) && run.removed.empty()) {
    out.warnings.push_back("reduction: the joined evaluation of the stations (" + Num(memory.join_bytes / 1048576.0) +
                           " MiB) and the replicas' join state in flight (" +
                           Num(PeerJoinStateBytes(memory) / 1048576.0) + " MiB) do not fit beside its table (" +
                           Num(memory.table_bytes / 1048576.0) + " MiB) in three quarters of the memory budget (" +
                           Num(double(options.memory_budget_bytes / 4 * 3) / 1048576.0) +
                           " MiB), so the evaluation stage evaluates the final stations again; a memory budget of " +
                           Num(PeerJoinBudgetBytes(in.scene.occupied.size()) / 1048576.0) + " MiB or more avoids that");
  } else if (!memory.keep_join && run.removed.empty() && !out.evaluation) {
    out.warnings.push_back("reduction: the joined evaluation of the stations (" + Num(memory.join_bytes / 1048576.0) +
                           " MiB) does not fit beside its table (" + Num(memory.table_bytes / 1048576.0) +
                           " MiB) in three quarters of the memory budget (" +
                           Num(double(options.memory_budget_bytes / 4 * 3) / 1048576.0) +
                           " MiB), so the evaluation stage evaluates the final stations again; a memory budget of " +
                           Num(ReductionJoinBudgetBytes(in.scene.occupied.size()) / 1048576.0) +
                           " MiB or more avoids that");
  }
  return out;
}

}  // namespace vc::planner
