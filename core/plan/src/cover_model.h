// The exact selection's integer program (exact_selector.h states it) over a reduced model: which
// block of columns and rows each kind of variable and constraint occupies, the matrix and bounds
// CBC is given, and the warm start made from a plan. Internal to the plan layer.
//
// Columns, in this order: x (one per candidate column), y (one per class; absent with set-cover
// rows), then with connectivity the single-commodity flow (Dehbi et al. 2021): r (a root, binary,
// one of them), g (the source's flow into the root, g_c <= N r_c) and f (a flow f_a <= (N - 1) x
// on each end of each arc of the scan graph). Every chosen station consumes one unit
// (g_c + in - out = x_c), so the chosen stations are exactly those the root's flow reaches.
//
// Thread-safe: immutable after construction.
#pragma once

#include <cstdint>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/visibility/voxel_set.h"

class OsiClpSolverInterface;

namespace vc::planner::internal {

// The coverable voxels partitioned into classes seen by exactly the same candidates (partition
// refinement: each candidate splits the classes it touches), with each class's candidates.
struct Classes {
  std::vector<uint64_t> weight;           // voxels per class
  std::vector<std::vector<int>> seen_by;  // per class: candidates seeing it, ascending
  std::vector<std::vector<int>> sees;     // per candidate: classes it sees, ascending
};
// The classes of `sets` (one per candidate), reported as "exact: voxel classes" progress of the
// selection stage; CANCELLED from ctx.
Result<Classes> BuildClasses(const std::vector<VoxelSet>& sets, const JobContext& ctx);

// The smallest voxel count k with k >= target * coverable (the greedy's stopping test): the need
// the exact selector's model and its bound are for.
uint64_t TargetVoxels(double target, uint64_t coverable);

// A run of consecutive rows or columns of one kind; count 0 where the model has none of them.
struct Block {
  int first = 0;
  int count = 0;
  int operator[](int i) const { return first + i; }  // the i-th row or column of the block
  int end() const { return first + count; }          // one past the block's last row or column
};

// The model after reduction: classes still to cover (merged again), the candidate columns, the
// candidates forced to 1 and where each dropped candidate's role goes.
struct ReducedModel {
  std::vector<uint64_t> weight;           // per class, in voxels
  std::vector<std::vector<int>> seen_by;  // per class: column indices (into columns), ascending
  std::vector<int> columns;               // candidate index per column
  std::vector<int> forced;                // candidates fixed to 1 (the fixed stations first)
  uint64_t forced_covered = 0;            // voxels the forced candidates cover
  std::vector<int> stand_in;              // per candidate: the candidate that replaces it, or -1
  int dominated = 0;                      // candidates dropped as dominated by another
  int forced_sole_view = 0;               // candidates forced as the only view of some class
};

// A directed arc of the scan graph, between two columns.
struct ScanArc {
  int from = 0;
  int to = 0;
};

// Which variant of the integer program to build.
struct CoverModelOptions {
  bool max_mode = false;    // maximise the covered weight under max_stations (else minimise stations)
  bool cover_rows = false;  // full coverage: a set-cover row per class and no y columns
  bool connect = false;     // the plan must be connected in the scan graph (the flow columns and rows)
  int max_stations = 0;     // the station budget in max_mode (the fixed stations not counted)
  int fixed = 0;            // candidates [0, fixed) are stations already placed
  uint64_t need = 0;        // voxels the columns must add to the forced candidates' (the target)
};

// A plan as a starting point for CBC: every column's value and what the plan achieves.
struct WarmStart {
  std::vector<double> values;  // per column of the model
  int stations = 0;            // x columns at 1
  uint64_t covered = 0;        // class weight the x columns at 1 cover, in voxels
  bool connected = true;       // with connectivity: false when the plan is not connected (no flow set)
  bool feasible = false;       // satisfies the model's rows (CBC may take it as its incumbent)
  double objective = 0;        // the model's objective at `values`
};

// The integer program over a ReducedModel; the layout is fixed at construction, the matrix is
// built only when loaded into a solver.
class CoverModel {
 public:
  // `reduced` must outlive the model; `arcs` (between its columns) is empty without connectivity.
  CoverModel(const ReducedModel& reduced, std::vector<ScanArc> arcs, const CoverModelOptions& options);

