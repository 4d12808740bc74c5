#include "vc/plan/route.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <tuple>
#include <utility>

#include "standing_surfaces.h"
#include "vc/base/parallel.h"

namespace vc::planner {

namespace {

using internal::ColumnSurfaces;
using internal::FreeVoxelsNeeded;
using internal::Surface;

constexpr int kDirs = 8;
// The 8 neighbour directions: 4 straight, then 4 diagonal. kSide* name a diagonal's straight sides.
constexpr int kDx[kDirs] = {1, -1, 0, 0, 1, -1, 1, -1};
constexpr int kDy[kDirs] = {0, 0, 1, -1, 1, 1, -1, -1};
constexpr int kSideX[kDirs] = {-1, -1, -1, -1, 0, 1, 0, 1};
constexpr int kSideY[kDirs] = {-1, -1, -1, -1, 2, 2, 3, 3};
// Bytes a walk node costs: surface, cell, 8 neighbours and their link kinds, region, Dijkstra
// stamp/distance/parent, heap and the transient surface lists while building.
constexpr uint64_t kBytesPerNode = 92;
// A link's kind: to a straight or a diagonal neighbour, or straight over a gap of 1 to
// kMaxGapVoxels cells with no walk surface near its height (kOverGap + the gap's cells - 1).
constexpr int kMaxGapVoxels = 2;
constexpr uint8_t kStraight = 0, kDiagonal = 1, kOverGap = 2;
constexpr int kLinkKinds = kOverGap + kMaxGapVoxels;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Progress reports per long loop (JobContext: at most a few hundred per stage).
constexpr int kProgressSteps = 50;
// Above kExhaustiveOrderMax stations (file comment, "Order"): each station's exact distances reach
// its kNearStations nearest stations; kLandmarks landmarks per component estimate the rest.
constexpr int kNearStations = 16;
constexpr int kLandmarks = 16;

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string Fmt(const char* format, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, format, a, b, c);
  return buf;
}

// The walk graph of the file comment, nodes sorted by (cell, z).
struct WalkGraph {
  const OccupancyGrid* grid = nullptr;
  double r = 0;
  int k = 1;  // voxel columns per cell edge
  int nx = 0, ny = 0;
  int step = 0;                       // max_step_m in voxels
  std::vector<uint32_t> cell_begin;   // per cell, its first node; nx * ny + 1 entries
  std::vector<int32_t> z;             // per node: the surface's top voxel index
  std::vector<uint32_t> cell;         // per node: its cell (y * nx + x)
  std::vector<int32_t> nbr;           // per node, kDirs neighbours or -1
  std::vector<uint8_t> unknown;       // per node: bridged under space the scan did not observe
  std::vector<uint8_t> bridged;       // per node: over unseen floor, its height a window's lowest floor
  std::vector<int32_t> region;        // per node: its connected region (nodes linked by walks)
  std::vector<uint32_t> region_size;  // per region: its nodes
  float unknown_factor = 1;           // cost factor of a link touching such a node
  uint64_t bridged_count = 0;
  double bridging_s = 0;            // seconds spent on the window minimum and the bridged candidates
  std::vector<uint8_t> link;        // per node, kDirs link kinds (kStraight, kDiagonal, kOverGap + cells)
  int headroom = 0;                 // free voxels above a walk surface
  float cost[kLinkKinds][64] = {};  // link cost (m) by [link kind][|dz| voxels]

  int CellX(uint32_t c) const { return int(c % uint32_t(nx)); }
  int CellY(uint32_t c) const { return int(c / uint32_t(nx)); }
  int ColumnX(int i) const { return grid->min_index().x + std::min(i * k + k / 2, grid->dims().x() - 1); }
  int ColumnY(int j) const { return grid->min_index().y + std::min(j * k + k / 2, grid->dims().y() - 1); }
  WorldPoint Point(int n) const {
    return {(ColumnX(CellX(cell[n])) + 0.5) * r, (ColumnY(CellY(cell[n])) + 0.5) * r, (z[n] + 1) * r};
  }
  double TopZ(int n) const { return (z[n] + 1) * r; }
  int size() const { return int(z.size()); }
  uint64_t cells() const { return uint64_t(nx) * uint64_t(ny); }
};

// The height difference (voxels) a link between nodes a and b may span: max_step_m, and a voxel
// more when either is bridged, since a bridged floor lies at the lowest seen floor near it, up to
// a voxel below the floor around it where that is uneven or noisy.
int LinkStep(const WalkGraph& g, int a, int b) { return g.step + (g.bridged[a] || g.bridged[b]); }

// The node of cell c that node n links to: the one closest in height to n's (the higher on a tie)
// within LinkStep, or -1.
int NodeNear(const WalkGraph& g, uint32_t c, int n) {
  int best = -1;
  for (uint32_t m = g.cell_begin[c]; m < g.cell_begin[c + 1]; ++m) {
    const int d = std::abs(g.z[m] - g.z[n]);
    if (d > LinkStep(g, n, int(m))) continue;
    if (best < 0 || d < std::abs(g.z[best] - g.z[n]) || (d == std::abs(g.z[best] - g.z[n]) && g.z[m] > g.z[best])) {
      best = int(m);
    }
  }
  return best;
}

Status MemoryCheck(uint64_t cells, uint64_t nodes, const RouteOptions& o, double r, int k) {
  const uint64_t bytes = (cells + 1) * 4 + nodes * kBytesPerNode;
  if (bytes <= o.memory_budget_bytes) return Status::Ok();
  return ResourceExhaustedError("the walk graph (" + std::to_string(cells) + " cells of " + Fmt("%.3g", k * r) +
                                " m, at least " + std::to_string(nodes) + " standing surfaces) needs " +
                                std::to_string(bytes >> 20) + " MiB, over the memory budget of " +
                                std::to_string(o.memory_budget_bytes >> 20) +
                                " MiB; use a coarser walk cell (cell_m) or a larger budget");
}

// Per cell, the standing surfaces of its centre column with headroom free voxels above them,
// ascending z: node candidates in CSR form (cell c's are z[begin[c]] .. z[begin[c + 1] - 1]).
struct CellSurfaces {
  std::vector<uint32_t> begin;  // nx * ny + 1 entries
  std::vector<int32_t> z;
};

Result<CellSurfaces> StandingSurfaces(const WalkGraph& g, int headroom, const RouteOptions& o, const JobContext& ctx) {
  const uint64_t cells = g.cells();
  CellSurfaces out;
  out.begin.assign(cells + 1, 0);
  std::vector<Surface> scratch;
  for (int j = 0; j < g.ny; ++j) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
    VC_RETURN_IF_ERROR(MemoryCheck(cells, out.z.size(), o, g.r, g.k));
    for (int i = 0; i < g.nx; ++i) {
      const uint32_t c = uint32_t(j) * uint32_t(g.nx) + uint32_t(i);
      out.begin[c] = uint32_t(out.z.size());
      ColumnSurfaces(*g.grid, g.ColumnX(i), g.ColumnY(j), headroom, scratch);
      for (auto s = scratch.rbegin(); s != scratch.rend(); ++s) out.z.push_back(s->z);
    }
  }
  out.begin[cells] = uint32_t(out.z.size());
  return out;
}

// A walk node candidate: a real standing surface or a bridged one over unseen floor.
struct Candidate {
  uint32_t cell;
  int32_t z;
  uint8_t lines;  // bridged: the orientations (x, y) of the gaps it lies in, a bit each; 0 = real
  bool operator<(const Candidate& o) const { return std::tie(cell, z, lines) < std::tie(o.cell, o.z, o.lines); }
};

// A cell's lowest real surface when it has none.
constexpr int kNoSurface = std::numeric_limits<int>::max();

