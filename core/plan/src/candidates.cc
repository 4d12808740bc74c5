#include "vc/plan/candidates.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "format.h"
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

// The band of auto's floor test (ChooseGround): the level band, but at most +-0.4 m (at least one
// voxel). At 0.4 m the level band's 2 voxels are +-0.8 m, and 3 levels of a 4 m slope held all its
// ground (`slope` 100 %, fr_campus 84 %: floors); one voxel, +-0.4 m, gives 75 % and terrain.
int AutoBandVoxels(double resolution_m, int band) {
  return std::max(1, std::min(band, static_cast<int>(std::floor(0.4 / resolution_m + 1e-9))));
}

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

// The obstacle slice of the level whose floor voxels are below index z `floor_top` (the first free
// voxel above the floor): per column (y * dims.x + x, relative to the grid's minimum), blocked if
// a voxel between the lowest tripod height minus and plus the clearance above the floor is occupied.
std::vector<uint8_t> FloorSlice(const OccupancyGrid& grid, int floor_top, const CandidateOptions& o) {
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
  return blocked;
}

// Narrow passages of an obstacle slice (FloorSlice, TerrainSlice): a free run of the slice along x
// (or y) is a cross-section of a passage if both its ends are blocked and it is at least
// 2 clearance_m and less than 2 grid_spacing_m wide; adjacent lines whose runs have the same
// midpoint (to grid_spacing_m / 4) form one passage, from its first line to its last. Positions, at
// the passage's midpoint across it, along it every grid_spacing_m / 4 from its centre, and beyond
// each end at half that step and then every step up to grid_spacing_m / 2 (just inside the rooms
// a door joins). A position rounding to the same point of a grid_spacing_m / 8 lattice as an earlier one is dropped.
std::vector<WorldPoint> PassagePoints(const OccupancyGrid& grid, const std::vector<uint8_t>& blocked,
                                      const CandidateOptions& o) {
  const double r = grid.resolution_m();
  const VoxelIndex& m = grid.min_index();
  const Eigen::Vector3i dims = grid.dims();
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

// Standing-surface heights over all columns, indexed by z - min.z: all of them and the roofs.
struct SurfaceHistogram {
  std::vector<uint64_t> all, roofs;
};

Result<SurfaceHistogram> HistogramSurfaces(const OccupancyGrid& grid, int free_needed, const JobContext& ctx) {
  const Eigen::Vector3i dims = grid.dims();
  const VoxelIndex& m = grid.min_index();
  SurfaceHistogram h{std::vector<uint64_t>(dims.z(), 0), std::vector<uint64_t>(dims.z(), 0)};
  std::vector<Surface> scratch;
  for (int y = 0; y < dims.y(); ++y) {
    if ((y & 15) == 0) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("candidate generation"));
      ctx.Report(Stage::kCandidates, 0.5 * y / std::max(1, dims.y()));
    }
    for (int x = 0; x < dims.x(); ++x) {
      ColumnSurfaces(grid, m.x + x, m.y + y, free_needed, scratch);
      for (const Surface& s : scratch) {
        ++h.all[s.z - m.z];
        if (s.roof()) ++h.roofs[s.z - m.z];
      }
    }
  }
  return h;
}

// A floor level: its height (z - min.z), its columns within the band, and the roofs among them.
struct Level {
  int z;
  uint64_t columns;
  uint64_t roofs;
};

