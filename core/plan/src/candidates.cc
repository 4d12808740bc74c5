#include "vc/plan/candidates.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <tuple>
#include <utility>

#include "standing_surfaces.h"

namespace vc::planner {

namespace internal {

int FreeVoxelsNeeded(double resolution_m, double height_m, double clearance_m) {
  return std::max(1, static_cast<int>(std::ceil((height_m + clearance_m) / resolution_m - 1e-9)));
}

void ColumnSurfaces(const OccupancyGrid& grid, int x, int y, int free_needed, std::vector<Surface>& out) {
  out.clear();
  const VoxelIndex& m = grid.min_index();
  if (x < m.x || y < m.y || x >= m.x + grid.dims().x() || y >= m.y + grid.dims().y()) return;
  // Occupied runs from the top: each run's top voxel and the free voxels above it.
  int free_above = std::numeric_limits<int>::max();
  int runs = 0;
  bool in_run = false;
  for (int z = m.z + grid.dims().z() - 1; z >= m.z; --z) {
    if (grid.Occupied(x, y, z)) {
      if (!in_run) {
        if (free_above >= free_needed) out.push_back({z, free_above, runs > 0, false, runs});
        ++runs;
        in_run = true;
      }
      free_above = 0;
    } else {
      in_run = false;
      if (free_above != std::numeric_limits<int>::max()) ++free_above;
    }
  }
  for (Surface& s : out) s.has_below = s.run + 1 < runs;
}

}  // namespace internal

namespace {

using internal::ColumnSurfaces;
using internal::FreeVoxelsNeeded;
using internal::Surface;

// The lowest tripod height of `o` (m).
double LowestHeight(const CandidateOptions& o) {
  if (o.tripod_heights_m.empty()) return o.tripod_height_m;
  return *std::min_element(o.tripod_heights_m.begin(), o.tripod_heights_m.end());
}

// Voxels of free space a standing surface needs above it: for the lowest height.
int FreeVoxelsNeeded(double resolution_m, const CandidateOptions& o) {
  return FreeVoxelsNeeded(resolution_m, LowestHeight(o), o.clearance_m);
}

// Half-width (voxels) of a level's height band: 0.15 m, at least 2 voxels.
int BandVoxels(double resolution_m) { return std::max(2, static_cast<int>(std::ceil(0.15 / resolution_m - 1e-9))); }

constexpr int kNoSurface = std::numeric_limits<int>::min();

// The standing surface with z in [ref - band, ref + band] closest to ref (the higher on a tie) in
// the 3 x 3 columns around (cx, cy), or kNoSurface; *free_above (if given) gets the most free
// voxels above it among the columns where that surface is.
int SurfaceNear(const OccupancyGrid& grid, int cx, int cy, int ref, int band, int free_needed,
                std::vector<Surface>& scratch, int* free_above = nullptr) {
  int best = kNoSurface, best_free = 0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      ColumnSurfaces(grid, cx + dx, cy + dy, free_needed, scratch);
      for (const Surface& s : scratch) {
        if (s.z < ref - band || s.z > ref + band) continue;
        const int d = std::abs(s.z - ref), d_best = best == kNoSurface ? band + 1 : std::abs(best - ref);
        if (d < d_best || (d == d_best && s.z > best)) {
          best = s.z;
          best_free = s.free_above;
        } else if (s.z == best) {
          best_free = std::max(best_free, s.free_above);
        }
      }
    }
  }
  if (free_above) *free_above = best_free;
  return best;
}

// Grid coordinates along one axis: n cells of `spacing` centred in [lo, hi].
std::vector<double> AxisCells(double lo, double hi, double spacing) {
  const double extent = hi - lo;
  const int n = std::max(1, static_cast<int>(std::floor(extent / spacing + 1e-9)));
  const double start = lo + (extent - (n - 1) * spacing) / 2;
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = start + i * spacing;
  return v;
}