// Per cell, the minimum of `lowest` over the square window of `radius` cells around it (two passes
// of a 1D minimum: rows, then columns).
Result<std::vector<int32_t>> WindowMinimum(const WalkGraph& g, const std::vector<int32_t>& lowest, int radius,
                                           const JobContext& ctx) {
  const uint64_t cells = g.cells();
  std::vector<int32_t> rows(cells, kNoSurface);
  for (int j = 0; j < g.ny; ++j) {
    for (int i = 0; i < g.nx; ++i) {
      int32_t m = kNoSurface;
      for (int t = std::max(0, i - radius); t <= std::min(g.nx - 1, i + radius); ++t) {
        m = std::min(m, lowest[uint64_t(j) * g.nx + t]);
      }
      rows[uint64_t(j) * g.nx + i] = m;
    }
  }
  std::vector<int32_t> window_low(cells, kNoSurface);
  for (int j = 0; j < g.ny; ++j) {
    if ((j & 15) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
    for (int i = 0; i < g.nx; ++i) {
      int32_t m = kNoSurface;
      for (int t = std::max(0, j - radius); t <= std::min(g.ny - 1, j + radius); ++t) {
        m = std::min(m, rows[uint64_t(t) * g.nx + i]);
      }
      window_low[uint64_t(j) * g.nx + i] = m;
    }
  }
  return window_low;
}

// The real surfaces as candidates, and bridged ones over gaps up to max_gap_m between two surfaces
// within max_step_m of each other (file comment, "Holes"), cell by cell.
Result<std::vector<Candidate>> ListCandidates(const WalkGraph& g, const CellSurfaces& surfaces, int headroom,
                                              const RouteOptions& o, const JobContext& ctx) {
  const uint64_t cells = g.cells();
  std::vector<Candidate> nodes;
  nodes.reserve(surfaces.z.size());
  const int max_gap_cells = static_cast<int>(std::floor(o.max_gap_m / (g.k * g.r) + 1e-9));
  // Per cell, the lowest real surface, and its minimum over the square window of max_gap_m around it.
  std::vector<int32_t> lowest(cells, kNoSurface), window_low;
  for (uint64_t c = 0; c < cells; ++c) {
    if (surfaces.begin[c] < surfaces.begin[c + 1]) lowest[c] = surfaces.z[surfaces.begin[c]];
  }
  if (max_gap_cells > 0) {
    VC_ASSIGN_OR_RETURN(window_low, WindowMinimum(g, lowest, max_gap_cells, ctx));
  }
  for (int j = 0; j < g.ny; ++j) {
    if ((j & 15) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
    for (int i = 0; i < g.nx; ++i) {
      const uint32_t c = uint32_t(j) * uint32_t(g.nx) + uint32_t(i);
      for (uint32_t a = surfaces.begin[c]; a < surfaces.begin[c + 1]; ++a) nodes.push_back({c, surfaces.z[a], 0});
      if (max_gap_cells == 0 || window_low[c] == kNoSurface) continue;
      // Unseen floor at the lowest real surface within max_gap_m: only over nothing seen (never in
      // the air beside a stair or above a floor that was seen), and with nothing at all from that
      // height up to the headroom.
      const int zb = window_low[c];
      if (lowest[c] != kNoSurface && lowest[c] <= zb + g.step) continue;
      const int x = g.ColumnX(i), y = g.ColumnY(j);
      if (g.grid->AnyOccupied({x, y, zb}, {x, y, zb + headroom})) continue;
      nodes.push_back({c, zb, 1});
    }
    VC_RETURN_IF_ERROR(MemoryCheck(cells, nodes.size(), o, g.r, g.k));
  }
  return nodes;
}

// Sorts the candidates (a real one precedes a bridged one at the same place). Bridged candidates of
// a cell within max_step_m of each other are one, at the lowest; it is kept if no real surface is
// within max_step_m of it.
void MergeBridgedCandidates(std::vector<Candidate>& nodes, int step) {
  std::sort(nodes.begin(), nodes.end());
  size_t out = 0;
  for (size_t a = 0; a < nodes.size();) {
    if (nodes[a].lines == 0) {
      nodes[out++] = nodes[a++];
      continue;
    }
    size_t b = a;
    uint8_t lines = 0;
    for (; b < nodes.size() && nodes[b].cell == nodes[a].cell && nodes[b].lines != 0 && nodes[b].z - nodes[a].z <= step;
         ++b) {
      lines |= nodes[b].lines;
    }
    bool near_real = false;
    for (size_t e = out; e-- > 0 && nodes[e].cell == nodes[a].cell;)
      near_real |= std::abs(nodes[e].z - nodes[a].z) <= step;
    for (size_t e = b; e < nodes.size() && nodes[e].cell == nodes[a].cell; ++e) {
      near_real |= nodes[e].lines == 0 && std::abs(nodes[e].z - nodes[a].z) <= step;
    }
    if (!near_real) nodes[out++] = {nodes[a].cell, nodes[a].z, lines};
    a = b;
  }
  nodes.resize(out);
}

// The walking cylinder of radius clearance_voxels around a column's centre, row by row: entry
// dy + rows is the half width (columns each side) of row dy, for dy in [-rows, rows].
std::vector<int> CylinderHalfWidths(double clearance_voxels) {
  int rows = 0;
  while (rows + 0.5 < clearance_voxels) ++rows;
  std::vector<int> half_width(2 * rows + 1);
  for (int dy = -rows; dy <= rows; ++dy) {
    // Columns whose square footprint comes closer than the clearance to the centre column's centre.
    const double ey = std::max(std::abs(dy) - 0.5, 0.0);
    int w = 0;
    while (std::pow(w + 0.5, 2) + ey * ey < clearance_voxels * clearance_voxels) ++w;
    half_width[dy + rows] = w;
  }
  return half_width;
}

// The candidates where a person fits become g's nodes: at most max_blocked_fraction of the columns
// of the cylinder of radius clearance_m hold an occupied voxel between max_step_m and headroom_m
// above the surface. Then g's cell index (cell_begin).
Status KeepNodesWhereAPersonFits(WalkGraph& g, const std::vector<Candidate>& nodes, int headroom, const RouteOptions& o,
                                 const JobContext& ctx) {
  const double r = g.r;
  const std::vector<int> half_width = CylinderHalfWidths(o.clearance_m / r);
  const int rows = int(half_width.size() / 2);
  for (size_t n = 0; n < nodes.size(); ++n) {
    if ((n & 0xffff) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
    const Candidate& cand = nodes[n];
    const int x = g.ColumnX(g.CellX(cand.cell)), y = g.ColumnY(g.CellY(cand.cell));
    const int lo = cand.z + 1 + g.step, hi = cand.z + headroom;
    int blocked = 0, columns = 0;
    for (int dy = -rows; dy <= rows && lo <= hi; ++dy) {
      const int w = half_width[dy + rows];
      for (int dx = -w; dx <= w; ++dx) {
        ++columns;
        blocked += g.grid->AnyOccupied({x + dx, y + dy, lo}, {x + dx, y + dy, hi});
      }
    }
    if (blocked > o.max_blocked_fraction * columns) continue;
    // With known_free: a node whose body space (0.5, 1.2 or 1.6 m above its surface) the scan
    // never observed as free, perhaps beside or inside a wall it never saw, is walked at a cost.
    bool unknown = false;
    if (o.known_free) {
      const WorldPoint floor_m((x + 0.5) * r, (y + 0.5) * r, (cand.z + 1) * r);
      unknown = true;
      for (double h : {0.5, 1.2, 1.6}) unknown = unknown && !o.known_free(floor_m + WorldPoint(0, 0, h));
    }
    g.z.push_back(cand.z);
    g.cell.push_back(cand.cell);
    g.unknown.push_back(unknown);
    g.bridged.push_back(cand.lines != 0);
    g.bridged_count += cand.lines != 0;
  }
  const uint64_t cells = g.cells();
  g.cell_begin.assign(cells + 1, 0);
  for (uint32_t c : g.cell) ++g.cell_begin[c + 1];
  for (uint64_t c = 0; c < cells; ++c) g.cell_begin[c + 1] += g.cell_begin[c];
  return Status::Ok();
}

// Whether no node of cell c lies within LinkStep of node a or of node b.
bool NoSurfaceNear(const WalkGraph& g, uint32_t c, int a, int b) {
  for (uint32_t m = g.cell_begin[c]; m < g.cell_begin[c + 1]; ++m) {
    if (std::abs(g.z[m] - g.z[a]) <= LinkStep(g, a, int(m)) || std::abs(g.z[m] - g.z[b]) <= LinkStep(g, b, int(m))) {
      return false;
    }
  }
  return true;
}

// The node n links to over a gap in straight direction d (file comment, "Gaps"), and the gap's
// cells; {-1, 0} if none.
std::pair<int, int> LinkOverGap(const WalkGraph& g, int n, int d) {
  const int i = g.CellX(g.cell[n]), j = g.CellY(g.cell[n]);
  const int max_gap_cells = kMaxGapVoxels / g.k;
  for (int span = 2; span <= max_gap_cells + 1; ++span) {
    const int ti = i + kDx[d] * span, tj = j + kDy[d] * span;
    if (ti < 0 || tj < 0 || ti >= g.nx || tj >= g.ny) return {-1, 0};
    const int m = NodeNear(g, uint32_t(tj) * uint32_t(g.nx) + uint32_t(ti), n);
    if (m < 0) continue;
    if (NodeNear(g, g.cell[n], m) != n) return {-1, 0};
    // Every cell between: no walk surface near either end's height, its column free from just
    // above the lower end's surface up to the higher end's headroom (a gap, not a wall or a desk)
    // and seen below that (a dip; unseen floor is max_gap_m's).
    const int lo = std::min(g.z[n], g.z[m]) + 1, hi = std::max(g.z[n], g.z[m]) + g.headroom;
    const int bottom = g.grid->min_index().z;
    for (int t = 1; t < span; ++t) {
      const int ci = i + kDx[d] * t, cj = j + kDy[d] * t, x = g.ColumnX(ci), y = g.ColumnY(cj);
      if (!NoSurfaceNear(g, uint32_t(cj) * uint32_t(g.nx) + uint32_t(ci), n, m)) return {-1, 0};
      if (g.grid->AnyOccupied({x, y, lo}, {x, y, hi}) || lo <= bottom ||
          !g.grid->AnyOccupied({x, y, bottom}, {x, y, lo - 1})) {
        return {-1, 0};
      }
    }
    return {m, span - 1};
  }
  return {-1, 0};
}

// g's link costs and links to the 8 neighbours, mutual only, diagonals only with both sides
// walkable, and straight ones over gaps of up to kMaxGapVoxels where a neighbour has no surface.
Status LinkNeighbours(WalkGraph& g, const JobContext& ctx) {
  const double r = g.r, cell_m = g.k * r;
  for (int dz = 0; dz < 64; ++dz) {
    g.cost[kStraight][dz] = float(std::hypot(cell_m, dz * r));
    g.cost[kDiagonal][dz] = float(std::sqrt(2 * cell_m * cell_m + dz * r * dz * r));
    for (int gap = 1; gap <= kMaxGapVoxels; ++gap)
      g.cost[kOverGap + gap - 1][dz] = float(std::hypot((gap + 1) * cell_m, dz * r));
  }
  g.nbr.assign(size_t(g.size()) * kDirs, -1);
  g.link.assign(size_t(g.size()) * kDirs, kStraight);
  for (int n = 0; n < g.size(); ++n) {
    if ((n & 0xffff) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
    const int i = g.CellX(g.cell[n]), j = g.CellY(g.cell[n]);
    int found[kDirs];
    for (int d = 0; d < kDirs; ++d) {
      found[d] = -1;
      const int ti = i + kDx[d], tj = j + kDy[d];
      if (ti < 0 || tj < 0 || ti >= g.nx || tj >= g.ny) continue;
      const uint32_t c = uint32_t(tj) * uint32_t(g.nx) + uint32_t(ti);
      const int m = NodeNear(g, c, n);
      if (m >= 0 && NodeNear(g, g.cell[n], m) == n) found[d] = m;
      g.link[size_t(n) * kDirs + d] = d >= 4 ? kDiagonal : kStraight;
      if (m < 0 && d < 4) {
        const auto [over, gap] = LinkOverGap(g, n, d);
        if (over >= 0) g.link[size_t(n) * kDirs + d] = uint8_t(kOverGap + gap - 1);
        g.nbr[size_t(n) * kDirs + d] = over;
      }
    }
    for (int d = 0; d < kDirs; ++d) {
      if (found[d] < 0 || (d >= 4 && (found[kSideX[d]] < 0 || found[kSideY[d]] < 0))) continue;
      g.nbr[size_t(n) * kDirs + d] = found[d];
    }
  }
  return Status::Ok();
}

// g's regions: connected components of the links (breadth first).
void LabelRegions(WalkGraph& g) {
  g.region.assign(size_t(g.size()), -1);
  g.region_size.clear();
  std::vector<int> queue;
  for (int s = 0; s < g.size(); ++s) {
    if (g.region[s] >= 0) continue;
    const int32_t label = int32_t(g.region_size.size());
    g.region[s] = label;
    queue.assign(1, s);
    for (size_t q = 0; q < queue.size(); ++q) {
      for (int d = 0; d < kDirs; ++d) {
        const int m = g.nbr[size_t(queue[q]) * kDirs + d];
        if (m >= 0 && g.region[m] < 0) {
          g.region[m] = label;
          queue.push_back(m);
        }
      }
    }
    g.region_size.push_back(uint32_t(queue.size()));
  }
}

// Per node, a label shared by every node linked to it in either direction (weakly connected
// components, by union-find): no walk leads from one label to another. (g.region follows links one
// way, and a diagonal link may be one-way where its side cells hold other surfaces.)
std::vector<int32_t> WeakComponents(const WalkGraph& g) {
  std::vector<int32_t> root(size_t(g.size()));
  std::iota(root.begin(), root.end(), 0);
  auto find = [&root](int32_t a) {
    while (root[a] != a) a = root[a] = root[root[a]];
    return a;
  };
  for (int n = 0; n < g.size(); ++n) {
    for (int d = 0; d < kDirs; ++d) {
      const int m = g.nbr[size_t(n) * kDirs + d];
      if (m < 0) continue;
      const int32_t a = find(n), b = find(m);
      if (a != b) root[std::max(a, b)] = std::min(a, b);
    }
  }
  for (int n = 0; n < g.size(); ++n) root[n] = find(n);
  return root;
}

// max_step_m in whole voxels of edge r_m (file comment, "Walk graph"): at least one when max_step_m
// > 0, since with voxels coarser than the step a walkable slope still rises a voxel at a time.
int StepVoxels(double max_step_m, double r_m) {
  const int step = static_cast<int>(std::floor(max_step_m / r_m + 1e-9));
  return max_step_m > 0 ? std::max(1, step) : 0;
}

// The walk graph of `grid` with cells of k x k columns (file comment).
Result<WalkGraph> BuildWalkGraph(const OccupancyGrid& grid, const RouteOptions& o, int k, const JobContext& ctx) {
  WalkGraph g;
  g.grid = &grid;
  g.r = grid.resolution_m();
  g.k = k;
  g.nx = (grid.dims().x() + k - 1) / k;
  g.ny = (grid.dims().y() + k - 1) / k;
  g.step = std::min(62, StepVoxels(o.max_step_m, g.r));
  g.unknown_factor = static_cast<float>(o.unknown_cost_factor);
  VC_RETURN_IF_ERROR(MemoryCheck(g.cells(), 0, o, g.r, k));
  const int headroom = FreeVoxelsNeeded(g.r, o.headroom_m, 0);
  g.headroom = headroom;
  std::vector<Candidate> nodes;
  {
    VC_ASSIGN_OR_RETURN(const CellSurfaces surfaces, StandingSurfaces(g, headroom, o, ctx));
    const Clock::time_point t = Clock::now();
    VC_ASSIGN_OR_RETURN(nodes, ListCandidates(g, surfaces, headroom, o, ctx));
    g.bridging_s = SecondsSince(t);
  }
  MergeBridgedCandidates(nodes, g.step);
  VC_RETURN_IF_ERROR(KeepNodesWhereAPersonFits(g, nodes, headroom, o, ctx));
  nodes = {};
  VC_RETURN_IF_ERROR(LinkNeighbours(g, ctx));
  LabelRegions(g);
  return g;
}

// Dijkstra over a WalkGraph; state kept between runs and reset lazily by a run stamp.
class ShortestPaths {
 public:
  explicit ShortestPaths(const WalkGraph& g) : g_(g), stamp_(g.size(), 0), dist_(g.size()), parent_(g.size()) {}

  // Distances from `source`, until every node of `targets` (-1 entries ignored) is settled, or
  // `stop_after` of them when positive, or none is left to reach; over all reachable nodes if
  // `targets` is empty. settled() lists the targets settled, nearest first.
  Status Run(int source, const std::vector<int>& targets, const JobContext& ctx, int stop_after = 0) {
    ++run_;
    heap_.clear();
    settled_.clear();
    Set(source, 0, -1);
    heap_.push_back({0.0f, source});
    std::vector<int> sorted_targets(targets);
    std::sort(sorted_targets.begin(), sorted_targets.end());
    sorted_targets.erase(std::unique(sorted_targets.begin(), sorted_targets.end()), sorted_targets.end());
    int remaining = int(std::count_if(sorted_targets.begin(), sorted_targets.end(), [](int t) { return t >= 0; }));
    if (stop_after > 0) remaining = std::min(remaining, stop_after);
    uint64_t pops = 0;
    while (!heap_.empty() && (targets.empty() || remaining > 0)) {
      std::pop_heap(heap_.begin(), heap_.end(), std::greater<>());
      const auto [d, n] = heap_.back();
      heap_.pop_back();
      if (d > dist_[n]) continue;
      if ((++pops & 0xffff) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
      if (std::binary_search(sorted_targets.begin(), sorted_targets.end(), n)) {
        --remaining;
        settled_.push_back(n);
      }
      const int32_t* nb = &g_.nbr[size_t(n) * kDirs];
      for (int k = 0; k < kDirs; ++k) {
        const int m = nb[k];
        if (m < 0) continue;
        float step = g_.cost[g_.link[size_t(n) * kDirs + k]][std::abs(g_.z[m] - g_.z[n])];
        if (g_.unknown[m] || g_.unknown[n]) step *= g_.unknown_factor;
        const float nd = d + step;
        if (nd < Dist(m)) {
          Set(m, nd, n);
          heap_.push_back({nd, m});
          std::push_heap(heap_.begin(), heap_.end(), std::greater<>());
        }
      }
    }
    return Status::Ok();
  }
  float Dist(int n) const { return stamp_[n] == run_ ? dist_[n] : kInf; }
  const std::vector<int>& settled() const { return settled_; }
  // Nodes from the last run's source to `target` (reached), in walking order.
  std::vector<int> PathTo(int target) const {
    std::vector<int> path;
    for (int n = target; n >= 0; n = parent_[n]) path.push_back(n);
    std::reverse(path.begin(), path.end());
    return path;
  }

 private:
  void Set(int n, float d, int parent) {
    stamp_[n] = run_;
    dist_[n] = d;
    parent_[n] = parent;
  }
  const WalkGraph& g_;
  uint32_t run_ = 0;
  std::vector<uint32_t> stamp_;
  std::vector<float> dist_;
  std::vector<int32_t> parent_;
  std::vector<std::pair<float, int>> heap_;
  std::vector<int> settled_;
};

// ShortestPaths states for parallel workers, each taken by one worker at a time (a state is the
// size of the graph: allocating one per station would cost more than a short run).
class ShortestPathsPool {
 public:
  explicit ShortestPathsPool(const WalkGraph& g) : g_(g) {}
  std::unique_ptr<ShortestPaths> Take() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty()) return std::make_unique<ShortestPaths>(g_);
    std::unique_ptr<ShortestPaths> sp = std::move(free_.back());
    free_.pop_back();
    return sp;
  }
  void Give(std::unique_ptr<ShortestPaths> sp) {
    const std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(sp));
  }

 private:
  const WalkGraph& g_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<ShortestPaths>> free_;
};

// Cell (clamped) of world x or y.
int CellOf(const WalkGraph& g, double v_m, int min_index, int cells) {
  const int col = static_cast<int>(std::floor(v_m * g.grid->inv_resolution())) - min_index;
  const int c = col >= 0 ? col / g.k : -((-col + g.k - 1) / g.k);
  return std::clamp(c, 0, cells - 1);
}

// Calls fn(node) for each node in cells within radius_m of (x, y) (a square window).
template <typename Fn>
void ForNodesNear(const WalkGraph& g, double x_m, double y_m, double radius_m, Fn&& fn) {
  const int w = static_cast<int>(std::ceil(radius_m / (g.k * g.r))) + 1;
  const int ci = CellOf(g, x_m, g.grid->min_index().x, g.nx), cj = CellOf(g, y_m, g.grid->min_index().y, g.ny);
  for (int j = std::max(0, cj - w); j <= std::min(g.ny - 1, cj + w); ++j) {
    for (int i = std::max(0, ci - w); i <= std::min(g.nx - 1, ci + w); ++i) {
      const uint32_t c = uint32_t(j) * uint32_t(g.nx) + uint32_t(i);
      for (uint32_t n = g.cell_begin[c]; n < g.cell_begin[c + 1]; ++n) fn(int(n));
    }
  }
}

double Horizontal2(const WorldPoint& a, const WorldPoint& b) { return (a - b).head<2>().squaredNorm(); }

// The node a point with floor top `floor_m` snaps to (file comment), or -1: within radius_m
// horizontally and tolerance_m in height, the nearest horizontally (then in 3D, then the lowest
// number); with largest_region, first the one in the largest region.
int SnapToFloor(const WalkGraph& g, const WorldPoint& floor_point, double tolerance_m, double radius_m,
                bool largest_region = false) {
  int best = -1;
  uint32_t best_size = 0;
  double best_h = 0, best_d = 0;
  ForNodesNear(g, floor_point.x(), floor_point.y(), radius_m, [&](int n) {
    const WorldPoint p = g.Point(n);
    if (std::abs(p.z() - floor_point.z()) > tolerance_m + (g.bridged[n] ? g.r : 0) + 1e-9) return;
    const double h = Horizontal2(p, floor_point), d = (p - floor_point).squaredNorm();
    if (h > radius_m * radius_m) return;
    const uint32_t size = largest_region ? g.region_size[g.region[n]] : 0;
    if (best < 0 || size > best_size ||
        (size == best_size && (h < best_h || (h == best_h && (d < best_d || (d == best_d && n < best)))))) {
      best = n;
      best_size = size;
      best_h = h;
      best_d = d;
    }
  });
  return best;
}

// Drops points equal to the previous one and points between two collinear segments of the same direction.
std::vector<WorldPoint> Simplify(const std::vector<WorldPoint>& in) {
  std::vector<WorldPoint> out;
  for (const WorldPoint& p : in) {
    if (!out.empty() && (p - out.back()).norm() < 1e-9) continue;
    if (out.size() >= 2) {
      const WorldPoint a = out.back() - out[out.size() - 2], b = p - out.back();
      if (a.cross(b).norm() <= 1e-9 * a.norm() * b.norm() && a.dot(b) > 0) out.pop_back();
    }
    out.push_back(p);
  }
  return out;
}

double PolylineLength(const std::vector<WorldPoint>& pts) {
  double len = 0;
  for (size_t i = 1; i < pts.size(); ++i) len += (pts[i] - pts[i - 1]).norm();
  return len;
}

// "station 3" / "stations 3, 7", numbered from `first` (RouteOptions::first_station_number).
std::string StationList(const std::vector<int>& stations, int first) {
  std::string s = stations.size() == 1 ? "station " : "stations ";
  for (size_t i = 0; i < stations.size(); ++i) s += (i ? ", " : "") + std::to_string(stations[i] + first);
  return s;
}

Status Validate(const std::vector<WorldPoint>& stations, const std::vector<double>& floor_z_m, const RouteOptions& o) {
  for (size_t i = 0; i < stations.size(); ++i) {
    if (!stations[i].allFinite()) return InvalidArgumentError("station " + std::to_string(i) + " is not finite");
  }
  if (!floor_z_m.empty() && floor_z_m.size() != stations.size()) {
    return InvalidArgumentError("floor_z_m has " + std::to_string(floor_z_m.size()) + " values for " +
                                std::to_string(stations.size()) + " stations; give one per station or none");
  }
  for (size_t i = 0; i < floor_z_m.size(); ++i) {
    if (std::isinf(floor_z_m[i]))
      return InvalidArgumentError("floor_z_m of station " + std::to_string(i) + " is infinite");
  }
  auto bad = [](double v, bool zero_ok) { return !std::isfinite(v) || v < 0 || (!zero_ok && v == 0); };
  if (bad(o.headroom_m, false)) return InvalidArgumentError("headroom_m must be positive and finite");
  if (bad(o.clearance_m, true)) return InvalidArgumentError("clearance_m must be non-negative and finite");
  if (bad(o.max_step_m, true)) return InvalidArgumentError("max_step_m must be non-negative and finite");
  if (bad(o.cell_m, true)) return InvalidArgumentError("cell_m must be non-negative and finite (0 = the resolution)");
  if (bad(o.max_gap_m, true)) return InvalidArgumentError("max_gap_m must be non-negative and finite");
  if (bad(o.snap_radius_m, false)) return InvalidArgumentError("snap_radius_m must be positive and finite");
  if (o.start && !o.start->allFinite()) return InvalidArgumentError("the start is not finite");
  return Status::Ok();
}

// The walk cell's edge in voxels that cell_m asks for (0: one voxel), or INVALID_ARGUMENT when it
// is coarser than twice the clearance (file comment).
Result<int> WalkCellVoxels(const RouteOptions& options, double r) {
  const int k_max = std::max(1, static_cast<int>(std::floor(2 * options.clearance_m / r + 1e-9)));
  const int k = options.cell_m == 0 ? 1 : std::max(1, static_cast<int>(std::lround(options.cell_m / r)));
  if (k > k_max) {
    return InvalidArgumentError("cell_m " + Fmt("%.3g", options.cell_m) + " m is coarser than twice the clearance (" +
                                Fmt("%.3g", k_max * r) + " m at most), so a thin wall could pass between two cells");
  }
  return k;
}

// PlanRoute over a built walk graph (file comment: "Stations", "Order"): snaps the stations and
// the start, measures the walking distances, splits the stations into parts and walks each part
// in order. One Plan per instance.
class RoutePlanner {
 public:
  RoutePlanner(const WalkGraph& g, const std::vector<WorldPoint>& stations, const RouteOptions& options,
               const JobContext& ctx)
      : g_(g),
        stations_(stations),
        options_(options),
        ctx_(ctx),
        n_(int(stations.size())),
        floor_point_(n_),
        node_(n_, -1),
        sp_(g),
        from_start_(n_, kNaN) {}

  // The route; `floor_z_m` as PlanRoute's (validated).
  Result<Route> Plan(const std::vector<double>& floor_z_m);

 private:
  // Each station's floor point and walk node (-1, with a warning, when it has none).
  void SnapStations(const std::vector<double>& floor_z_m);
  // The start's walk node and floor point when options.start is set (-1, with a warning: none).
  void SnapStart();
  // Walking distances between stations (file comment, "Order"), on options.threads workers: up to
  // kExhaustiveOrderMax stations all pairs exactly, else ExactNearDistances and LandmarkDistances.
  Status DistancesBetweenStations();
  // Per station, the distances to its kNearStations nearest stations (and any settled on the way).
  Status ExactNearDistances(const std::vector<int32_t>& component);
  // One shortest-path run, in parallel, from each station with a walk node to the stations t with
  // is_target(s, t) (stopping after stop_after of them when positive); record(s, run) writes what it
  // found into the pairs only station s writes. Progress is reported as `what`.
  Status FromEachStation(const char* what, int stop_after, const std::function<bool(int s, int t)>& is_target,
                         const std::function<void(int s, const ShortestPaths& run)>& record);
  // Per weak component, kLandmarks landmark stations' distances to all its stations, and the
  // estimate via the best landmark for every pair still without a distance.
  Status LandmarkDistances(const std::vector<int32_t>& component);
  // A progress report when `done` of the stations crosses one of kProgressSteps steps.
  void ReportDone(int done, const char* what) const;
  // Walking distances from the start to each station, when the start snapped to a node.
  Status DistancesFromStart();
  // Parts: stations linked by finite distances (connected components are transitive).
  void FindParts();
  // The order of the parts: the start's part first, then from the lowest floor up.
  void OrderParts();
  // Warnings about a start linked to no station and about each part after the first, one each.
  void WarnAboutUnlinkedParts();
  // Why `part` (its stations snapped) is apart: where its walkable floor comes nearest to the
  // others' and what lies between, or that none is near (another storey).
  std::string WhySplit(const std::vector<int>& part) const;
  // The open path problem of the stations of `part`, from the start when `from_the_start`.
  OpenPathProblem PartProblem(const std::vector<int>& part, bool from_the_start) const;
  // Orders the pi-th part in part order and appends its stations, legs and polylines to the route.
  Status WalkPart(size_t pi);

  // From station s's floor point to its walk node (m).
  double Connector(int s) const { return (g_.Point(node_[s]) - floor_point_[s]).norm(); }
  // The lowest floor (m) of the stations of `part`, infinity if none has a floor.
  double LowestFloor(const std::vector<int>& part) const;

  const WalkGraph& g_;
  const std::vector<WorldPoint>& stations_;
  const RouteOptions& options_;
  const JobContext& ctx_;
  const int n_;  // stations
  Route route_;
  std::vector<WorldPoint> floor_point_;
  std::vector<int> node_;
  int start_node_ = -1;
  WorldPoint start_point_;
  ShortestPaths sp_;
  std::vector<double> dist_;  // n_ x n_, NaN: not linked
  std::vector<double> from_start_;
  std::vector<int> part_of_;
  std::vector<std::vector<int>> parts_;
  int start_part_ = -1;
  std::vector<int> part_order_;
};

Result<Route> RoutePlanner::Plan(const std::vector<double>& floor_z_m) {
  route_.walk_cells = g_.cells();
  route_.walk_nodes = uint64_t(g_.size());
  route_.bridged_nodes = g_.bridged_count;
  route_.cell_m = g_.k * g_.r;
  // The distances, and a part's copy of them for its ordering (OpenPathProblem).
  const uint64_t distance_bytes = 2 * sizeof(double) * uint64_t(n_) * uint64_t(n_);
  if (distance_bytes > options_.memory_budget_bytes) {
    return ResourceExhaustedError("the walking distances between " + std::to_string(n_) + " stations need " +
                                  std::to_string(distance_bytes >> 20) + " MiB, over the memory budget of " +
                                  std::to_string(options_.memory_budget_bytes >> 20) +
                                  " MiB; plan fewer stations (a coarser grid_spacing_m) or give a larger budget");
  }
  dist_.assign(size_t(n_) * n_, kNaN);
  Clock::time_point t = Clock::now();
  SnapStations(floor_z_m);
  SnapStart();
  VC_RETURN_IF_ERROR(DistancesBetweenStations());
  VC_RETURN_IF_ERROR(DistancesFromStart());
  route_.seconds.distances_s = SecondsSince(t);
  t = Clock::now();
  FindParts();
  OrderParts();
  WarnAboutUnlinkedParts();
  route_.seconds.parts_s = SecondsSince(t);
  for (size_t pi = 0; pi < part_order_.size(); ++pi) VC_RETURN_IF_ERROR(WalkPart(pi));
  return std::move(route_);
}

void RoutePlanner::SnapStations(const std::vector<double>& floor_z_m) {
  const double tolerance_m = std::max(options_.max_step_m, 2 * g_.r);
  for (int s = 0; s < n_; ++s) {
    double f = floor_z_m.empty() ? kNaN : floor_z_m[s];
    if (std::isnan(f)) f = FloorBelow(*g_.grid, stations_[s]);
    floor_point_[s] = WorldPoint(stations_[s].x(), stations_[s].y(), f);
    if (std::isnan(f)) {
      route_.warnings.push_back("station " + std::to_string(s + options_.first_station_number) +
                                " has no floor below it: the route has a part of its own for it, walking to it is "
                                "not counted");
      continue;
    }
    // Within the tripod's footprint, the floor a crew walks in on rather than clutter beside it.
    node_[s] = SnapToFloor(g_, floor_point_[s], tolerance_m, std::max(options_.clearance_m, g_.k * g_.r), true);
    if (node_[s] < 0) node_[s] = SnapToFloor(g_, floor_point_[s], tolerance_m, options_.snap_radius_m);
    if (node_[s] < 0) {
      route_.warnings.push_back(
          "station " + std::to_string(s + options_.first_station_number) +
          Fmt(" has no walkable cell within %.2g m", options_.snap_radius_m) +
          Fmt(" of (%.2f, %.2f)", stations_[s].x(), stations_[s].y()) +
          Fmt(" on its floor (z = %.2f m): the route has a part of its own for it, walking to it is not counted", f));
    }
  }
}

void RoutePlanner::SnapStart() {
  if (!options_.start) return;
  const WorldPoint& st = *options_.start;
  double level = kNaN, nearest = kNaN;
  ForNodesNear(g_, st.x(), st.y(), options_.snap_radius_m, [&](int m) {
    const WorldPoint p = g_.Point(m);
    if (Horizontal2(p, st) > options_.snap_radius_m * options_.snap_radius_m) return;
    if (p.z() <= st.z() + options_.max_step_m + 1e-9 && !(p.z() <= level)) level = p.z();
    if (std::isnan(nearest) || std::abs(p.z() - st.z()) < std::abs(nearest - st.z())) nearest = p.z();
  });
  if (std::isnan(level)) level = nearest;
  if (!std::isnan(level)) {
    start_node_ = SnapToFloor(g_, WorldPoint(st.x(), st.y(), level), options_.max_step_m, options_.snap_radius_m);
    start_point_ = WorldPoint(st.x(), st.y(), level);
  } else {
    route_.warnings.push_back(Fmt("the start (%.2f, %.2f, %.2f) has no walkable cell within ", st.x(), st.y(), st.z()) +
                              Fmt("%.2g m: the walk from it is not counted", options_.snap_radius_m));
  }
}

Status RoutePlanner::DistancesBetweenStations() {
  const int n = n_;
  // Targets of a station: the others of its weak component, the only ones it may reach.
  std::vector<int32_t> component(n, -1);
  {
    const std::vector<int32_t> label = WeakComponents(g_);
    for (int s = 0; s < n; ++s) {
      if (node_[s] >= 0) component[s] = label[node_[s]];
    }
  }
  if (n > kExhaustiveOrderMax) {
    VC_RETURN_IF_ERROR(ExactNearDistances(component));
    return LandmarkDistances(component);
  }
  return FromEachStation(
      "walking distances between stations", 0, [&](int s, int t) { return t > s && component[t] == component[s]; },
      [&](int s, const ShortestPaths& run) {
        for (int t = s + 1; t < n; ++t) {
          if (component[t] != component[s] || run.Dist(node_[t]) == kInf) continue;
          const double d = Connector(s) + double(run.Dist(node_[t])) + Connector(t);
          dist_[size_t(s) * n + t] = dist_[size_t(t) * n + s] = d;  // each pair written by s only
        }
      });
}

Status RoutePlanner::FromEachStation(const char* what, int stop_after,
                                     const std::function<bool(int s, int t)>& is_target,
                                     const std::function<void(int s, const ShortestPaths& run)>& record) {
  const int n = n_;
  std::vector<Status> run_status(n, Status::Ok());
  std::atomic<int> done{0};
  ShortestPathsPool pool(g_);
  VC_RETURN_IF_ERROR(ParallelChunks(
      uint64_t(n), 1, options_.threads, ctx_,
      [&](uint64_t, uint64_t begin, uint64_t) {
        const int s = int(begin);
        if (node_[s] >= 0) {
          dist_[size_t(s) * n + s] = 0;
          std::vector<int> targets;
          for (int t = 0; t < n; ++t) {
            if (is_target(s, t)) targets.push_back(node_[t]);
          }
          if (!targets.empty()) {
            std::unique_ptr<ShortestPaths> own = pool.Take();
            run_status[s] = own->Run(node_[s], targets, ctx_, stop_after);
            if (run_status[s].ok()) record(s, *own);
            pool.Give(std::move(own));
          }
        }
        ReportDone(++done, what);
      },
      "walking route"));
  for (const Status& st : run_status) VC_RETURN_IF_ERROR(st);
  return Status::Ok();
}

Status RoutePlanner::ExactNearDistances(const std::vector<int32_t>& component) {
  const int n = n_;
  VC_RETURN_IF_ERROR(FromEachStation(
      "walking distances to each station's nearest stations", kNearStations,
      [&](int s, int t) { return t != s && component[t] == component[s]; },
      [&](int s, const ShortestPaths& run) {
        // Row s only (no other worker writes it): every station on a settled node.
        std::vector<int> settled = run.settled();
        std::sort(settled.begin(), settled.end());
        for (int t = 0; t < n; ++t) {
          if (t == s || component[t] != component[s]) continue;
          if (std::binary_search(settled.begin(), settled.end(), node_[t])) {
            dist_[size_t(s) * n + t] = Connector(s) + double(run.Dist(node_[t])) + Connector(t);
          }
        }
      }));
  // Both directions the shorter of the two runs' values (they differ by float rounding at most).
  for (int s = 0; s < n; ++s) {
    for (int t = s + 1; t < n; ++t) {
      double& a = dist_[size_t(s) * n + t];
      double& b = dist_[size_t(t) * n + s];
      if (std::isnan(a) || b < a) a = b;
      b = a;
    }
  }
  return Status::Ok();
}

Status RoutePlanner::LandmarkDistances(const std::vector<int32_t>& component) {
  const int n = n_;
  std::vector<std::vector<int>> groups;  // stations per weak component, ascending
  {
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return component[a] < component[b]; });
    for (int s : order) {
      if (component[s] < 0) continue;
      if (groups.empty() || component[groups.back().front()] != component[s]) groups.emplace_back();
      groups.back().push_back(s);
    }
  }
  // Landmarks by farthest point (straight, between floor points): the group's first station,
  // then each time the station farthest from those chosen.
  struct Landmark {
    size_t group;
    int station;
    std::vector<double> row;  // distances (m) to the group's stations, NaN where not reached
  };
  std::vector<Landmark> landmarks;
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    const std::vector<int>& group = groups[gi];
    if (group.size() < 2) continue;
    std::vector<double> nearest(group.size(), std::numeric_limits<double>::infinity());
    for (int landmark = group.front(), count = 0; landmark >= 0 && count < kLandmarks; ++count) {
      landmarks.push_back({gi, landmark, {}});
      for (size_t i = 0; i < group.size(); ++i) {
        nearest[i] = std::min(nearest[i], (floor_point_[group[i]] - floor_point_[landmark]).norm());
      }
      const size_t far = size_t(std::max_element(nearest.begin(), nearest.end()) - nearest.begin());
      landmark = nearest[far] > 0 ? group[far] : -1;
    }
  }
  std::vector<Status> run_status(landmarks.size(), Status::Ok());
  std::atomic<int> done{0};
  ShortestPathsPool pool(g_);
  VC_RETURN_IF_ERROR(ParallelChunks(
      uint64_t(landmarks.size()), 1, options_.threads, ctx_,
      [&](uint64_t, uint64_t begin, uint64_t) {
        Landmark& l = landmarks[begin];
        const std::vector<int>& group = groups[l.group];
        std::unique_ptr<ShortestPaths> own = pool.Take();
        run_status[begin] = own->Run(node_[l.station], {}, ctx_);
        l.row.assign(group.size(), kNaN);
        for (size_t i = 0; i < group.size() && run_status[begin].ok(); ++i) {
          const int t = group[i];
          if (own->Dist(node_[t]) == kInf) continue;
          l.row[i] = t == l.station ? 0.0 : Connector(l.station) + double(own->Dist(node_[t])) + Connector(t);
        }
        pool.Give(std::move(own));
        const int finished = ++done;
        ctx_.ReportCount(Stage::kRoute, uint64_t(finished), uint64_t(landmarks.size()), "landmarks",
                         "walking distances from landmark stations");
      },
      "walking route"));
  for (const Status& st : run_status) VC_RETURN_IF_ERROR(st);
  // A landmark's distances are exact; every other pair without one: the walk via the landmark that
  // makes it shortest (an upper bound).
  for (const Landmark& l : landmarks) {
    const std::vector<int>& group = groups[l.group];
    for (size_t i = 0; i < group.size(); ++i) {
      double& a = dist_[size_t(l.station) * n + group[i]];
      if (!std::isnan(l.row[i]) && !(l.row[i] >= a)) a = dist_[size_t(group[i]) * n + l.station] = l.row[i];
    }
  }
  size_t first = 0;
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    const std::vector<int>& group = groups[gi];
    size_t last = first;
    while (last < landmarks.size() && landmarks[last].group == gi) ++last;
    for (size_t i = 0; i < group.size(); ++i) {
      for (size_t j = i + 1; j < group.size(); ++j) {
        double& a = dist_[size_t(group[i]) * n + group[j]];
        if (!std::isnan(a)) continue;
        for (size_t li = first; li < last; ++li) {
          const double via = landmarks[li].row[i] + landmarks[li].row[j];
          if (!std::isnan(via) && !(via >= a)) a = via;
        }
        dist_[size_t(group[j]) * n + group[i]] = a;
      }
    }
    first = last;
  }
  return Status::Ok();
}

