#include "vc/core/ray_traversal.h"

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

std::optional<VoxelIndex> FirstOccupied(const OccupancyGrid& grid, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b, const VoxelIndex* transparent) {
  Walk w(a, b);
  const VoxelIndex skip = transparent ? *transparent : VoxelIndex{INT32_MIN, INT32_MIN, INT32_MIN};
  while (true) {
    if (grid.Occupied(w.cur[0], w.cur[1], w.cur[2])) {
      const VoxelIndex v{w.cur[0], w.cur[1], w.cur[2]};
      if (v != skip) return v;
    }
    if (w.remaining == 0) return std::nullopt;
    w.Advance();
  }
}

}  // namespace vc