// Narrow passages of the level whose floor voxels are below index z `floor_top` (the first free
// voxel above the floor): the obstacle slice marks a column blocked if a voxel between the lowest
// tripod height minus and plus the clearance above the floor is occupied. A free run of the slice
// along x (or y) is a cross-section of a passage if both its ends are blocked and it is at least
// 2 clearance_m and less than 2 grid_spacing_m wide; adjacent lines whose runs have the same
// midpoint (to grid_spacing_m / 4) form one passage, from its first line to its last. Positions, at
// the passage's midpoint across it, along it every grid_spacing_m / 4 from its centre, and beyond
// each end at half that step and then every step up to grid_spacing_m / 2 (just inside the rooms
// a door joins). A position rounding to the same point of a grid_spacing_m / 8 lattice as an earlier one is dropped.
std::vector<WorldPoint> PassagePoints(const OccupancyGrid& grid, int floor_top, const CandidateOptions& o) {
  const double r = grid.resolution_m();
  const VoxelIndex& m = grid.min_index();
  const Eigen::Vector3i dims = grid.dims();
  const int eye = floor_top + static_cast<int>(std::floor(LowestHeight(o) / r));
  const int c = static_cast<int>(std::ceil(o.clearance_m / r - 1e-9));
  std::vector<uint8_t> blocked(static_cast<size_t>(dims.x()) * dims.y(), 0);
  for (int y = 0; y < dims.y(); ++y) {
    for (int x = 0; x < dims.x(); ++x) {
      for (int z = std::max(eye - c, m.z); z <= std::min(eye + c, m.z + dims.z() - 1); ++z) {
        if (grid.Occupied(m.x + x, m.y + y, z)) {
          blocked[static_cast<size_t>(y) * dims.x() + x] = 1;
          break;
        }
      }
    }
  }
  const double fine = o.grid_spacing_m / 4;
  const int max_width = static_cast<int>(std::ceil(2 * o.grid_spacing_m / r - 1e-9));  // exclusive, voxels
  const int min_width = std::max(1, static_cast<int>(std::floor(2 * o.clearance_m / r)));
  std::vector<WorldPoint> out;
  std::set<std::pair<long, long>> seen;
  auto emit = [&](int axis, double mid, double b) {
    const long ka = std::lround(mid / (fine / 2)), kb = std::lround(b / (fine / 2));
    if (!seen.insert(axis == 0 ? std::pair{ka, kb} : std::pair{kb, ka}).second) return;
    out.push_back(axis == 0 ? WorldPoint(mid, b, 0) : WorldPoint(b, mid, 0));
  };
  for (int axis = 0; axis < 2; ++axis) {  // axis 0: runs along x (a passage crossed in x), 1: along y
    const int n_along = axis == 0 ? dims.x() : dims.y(), n_lines = axis == 0 ? dims.y() : dims.x();
    const int lo_along = axis == 0 ? m.x : m.y, lo_line = axis == 0 ? m.y : m.x;
    auto world = [&](int a, double index) {  // world coordinate along axis a of an index-space value
      Eigen::Vector3d u(0, 0, 0);
      u[a] = index;
      return grid.IndexSpaceToWorld(u)[a];
    };
    struct Section {
      long key;
      int line;
      double mid;
    };
    std::vector<Section> sections;
    for (int line = 0; line < n_lines; ++line) {
      auto is_blocked = [&](int i) {
        return axis == 0 ? blocked[static_cast<size_t>(line) * dims.x() + i]
                         : blocked[static_cast<size_t>(i) * dims.x() + line];
      };
      int i = 0;
      while (i < n_along) {
        if (is_blocked(i)) {
          ++i;
          continue;
        }
        const int lo = i;
        while (i < n_along && !is_blocked(i)) ++i;
        const int width = i - lo;
        if (lo == 0 || i == n_along || width < min_width || width >= max_width) continue;
        const double mid = world(axis, lo_along + lo + width / 2.0);
        sections.push_back({std::lround(mid / fine), line, mid});
      }
    }
    std::sort(sections.begin(), sections.end(),
              [](const Section& a, const Section& b) { return std::tie(a.key, a.line) < std::tie(b.key, b.line); });
    for (size_t first = 0; first < sections.size();) {
      size_t last = first;
      double mid_sum = sections[first].mid;
      while (last + 1 < sections.size() && sections[last + 1].key == sections[first].key &&
             sections[last + 1].line == sections[last].line + 1) {
        ++last;
        mid_sum += sections[last].mid;
      }
      const double mid = mid_sum / static_cast<double>(last - first + 1);
      const double b_lo = world(1 - axis, lo_line + sections[first].line);
      const double b_hi = world(1 - axis, lo_line + sections[last].line + 1);
      const double centre = (b_lo + b_hi) / 2;
      for (int k = 0; centre + k * fine <= b_hi; ++k) {
        emit(axis, mid, centre + k * fine);
        emit(axis, mid, centre - k * fine);
      }
      for (double d = fine / 2; d <= o.grid_spacing_m / 2 + 1e-9; d += fine) {
        emit(axis, mid, b_hi + d);
        emit(axis, mid, b_lo - d);
      }
      first = last + 1;
    }
  }
  return out;
}

}  // namespace