// The dominant levels, strongest first with suppression of weaker ones nearby, less those that are
// mostly roofs; ascending.
std::vector<Level> FindLevels(const SurfaceHistogram& h, int band, int free_needed) {
  const int nz = static_cast<int>(h.all.size());
  auto band_sum = [&](const std::vector<uint64_t>& v, int z) {
    uint64_t s = 0;
    for (int k = std::max(0, z - band); k <= std::min(nz - 1, z + band); ++k) s += v[k];
    return s;
  };
  std::vector<uint64_t> score(nz);
  for (int z = 0; z < nz; ++z) score[z] = band_sum(h.all, z);
  std::vector<bool> suppressed(nz, false);
  std::vector<Level> levels;
  uint64_t strongest = 0;
  for (int iter = 0; iter < 32; ++iter) {
    int best = -1;
    for (int z = 0; z < nz; ++z) {
      if (!suppressed[z] && score[z] > 0 && (best < 0 || score[z] > score[best])) best = z;
    }
    if (best < 0) break;
    if (levels.empty()) strongest = score[best];
    if (score[best] * 4 < strongest) break;
    // The level's height: the fullest bin within the band.
    int mode = best;
    for (int k = std::max(0, best - band); k <= std::min(nz - 1, best + band); ++k) {
      if (h.all[k] > h.all[mode]) mode = k;
    }
    levels.push_back({mode, band_sum(h.all, mode), band_sum(h.roofs, mode)});
    for (int z = std::max(0, mode - free_needed + 1); z <= std::min(nz - 1, mode + free_needed - 1); ++z) {
      suppressed[z] = true;
    }
  }
  std::sort(levels.begin(), levels.end(), [](const Level& a, const Level& b) { return a.z < b.z; });
  std::vector<Level> kept;
  for (const Level& l : levels) {
    if (l.roofs * 2 <= l.columns) kept.push_back(l);
  }
  return kept;
}

// The terrain model's ground: every column's standing surfaces (columns y * nx + x relative to the
// grid's minimum; surfaces top to bottom) and which of them belong to the ground component.
struct GroundField {
  int nx = 0, ny = 0;
  std::vector<uint32_t> first;  // per column, its first surface; one more entry at the end
  std::vector<int> z;           // per surface: voxel index z of its top voxel
  std::vector<int> free_above;  // per surface: free voxels above it
  std::vector<uint8_t> ground;  // per surface: in the ground component
  uint64_t columns = 0;         // columns with a ground surface
  uint32_t Column(int x, int y) const { return static_cast<uint32_t>(y) * static_cast<uint32_t>(nx) + x; }
};

uint32_t FindRoot(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// The surface of column (x, y) (relative) with z within `window` of `z_ref` closest to it, or kNoSurface.
int ClosestSurface(const GroundField& f, int x, int y, int z_ref, int window) {
  if (x < 0 || y < 0 || x >= f.nx || y >= f.ny) return kNoSurface;
  int best = kNoSurface;
  const uint32_t c = f.Column(x, y);
  for (uint32_t i = f.first[c]; i < f.first[c + 1]; ++i) {
    if (std::abs(f.z[i] - z_ref) <= window &&
        (best == kNoSurface || std::abs(f.z[i] - z_ref) < std::abs(best - z_ref))) {
      best = f.z[i];
    }
  }
  return best;
}

// Whether the surface at height z of column (x, y) is no steeper than kTerrainMaxSlope along x and
// along y, measured to the closest surfaces `base` columns away on each side (centred when both
// exist; a side with no surface within a 45-degree rise plus a step, a wall or a drop, is left out).
bool GentleSlope(const GroundField& f, int x, int y, int z, int base, int step) {
  const int window = base + step;
  for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
    const int plus = ClosestSurface(f, x + dx * base, y + dy * base, z, window);
    const int minus = ClosestSurface(f, x - dx * base, y - dy * base, z, window);
    double slope = 0;
    if (plus != kNoSurface && minus != kNoSurface) {
      slope = std::abs(plus - minus) / (2.0 * base);
    } else if (plus != kNoSurface || minus != kNoSurface) {
      slope = std::abs((plus != kNoSurface ? plus : minus) - z) / static_cast<double>(base);
    }
    if (slope > kTerrainMaxSlope) return false;
  }
  return true;
}