void RoutePlanner::ReportDone(int done, const char* what) const {
  if (done * kProgressSteps / n_ != (done - 1) * kProgressSteps / n_) {
    ctx_.ReportCount(Stage::kRoute, uint64_t(done), uint64_t(n_), "stations", what);
  }
}

Status RoutePlanner::DistancesFromStart() {
  if (start_node_ < 0) return Status::Ok();
  VC_RETURN_IF_ERROR(sp_.Run(start_node_, node_, ctx_));
  for (int s = 0; s < n_; ++s) {
    if (node_[s] >= 0 && sp_.Dist(node_[s]) != kInf) {
      from_start_[s] = (g_.Point(start_node_) - start_point_).norm() + double(sp_.Dist(node_[s])) + Connector(s);
    }
  }
  return Status::Ok();
}

void RoutePlanner::FindParts() {
  part_of_.assign(n_, -1);
  for (int s = 0; s < n_; ++s) {
    if (part_of_[s] >= 0) continue;
    part_of_[s] = int(parts_.size());
    parts_.push_back({s});
    for (int t = s + 1; t < n_; ++t) {
      if (part_of_[t] < 0 && !std::isnan(dist_[size_t(s) * n_ + t])) {
        part_of_[t] = part_of_[s];
        parts_.back().push_back(t);
      }
    }
  }
}

