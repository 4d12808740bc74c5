#include "cover_model.h"

#include <CoinPackedMatrix.hpp>
#include <OsiClpSolverInterface.hpp>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "progress_pacer.h"

namespace vc::planner::internal {

// The columns as CBC takes them: a column-ordered matrix in one piece (appending column by
// column to a CoinPackedMatrix reallocates each time), with the columns' bounds and objective.
struct CoverModel::Columns {
  std::vector<double> elements;
  std::vector<int> indices;
  std::vector<CoinBigIndex> starts;
  std::vector<int> lengths;
  std::vector<double> lower, upper, objective;

  Columns(int n_columns, uint64_t reserve_nonzeros)
      : lower(n_columns, 0.0), upper(n_columns, 1.0), objective(n_columns, 0.0) {
    elements.reserve(reserve_nonzeros);
    indices.reserve(reserve_nonzeros);
  }
  void Start() { starts.push_back(static_cast<CoinBigIndex>(indices.size())); }
  void Add(int row, double value) {
    indices.push_back(row);
    elements.push_back(value);
  }
  void End() { lengths.push_back(static_cast<int>(indices.size()) - starts.back()); }
};

CoverModel::CoverModel(const ReducedModel& reduced, std::vector<ScanArc> arcs, const CoverModelOptions& options)
    : reduced_(reduced), arcs_(std::move(arcs)), options_(options) {
  const int n_stations = static_cast<int>(reduced_.columns.size());
  const int n_classes = static_cast<int>(reduced_.weight.size());
  const int n_arcs = static_cast<int>(arcs_.size());
  const int flow = options_.connect ? 1 : 0;
  station_cols_ = {0, n_stations};
  cover_cols_ = {station_cols_.end(), options_.cover_rows ? 0 : n_classes};
  root_cols_ = {cover_cols_.end(), flow * n_stations};
  source_flow_cols_ = {root_cols_.end(), flow * n_stations};
  arc_flow_cols_ = {source_flow_cols_.end(), flow * n_arcs};
  n_columns_ = arc_flow_cols_.end();

  class_rows_ = {0, n_classes};
  weight_row_ = {class_rows_.end(), options_.cover_rows ? 0 : 1};
  budget_row_ = {weight_row_.end(), options_.max_mode ? 1 : 0};
  root_row_ = {budget_row_.end(), flow};
  root_link_rows_ = {root_row_.end(), flow * n_stations};
  source_flow_rows_ = {root_link_rows_.end(), flow * n_stations};
  conservation_rows_ = {source_flow_rows_.end(), flow * n_stations};
  capacity_rows_ = {conservation_rows_.end(), flow * 2 * n_arcs};
  n_rows_ = capacity_rows_.end();

  big_n_ = options_.max_mode ? std::min<double>(n_stations, options_.max_stations + options_.fixed) : n_stations;
  eps_ = 1.0 / (n_stations + 1.0);
  arcs_at_.resize(n_stations);
  for (int a = 0; a < n_arcs; ++a) {
    arcs_at_[arcs_[a].from].push_back(a);
    arcs_at_[arcs_[a].to].push_back(a);
  }
}

uint64_t CoverModel::ClassNonZeros() const {
  uint64_t nnz = 0;
  for (const std::vector<int>& s : reduced_.seen_by) nnz += s.size() + (options_.cover_rows ? 0 : 2);
  return nnz;
}

uint64_t CoverModel::EstimatedBytes(uint64_t class_nonzeros, uint64_t rows, uint64_t columns) {
  return class_nonzeros * 200 + (rows + columns) * 1000;
}

uint64_t CoverModel::EstimatedBytes() const {
  return EstimatedBytes(ClassNonZeros(), n_rows_, station_cols_.count + cover_cols_.count);
}

void CoverModel::AppendStationColumns(Columns& cols) const {
  const ReducedModel& m = reduced_;
  std::vector<std::vector<int>> col_classes(station_cols_.count);
  for (int k = 0; k < class_rows_.count; ++k) {
    for (int j : m.seen_by[k]) col_classes[j].push_back(k);
  }
  for (int j = 0; j < station_cols_.count; ++j) {
    cols.Start();
    for (int k : col_classes[j]) cols.Add(class_rows_[k], options_.cover_rows ? 1.0 : -1.0);
    if (options_.max_mode) cols.Add(budget_row_[0], 1.0);
    if (options_.connect) {
      cols.Add(root_link_rows_[j], -1.0);
      cols.Add(conservation_rows_[j], -1.0);
      for (int a : arcs_at_[j]) cols.Add(capacity_rows_[2 * a + (arcs_[a].from == j ? 0 : 1)], -(big_n_ - 1));
      if (m.columns[j] < options_.fixed) cols.lower[station_cols_[j]] = 1.0;  // fixed stations are in the plan
    }
    cols.End();
    cols.objective[station_cols_[j]] = options_.max_mode ? eps_ : 1.0;
  }
}

void CoverModel::AppendCoverColumns(Columns& cols) const {
  for (int k = 0; k < cover_cols_.count; ++k) {
    cols.Start();
    cols.Add(class_rows_[k], 1.0);
    cols.Add(weight_row_[0], static_cast<double>(reduced_.weight[k]));
    cols.End();
    cols.objective[cover_cols_[k]] = options_.max_mode ? -static_cast<double>(reduced_.weight[k]) : 0.0;
  }
}

void CoverModel::AppendFlowColumns(Columns& cols) const {
  for (int j = 0; j < root_cols_.count; ++j) {
    cols.Start();
    cols.Add(root_row_[0], 1.0);
    cols.Add(root_link_rows_[j], 1.0);
    cols.Add(source_flow_rows_[j], -big_n_);
    cols.End();
  }
  for (int j = 0; j < source_flow_cols_.count; ++j) {
    cols.Start();
    cols.Add(source_flow_rows_[j], 1.0);
    cols.Add(conservation_rows_[j], 1.0);
    cols.End();
    cols.upper[source_flow_cols_[j]] = big_n_;
  }
  for (int a = 0; a < arc_flow_cols_.count; ++a) {
    cols.Start();
    cols.Add(conservation_rows_[arcs_[a].to], 1.0);
    cols.Add(conservation_rows_[arcs_[a].from], -1.0);
    cols.Add(capacity_rows_[2 * a], 1.0);
    cols.Add(capacity_rows_[2 * a + 1], 1.0);
    cols.End();
    cols.upper[arc_flow_cols_[a]] = big_n_ - 1;
  }
}

void CoverModel::SetRowBounds(std::vector<double>& lower, std::vector<double>& upper) const {
  const auto set = [&](Block rows, double lo, double hi) {
    for (int i = 0; i < rows.count; ++i) {
      lower[rows[i]] = lo;
      upper[rows[i]] = hi;
    }
  };
  const double need = static_cast<double>(options_.need);
  set(class_rows_, options_.cover_rows ? 1.0 : -COIN_DBL_MAX, options_.cover_rows ? COIN_DBL_MAX : 0.0);
  set(weight_row_, options_.max_mode ? -COIN_DBL_MAX : need, options_.max_mode ? need : COIN_DBL_MAX);
  set(budget_row_, -COIN_DBL_MAX, options_.max_stations);
  set(root_row_, 1.0, 1.0);
  set(root_link_rows_, -COIN_DBL_MAX, 0.0);
  set(source_flow_rows_, -COIN_DBL_MAX, 0.0);
  set(conservation_rows_, 0.0, 0.0);
  set(capacity_rows_, -COIN_DBL_MAX, 0.0);
}

void CoverModel::LoadInto(OsiClpSolverInterface& solver) const {
  Columns cols(n_columns_, ClassNonZeros() + station_cols_.count);
  AppendStationColumns(cols);
  AppendCoverColumns(cols);
  AppendFlowColumns(cols);
  const CoinPackedMatrix matrix(true, n_rows_, n_columns_, static_cast<CoinBigIndex>(cols.indices.size()),
                                cols.elements.data(), cols.indices.data(), cols.starts.data(), cols.lengths.data());
  std::vector<double> row_lower(n_rows_), row_upper(n_rows_);
  SetRowBounds(row_lower, row_upper);
  solver.loadProblem(matrix, cols.lower.data(), cols.upper.data(), cols.objective.data(), row_lower.data(),
                     row_upper.data());
  for (int j = 0; j < station_cols_.count; ++j) solver.setInteger(station_cols_[j]);
  for (int j = 0; j < root_cols_.count; ++j) solver.setInteger(root_cols_[j]);
}

WarmStart CoverModel::WarmStartFrom(const std::vector<int>& picks, int n_candidates) const {
  const ReducedModel& m = reduced_;
  const uint64_t need = options_.need;
  std::vector<char> in_plan(n_candidates, 0);
  for (int p : picks) {
    if (m.stand_in[p] >= 0) in_plan[m.stand_in[p]] = 1;
  }
  WarmStart warm;
  warm.values.assign(n_columns_, 0.0);
  for (int j = 0; j < station_cols_.count; ++j) {
    warm.values[station_cols_[j]] = in_plan[m.columns[j]] ? 1.0 : 0.0;
    warm.stations += in_plan[m.columns[j]];
  }
  for (int k = 0; k < class_rows_.count; ++k) {
    bool seen = false;
    for (int j : m.seen_by[k]) seen = seen || warm.values[station_cols_[j]] > 0.5;
    if (!seen) continue;
    if (!options_.cover_rows) {
      const uint64_t room = options_.max_mode ? need - std::min(need, warm.covered) : m.weight[k];
      warm.values[cover_cols_[k]] = std::min(1.0, double(room) / double(m.weight[k]));
    }
    warm.covered += m.weight[k];
  }
  if (options_.connect && warm.stations > 0) warm.connected = SetWarmFlow(warm);
  warm.feasible = warm.connected && (options_.max_mode ? warm.stations <= options_.max_stations : warm.covered >= need);
  warm.objective = options_.max_mode ? -double(std::min(warm.covered, need)) + eps_ * warm.stations : warm.stations;
  return warm;
}

bool CoverModel::SetWarmFlow(WarmStart& warm) const {
  const auto chosen = [&](int j) { return warm.values[station_cols_[j]] > 0.5; };
  int root = -1;
  for (int j = 0; j < station_cols_.count && root < 0; ++j) {
    if (chosen(j)) root = j;
  }
  // Breadth first from the root over arcs between chosen stations.
  std::vector<int> parent_arc(station_cols_.count, -2), order{root};
  parent_arc[root] = -1;
  for (size_t q = 0; q < order.size(); ++q) {
    for (int a : arcs_at_[order[q]]) {
      const int to = arcs_[a].to;
      if (arcs_[a].from == order[q] && chosen(to) && parent_arc[to] == -2) {
        parent_arc[to] = a;
        order.push_back(to);
      }
    }
  }
  if (static_cast<int>(order.size()) != warm.stations) return false;
  // Each tree arc carries the stations below it.
  std::vector<double> below(station_cols_.count, 1.0);
  for (size_t q = order.size(); q-- > 1;) {
    const int a = parent_arc[order[q]];
    warm.values[arc_flow_cols_[a]] = below[order[q]];
    below[arcs_[a].from] += below[order[q]];
  }
  warm.values[root_cols_[root]] = 1.0;
  warm.values[source_flow_cols_[root]] = warm.stations;
  return true;
}

uint64_t TargetVoxels(double target, uint64_t coverable) {
  const double t = target * static_cast<double>(coverable);
  uint64_t k = static_cast<uint64_t>(std::max(0.0, std::ceil(t)));
  while (k > 0 && static_cast<double>(k - 1) >= t) --k;
  while (static_cast<double>(k) < t) ++k;
  return std::min(k, coverable);
}

Result<Classes> BuildClasses(const std::vector<VoxelSet>& sets, const JobContext& ctx) {
  const size_t n_voxels = sets.empty() ? 0 : sets[0].size();
  // Class 0 = seen by no candidate so far; ids grow as candidates split classes.
  std::vector<int32_t> cls(n_voxels, 0);
  std::vector<int32_t> remap(1, -1), stamp(1, -1);
  int32_t next = 1;
  // Two passes over the candidates, counted as one.
  const uint64_t steps = 2 * sets.size();
  internal::ProgressPacer pacer;
  auto report = [&](uint64_t done) {
    if (!pacer.Due()) return;
    std::string note = "exact: voxel classes";
    if (const std::string left = pacer.TimeLeft(done, steps); !left.empty()) note += ", " + left;
    ctx.ReportCount(Stage::kSelection, done, steps, "candidate passes", std::move(note));
  };
  for (size_t c = 0; c < sets.size(); ++c) {
    if (c % 64 == 0) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (voxel classes)"));
      report(c);
    }
    sets[c].ForEach([&](size_t v) {
      const int32_t old = cls[v];
      if (stamp[old] != static_cast<int32_t>(c)) {
        stamp[old] = static_cast<int32_t>(c);
        remap[old] = next++;
        remap.push_back(-1);
        stamp.push_back(-1);
      }
      cls[v] = remap[old];
    });
  }
  // Compact the ids that still hold voxels (class 0 holds the uncoverable ones).
  std::vector<int32_t> compact(next, -1);
  Classes out;
  for (size_t v = 0; v < n_voxels; ++v) {
    const int32_t k = cls[v];
    if (k == 0) continue;
    if (compact[k] < 0) {
      compact[k] = static_cast<int32_t>(out.weight.size());
      out.weight.push_back(0);
    }
    ++out.weight[compact[k]];
  }
  out.seen_by.resize(out.weight.size());
  out.sees.resize(sets.size());
  std::vector<int32_t> last(out.weight.size(), -1);
  for (size_t c = 0; c < sets.size(); ++c) {
    if (c % 64 == 0) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("exact selection (voxel classes)"));
      report(sets.size() + c);
    }
    sets[c].ForEach([&](size_t v) {
      const int32_t k = compact[cls[v]];
      if (last[k] == static_cast<int32_t>(c)) return;
      last[k] = static_cast<int32_t>(c);
      out.seen_by[k].push_back(static_cast<int>(c));
      out.sees[c].push_back(k);
    });
    std::sort(out.sees[c].begin(), out.sees[c].end());
  }
  return out;
}

}  // namespace vc::planner::internal
