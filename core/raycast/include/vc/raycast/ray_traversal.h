// Amanatides & Woo (1987) voxel traversal over an OccupancyGrid.
//
// The segment from a to b (continuous index-space coordinates, u = p / r; see occupancy_grid.h)
// visits, in order, every voxel whose interior it passes through, from the voxel containing a to
// the voxel containing b; a step never skips a face-adjacent voxel. Ties (the segment crossing an
// edge or a corner exactly) are broken by a fixed rule, the one OctoMap's castRay uses: among the
// axes whose boundary is crossed at the same parameter, step z first, then y, then x. Each axis
// takes exactly |floor(b) - floor(a)| steps, so the walk always ends in the voxel containing b.
// The rule is documented in docs/VISIBILITY.md and pinned by tests/core/raycast/ray_traversal_test.cc.
//
// RayTraversal is the plain, readable range used by tests and cold paths
// (`for (const VoxelIndex& v : RayTraversal(a, b))`). FirstOccupied is the hot path: the same
// stepping, fused with the occupancy test and empty-brick skipping, giving exactly the same answer
// as walking RayTraversal voxel by voxel. Both are re-entrant and allocation-free.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "vc/base/geometry.h"
#include "vc/scene/occupancy_grid.h"

namespace vc {

class RayTraversal {
 public:
  // Voxels from the one containing `a` to the one containing `b` (both in index space).
  RayTraversal(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

  class Iterator {
   public:
    const VoxelIndex& operator*() const { return cur_; }
    Iterator& operator++();
    bool operator!=(const Iterator& o) const { return done_ != o.done_; }

   private:
    friend class RayTraversal;
    VoxelIndex cur_;
    int step_[3] = {0, 0, 0};
    int left_[3] = {0, 0, 0};  // steps each axis still has to take
    double t_max_[3] = {0, 0, 0};
    double t_delta_[3] = {0, 0, 0};
    int remaining_ = 0;  // voxels still to visit after cur_
    bool done_ = true;
  };

  Iterator begin() const { return first_; }
  Iterator end() const { return Iterator(); }

 private:
  Iterator first_;
};

// The first occupied voxel on the segment a -> b (index space), in traversal order, or nullopt if
// the segment reaches the voxel containing b without meeting one. The voxel `transparent` (if
// given) is treated as free.
std::optional<VoxelIndex> FirstOccupied(const OccupancyGrid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                        const VoxelIndex* transparent = nullptr);

// FirstOccupied on many segments at once: out[i] = FirstOccupied(grid, a[i], b[i]) for
// i < min(a.size(), b.size(), out.size()). Google Highway picks the instruction set at run time.
// Where SIMD pays (AVX-512: 16 lanes of floats) each lane walks one segment and takes the next one
// as soon as its own ends; a segment on which a lane would have to decide a near-tie (two boundary
// crossings within 2^-20 of each other in the segment's parameter) is left to FirstOccupied, and
// *rechecked (if given) counts those. Elsewhere (AVX2 and below, where the lanes measured slower
// than the scalar walk) it calls FirstOccupied per segment, unless `kernel` is kLanes, which forces
// the lanes on any target (for tests and benchmarks). A grid of 2^31 bricks or more, or one not
// within +-2^29 voxels of the origin, and batches of 2^31 segments or more, are walked per
// segment. Returns what ran, e.g. "AVX3 lanes", "AVX2 per segment", "SCALAR lanes".
// `certified` (if not empty; at least as long as `out`): certified[i] is 1 where a lane walked
// segment i and took every decision with the margin, so the voxels it passed are in the exact order
// of the segment's boundary crossings (any walk along the same line, from any start before a[i],
// crosses them in that order, up to near-ties inside free boxes the lane jumped across), and 0
// where FirstOccupied walked it (near-ties, and every segment when the lanes do not run).
enum class BatchKernel { kAuto, kLanes };
std::string FirstOccupiedBatch(const OccupancyGrid& grid, std::span<const Eigen::Vector3d> a,
                               std::span<const Eigen::Vector3d> b, std::span<std::optional<VoxelIndex>> out,
                               BatchKernel kernel = BatchKernel::kAuto, size_t* rechecked = nullptr,
                               std::span<char> certified = {});

}  // namespace vc