// The ground of the terrain model: standing surfaces of gentle slope, linked between 4-adjacent
// columns when their heights differ by at most walk_max_step_m (at least a voxel); the largest
// linked component is the ground.
Result<GroundField> FindGround(const OccupancyGrid& grid, int free_needed, const CandidateOptions& o,
                               const JobContext& ctx) {
  const double r = grid.resolution_m();
  const VoxelIndex& m = grid.min_index();
  GroundField f;
  f.nx = grid.dims().x();
  f.ny = grid.dims().y();
  f.first.reserve(static_cast<size_t>(f.nx) * f.ny + 1);
  std::vector<Surface> scratch;
  for (int y = 0; y < f.ny; ++y) {
    if ((y & 15) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("terrain ground"));
    for (int x = 0; x < f.nx; ++x) {
      f.first.push_back(static_cast<uint32_t>(f.z.size()));
      ColumnSurfaces(grid, m.x + x, m.y + y, free_needed, scratch);
      for (const Surface& s : scratch) {
        if (s.roof()) continue;
        f.z.push_back(s.z);
        f.free_above.push_back(s.free_above);
      }
    }
  }
  f.first.push_back(static_cast<uint32_t>(f.z.size()));
  // The slope's base: kSlopeBaseM, but at least so many voxels that one voxel of rise across the
  // centred base (2 x base) is within kTerrainMaxSlope. Any slope rises a voxel at a time; at 0.4 m
  // 0.5 m rounded to 1 voxel, every such rise measured 1 / 2 = 0.5 > 0.36, and the ground broke
  // into strips between them (fr_campus: 1,511 terrain candidates, so auto picked floors).
  const int min_base = static_cast<int>(std::ceil(1.0 / (2.0 * kTerrainMaxSlope) - 1e-9));
  const int base = std::max(min_base, static_cast<int>(std::lround(kSlopeBaseM / r)));
  const int step = std::max(1, static_cast<int>(std::floor(o.walk_max_step_m / r + 1e-9)));
  std::vector<uint8_t> gentle(f.z.size(), 0);
  std::vector<uint32_t> parent(f.z.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  for (int y = 0; y < f.ny; ++y) {
    if ((y & 15) == 0) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("terrain ground"));
      ctx.Report(Stage::kCandidates, 0.5 + 0.25 * y / std::max(1, f.ny));
    }
    for (int x = 0; x < f.nx; ++x) {
      const uint32_t c = f.Column(x, y);
      for (uint32_t i = f.first[c]; i < f.first[c + 1]; ++i) gentle[i] = GentleSlope(f, x, y, f.z[i], base, step);
    }
  }
  for (int y = 0; y < f.ny; ++y) {
    for (int x = 0; x < f.nx; ++x) {
      const uint32_t c = f.Column(x, y);
      for (const auto& [nx, ny] : {std::pair{x + 1, y}, std::pair{x, y + 1}}) {
        if (nx >= f.nx || ny >= f.ny) continue;
        const uint32_t n = f.Column(nx, ny);
        for (uint32_t i = f.first[c]; i < f.first[c + 1]; ++i) {
          for (uint32_t j = f.first[n]; j < f.first[n + 1]; ++j) {
            if (gentle[i] && gentle[j] && std::abs(f.z[i] - f.z[j]) <= step) {
              parent[FindRoot(parent, i)] = FindRoot(parent, j);
            }
          }
        }
      }
    }
  }
  std::vector<uint32_t> size(parent.size(), 0);
  uint32_t largest = 0;
  for (uint32_t i = 0; i < parent.size(); ++i) {
    if (!gentle[i]) continue;
    const uint32_t root = FindRoot(parent, i);
    if (++size[root] > size[largest] || !gentle[largest]) largest = root;
  }
  f.ground.assign(f.z.size(), 0);
  for (int y = 0; y < f.ny; ++y) {
    for (int x = 0; x < f.nx; ++x) {
      const uint32_t c = f.Column(x, y);
      bool any = false;
      for (uint32_t i = f.first[c]; i < f.first[c + 1]; ++i) {
        f.ground[i] = gentle[i] && FindRoot(parent, i) == largest;
        any |= f.ground[i] != 0;
      }
      f.columns += any;
    }
  }
  return f;
}

// The ground's surfaces, and those of them within `band` of a kept level.
struct SurfaceCount {
  uint64_t surfaces = 0, on_levels = 0;
};

SurfaceCount CountOnLevels(const GroundField& f, int min_z, int nz, const std::vector<Level>& kept, int band) {
  std::vector<bool> on_level(nz, false);
  for (const Level& l : kept) {
    for (int k = std::max(0, l.z - band); k <= std::min(nz - 1, l.z + band); ++k) on_level[k] = true;
  }
  SurfaceCount c;
  for (size_t i = 0; i < f.z.size(); ++i) {
    if (!f.ground[i]) continue;
    ++c.surfaces;
    if (on_level[f.z[i] - min_z]) ++c.on_levels;
  }
  return c;
}

