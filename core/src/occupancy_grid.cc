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
  return bx * by * bz * (sizeof(uint32_t) + sizeof(uint8_t)) + occupied_bricks * kBrick * sizeof(uint64_t);
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
  const uint64_t slot_bytes = slots * (sizeof(uint32_t) + sizeof(uint8_t));
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
    uint32_t& slot = g.bricks_[g.BrickLinear(uint32_t(v.x - lo.x) >> kBrickShift, uint32_t(v.y - lo.y) >> kBrickShift,
                                             uint32_t(v.z - lo.z) >> kBrickShift)];
    if (slot == 0) {
      if (used + 1 >= std::numeric_limits<uint32_t>::max()) return refuse(~uint64_t{0});
      slot = uint32_t(++used);
    }
  }
  const uint64_t need = BytesNeeded(lo, hi, used);
  if (need > memory_budget_bytes) return refuse(need);
  g.payload_.assign(used * kBrick, 0);
  for (const VoxelIndex& v : occupied) {
    const uint32_t rx = uint32_t(v.x - lo.x), ry = uint32_t(v.y - lo.y), rz = uint32_t(v.z - lo.z);
    const uint32_t slot = g.bricks_[g.BrickLinear(rx >> kBrickShift, ry >> kBrickShift, rz >> kBrickShift)];
    g.payload_[uint64_t(slot - 1) * kBrick + (rz & 7)] |= uint64_t{1} << (((ry & 7) << 3) | (rx & 7));
  }
  g.ComputeBrickDistances();
  const uint64_t voxels = uint64_t(g.dims_.x()) * uint64_t(g.dims_.y()) * uint64_t(g.dims_.z());
  if (need + voxels <= memory_budget_bytes) g.ComputeVoxelDistances();
  return g;
}

void OccupancyGrid::ComputeVoxelDistances() {
  // Chessboard distance transform, exact with two raster passes over the 26-neighbourhood with
  // unit weights (Rosenfeld & Pfaltz 1966): the chessboard metric is the path metric of 26-steps.
  const int nx = dims_.x(), ny = dims_.y(), nz = dims_.z();
  voxel_distance_.assign(uint64_t(nx) * ny * nz, 255);
  for (uint64_t b = 0; b < bricks_.size(); ++b) {
    if (bricks_[b] == 0) continue;
    const uint64_t* bits = &payload_[uint64_t(bricks_[b] - 1) * kBrick];
    const int bx = int(b % uint64_t(bdims_.x())), by = int((b / uint64_t(bdims_.x())) % uint64_t(bdims_.y())),
              bz = int(b / (uint64_t(bdims_.x()) * uint64_t(bdims_.y())));
    for (int z = 0; z < kBrick; ++z)
      for (int yx = 0; yx < 64; ++yx)
        if ((bits[z] >> yx) & 1u)
          voxel_distance_[VoxelLinear(bx * kBrick + (yx & 7), by * kBrick + (yx >> 3), bz * kBrick + z)] = 0;
  }
  uint8_t* d = voxel_distance_.data();
  const int64_t sx = 1, sy = nx, sz = int64_t(nx) * ny;
  auto relax = [&](int x, int y, int z, int dir) {
    const int64_t p = z * sz + y * sy + x * sx;
    int best = d[p];
    if (best == 0) return;
    for (int dz = -1; dz <= 1; ++dz) {
      const int zz = z + dz * dir;
      if (zz < 0 || zz >= nz) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = y + dy * dir;
        if (yy < 0 || yy >= ny) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          // Only neighbours already visited in this pass's raster order.
          if (dz > 0 || (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0)))) continue;
          const int xx = x + dx * dir;
          if (xx < 0 || xx >= nx) continue;
          best = std::min(best, d[zz * sz + yy * sy + xx * sx] + 1);
        }
      }
    }
    d[p] = uint8_t(std::min(best, 255));
  };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) relax(x, y, z, 1);
  for (int z = nz - 1; z >= 0; --z)
    for (int y = ny - 1; y >= 0; --y)
      for (int x = nx - 1; x >= 0; --x) relax(x, y, z, -1);
}

void OccupancyGrid::ComputeBrickDistances() {
  // Exact Chebyshev (L-infinity) distance transform, separable: D = min over q of
  // max(|dx|, |dy|, |dz|), computed one axis at a time as h(i) = min_r max(r, f(i-r), f(i+r))
  // over r <= kCap. Bricks outside the grid are empty and do not count as sources.
  constexpr int kCap = 255;
  const int nx = bdims_.x(), ny = bdims_.y(), nz = bdims_.z();
  std::vector<int> d(bricks_.size());
  for (size_t i = 0; i < bricks_.size(); ++i) d[i] = bricks_[i] ? 0 : kCap;
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
  brick_distance_.resize(d.size());
  for (size_t i = 0; i < d.size(); ++i) brick_distance_[i] = uint8_t(std::min(d[i], kCap));
}

uint64_t OccupancyGrid::memory_bytes() const {
  return bricks_.size() * sizeof(uint32_t) + brick_distance_.size() + payload_.size() * sizeof(uint64_t) +
         voxel_distance_.size();
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