double RoutePlanner::LowestFloor(const std::vector<int>& part) const {
  double z = std::numeric_limits<double>::infinity();
  for (int s : part) {
    if (!std::isnan(floor_point_[s].z())) z = std::min(z, floor_point_[s].z());
  }
  return z;
}

void RoutePlanner::OrderParts() {
  for (int s = 0; s < n_ && start_part_ < 0; ++s) {
    if (!std::isnan(from_start_[s])) start_part_ = part_of_[s];
  }
  part_order_.resize(parts_.size());
  std::iota(part_order_.begin(), part_order_.end(), 0);
  std::stable_sort(part_order_.begin(), part_order_.end(), [&](int a, int b) {
    if ((a == start_part_) != (b == start_part_)) return a == start_part_;
    return LowestFloor(parts_[a]) < LowestFloor(parts_[b]);
  });
}

// The highest thing (m above the lower of the two surfaces, up to the headroom) in the voxel
// columns along the straight line between nodes a and b; 0 when they are free.
double HighestBetween(const WalkGraph& g, int a, int b) {
  const WorldPoint p = g.Point(a), q = g.Point(b);
  const int floor_z = std::min(g.z[a], g.z[b]);
  const int samples = std::max(1, static_cast<int>(std::ceil((q - p).head<2>().norm() / (0.5 * g.r))));
  int highest = floor_z;
  for (int k = 0; k <= samples; ++k) {
    const VoxelIndex v = g.grid->WorldToIndex(p + (q - p) * (double(k) / samples));
    for (int z = floor_z + g.headroom; z > highest; --z) {
      if (g.grid->Occupied(v.x, v.y, z)) {
        highest = z;
        break;
      }
    }
  }
  return (highest - floor_z) * g.r;
}

