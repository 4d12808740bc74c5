#include "vc/scene/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace vc {
namespace {

std::string FormatBytes(uint64_t b) {
  std::ostringstream os;
  os.precision(3);
  if (b >= (uint64_t{1} << 30))
    os << double(b) / double(uint64_t{1} << 30) << " GiB";
  else
    os << double(b) / double(1 << 20) << " MiB";
  return os.str();
}

int FloorDiv8(int v) { return v >= 0 ? v / 8 : -((-v + 7) / 8); }

}  // namespace

uint64_t OccupancyGrid::BytesNeeded(const VoxelIndex& min, const VoxelIndex& max, uint64_t occupied_bricks) {
  const uint64_t bx = uint64_t(max.x - min.x) / kBrick + 1;
  const uint64_t by = uint64_t(max.y - min.y) / kBrick + 1;
  const uint64_t bz = uint64_t(max.z - min.z) / kBrick + 1;
  return bx * by * bz * sizeof(int32_t) + occupied_bricks * kBrick * sizeof(uint64_t);
}

Result<OccupancyGrid> OccupancyGrid::Build(double resolution_m, const std::vector<VoxelIndex>& occupied,
                                           uint64_t memory_budget_bytes) {
  if (!std::isfinite(resolution_m) || resolution_m <= 0) {
    return InvalidArgumentError("resolution must be a positive number of metres, got " + std::to_string(resolution_m));
  }
  if (occupied.empty()) return InvalidArgumentError("the scene has no occupied voxels");
  VoxelIndex lo = occupied.front(), hi = occupied.front();
  for (const VoxelIndex& v : occupied) {
    lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
  }
  // Align the box to bricks of 8 in absolute index space (deterministic brick layout).
  lo = {FloorDiv8(lo.x) * kBrick, FloorDiv8(lo.y) * kBrick, FloorDiv8(lo.z) * kBrick};
  const uint64_t nbx = uint64_t(hi.x - lo.x) / kBrick + 1, nby = uint64_t(hi.y - lo.y) / kBrick + 1,
                 nbz = uint64_t(hi.z - lo.z) / kBrick + 1;
  const uint64_t slots = nbx * nby * nbz;
  // The slot array alone must fit before we count bricks (which needs it).
  const uint64_t slot_bytes = slots * sizeof(int32_t);
  auto refuse = [&](uint64_t need) {
    const double ex = (hi.x - lo.x + 1) * resolution_m, ey = (hi.y - lo.y + 1) * resolution_m,
                 ez = (hi.z - lo.z + 1) * resolution_m;
    // Memory scales about with 1/r^3 for the slots and 1/r^2 for surface bricks; suggest the
    // resolution that brings the dominant term under budget with some headroom.
    const double factor = std::cbrt(double(need) / double(memory_budget_bytes) * 1.25);
    std::ostringstream os;
    os.precision(4);
    os << "the scene spans " << ex << " x " << ey << " x " << ez << " m; at resolution " << resolution_m
       << " m its traversal grid needs " << FormatBytes(need) << ", over the memory budget of "
       << FormatBytes(memory_budget_bytes) << "; use a resolution of at least "
       << std::ceil(resolution_m * std::max(factor, 1.0) * 1000.0) / 1000.0
       << " m, raise the budget, or crop the scene";
    return ResourceExhaustedError(os.str());
  };
  if (slot_bytes > memory_budget_bytes || slots > std::numeric_limits<uint32_t>::max() * uint64_t{64}) {
    return refuse(slot_bytes);
  }
  OccupancyGrid g;
  g.resolution_m_ = resolution_m;
  g.inv_resolution_ = 1.0 / resolution_m;
  g.min_ = lo;
  g.bdims_ = Eigen::Vector3i(int(nbx), int(nby), int(nbz));
  g.dims_ = g.bdims_ * kBrick;
  g.bricks_.assign(slots, 0);
  uint64_t used = 0;
  for (const VoxelIndex& v : occupied) {
    int32_t& slot = g.bricks_[g.BrickLinear(uint32_t(v.x - lo.x) >> kBrickShift, uint32_t(v.y - lo.y) >> kBrickShift,
                                            uint32_t(v.z - lo.z) >> kBrickShift)];
    if (slot == 0) {
      if (used + 1 >= uint64_t(std::numeric_limits<int32_t>::max())) return refuse(~uint64_t{0});
      slot = int32_t(++used);
    }
  }
  const uint64_t need = BytesNeeded(lo, hi, used);
  if (need > memory_budget_bytes) return refuse(need);
  g.payload_.assign(used * kBrick, 0);
  for (const VoxelIndex& v : occupied) {
    const uint32_t rx = uint32_t(v.x - lo.x), ry = uint32_t(v.y - lo.y), rz = uint32_t(v.z - lo.z);
    const uint32_t slot = uint32_t(g.bricks_[g.BrickLinear(rx >> kBrickShift, ry >> kBrickShift, rz >> kBrickShift)]);
    g.payload_[uint64_t(slot - 1) * kBrick + (rz & 7)] |= uint64_t{1} << (((ry & 7) << 3) | (rx & 7));
  }
  g.ComputeBrickDistances();
  g.ComputeFreeExtents();  // reads the distances
  return g;
}

