#include "vc/core/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace vc {
namespace {

std::string FormatBytes(uint64_t b) {
  std::ostringstream os;
  os.precision(3);
  if (b >= (uint64_t{1} << 30)) os << double(b) / double(uint64_t{1} << 30) << " GiB";
  else os << double(b) / double(1 << 20) << " MiB";
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
    return InvalidArgumentError("resolution must be a positive number of metres, got " +
                                std::to_string(resolution_m));
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
  return {(double(int(key.x) - kKeyOffset) + 0.5) * resolution_m, (double(int(key.y) - kKeyOffset) + 0.5) * resolution_m,
          (double(int(key.z) - kKeyOffset) + 0.5) * resolution_m};
}

}  // namespace vc
