#include "vc/core/ray_traversal.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Shared set-up of the Amanatides & Woo walk: start voxel, per-axis step, t of the first boundary
// crossing, t between crossings, and the number of steps each axis must take.
struct Walk {
  int cur[3];
  int step[3];
  int left[3];
  double t_max[3];
  double t_delta[3];
  int remaining;

  Walk(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    remaining = 0;
    for (int i = 0; i < 3; ++i) {
      const double fa = std::floor(a[i]);
      const double fb = std::floor(b[i]);
      cur[i] = int(fa);
      const double d = b[i] - a[i];
      if (d > 0) {
        step[i] = 1;
        t_delta[i] = 1.0 / d;
        t_max[i] = (fa + 1.0 - a[i]) / d;
        left[i] = int(fb) - cur[i];
      } else if (d < 0) {
        step[i] = -1;
        t_delta[i] = -1.0 / d;
        t_max[i] = (fa - a[i]) / d;
        left[i] = cur[i] - int(fb);
      } else {
        step[i] = 0;
        t_delta[i] = kInf;
        t_max[i] = kInf;
        left[i] = 0;
      }
      if (left[i] <= 0) {
        left[i] = 0;
        t_max[i] = kInf;
      }
      remaining += left[i];
    }
  }

  // Advances to the next voxel. Tie rule: the highest axis among equal t_max (z, then y, then x).
  void Advance() {
    int axis = 2;
    if (t_max[1] < t_max[axis]) axis = 1;
    if (t_max[0] < t_max[axis]) axis = 0;
    cur[axis] += step[axis];
    if (--left[axis] == 0) {
      t_max[axis] = kInf;
    } else {
      t_max[axis] += t_delta[axis];
    }
    --remaining;
  }
};

}  // namespace

RayTraversal::RayTraversal(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Walk w(a, b);
  first_.cur_ = {w.cur[0], w.cur[1], w.cur[2]};
  for (int i = 0; i < 3; ++i) {
    first_.step_[i] = w.step[i];
    first_.t_max_[i] = w.t_max[i];
    first_.t_delta_[i] = w.t_delta[i];
    first_.left_[i] = w.left[i];
  }
  first_.remaining_ = w.remaining;
  first_.done_ = false;
}

RayTraversal::Iterator& RayTraversal::Iterator::operator++() {
  if (remaining_ == 0) {
    done_ = true;
    return *this;
  }
  int axis = 2;
  if (t_max_[1] < t_max_[axis]) axis = 1;
  if (t_max_[0] < t_max_[axis]) axis = 0;
  int* c[3] = {&cur_.x, &cur_.y, &cur_.z};
  *c[axis] += step_[axis];
  if (--left_[axis] == 0) {
    t_max_[axis] = kInf;
  } else {
    t_max_[axis] += t_delta_[axis];
  }
  --remaining_;
  return *this;
}

namespace {

// Jumps the walk `w` (positioned in an empty brick) to the last voxel it visits inside the free
// box of bricks around that brick. Returns false if the walk ends inside the box (no hit).
// Every voxel skipped lies inside the box, which holds no occupied voxel.
bool JumpAcrossFreeBox(const OccupancyGrid& grid, uint64_t brick, const uint32_t rel[3], const int lo3[3], Walk& w) {
  const int k = grid.BrickDistance(brick) - 1;
  int box_lo[3], box_hi[3], steps_to_exit[3];
  bool end_inside = true;
  double t_exit = kInf;
  for (int i = 0; i < 3; ++i) {
    const int brick_i = int(rel[i] >> OccupancyGrid::kBrickShift);
    box_lo[i] = lo3[i] + (brick_i - k) * OccupancyGrid::kBrick;
    box_hi[i] = lo3[i] + (brick_i + k + 1) * OccupancyGrid::kBrick - 1;
    const int end_i = w.cur[i] + w.step[i] * w.left[i];
    end_inside = end_inside && end_i >= box_lo[i] && end_i <= box_hi[i];
    steps_to_exit[i] = w.step[i] > 0 ? box_hi[i] - w.cur[i] : w.step[i] < 0 ? w.cur[i] - box_lo[i] : 0;
    if (w.step[i] != 0 && w.left[i] > steps_to_exit[i]) {
      t_exit = std::min(t_exit, w.t_max[i] + steps_to_exit[i] * w.t_delta[i]);
    }
  }
  if (end_inside) return false;
  for (int i = 0; i < 3; ++i) {
    if (w.left[i] == 0 || !(w.t_max[i] < t_exit)) continue;
    // Crossings of axis i strictly before t_exit, never past the box or the walk's end.
    int n = int(std::ceil((t_exit - w.t_max[i]) / w.t_delta[i]));
    n = std::clamp(n, 0, std::min(steps_to_exit[i], w.left[i]));
    if (n == 0) continue;
    w.cur[i] += w.step[i] * n;
    w.left[i] -= n;
    w.remaining -= n;
    w.t_max[i] = w.left[i] == 0 ? kInf : w.t_max[i] + n * w.t_delta[i];
  }
  return true;
}

}  // namespace