void OccupancyGrid::ComputeBrickDistances() {
  // Exact Chebyshev (L-infinity) distance transform, separable: D = min over q of
  // max(|dx|, |dy|, |dz|), computed one axis at a time as h(i) = min_r max(r, f(i-r), f(i+r))
  // over r <= kCap. Bricks outside the grid are empty and do not count as sources.
  constexpr int kCap = 255;
  const int nx = bdims_.x(), ny = bdims_.y(), nz = bdims_.z();
  std::vector<int> d(bricks_.size());
  for (size_t i = 0; i < bricks_.size(); ++i) d[i] = bricks_[i] > 0 ? 0 : kCap;
  std::vector<int> line, out;
  auto pass = [&](int n, int count_a, int count_b, auto index) {
    line.resize(n);
    out.resize(n);
    for (int a = 0; a < count_a; ++a)
      for (int b = 0; b < count_b; ++b) {
        for (int i = 0; i < n; ++i) line[i] = d[index(i, a, b)];
        for (int i = 0; i < n; ++i) {
          int best = line[i];
          for (int r = 1; r < best; ++r) {
            const int lo = i - r >= 0 ? line[i - r] : kCap, hi = i + r < n ? line[i + r] : kCap;
            best = std::min(best, std::max(r, std::min(lo, hi)));
          }
          out[i] = best;
        }
        for (int i = 0; i < n; ++i) d[index(i, a, b)] = out[i];
      }
  };
  pass(nx, ny, nz, [&](int i, int a, int b) { return BrickLinear(i, a, b); });
  pass(ny, nx, nz, [&](int i, int a, int b) { return BrickLinear(a, i, b); });
  pass(nz, nx, ny, [&](int i, int a, int b) { return BrickLinear(a, b, i); });
  for (size_t i = 0; i < d.size(); ++i) {
    if (d[i] > 0) bricks_[i] = -std::min(d[i], kCap);
  }
}

