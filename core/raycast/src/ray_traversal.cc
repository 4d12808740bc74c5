#include "vc/raycast/ray_traversal.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vc/raycast/walk.h"

namespace vc {
namespace {

using internal::kInf;
using internal::Walk;

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

using internal::JumpAcrossFreeBrickBox;

// GCC's straight-line vectoriser merges the reload of t_max[0] and t_max[1] at the top of the outer
// loop below into one 16-byte load of two values just stored one at a time (after a jump), which
// the store buffer cannot forward: 5.5 % of FirstOccupied's profile samples waited on it (fr_campus,
// exact evaluation). Without it the evaluation is 1-5 % faster (docs/BENCHMARKS.md, "What was
// tried"); the code and its answers are the same. Other compilers (clang, for the sanitizer builds)
// get the function as it was.
#if defined(__GNUC__) && !defined(__clang__)
#define VC_NO_SLP_VECTORIZE __attribute__((optimize("no-tree-slp-vectorize")))
#else
#define VC_NO_SLP_VECTORIZE
#endif

VC_NO_SLP_VECTORIZE std::optional<VoxelIndex> FirstOccupied(const OccupancyGrid& grid, const Eigen::Vector3d& a,
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
    if (need_jump && !JumpAcrossFreeBrickBox(grid, brick, rel, lo3, w)) return std::nullopt;
    if (w.remaining == 0) return std::nullopt;
    w.Advance();
  }
}

}  // namespace vc