// The model to use for `requested`: auto takes floors when at least kFloorShare of the ground's
// surfaces lie on a kept level (or there is no ground), else terrain. The reason gives the test's
// numbers.
GroundChoice ChooseGround(GroundModel requested, const SurfaceCount& count, size_t levels, double band_m) {
  GroundChoice c;
  c.floor_share =
      count.surfaces == 0 ? 0.0 : static_cast<double>(count.on_levels) / static_cast<double>(count.surfaces);
  const std::string measured = std::to_string(static_cast<int>(std::lround(c.floor_share * 100))) +
                               "% of the walkable ground's surfaces lie within " + Num(band_m) + " m of " +
                               std::to_string(levels) + (levels == 1 ? " floor level" : " floor levels");
  if (requested != GroundModel::kAuto) {
    c.model = requested;
    c.reason = std::string(GroundModelName(requested)) + ", as requested; " + measured;
    return c;
  }
  const std::string threshold =
      " (floors from " + std::to_string(static_cast<int>(std::lround(kFloorShare * 100))) + "%)";
  c.model = c.floor_share >= kFloorShare || count.surfaces == 0 ? GroundModel::kFloors : GroundModel::kTerrain;
  c.reason =
      c.model == GroundModel::kFloors ? "floors: " + measured + threshold : "terrain: only " + measured + threshold;
  return c;
}

// One grid position (x, y) over the floor whose top voxel has index z and `free_above` free voxels
// above it: a candidate per height with the headroom and clearance, appended to `out` with `level`.
// Returns how many; counts the rejected heights in *no_clearance.
int PlaceOnFloor(const OccupancyGrid& grid, double x, double y, int z, int free_above,
                 const std::vector<double>& heights, const CandidateOptions& options, int level, CandidateGrid& out,
                 uint64_t* no_clearance) {
  const double top = grid.IndexSpaceToWorld(Eigen::Vector3d(0, 0, z + 1)).z();
  int placed = 0;
  for (double h : heights) {
    const WorldPoint p(x, y, top + h);
    if (free_above < FreeVoxelsNeeded(grid.resolution_m(), h, options.clearance_m) ||
        !HasClearance(grid, p, options.clearance_m)) {
      ++*no_clearance;
      continue;
    }
    out.positions.push_back(p);
    out.floor_z_m.push_back(top);
    out.level.push_back(level);
    out.height_m.push_back(h);
    ++placed;
  }
  return placed;
}

// Candidates over the terrain's ground at (x, y): over each ground surface of the column under it,
// or else over the highest ground surface of the 8 columns around it. Returns how many; counts the
// heights without ground in *no_floor and those rejected in *no_clearance.
int PlaceOnGround(const OccupancyGrid& grid, const GroundField& f, double x, double y,
                  const std::vector<double>& heights, const CandidateOptions& options, CandidateGrid& out,
                  uint64_t* no_floor, uint64_t* no_clearance) {
  const VoxelIndex& m = grid.min_index();
  const Eigen::Vector3d u = grid.WorldToIndexSpace(WorldPoint(x, y, 0));
  const int cx = static_cast<int>(std::floor(u.x())) - m.x, cy = static_cast<int>(std::floor(u.y())) - m.y;
  std::vector<uint32_t> under;
  for (int ring = 0; ring <= 1 && under.empty(); ++ring) {
    uint32_t highest = 0;
    bool found = false;
    for (int dy = -ring; dy <= ring; ++dy) {
      for (int dx = -ring; dx <= ring; ++dx) {
        const int cxx = cx + dx, cyy = cy + dy;
        if (cxx < 0 || cyy < 0 || cxx >= f.nx || cyy >= f.ny) continue;
        const uint32_t c = f.Column(cxx, cyy);
        for (uint32_t i = f.first[c]; i < f.first[c + 1]; ++i) {
          if (!f.ground[i]) continue;
          if (ring == 0) {
            under.push_back(i);
          } else if (!found || f.z[i] > f.z[highest]) {
            highest = i;
            found = true;
          }
        }
      }
    }
    if (found) under.push_back(highest);
  }
  if (under.empty()) *no_floor += heights.size();
  int placed = 0;
  for (uint32_t i : under) {
    placed += PlaceOnFloor(grid, x, y, f.z[i], f.free_above[i], heights, options, -1, out, no_clearance);
  }
  return placed;
}