void OccupancyGrid::ComputeFreeExtents() {
  const int nx = bdims_.x(), ny = bdims_.y(), nz = bdims_.z();
  // Counts of non-empty bricks in any box of bricks, from a 3-D prefix sum (a transient table of
  // one uint32 per brick, skipped on grids too large for it: their boxes stay cubes).
  const uint64_t px = uint64_t(nx) + 1, py = uint64_t(ny) + 1, pz = uint64_t(nz) + 1;
  if (px * py * pz > kMaxExtentTable) return;
  std::vector<uint32_t> sum(px * py * pz, 0);
  auto at = [&](int x, int y, int z) -> uint32_t& { return sum[(uint64_t(z) * py + uint64_t(y)) * px + uint64_t(x)]; };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        at(x + 1, y + 1, z + 1) = uint32_t(bricks_[BrickLinear(x, y, z)] > 0) + at(x, y + 1, z + 1) +
                                  at(x + 1, y, z + 1) + at(x + 1, y + 1, z) - at(x, y, z + 1) - at(x, y + 1, z) -
                                  at(x + 1, y, z) + at(x, y, z);
      }
  const int n[3] = {nx, ny, nz};
  // Whether the box of bricks [lo, hi] holds no non-empty brick (bricks outside the grid are empty).
  auto free = [&](const int lo[3], const int hi[3]) {
    int a[3], b[3];
    for (int i = 0; i < 3; ++i) {
      a[i] = std::max(lo[i], 0), b[i] = std::min(hi[i], n[i] - 1);
      if (a[i] > b[i]) return true;
    }
    const uint32_t count = at(b[0] + 1, b[1] + 1, b[2] + 1) - at(a[0], b[1] + 1, b[2] + 1) -
                           at(b[0] + 1, a[1], b[2] + 1) - at(b[0] + 1, b[1] + 1, a[2]) + at(a[0], a[1], b[2] + 1) +
                           at(a[0], b[1] + 1, a[2]) + at(b[0] + 1, a[1], a[2]) - at(a[0], a[1], a[2]);
    return count == 0;
  };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        int32_t& entry = bricks_[BrickLinear(x, y, z)];
        if (entry >= 0) continue;  // non-empty
        const int k = -entry - 1;  // the cube of bricks within k is free
        int lo[3] = {x - k, y - k, z - k}, hi[3] = {x + k, y + k, z + k};
        int extra[6] = {0, 0, 0, 0, 0, 0};
        bool open[6] = {true, true, true, true, true, true};
        // One layer at a time, round the six sides, while the layer is free.
        for (bool grew = true; grew;) {
          grew = false;
          for (int side = 0; side < 6; ++side) {
            if (!open[side]) continue;
            const int axis = side / 2;
            int llo[3] = {lo[0], lo[1], lo[2]}, lhi[3] = {hi[0], hi[1], hi[2]};
            llo[axis] = lhi[axis] = side % 2 == 0 ? hi[axis] + 1 : lo[axis] - 1;
            if (!free(llo, lhi)) {
              open[side] = false;
              continue;
            }
            (side % 2 == 0 ? hi[axis] : lo[axis]) = llo[axis];
            grew = true;
            if (++extra[side] == kMaxExtra) open[side] = false;
          }
        }
        int32_t code = -entry;
        for (int side = 0; side < 6; ++side) code |= extra[side] << (kExtraShift + kExtraBits * side);
        entry = -code;
      }
}

uint64_t OccupancyGrid::memory_bytes() const {
  return bricks_.size() * sizeof(int32_t) + payload_.size() * sizeof(uint64_t);
}

WorldPoint OccupancyGrid::VoxelCenter(const VoxelIndex& v) const { return KeyToCoord(resolution_m_, IndexToKey(v)); }

VoxelIndex OccupancyGrid::WorldToIndex(const WorldPoint& p) const {
  return {int(std::floor(inv_resolution_ * p.x())), int(std::floor(inv_resolution_ * p.y())),
          int(std::floor(inv_resolution_ * p.z()))};
}

bool CoordToKey(double resolution_m, const WorldPoint& p, VoxelKey* key) {
  const double f = 1.0 / resolution_m;
  uint16_t k[3];
  for (int i = 0; i < 3; ++i) {
    const double s = f * p[i];
    if (!std::isfinite(s)) return false;
    const double fl = std::floor(s);
    if (fl < -kKeyOffset || fl >= kKeyOffset) return false;
    k[i] = uint16_t(int(fl) + kKeyOffset);
  }
  *key = {k[0], k[1], k[2]};
  return true;
}

WorldPoint KeyToCoord(double resolution_m, const VoxelKey& key) {
  // OctoMap: ((double)((int)key - (int)tree_max_val) + 0.5) * resolution
  return {(double(int(key.x) - kKeyOffset) + 0.5) * resolution_m,
          (double(int(key.y) - kKeyOffset) + 0.5) * resolution_m,
          (double(int(key.z) - kKeyOffset) + 0.5) * resolution_m};
}

}  // namespace vc