bool HasClearance(const OccupancyGrid& grid, const WorldPoint& p, double clearance_m) {
  const Eigen::Vector3d u = grid.WorldToIndexSpace(p);
  const Eigen::Vector3i own(static_cast<int>(std::floor(u.x())), static_cast<int>(std::floor(u.y())),
                            static_cast<int>(std::floor(u.z())));
  if (grid.Occupied(own.x(), own.y(), own.z())) return false;
  const double c = clearance_m / grid.resolution_m();
  if (c <= 0) return true;
  const double c2 = c * c;
  const Eigen::Vector3i lo((u.array() - c).floor().cast<int>());
  const Eigen::Vector3i hi((u.array() + c).floor().cast<int>());
  for (int z = lo.z(); z <= hi.z(); ++z) {
    const double dz = std::max({z - u.z(), 0.0, u.z() - (z + 1)});
    for (int y = lo.y(); y <= hi.y(); ++y) {
      const double dy = std::max({y - u.y(), 0.0, u.y() - (y + 1)});
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const double dx = std::max({x - u.x(), 0.0, u.x() - (x + 1)});
        if (dx * dx + dy * dy + dz * dz < c2 && grid.Occupied(x, y, z)) return false;
      }
    }
  }
  return true;
}

std::optional<double> FloorTopNear(const OccupancyGrid& grid, double x_m, double y_m, double near_z_m,
                                   const CandidateOptions& options) {
  const double r = grid.resolution_m();
  const Eigen::Vector3d u = grid.WorldToIndexSpace(WorldPoint(x_m, y_m, near_z_m));
  // near_z_m is a surface top, i.e. the boundary above voxel round(u.z) - 1.
  const int z_ref = static_cast<int>(std::lround(u.z())) - 1;
  const int band = BandVoxels(r);
  std::vector<Surface> scratch;
  const int z = SurfaceNear(grid, static_cast<int>(std::floor(u.x())), static_cast<int>(std::floor(u.y())), z_ref, band,
                            FreeVoxelsNeeded(r, options), scratch);
  if (z == kNoSurface) return std::nullopt;
  return grid.IndexSpaceToWorld(Eigen::Vector3d(0, 0, z + 1)).z();
}