// Candidates on the terrain model's ground, per grid cell (PlaceOnGround); on_grid (per cell,
// iy * |xs| + ix) gets whether the cell got one.
Status PlaceOnTerrain(const OccupancyGrid& grid, const GroundField& f, const std::vector<double>& xs,
                      const std::vector<double>& ys, const std::vector<double>& heights,
                      const CandidateOptions& options, CandidateGrid& out, std::vector<uint8_t>& on_grid,
                      const JobContext& ctx) {
  on_grid.assign(xs.size() * ys.size(), 0);
  for (size_t iy = 0; iy < ys.size(); ++iy) {
    VC_RETURN_IF_ERROR(ctx.CheckCancelled("candidate generation"));
    ctx.Report(Stage::kCandidates, 0.75 + 0.25 * static_cast<double>(iy) / ys.size());
    for (size_t ix = 0; ix < xs.size(); ++ix) {
      out.cells += heights.size();
      on_grid[iy * xs.size() + ix] = PlaceOnGround(grid, f, xs[ix], ys[iy], heights, options, out,
                                                   &out.rejected_no_floor, &out.rejected_clearance) > 0;
    }
  }
  return Status::Ok();
}

// The terrain's obstacle slice (as FloorSlice's, for PassagePoints), following the ground: each
// column's reference is its lowest ground surface or, for a column without ground (a wall, an
// object, a gap in the map), that of the nearest ground column within grid_spacing_m (4-connected,
// breadth first); a column is blocked if a voxel within the clearance of the lowest tripod height
// above its reference is occupied, or if no ground column is that near.
std::vector<uint8_t> TerrainSlice(const OccupancyGrid& grid, const GroundField& f, const CandidateOptions& o) {
  const double r = grid.resolution_m();
  const VoxelIndex& m = grid.min_index();
  const int above = static_cast<int>(std::floor(LowestHeight(o) / r));
  const int c = static_cast<int>(std::ceil(o.clearance_m / r - 1e-9));
  const int reach = std::max(1, static_cast<int>(std::ceil(o.grid_spacing_m / r - 1e-9)));
  const size_t n = static_cast<size_t>(f.nx) * f.ny;
  std::vector<int> ref(n, kNoSurface), dist(n, -1);
  std::vector<uint32_t> queue;
  for (uint32_t col = 0; col < n; ++col) {
    for (uint32_t i = f.first[col]; i < f.first[col + 1]; ++i) {
      if (f.ground[i]) ref[col] = f.z[i];  // surfaces run top to bottom: the last is the lowest
    }
    if (ref[col] != kNoSurface) {
      dist[col] = 0;
      queue.push_back(col);
    }
  }
  for (size_t head = 0; head < queue.size(); ++head) {
    const uint32_t col = queue[head];
    if (dist[col] >= reach) continue;
    const int x = static_cast<int>(col % f.nx), y = static_cast<int>(col / f.nx);
    for (const auto& [nx, ny] : {std::pair{x + 1, y}, std::pair{x - 1, y}, std::pair{x, y + 1}, std::pair{x, y - 1}}) {
      if (nx < 0 || ny < 0 || nx >= f.nx || ny >= f.ny) continue;
      const uint32_t next = f.Column(nx, ny);
      if (dist[next] >= 0) continue;
      dist[next] = dist[col] + 1;
      ref[next] = ref[col];
      queue.push_back(next);
    }
  }
  std::vector<uint8_t> blocked(n, 1);
  const int z_max = m.z + grid.dims().z() - 1;
  for (uint32_t col = 0; col < n; ++col) {
    if (ref[col] == kNoSurface) continue;
    const int eye = ref[col] + 1 + above;
    bool occupied = false;
    for (int z = std::max(eye - c, m.z); z <= std::min(eye + c, z_max) && !occupied; ++z) {
      occupied = grid.Occupied(m.x + static_cast<int>(col % f.nx), m.y + static_cast<int>(col / f.nx), z);
    }
    blocked[col] = occupied;
  }
  return blocked;
}