// Where the walkable floor of region `from` comes nearest to that of the regions in `to`: a
// breadth-first search over the cells from those holding a node of `from`, up to kSplitSearchM;
// of the pairs found at the nearest ring, the one with the lowest obstacle between.
struct NearestApproach {
  int from_node = -1;  // a node of `from`, or -1 when no node of `to` lies within kSplitSearchM
  int to_node = -1;    // the node of `to` it comes nearest to
};
constexpr double kSplitSearchM = 3.0;

NearestApproach ApproachBetween(const WalkGraph& g, int32_t from, const std::vector<uint8_t>& to) {
  const uint64_t cells = g.cells();
  std::vector<int32_t> origin(cells, -1);  // per reached cell, the `from` node it was reached from
  std::vector<uint32_t> frontier, next;
  for (int n = 0; n < g.size(); ++n) {
    if (g.region[n] == from && origin[g.cell[n]] < 0) {
      origin[g.cell[n]] = n;
      frontier.push_back(g.cell[n]);
    }
  }
  const int max_rings = static_cast<int>(std::ceil(kSplitSearchM / (g.k * g.r)));
  for (int ring = 0; ring <= max_rings && !frontier.empty(); ++ring) {
    NearestApproach best;
    double best_obstacle_m = 0;
    for (uint32_t c : frontier) {
      for (uint32_t m = g.cell_begin[c]; m < g.cell_begin[c + 1]; ++m) {
        if (!to[g.region[m]]) continue;
        const double obstacle_m = HighestBetween(g, origin[c], int(m));
        if (best.to_node < 0 || obstacle_m < best_obstacle_m) {
          best = {origin[c], int(m)};
          best_obstacle_m = obstacle_m;
        }
      }
    }
    if (best.to_node >= 0) return best;
    next.clear();
    for (uint32_t c : frontier) {
      const int i = g.CellX(c), j = g.CellY(c);
      for (int d = 0; d < 4; ++d) {
        const int ti = i + kDx[d], tj = j + kDy[d];
        if (ti < 0 || tj < 0 || ti >= g.nx || tj >= g.ny) continue;
        const uint32_t t = uint32_t(tj) * uint32_t(g.nx) + uint32_t(ti);
        if (origin[t] >= 0) continue;
        origin[t] = origin[c];
        next.push_back(t);
      }
    }
    frontier.swap(next);
  }
  return {};
}