  const ReducedModel& reduced() const { return reduced_; }
  const CoverModelOptions& options() const { return options_; }
  const std::vector<ScanArc>& arcs() const { return arcs_; }

  Block station_cols() const { return station_cols_; }          // x_j: column j's candidate is a station (binary)
  Block cover_cols() const { return cover_cols_; }              // y_k in [0, 1]: class k counts as covered
  Block root_cols() const { return root_cols_; }                // r_j: the flow's root is at column j (binary)
  Block source_flow_cols() const { return source_flow_cols_; }  // g_j in [0, N]: the source's flow into j
  Block arc_flow_cols() const { return arc_flow_cols_; }        // f_a in [0, N - 1]: the flow along arc a

  Block class_rows() const { return class_rows_; }                // y_k - sum x <= 0, or sum x >= 1 (cover rows)
  Block weight_row() const { return weight_row_; }                // sum w_k y_k >= need (max_mode: <= need)
  Block budget_row() const { return budget_row_; }                // max_mode: sum x <= max_stations
  Block root_row() const { return root_row_; }                    // sum r = 1
  Block root_link_rows() const { return root_link_rows_; }        // r_j - x_j <= 0
  Block source_flow_rows() const { return source_flow_rows_; }    // g_j - N r_j <= 0
  Block conservation_rows() const { return conservation_rows_; }  // g_j + in_j - out_j - x_j = 0
  Block capacity_rows() const { return capacity_rows_; }          // per arc a: f_a - (N-1) x_from <= 0, then x_to

  int n_columns() const { return n_columns_; }
  int n_rows() const { return n_rows_; }
  double big_n() const { return big_n_; }  // N: the most stations a plan can have
  double eps() const { return eps_; }      // max_mode: the objective's weight per station

  // The memory CBC would take for this model, in bytes (row and column copies, the LP
  // factorisation and cuts; an estimate from the non-zeros, rows and columns).
  uint64_t EstimatedBytes() const;
  // The same estimate from the model's class non-zeros (the weight row's included), rows and columns.
  static uint64_t EstimatedBytes(uint64_t class_nonzeros, uint64_t rows, uint64_t columns);
  // Loads the matrix, bounds and objective into `solver` and marks the x and r columns integer.
  void LoadInto(OsiClpSolverInterface& solver) const;
  // `picks` (candidate indices < n_candidates) as a solution: each dropped candidate replaced by
  // its stand-in, with connectivity a flow along a spanning tree from the first station.
  WarmStart WarmStartFrom(const std::vector<int>& picks, int n_candidates) const;

 private:
  struct Columns;  // the matrix, bounds and objective under construction, column by column

  // Non-zeros of the class rows and the weight row.
  uint64_t ClassNonZeros() const;
  void AppendStationColumns(Columns& cols) const;
  void AppendCoverColumns(Columns& cols) const;
  void AppendFlowColumns(Columns& cols) const;
  void SetRowBounds(std::vector<double>& lower, std::vector<double>& upper) const;
  // The flow along a spanning tree of the warm start's stations; false if they are not connected.
  bool SetWarmFlow(WarmStart& warm) const;

  const ReducedModel& reduced_;
  std::vector<ScanArc> arcs_;
  CoverModelOptions options_;
  std::vector<std::vector<int>> arcs_at_;  // per column: the arcs it is an end of, ascending
  Block station_cols_, cover_cols_, root_cols_, source_flow_cols_, arc_flow_cols_;
  Block class_rows_, weight_row_, budget_row_, root_row_, root_link_rows_, source_flow_rows_, conservation_rows_,
      capacity_rows_;
  int n_columns_ = 0;
  int n_rows_ = 0;
  double big_n_ = 0;
  double eps_ = 0;
};

}  // namespace vc::planner::internal
