// Internal to vc_core: the Amanatides & Woo (1987) walk state and the exact jumps across free
// boxes used by FirstOccupied (ray_traversal.cc). Any other traversal must share this code or
// perform exactly its operations: a jump adds n * t_delta in one go, so the jump policy itself
// decides later tie-breaks. The SIMD kernel (ray_batch.cc) re-states Walk's set-up and
// JumpAcrossBox lane-wise, operation for operation; a change here must be made there too, and
// tests/core/raycast/ray_batch_test.cc fails if the two disagree. Plain scalar double code for the
// baseline ISA. Re-entrant; no state beyond the Walk. FreeCone (surface_groups.cc) uses
// FreeBrickBox too, so that the cone test skips the same boxes the walks jump across.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "vc/scene/occupancy_grid.h"

namespace vc::internal {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

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

// Jumps the walk `w` to the last voxel it visits inside the box [box_lo, box_hi] (voxel indices)
// that contains its current voxel and holds no occupied voxel. Returns false if the walk ends
// inside the box (so it meets nothing). Every voxel skipped lies inside the box: counts are
// clamped, so rounding in the jump can only shorten it, never skip a voxel outside.
inline bool JumpAcrossBox(const int box_lo[3], const int box_hi[3], Walk& w) {
  int steps_to_exit[3];
  bool end_inside = true;
  double t_exit = kInf;
  int exit_axis = -1;
  for (int i = 0; i < 3; ++i) {
    const int end_i = w.cur[i] + w.step[i] * w.left[i];
    end_inside = end_inside && end_i >= box_lo[i] && end_i <= box_hi[i];
    steps_to_exit[i] = w.step[i] > 0 ? box_hi[i] - w.cur[i] : w.step[i] < 0 ? w.cur[i] - box_lo[i] : 0;
    if (w.step[i] != 0 && w.left[i] > steps_to_exit[i]) {
      const double t = w.t_max[i] + steps_to_exit[i] * w.t_delta[i];
      if (t < t_exit) t_exit = t, exit_axis = i;
    }
  }
  if (end_inside) return false;
  for (int i = 0; i < 3; ++i) {
    if (w.left[i] == 0 || !(w.t_max[i] < t_exit)) continue;
    // Crossings of axis i strictly before t_exit, never past the box or the walk's end. For the
    // axis that defines t_exit the quotient is steps_to_exit up to rounding, and the clamp makes
    // it exactly that: no division needed.
    // The clamp is done in double before converting, so a quotient that is NaN or beyond int's
    // range is well defined (0 or the limit); the SIMD kernel (ray_batch.cc) does the same.
    const int limit = std::min(steps_to_exit[i], w.left[i]);
    int n = limit;
    if (i != exit_axis) {
      const double q = std::ceil((t_exit - w.t_max[i]) / w.t_delta[i]);
      n = !(q > 0) ? 0 : q >= double(limit) ? limit : int(q);
    }
    if (n == 0) continue;
    w.cur[i] += w.step[i] * n;
    w.left[i] -= n;
    w.remaining -= n;
    w.t_max[i] = w.left[i] == 0 ? kInf : w.t_max[i] + n * w.t_delta[i];
  }
  return true;
}

// The free box of bricks around an empty brick, in voxel indices [box_lo, box_hi]: the bricks
// within its distance - 1, widened on each side by the grid's extra layers
// (OccupancyGrid::ExtraBricks). `brick` is the linear number of the brick holding the voxel at
// rel (relative to the grid's smallest index lo3); the brick must be empty.
inline void FreeBrickBox(const OccupancyGrid& grid, uint64_t brick, const uint32_t rel[3], const int lo3[3],
                         int box_lo[3], int box_hi[3]) {
  const int k = grid.BrickDistance(brick) - 1;
  for (int i = 0; i < 3; ++i) {
    const int brick_i = int(rel[i] >> OccupancyGrid::kBrickShift);
    box_lo[i] = lo3[i] + (brick_i - k - grid.ExtraBricks(brick, 2 * i + 1)) * OccupancyGrid::kBrick;
    box_hi[i] = lo3[i] + (brick_i + k + grid.ExtraBricks(brick, 2 * i) + 1) * OccupancyGrid::kBrick - 1;
  }
}

// Jumps across the free box of bricks around an empty brick (FreeBrickBox), as the SIMD
// kernel's jump does.
inline bool JumpAcrossFreeBrickBox(const OccupancyGrid& grid, uint64_t brick, const uint32_t rel[3], const int lo3[3],
                                   Walk& w) {
  int box_lo[3], box_hi[3];
  FreeBrickBox(grid, brick, rel, lo3, box_lo, box_hi);
  return JumpAcrossBox(box_lo, box_hi, w);
}

}  // namespace vc::internal