std::string RoutePlanner::WhySplit(const std::vector<int>& part) const {
  std::vector<uint8_t> others(g_.region_size.size(), 0);
  for (int s = 0; s < n_; ++s) {
    if (node_[s] >= 0 && part_of_[s] != part_of_[part.front()]) others[g_.region[node_[s]]] = 1;
  }
  const NearestApproach a = ApproachBetween(g_, g_.region[node_[part.front()]], others);
  if (a.from_node < 0) {
    return Fmt(
        ": no floor the others walk on lies within %.0f m of its walkable floor, so it is another storey or "
        "area that no stairs or ramp in the data links",
        kSplitSearchM);
  }
  const WorldPoint p = g_.Point(a.from_node), q = g_.Point(a.to_node);
  const double rise = q.z() - p.z();
  const std::string where = Fmt(": its walkable floor ends at (%.2f, %.2f, %.2f)", p.x(), p.y(), p.z()) +
                            Fmt(", %.2f m from the others' at (%.2f, %.2f", (q - p).head<2>().norm(), q.x(), q.y()) +
                            Fmt(", %.2f), ", q.z());
  if (std::abs(rise) > options_.max_step_m + g_.r) {
    return where + Fmt("%.2f m ", std::abs(rise)) + (rise > 0 ? "higher" : "lower") +
           (std::abs(rise) >= options_.headroom_m
                ? std::string(": another storey, and no stairs or ramp in the data links them")
                : Fmt(": a rise above the walkable step (%.2f m), and no stairs or ramp in the data",
                      options_.max_step_m));
  }
  const double obstacle_m = HighestBetween(g_, a.from_node, a.to_node);
  if (obstacle_m >= options_.headroom_m - g_.r) return where + "at about the same height, with a wall between";
  if (obstacle_m > 0) {
    return where + Fmt("at about the same height, with something %.2f m high between ", obstacle_m) +
           Fmt("(a sill or step above the walkable step of %.2f m, or clutter)", options_.max_step_m);
  }
  return where +
         Fmt("at about the same height: clutter within %.2f m of the way (the walking clearance) ",
             options_.clearance_m) +
         Fmt("or unseen floor wider than %.1f m closes it", 2 * options_.max_gap_m);
}

