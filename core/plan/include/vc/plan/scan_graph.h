// The scan graph (docs/PLANNING.md, "Registration: overlap and the scan graph").
//
// Scans register into one cloud only where they share enough surface. The overlap of stations i
// and j is |S_i ∩ S_j| / min(|S_i|, |S_j|), S being the voxels each sees by the plan's selection
// test and scanner model (its visibility set), and 0 when either set is empty. The scan graph has
// an edge (i, j) when the overlap is at least min_overlap and above 0 (so with min_overlap 0,
// "off", any shared voxel links two stations). A plan is connected when its scan graph is: every
// scan then reaches every other through a chain of registrable pairs. 0.3 is the usual figure for
// target-less (cloud-to-cloud) registration.
//
// Components are counted over a subset of nodes; the planner's stages use this to refuse a change
// (a dropped, merged, moved or removed station) that would split the plan into more groups than it
// had. Thread-compatible: no shared state.
#pragma once

#include <cstdint>
#include <vector>

#include "vc/visibility/visibility.h"

namespace vc {

// The plan's scan graph over its final stations (PlanResult::stations indices).
struct ScanGraph {
  struct Edge {
    int i = 0;  // i < j
    int j = 0;
    double overlap = 0;  // in (0, 1]
  };
  double min_overlap = 0;  // the threshold the components and `connected` are judged at
  bool connected = true;   // one component (true for no station or one)
  // Groups of stations linked by edges of overlap >= min_overlap (and > 0); each ascending, the
  // groups ordered by their smallest station.
  std::vector<std::vector<int>> components;
  std::vector<Edge> edges;  // every pair with overlap > 0, ordered by (i, j)
};

}  // namespace vc

namespace vc::planner {

// The overlap of two sizes and their intersection: common / min(size_a, size_b), 0 when either is 0.
double Overlap(uint64_t common, uint64_t size_a, uint64_t size_b);
// The overlap of two visibility sets (equal sizes).
double Overlap(const VoxelSet& a, const VoxelSet& b);
// Whether `overlap` makes an edge at `min_overlap`.
inline bool IsEdge(double overlap, double min_overlap) { return overlap > 0 && overlap >= min_overlap; }

// Every pairwise overlap among a few sets (stations), computed once: n (n - 1) / 2 intersections,
// a row at a time on `threads` workers (0: all cores), the same values whatever their number. (A
// campus plan's 905 stations are 409,060 intersections: 8.5 s on one thread.)
class OverlapMatrix {
 public:
  OverlapMatrix() = default;
  explicit OverlapMatrix(const std::vector<VoxelSet>& sets, int threads = 1);
  [[nodiscard]] int size() const { return n_; }
  [[nodiscard]] double at(int i, int j) const { return i == j ? 1.0 : values_[static_cast<size_t>(i) * n_ + j]; }
  // Replaces node i's set by `set` (a station moved): its row and column are recomputed.
  void Replace(int i, const VoxelSet& set, const std::vector<VoxelSet>& sets);

 private:
  int n_ = 0;
  std::vector<double> values_;  // n x n, symmetric
};

// The components of `nodes` (indices into m) under min_overlap: each ascending, ordered by their
// smallest node.
std::vector<std::vector<int>> Components(const OverlapMatrix& m, const std::vector<int>& nodes, double min_overlap);
// The number of components of `nodes` (0 for none).
int CountComponents(const OverlapMatrix& m, const std::vector<int>& nodes, double min_overlap);

// The scan graph of all m.size() nodes.
ScanGraph BuildScanGraph(const OverlapMatrix& m, double min_overlap);

}  // namespace vc::planner