Result<CandidateGrid> GenerateCandidates(const VoxelScene& scene, const CandidateOptions& options,
                                         const JobContext& ctx) {
  const OccupancyGrid& grid = scene.grid;
  const double r = grid.resolution_m();
  const int free_needed = FreeVoxelsNeeded(r, options);
  const int band = BandVoxels(r);
  const Eigen::Vector3i dims = grid.dims();
  CandidateGrid out;
  const std::vector<double> heights =
      options.tripod_heights_m.empty() ? std::vector<double>{options.tripod_height_m} : options.tripod_heights_m;

  // 1. Histogram of standing surfaces over all columns.
  // Histograms are indexed by z - min.z.
  const VoxelIndex m = grid.min_index();
  std::vector<uint64_t> hist(dims.z(), 0), roofs(dims.z(), 0);
  std::vector<Surface> scratch;
  for (int y = 0; y < dims.y(); ++y) {
    if ((y & 15) == 0) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("candidate generation"));
      ctx.Report(Stage::kCandidates, 0.5 * y / std::max(1, dims.y()));
    }
    for (int x = 0; x < dims.x(); ++x) {
      ColumnSurfaces(grid, m.x + x, m.y + y, free_needed, scratch);
      for (const Surface& s : scratch) {
        ++hist[s.z - m.z];
        if (s.roof()) ++roofs[s.z - m.z];
      }
    }
  }

  // 2. Dominant levels, strongest first, with suppression of weaker ones nearby.
  auto band_sum = [&](const std::vector<uint64_t>& h, int z) {
    uint64_t s = 0;
    for (int k = std::max(0, z - band); k <= std::min(dims.z() - 1, z + band); ++k) s += h[k];
    return s;
  };
  std::vector<uint64_t> score(dims.z());
  for (int z = 0; z < dims.z(); ++z) score[z] = band_sum(hist, z);
  std::vector<bool> suppressed(dims.z(), false);
  struct Level {
    int z;
    uint64_t columns;
    uint64_t roofs;
  };
  std::vector<Level> levels;
  uint64_t strongest = 0;
  for (int iter = 0; iter < 32; ++iter) {
    int best = -1;
    for (int z = 0; z < dims.z(); ++z) {
      if (!suppressed[z] && score[z] > 0 && (best < 0 || score[z] > score[best])) best = z;
    }
    if (best < 0) break;
    if (levels.empty()) strongest = score[best];
    if (score[best] * 4 < strongest) break;
    // The level's height: the fullest bin within the band.
    int mode = best;
    for (int k = std::max(0, best - band); k <= std::min(dims.z() - 1, best + band); ++k) {
      if (hist[k] > hist[mode]) mode = k;
    }
    levels.push_back({mode, band_sum(hist, mode), band_sum(roofs, mode)});
    for (int z = std::max(0, mode - free_needed + 1); z <= std::min(dims.z() - 1, mode + free_needed - 1); ++z) {
      suppressed[z] = true;
    }
  }
  std::sort(levels.begin(), levels.end(), [](const Level& a, const Level& b) { return a.z < b.z; });
  // Roofs: levels whose surfaces are mostly the outside of a ceiling.
  std::vector<Level> kept;
  for (const Level& l : levels) {
    if (l.roofs * 2 <= l.columns) kept.push_back(l);
  }
  for (const Level& l : kept) {
    out.levels.push_back({grid.IndexSpaceToWorld(Eigen::Vector3d(0, 0, m.z + l.z + 1)).z(), l.columns});
  }

  // 3. Cells of the grid over the footprint, per level. place() examines one position: the floor
  // under it, then each height's headroom and clearance; it appends the kept candidates and
  // returns how many.
  const WorldPoint lo = scene.BoundsMin(), hi = scene.BoundsMax();
  const std::vector<double> xs = AxisCells(lo.x(), hi.x(), options.grid_spacing_m);
  const std::vector<double> ys = AxisCells(lo.y(), hi.y(), options.grid_spacing_m);
  auto place = [&](double x, double y, size_t li, int lz, uint64_t* no_floor, uint64_t* no_clearance) {
    const Eigen::Vector3d u = grid.WorldToIndexSpace(WorldPoint(x, y, lo.z()));
    int free_above = 0;
    const int z = SurfaceNear(grid, static_cast<int>(std::floor(u.x())), static_cast<int>(std::floor(u.y())), lz, band,
                              free_needed, scratch, &free_above);
    if (z == kNoSurface) {
      *no_floor += heights.size();
      return 0;
    }
    const double top = grid.IndexSpaceToWorld(Eigen::Vector3d(0, 0, z + 1)).z();
    int placed = 0;
    for (double h : heights) {
      const WorldPoint p(x, y, top + h);
      if (free_above < FreeVoxelsNeeded(r, h, options.clearance_m) || !HasClearance(grid, p, options.clearance_m)) {
        ++*no_clearance;
        continue;
      }
      out.positions.push_back(p);
      out.floor_z_m.push_back(top);
      out.level.push_back(static_cast<int>(li));
      out.height_m.push_back(h);
      ++placed;
    }
    return placed;
  };
  // Per level, per grid cell (iy * |xs| + ix): whether the cell got a candidate.
  std::vector<std::vector<uint8_t>> on_grid(kept.size(), std::vector<uint8_t>(xs.size() * ys.size(), 0));
  for (size_t li = 0; li < kept.size(); ++li) {
    const int lz = m.z + kept[li].z;
    for (size_t iy = 0; iy < ys.size(); ++iy) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("candidate generation"));
      ctx.Report(Stage::kCandidates, 0.5 + 0.5 * (li + static_cast<double>(iy) / ys.size()) / kept.size());
      for (size_t ix = 0; ix < xs.size(); ++ix) {
        out.cells += heights.size();
        on_grid[li][iy * xs.size() + ix] =
            place(xs[ix], ys[iy], li, lz, &out.rejected_no_floor, &out.rejected_clearance) > 0;
      }
    }
  }
  if (options.doorway_candidates) {
    const double fine = options.grid_spacing_m / 4;
    uint64_t no_floor = 0, no_clearance = 0;
    for (size_t li = 0; li < kept.size(); ++li) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("candidate generation"));
      const int lz = m.z + kept[li].z;
      for (const WorldPoint& q : PassagePoints(grid, lz + 1, options)) {
        // The nearest grid cell; skip q if it got a candidate within fine / 2 of q in x and y.
        auto nearest = [&](const std::vector<double>& cells, double v) {
          const long i = std::lround((v - cells.front()) / options.grid_spacing_m);
          return static_cast<size_t>(std::clamp<long>(i, 0, static_cast<long>(cells.size()) - 1));
        };
        const size_t ix = nearest(xs, q.x()), iy = nearest(ys, q.y());
        const bool near_grid = on_grid[li][iy * xs.size() + ix] && std::abs(xs[ix] - q.x()) < fine / 2 &&
                               std::abs(ys[iy] - q.y()) < fine / 2;
        if (!near_grid) out.passage_candidates += place(q.x(), q.y(), li, lz, &no_floor, &no_clearance);
      }
    }
  }
  ctx.Report(Stage::kCandidates, 1.0);
  return out;
}

}  // namespace vc::planner