void RoutePlanner::WarnAboutUnlinkedParts() {
  if (options_.start && start_node_ >= 0 && start_part_ < 0) {
    route_.warnings.push_back(
        "the start is not linked to any station by a walkable path: the walk from it is not counted");
  }
  route_.parts = int(parts_.size());
  for (size_t pi = 1; pi < part_order_.size(); ++pi) {
    const std::vector<int>& part = parts_[part_order_[pi]];
    if (node_[part.front()] < 0) continue;  // SnapStations said where and why
    const double z = LowestFloor(part);
    route_.warnings.push_back(StationList(part, options_.first_station_number) +
                              (std::isinf(z) ? std::string() : Fmt(" (floor z = %.2f m)", z)) +
                              " not linked to the others by any walkable path" + WhySplit(part) + "; the route has " +
                              std::to_string(parts_.size()) + " parts, walking between them is not counted");
  }
}

OpenPathProblem RoutePlanner::PartProblem(const std::vector<int>& part, bool from_the_start) const {
  OpenPathProblem problem;
  problem.n = int(part.size());
  problem.distance_m.resize(part.size() * part.size());
  for (size_t a = 0; a < part.size(); ++a) {
    for (size_t b = 0; b < part.size(); ++b)
      problem.distance_m[a * part.size() + b] = dist_[size_t(part[a]) * n_ + part[b]];
  }
  if (from_the_start) {
    for (int s : part) problem.from_start_m.push_back(from_start_[s]);
  }
  return problem;
}

Status RoutePlanner::WalkPart(size_t pi) {
  const std::vector<int>& part = parts_[part_order_[pi]];
  const bool from_the_start = part_order_[pi] == start_part_;
  const OpenPathProblem problem = PartProblem(part, from_the_start);
  VC_RETURN_IF_ERROR(ctx_.CheckCancelled("walking route"));
  Clock::time_point t = Clock::now();
  VC_ASSIGN_OR_RETURN(const std::vector<int> local, OrderOpenPath(problem, ctx_));
  route_.seconds.order_s += SecondsSince(t);
  t = Clock::now();
  for (size_t li = 0; li < local.size(); ++li) {
    const int s = part[local[li]];
    const bool first = li == 0;
    route_.order.push_back(s);
    if (first && !from_the_start) {
      route_.legs_m.push_back(pi == 0 && !options_.start ? 0.0 : kNaN);
      route_.polylines.emplace_back();
      continue;
    }
    const int prev = first ? -1 : route_.order[route_.order.size() - 2];
    const int src = first ? start_node_ : node_[prev];
    VC_RETURN_IF_ERROR(sp_.Run(src, {node_[s]}, ctx_));
    std::vector<WorldPoint> pts{first ? start_point_ : floor_point_[prev]};
    for (int m : sp_.PathTo(node_[s])) pts.push_back(g_.Point(m));
    pts.push_back(floor_point_[s]);
    route_.polylines.push_back(Simplify(pts));
    route_.legs_m.push_back(PolylineLength(route_.polylines.back()));
    route_.length_m += route_.legs_m.back();
  }
  route_.seconds.legs_s += SecondsSince(t);
  return Status::Ok();
}

}  // namespace

double FloorBelow(const OccupancyGrid& grid, const WorldPoint& p) {
  const VoxelIndex v = grid.WorldToIndex(p);
  std::vector<Surface> runs;
  ColumnSurfaces(grid, v.x, v.y, 1, runs);
  for (const Surface& s : runs) {
    if ((s.z + 1) * grid.resolution_m() <= p.z() + 1e-9) return (s.z + 1) * grid.resolution_m();
  }
  return kNaN;
}

double OpenPathLength(const OpenPathProblem& p, const std::vector<int>& order) {
  double len = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    if (i == 0) {
      len += p.from_start_m.empty() ? 0 : p.from_start_m[order[0]];
    } else {
      len += p.distance_m[size_t(order[i - 1]) * p.n + order[i]];
    }
  }
  return len;
}

std::vector<int> NearestNeighbourPath(const OpenPathProblem& p, int first) {
  std::vector<int> order;
  if (p.n == 0) return order;
  std::vector<bool> used(p.n, false);
  int cur = first;
  if (cur < 0) {
    cur = 0;
    for (int i = 1; i < p.n && !p.from_start_m.empty(); ++i) {
      if (p.from_start_m[i] < p.from_start_m[cur]) cur = i;
    }
  }
  for (;;) {
    order.push_back(cur);
    used[cur] = true;
    int next = -1;
    for (int i = 0; i < p.n; ++i) {
      if (!used[i] && (next < 0 || p.distance_m[size_t(cur) * p.n + i] < p.distance_m[size_t(cur) * p.n + next])) {
        next = i;
      }
    }
    if (next < 0) break;
    cur = next;
  }
  return order;
}

std::vector<int> ImprovePath(const OpenPathProblem& p, std::vector<int> order) {
  const int n = int(order.size());
  // d(a, b): from a to b; a < 0 is the start (0 without one); b < 0 is the free end (0).
  auto d = [&](int a, int b) -> double {
    if (b < 0) return 0;
    if (a < 0) return p.from_start_m.empty() ? 0 : p.from_start_m[b];
    return p.distance_m[size_t(a) * p.n + b];
  };
  auto at = [&](int i) { return i < 0 || i >= n ? -1 : order[i]; };
  constexpr double kEps = 1e-9;
  std::vector<int> rest;
  for (bool improved = true; improved;) {
    improved = false;
    // 2-opt: reverse order[i..j].
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        const int a = at(i - 1), b = at(j + 1);
        const double delta =
            d(a, order[j]) + (b < 0 ? 0 : d(order[i], b)) - d(a, order[i]) - (b < 0 ? 0 : d(order[j], b));
        if (delta < -kEps) {
          std::reverse(order.begin() + i, order.begin() + j + 1);
          improved = true;
        }
      }
    }
    // Or-opt: move order[i..i+len-1], either way round, elsewhere.
    for (int len = 1; len <= 3; ++len) {
      for (int i = 0; i + len <= n; ++i) {
        const int first = order[i], last = order[i + len - 1], a = at(i - 1), b = at(i + len);
        const double gain = d(a, first) + d(last, b) - (b < 0 ? 0 : d(a, b));
        rest.assign(order.begin(), order.begin() + i);
        rest.insert(rest.end(), order.begin() + i + len, order.end());
        const int m = int(rest.size());
        double best = -kEps;
        int best_g = -1;
        bool best_rev = false;
        for (int g = 0; g <= m; ++g) {
          const int x = g == 0 ? -1 : rest[g - 1], y = g == m ? -1 : rest[g];
          for (int rev = 0; rev < (len > 1 ? 2 : 1); ++rev) {
            if (g == i && !rev) continue;
            const int s = rev ? last : first, e = rev ? first : last;
            const double delta = d(x, s) + d(e, y) - (y < 0 ? 0 : d(x, y)) - gain;
            if (delta < best) {
              best = delta;
              best_g = g;
              best_rev = rev;
            }
          }
        }
        if (best_g >= 0) {
          std::vector<int> seg(order.begin() + i, order.begin() + i + len);
          if (best_rev) std::reverse(seg.begin(), seg.end());
          rest.insert(rest.begin() + best_g, seg.begin(), seg.end());
          order = rest;
          improved = true;
        }
      }
    }
  }
  return order;
}

namespace {

// The K points nearest to each point (by distance_m; ties to the lower index), and to the start.
struct NeighbourLists {
  int k = 0;
  std::vector<int> of;          // n x k: of[a * k + r] is a's r-th nearest other point
  std::vector<int> from_start;  // k points nearest the start; empty without a start
};

NeighbourLists NearestPoints(const OpenPathProblem& p, int neighbours) {
  NeighbourLists out;
  out.k = std::max(0, std::min(neighbours, p.n - 1));
  std::vector<int> idx;
  auto nearest = [&](auto&& dist, int self) {
    idx.clear();
    for (int b = 0; b < p.n; ++b) {
      if (b != self) idx.push_back(b);
    }
    std::partial_sort(idx.begin(), idx.begin() + out.k, idx.end(),
                      [&](int x, int y) { return dist(x) < dist(y) || (dist(x) == dist(y) && x < y); });
  };
  out.of.reserve(size_t(p.n) * out.k);
  for (int a = 0; a < p.n; ++a) {
    nearest([&](int b) { return p.distance_m[size_t(a) * p.n + b]; }, a);
    out.of.insert(out.of.end(), idx.begin(), idx.begin() + out.k);
  }
  if (!p.from_start_m.empty()) {
    nearest([&](int b) { return p.from_start_m[b]; }, -1);
    out.from_start.assign(idx.begin(), idx.begin() + out.k);
  }
  return out;
}

// ImprovePathNear's moves over one path; `pos` is the inverse of `order`.
class NearMoves {
 public:
  NearMoves(const OpenPathProblem& p, const NeighbourLists& near, std::vector<int>& order)
      : p_(p), near_(near), order_(order), n_(int(order.size())), pos_(p.n) {
    Reindex();
  }
  // One pass of 2-opt moves (each reversal adds an edge to one of an end's nearest points), then
  // of Or-opt moves (a segment of 1-3 points, either way round, next to one of its ends' nearest
  // points, or at either end of the path); whether any shortened the path.
  bool Pass() {
    const bool two_opt = TwoOptPass();  // first, then Or-opt on its result: both always run
    const bool or_opt = OrOptPass();
    return two_opt || or_opt;
  }

