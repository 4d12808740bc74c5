// Viewpoint reduction (ALGORITHM.md s.7.5; paper s.3.3 and Fig. 12).
//
// The reduction potential of a subset T of the chosen stations P is G(P) - G(P - T), the global
// visibility lost by removing T. Only the best, second and third best V of each face matter for
// every single and every pair: removing {i} loses v1 - v2 on the faces where i is best; removing
// {i, j} loses v1 - v3 where i and j are the two best, v1 - v2 where only one of them is best. So
// the whole |P| x |P| matrix comes from one pass over a per-face top-3 table, exactly:
//   loss{i}    = sum over faces with s1 = i of (v1 - v2)
//   loss{i,j}  = loss{i} + loss{j} + sum over faces with {s1, s2} = {i, j} of (v2 - v3)
// divided by |F|. Face values come from a callback, a batch of stations at a time, as each
// station's faces with V > 0 (the planner wraps vc::Evaluate with keep_sparse_per_viewpoint_values,
// or hands the batch to replicas), so this file is testable on hand-made values. Internal to vc_core.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/visibility/visibility.h"

namespace vc::planner {

// The three largest V (> 0) of one face among the active stations, in descending order; unused
// slots hold value 0 and station -1.
struct FaceTop3 {
  std::array<float, 3> v{0.f, 0.f, 0.f};
  std::array<int32_t, 3> s{-1, -1, -1};
};

// Inserts station's value into t (ignored when value <= 0). Equal values keep insertion order.
void InsertTop3(FaceTop3& t, float value, int32_t station);

struct ReductionMatrix {
  int size = 0;                  // stations, indexed 0..size-1 (inactive ones have zero rows)
  std::vector<double> loss;      // size x size, row-major: [i][i] = loss{i}, [i][j] = loss{i,j}
  double global_visibility = 0;  // G(P) of the active stations
  double at(int i, int j) const { return loss[static_cast<size_t>(i) * size + j]; }
};

// The matrix from a top-3 table over |F| = faces_total faces (top3.size() <= faces_total; faces
// not in the table are seen by nobody). Deterministic for any thread count.
ReductionMatrix ComputeReductionMatrix(const std::vector<FaceTop3>& top3, int num_stations, uint64_t faces_total,
                                       int threads = 0);

// What to remove next among `active` (station indices, ascending): the default rule removes only
// zero-loss stations (a zero-loss pair beats a zero-loss single; among equals, the latest in
// greedy order); with reduce_to > 0 it then keeps removing the subset with the lowest loss per
// removed station (a pair only while at least two must go) until at most reduce_to remain. Never
// removes the last station, nor a station s with fixed[s] (fixed stations; may be shorter than
// the stations, or empty), nor a subset after whose removal `keeps(remaining)` is false (when
// set; registration: the scan graph must keep its groups). Empty when nothing is to be removed.
using RemovalCheck = std::function<bool(const std::vector<int>& remaining)>;
std::vector<int> ChooseRemoval(const ReductionMatrix& m, const std::vector<int>& active, int reduce_to,
                               const std::vector<bool>& fixed = {}, const RemovalCheck& keeps = {});

// For each of `stations` (indices, ascending), its faces with V > 0 (F order).
using StationFaceValuesFn =
    std::function<Result<std::vector<SparseFaceValues>>(const std::vector<int>& stations, const JobContext& ctx)>;

struct ReductionRunOptions {
  int reduce_to = 0;        // 0 = zero-loss rule only
  bool remove = true;       // false: only compute the matrix
  std::vector<bool> fixed;  // per station: never removed (fixed stations); empty = none
  RemovalCheck keeps;       // when set, a removal must leave stations it accepts (ChooseRemoval)
  // Keep every station's face values in memory (for exact top-3 refills after a removal) while
  // they fit in this many bytes; otherwise the values are recomputed after each removal.
  uint64_t cache_budget_bytes = uint64_t{1} << 30;
  // Stations per call of the values callback, at most; fewer while a batch's values could exceed
  // cache_budget_bytes (at first judged by the worst case, every face seen; then by the average of
  // the stations asked so far), so the values in flight stay within that budget too.
  int batch_stations = 256;
  int threads = 0;
};

struct ReductionRun {
  ReductionMatrix initial;   // the matrix of all stations (Fig. 12)
  std::vector<int> removed;  // station indices, in removal order
  // Each removal step: the stations removed together and the G it lost.
  struct Step {
    std::vector<int> stations;
    double loss = 0;
  };
  std::vector<Step> steps;
  double global_visibility_before = 0;
  double global_visibility_after = 0;
};

// Computes the matrix of `num_stations` stations over `faces_total` faces and applies the
// removal rule. Errors from `values` (e.g. CANCELLED) are returned as they are.
Result<ReductionRun> RunReduction(int num_stations, uint64_t faces_total, const StationFaceValuesFn& values,
                                  const ReductionRunOptions& options, const JobContext& ctx = {});

}  // namespace vc::planner