std::optional<VoxelIndex> FirstOccupied(const OccupancyGrid& grid, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b, const VoxelIndex* transparent) {
  Walk w(a, b);
  const VoxelIndex skip = transparent ? *transparent : VoxelIndex{INT32_MIN, INT32_MIN, INT32_MIN};
  const VoxelIndex& lo = grid.min_index();
  const int lo3[3] = {lo.x, lo.y, lo.z};
  const uint32_t nx = uint32_t(grid.dims().x()), ny = uint32_t(grid.dims().y()), nz = uint32_t(grid.dims().z());
  // The box is convex: a segment that started inside it and left it never comes back.
  bool was_inside = false;
  while (true) {
    // Hot loop on locals; the Walk struct is only synchronised around jumps.
    int x = w.cur[0], y = w.cur[1], z = w.cur[2];
    double tx = w.t_max[0], ty = w.t_max[1], tz = w.t_max[2];
    int lx = w.left[0], ly = w.left[1], lz = w.left[2];
    int remaining = w.remaining;
    const int sx = w.step[0], sy = w.step[1], sz = w.step[2];
    const double dx = w.t_delta[0], dy = w.t_delta[1], dz = w.t_delta[2];
    uint64_t brick = 0;
    uint32_t rel[3];
    bool need_jump = false;
    while (true) {
      rel[0] = uint32_t(x - lo3[0]);
      rel[1] = uint32_t(y - lo3[1]);
      rel[2] = uint32_t(z - lo3[2]);
      if (rel[0] < nx && rel[1] < ny && rel[2] < nz) {
        was_inside = true;
        brick = grid.BrickLinear(rel[0] >> 3, rel[1] >> 3, rel[2] >> 3);
        const uint32_t slot = grid.BrickSlot(brick);
        if (slot == 0) {
          need_jump = true;
          break;
        }
        if ((grid.BrickBits(slot)[rel[2] & 7] >> (((rel[1] & 7) << 3) | (rel[0] & 7))) & 1u) {
          const VoxelIndex v{x, y, z};
          if (v != skip) return v;
        }
      } else if (was_inside) {
        return std::nullopt;
      }
      if (remaining == 0) return std::nullopt;
      // Tie rule: z, then y, then x among equal parameters (OctoMap's).
      if (tz <= ty && tz <= tx) {
        z += sz;
        tz = --lz == 0 ? kInf : tz + dz;
      } else if (ty <= tx) {
        y += sy;
        ty = --ly == 0 ? kInf : ty + dy;
      } else {
        x += sx;
        tx = --lx == 0 ? kInf : tx + dx;
      }
      --remaining;
    }
    w.cur[0] = x, w.cur[1] = y, w.cur[2] = z;
    w.t_max[0] = tx, w.t_max[1] = ty, w.t_max[2] = tz;
    w.left[0] = lx, w.left[1] = ly, w.left[2] = lz;
    w.remaining = remaining;
    if (need_jump && !JumpAcrossFreeBox(grid, brick, rel, lo3, w)) return std::nullopt;
    if (w.remaining == 0) return std::nullopt;
    w.Advance();
  }
}

}  // namespace vc