 private:
  static constexpr double kEps = 1e-9;
  // From a to b; a < 0 is the start (0 without one); b < 0 is the free end (0).
  double D(int a, int b) const {
    if (b < 0) return 0;
    if (a < 0) return p_.from_start_m.empty() ? 0 : p_.from_start_m[b];
    return p_.distance_m[size_t(a) * p_.n + b];
  }
  int At(int i) const { return i < 0 || i >= n_ ? -1 : order_[i]; }
  const int* Near(int a) const { return &near_.of[size_t(a) * near_.k]; }
  void Reindex() {
    for (int i = 0; i < n_; ++i) pos_[order_[i]] = i;
  }
  // The change of reversing order[i..j].
  double ReverseDelta(int i, int j) const {
    const int a = At(i - 1), b = At(j + 1), oi = order_[i], oj = order_[j];
    return D(a, oj) + (b < 0 ? 0 : D(oi, b)) - D(a, oi) - (b < 0 ? 0 : D(oj, b));
  }
  void Reverse(int i, int j) {
    std::reverse(order_.begin() + i, order_.begin() + j + 1);
    for (int t = i; t <= j; ++t) pos_[order_[t]] = t;
  }
  bool TwoOptPass();
  bool OrOptPass();
  bool MoveSegment(int i, int len);

  const OpenPathProblem& p_;
  const NeighbourLists& near_;
  std::vector<int>& order_;
  const int n_;
  std::vector<int> pos_;
  std::vector<int> rest_;
};

bool NearMoves::TwoOptPass() {
  bool improved = false;
  for (int q = -1; q < n_; ++q) {
    // A new edge from order[q] (or the start) to a nearer point c = order[j]: reverse order[q+1..j].
    const int i = q + 1;
    if (i < n_ && (q >= 0 || !p_.from_start_m.empty())) {
      const int a = At(q);
      const int* list = q >= 0 ? Near(a) : near_.from_start.data();
      const int len = q >= 0 ? near_.k : int(near_.from_start.size());
      for (int r = 0; r < len; ++r) {
        const int c = list[r];
        if (D(a, c) >= D(a, order_[i]) - kEps) break;
        const int j = pos_[c];
        if (j > i && ReverseDelta(i, j) < -kEps) {
          Reverse(i, j);
          improved = true;
          break;
        }
      }
    }
    // A new edge from order[q] back to a nearer point c = order[i]: reverse order[i..q-1].
    const int j = q - 1;
    if (q >= 1) {
      const int b = order_[q];
      for (int r = 0; r < near_.k; ++r) {
        const int c = Near(b)[r];
        if (D(c, b) >= D(order_[j], b) - kEps) break;
        const int ic = pos_[c];
        if (ic < j && ReverseDelta(ic, j) < -kEps) {
          Reverse(ic, j);
          improved = true;
          break;
        }
      }
    }
  }
  return improved;
}

bool NearMoves::OrOptPass() {
  bool improved = false;
  for (int len = 1; len <= 3; ++len) {
    for (int i = 0; i + len <= n_; ++i) improved |= MoveSegment(i, len);
  }
  return improved;
}

// Moves order[i..i+len-1] to its best place among those next to its ends' nearest points and the
// path's two ends, if that shortens the path.
bool NearMoves::MoveSegment(int i, int len) {
  const int first = order_[i], last = order_[i + len - 1], a = At(i - 1), b = At(i + len);
  const double gain = D(a, first) + D(last, b) - (b < 0 ? 0 : D(a, b));
  const int m = n_ - len;  // places in the path without the segment: 0..m
  auto rest_at = [&](int g) { return g < 0 || g >= m ? -1 : order_[g < i ? g : g + len]; };
  double best = -kEps;
  int best_g = -1;
  bool best_rev = false;
  auto consider = [&](int g) {
    if (g < 0 || g > m) return;
    const int x = rest_at(g - 1), y = rest_at(g);
    for (int rev = 0; rev < (len > 1 ? 2 : 1); ++rev) {
      if (g == i && !rev) continue;
      const int s = rev ? last : first, e = rev ? first : last;
      const double delta = D(x, s) + D(e, y) - (y < 0 ? 0 : D(x, y)) - gain;
      if (delta < best) {
        best = delta;
        best_g = g;
        best_rev = rev;
      }
    }
  };
  consider(0);
  consider(m);
  for (int end : {first, last}) {
    for (int r = 0; r < near_.k; ++r) {
      const int c = Near(end)[r], pc = pos_[c];
      if (pc >= i && pc < i + len) continue;
      const int gc = pc < i ? pc : pc - len;  // c's place without the segment
      consider(gc);
      consider(gc + 1);
    }
  }
  if (best_g < 0) return false;
  rest_.assign(order_.begin(), order_.begin() + i);
  rest_.insert(rest_.end(), order_.begin() + i + len, order_.end());
  std::vector<int> seg(order_.begin() + i, order_.begin() + i + len);
  if (best_rev) std::reverse(seg.begin(), seg.end());
  rest_.insert(rest_.begin() + best_g, seg.begin(), seg.end());
  order_.swap(rest_);
  Reindex();
  return true;
}

// Up to `count` points spread over the problem: point 0, then each time the point farthest from
// those chosen (ties to the lower index).
std::vector<int> SpreadPoints(const OpenPathProblem& p, int count) {
  std::vector<int> chosen{0};
  std::vector<double> nearest(p.distance_m.begin(), p.distance_m.begin() + p.n);
  while (int(chosen.size()) < std::min(count, p.n)) {
    int far = 0;
    for (int a = 1; a < p.n; ++a) {
      if (nearest[a] > nearest[far]) far = a;
    }
    chosen.push_back(far);
    for (int a = 0; a < p.n; ++a) nearest[a] = std::min(nearest[a], p.distance_m[size_t(far) * p.n + a]);
  }
  return chosen;
}

}  // namespace

Result<std::vector<int>> ImprovePathNear(const OpenPathProblem& p, std::vector<int> order, int neighbours,
                                         const JobContext& ctx) {
  const NeighbourLists near = NearestPoints(p, neighbours);
  NearMoves moves(p, near, order);
  for (bool improved = true; improved;) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
    improved = moves.Pass();
  }
  return order;
}

Result<std::vector<int>> OrderOpenPath(const OpenPathProblem& p, const JobContext& ctx) {
  if (p.n == 0) return std::vector<int>{};
  const bool large = p.n > kExhaustiveOrderMax;
  auto improve = [&](std::vector<int> order) -> Result<std::vector<int>> {
    if (!large) return ImprovePath(p, std::move(order));
    return ImprovePathNear(p, std::move(order), kOrderNeighbours, ctx);
  };
  if (!p.from_start_m.empty()) return improve(NearestNeighbourPath(p, -1));
  std::vector<int> firsts(size_t(p.n));
  std::iota(firsts.begin(), firsts.end(), 0);
  if (large) firsts = SpreadPoints(p, kLargeOrderRestarts);
  std::vector<int> best;
  double best_len = 0;
  for (int first : firsts) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("walking route"));
    VC_ASSIGN_OR_RETURN(std::vector<int> o, improve(NearestNeighbourPath(p, first)));
    const double len = OpenPathLength(p, o);
    if (best.empty() || len < best_len - 1e-9) {
      best = std::move(o);
      best_len = len;
    }
  }
  return best;
}

Result<Route> PlanRoute(const VoxelScene& scene, const std::vector<WorldPoint>& stations,
                        const std::vector<double>& floor_z_m, const RouteOptions& options, const JobContext& ctx) {
  VC_RETURN_IF_ERROR(Validate(stations, floor_z_m, options));
  if (stations.empty()) return Route{};
  const OccupancyGrid& grid = scene.grid;
  const double r = grid.resolution_m();
  if (!(r > 0) || grid.brick_count() == 0) return InvalidArgumentError("the scene has no voxels to walk on");
  VC_ASSIGN_OR_RETURN(const int k, WalkCellVoxels(options, r));
  const Clock::time_point t = Clock::now();
  VC_ASSIGN_OR_RETURN(const WalkGraph g, BuildWalkGraph(grid, options, k, ctx));
  const double walk_graph_s = SecondsSince(t);
  RoutePlanner planner(g, stations, options, ctx);
  VC_ASSIGN_OR_RETURN(Route route, planner.Plan(floor_z_m));
  route.seconds.walk_graph_s = walk_graph_s;
  route.seconds.bridging_s = g.bridging_s;
  return route;
}

}  // namespace vc::planner