// Whether the grid cell nearest to q (per cell iy * |xs| + ix in `on_grid`) got a candidate and q
// lies within grid_spacing_m / 8 of its centre in x and in y (a passage position the grid has).
bool NearAGridCandidate(const WorldPoint& q, const std::vector<double>& xs, const std::vector<double>& ys,
                        const std::vector<uint8_t>& on_grid, double grid_spacing_m) {
  auto nearest = [&](const std::vector<double>& cells, double v) {
    const long i = std::lround((v - cells.front()) / grid_spacing_m);
    return static_cast<size_t>(std::clamp<long>(i, 0, static_cast<long>(cells.size()) - 1));
  };
  const double fine = grid_spacing_m / 4;
  const size_t ix = nearest(xs, q.x()), iy = nearest(ys, q.y());
  return on_grid[iy * xs.size() + ix] && std::abs(xs[ix] - q.x()) < fine / 2 && std::abs(ys[iy] - q.y()) < fine / 2;
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

std::optional<double> GroundTopReached(const OccupancyGrid& grid, const WorldPoint& from, double from_floor_z_m,
                                       double x_m, double y_m, const CandidateOptions& options) {
  const double r = grid.resolution_m();
  const int free_needed = FreeVoxelsNeeded(r, options);
  const int step = std::max(1, static_cast<int>(std::floor(options.walk_max_step_m / r + 1e-9)));
  const Eigen::Vector3d a = grid.WorldToIndexSpace(WorldPoint(from.x(), from.y(), from_floor_z_m));
  const Eigen::Vector3d b = grid.WorldToIndexSpace(WorldPoint(x_m, y_m, from_floor_z_m));
  const int z0 = static_cast<int>(std::lround(a.z())) - 1;  // the floor's top voxel
  int z = z0, last_x = static_cast<int>(std::floor(a.x())), last_y = static_cast<int>(std::floor(a.y()));
  const double run = (b - a).head<2>().norm();  // voxels
  const int samples = std::max(1, static_cast<int>(std::ceil(run * 4)));
  int gap = 0;  // columns in a row without a surface within a step: a gap in the map, crossed up to 2
  std::vector<Surface> scratch;
  for (int k = 1; k <= samples; ++k) {
    const double t = static_cast<double>(k) / samples;
    const int cx = static_cast<int>(std::floor(a.x() + t * (b.x() - a.x())));
    const int cy = static_cast<int>(std::floor(a.y() + t * (b.y() - a.y())));
    if (cx == last_x && cy == last_y) continue;
    last_x = cx;
    last_y = cy;
    ColumnSurfaces(grid, cx, cy, free_needed, scratch);
    int best = kNoSurface;
    for (const Surface& s : scratch) {
      if (s.roof() || std::abs(s.z - z) > step) continue;
      if (best == kNoSurface || std::abs(s.z - z) < std::abs(best - z) ||
          (std::abs(s.z - z) == std::abs(best - z) && s.z > best)) {
        best = s.z;
      }
    }
    if (best != kNoSurface) {
      z = best;
      gap = 0;
      continue;
    }
    // No surface within a step: a wall or an object if anything is occupied from a step below to
    // the headroom above, else a gap in the map (or a drop, which the next columns show).
    bool occupied = false;
    for (int zz = z - step; zz <= z + free_needed && !occupied; ++zz) occupied = grid.Occupied(cx, cy, zz);
    if (occupied || ++gap > 2) return std::nullopt;
  }
  if (gap > 0) return std::nullopt;  // no ground under (x_m, y_m) itself
  if (std::abs(z - z0) * r > kTerrainMaxSlope * run * r + r + 1e-9) return std::nullopt;
  return grid.IndexSpaceToWorld(Eigen::Vector3d(0, 0, z + 1)).z();
}

std::optional<double> MovedStationFloor(const OccupancyGrid& grid, const WorldPoint& from, double from_floor_z_m,
                                        double x_m, double y_m, const CandidateOptions& options) {
  if (options.ground == GroundModel::kTerrain) return GroundTopReached(grid, from, from_floor_z_m, x_m, y_m, options);
  return FloorTopNear(grid, x_m, y_m, from_floor_z_m, options);
}

}  // namespace vc::planner

