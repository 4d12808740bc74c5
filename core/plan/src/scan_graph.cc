#include "vc/plan/scan_graph.h"

#include <algorithm>
#include <numeric>

#include "vc/base/parallel.h"

namespace vc::planner {

double Overlap(uint64_t common, uint64_t size_a, uint64_t size_b) {
  const uint64_t smaller = std::min(size_a, size_b);
  return smaller == 0 ? 0.0 : static_cast<double>(common) / static_cast<double>(smaller);
}

double Overlap(const VoxelSet& a, const VoxelSet& b) { return Overlap(a.CountAnd(b), a.count(), b.count()); }

OverlapMatrix::OverlapMatrix(const std::vector<VoxelSet>& sets, int threads)
    : n_(static_cast<int>(sets.size())), values_(sets.size() * sets.size(), 0.0) {
  std::vector<uint64_t> sizes(sets.size());
  for (size_t i = 0; i < sets.size(); ++i) sizes[i] = sets[i].count();
  // Row i's task fills (i, j) for j > i, its own part of the upper triangle; the lower one is
  // mirrored after.
  const Status st = ParallelChunks(sets.size(), 1, threads, {}, [&](uint64_t row, uint64_t, uint64_t) {
    const int i = static_cast<int>(row);
    for (int j = i + 1; j < n_; ++j) {
      values_[static_cast<size_t>(i) * n_ + j] = Overlap(sets[i].CountAnd(sets[j]), sizes[i], sizes[j]);
    }
  });
  (void)st;  // no token: cannot fail
  for (int i = 0; i < n_; ++i) {
    for (int j = i + 1; j < n_; ++j)
      values_[static_cast<size_t>(j) * n_ + i] = values_[static_cast<size_t>(i) * n_ + j];
  }
}

void OverlapMatrix::Replace(int i, const VoxelSet& set, const std::vector<VoxelSet>& sets) {
  const uint64_t size = set.count();
  for (int j = 0; j < n_; ++j) {
    if (j == i) continue;
    const double o = Overlap(set.CountAnd(sets[j]), size, sets[j].count());
    values_[static_cast<size_t>(i) * n_ + j] = o;
    values_[static_cast<size_t>(j) * n_ + i] = o;
  }
}

namespace {

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// Union-find roots of `nodes` (positions into nodes) under min_overlap.
std::vector<int> Roots(const OverlapMatrix& m, const std::vector<int>& nodes, double min_overlap) {
  std::vector<int> parent(nodes.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t a = 0; a < nodes.size(); ++a) {
    for (size_t b = a + 1; b < nodes.size(); ++b) {
      if (!IsEdge(m.at(nodes[a], nodes[b]), min_overlap)) continue;
      const int ra = Find(parent, static_cast<int>(a));
      const int rb = Find(parent, static_cast<int>(b));
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  for (size_t a = 0; a < nodes.size(); ++a) parent[a] = Find(parent, static_cast<int>(a));
  return parent;
}

}  // namespace

std::vector<std::vector<int>> Components(const OverlapMatrix& m, const std::vector<int>& nodes, double min_overlap) {
  const std::vector<int> roots = Roots(m, nodes, min_overlap);
  std::vector<std::vector<int>> groups(nodes.size());
  for (size_t a = 0; a < nodes.size(); ++a) groups[roots[a]].push_back(nodes[a]);
  std::vector<std::vector<int>> out;
  for (std::vector<int>& g : groups) {
    if (g.empty()) continue;
    std::sort(g.begin(), g.end());
    out.push_back(std::move(g));
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.front() < b.front(); });
  return out;
}

int CountComponents(const OverlapMatrix& m, const std::vector<int>& nodes, double min_overlap) {
  const std::vector<int> roots = Roots(m, nodes, min_overlap);
  int count = 0;
  for (size_t a = 0; a < roots.size(); ++a) count += roots[a] == static_cast<int>(a);
  return count;
}

ScanGraph BuildScanGraph(const OverlapMatrix& m, double min_overlap) {
  ScanGraph graph;
  graph.min_overlap = min_overlap;
  std::vector<int> all(m.size());
  std::iota(all.begin(), all.end(), 0);
  graph.components = Components(m, all, min_overlap);
  graph.connected = graph.components.size() <= 1;
  for (int i = 0; i < m.size(); ++i) {
    for (int j = i + 1; j < m.size(); ++j) {
      if (m.at(i, j) > 0) graph.edges.push_back({i, j, m.at(i, j)});
    }
  }
  return graph;
}

}  // namespace vc::planner