namespace vc {

std::string_view GroundModelName(GroundModel model) {
  switch (model) {
    case GroundModel::kFloors:
      return "floors";
    case GroundModel::kTerrain:
      return "terrain";
    case GroundModel::kAuto:
      break;
  }
  return "auto";
}

namespace planner {

Result<CandidateGrid> GenerateCandidates(const VoxelScene& scene, const CandidateOptions& options,
                                         const JobContext& ctx) {
  const OccupancyGrid& grid = scene.grid;
  const double r = grid.resolution_m();
  const int free_needed = FreeVoxelsNeeded(r, options);
  const int band = BandVoxels(r);
  CandidateGrid out;
  const std::vector<double> heights =
      options.tripod_heights_m.empty() ? std::vector<double>{options.tripod_height_m} : options.tripod_heights_m;

  // 1. Histogram of standing surfaces over all columns; the floor levels; the ground model.
  const VoxelIndex m = grid.min_index();
  VC_ASSIGN_OR_RETURN(const SurfaceHistogram hist, HistogramSurfaces(grid, free_needed, ctx));
  const std::vector<Level> kept = FindLevels(hist, band, free_needed);
  VC_ASSIGN_OR_RETURN(const GroundField ground, FindGround(grid, free_needed, options, ctx));
  const int auto_band = AutoBandVoxels(r, band);
  out.ground = ChooseGround(options.ground, CountOnLevels(ground, m.z, grid.dims().z(), kept, auto_band), kept.size(),
                            auto_band * r);
  const WorldPoint lo = scene.BoundsMin(), hi = scene.BoundsMax();
  const std::vector<double> xs = AxisCells(lo.x(), hi.x(), options.grid_spacing_m);
  const std::vector<double> ys = AxisCells(lo.y(), hi.y(), options.grid_spacing_m);
  if (out.ground.model == GroundModel::kTerrain) {
    out.ground_columns = ground.columns;
    std::vector<uint8_t> on_grid;
    VC_RETURN_IF_ERROR(PlaceOnTerrain(grid, ground, xs, ys, heights, options, out, on_grid, ctx));
    if (options.doorway_candidates) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("candidate generation"));
      uint64_t no_floor = 0, no_clearance = 0;
      for (const WorldPoint& q : PassagePoints(grid, TerrainSlice(grid, ground, options), options)) {
        if (NearAGridCandidate(q, xs, ys, on_grid, options.grid_spacing_m)) continue;
        out.passage_candidates +=
            PlaceOnGround(grid, ground, q.x(), q.y(), heights, options, out, &no_floor, &no_clearance);
      }
    }
    ctx.Report(Stage::kCandidates, 1.0);
    return out;
  }
  for (const Level& l : kept) {
    out.levels.push_back({grid.IndexSpaceToWorld(Eigen::Vector3d(0, 0, m.z + l.z + 1)).z(), l.columns});
  }

  // 2. Cells of the grid over the footprint, per level. place() examines one position: the floor
  // under it, then each height's headroom and clearance; it appends the kept candidates and
  // returns how many.
  std::vector<Surface> scratch;
  auto place = [&](double x, double y, size_t li, int lz, uint64_t* no_floor, uint64_t* no_clearance) {
    const Eigen::Vector3d u = grid.WorldToIndexSpace(WorldPoint(x, y, lo.z()));
    int free_above = 0;
    const int z = SurfaceNear(grid, static_cast<int>(std::floor(u.x())), static_cast<int>(std::floor(u.y())), lz, band,
                              free_needed, scratch, &free_above);
    if (z == kNoSurface) {
      *no_floor += heights.size();
      return 0;
    }
    return PlaceOnFloor(grid, x, y, z, free_above, heights, options, static_cast<int>(li), out, no_clearance);
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
    uint64_t no_floor = 0, no_clearance = 0;
    for (size_t li = 0; li < kept.size(); ++li) {
      VC_RETURN_IF_ERROR(ctx.CheckCancelled("candidate generation"));
      const int lz = m.z + kept[li].z;
      for (const WorldPoint& q : PassagePoints(grid, FloorSlice(grid, lz + 1, options), options)) {
        if (NearAGridCandidate(q, xs, ys, on_grid[li], options.grid_spacing_m)) continue;
        out.passage_candidates += place(q.x(), q.y(), li, lz, &no_floor, &no_clearance);
      }
    }
  }
  ctx.Report(Stage::kCandidates, 1.0);
  return out;
}

}  // namespace planner
}  // namespace vc
