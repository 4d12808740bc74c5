// OccupancyGrid: the traversal structure for fast, exact ray casting.
//
// A dense bitset over the bounding box of the occupied voxels (plus a one-voxel margin), in
// OctoMap's key space at resolution r, with an 8x8x8-voxel brick summary used to skip empty space.
// It answers "is voxel (x,y,z) occupied" exactly as the octree at resolution r does (ALGORITHM.md
// section 1); anything outside the box is free. The memory is checked against a budget before
// anything is allocated: a scene that does not fit is refused with RESOURCE_EXHAUSTED and a message
// stating the extent and a resolution that would fit, never an out-of-memory kill.
//
// Index space: voxel (x,y,z) covers [x, x+1) x [y, y+1) x [z, z+1) in continuous index
// coordinates; index = key - origin_key. Immutable after Build; safe to share across threads.
#pragma once

#include <cstdint>
#include <vector>

#include "vc/core/geometry.h"
#include "vc/core/status.h"

namespace vc {

class OccupancyGrid {
 public:
  static constexpr int kBrickShift = 3;  // bricks of 8x8x8 voxels
  static constexpr int kBrick = 1 << kBrickShift;

  OccupancyGrid() = default;

  // Bytes the grid needs for voxels spanning keys [min_key, max_key] at any resolution.
  static uint64_t BytesNeeded(const VoxelKey& min_key, const VoxelKey& max_key);

  // Builds the grid of `occupied` keys (any order, duplicates allowed). RESOURCE_EXHAUSTED if it
  // needs more than `memory_budget_bytes`; INVALID_ARGUMENT if `occupied` is empty.
  static Result<OccupancyGrid> Build(double resolution_m, const std::vector<VoxelKey>& occupied,
                                     uint64_t memory_budget_bytes);

  double resolution_m() const { return resolution_m_; }
  // Grid size in voxels per axis.
  const Eigen::Vector3i& dims() const { return dims_; }
  // Key of index (0,0,0).
  const VoxelKey& origin_key() const { return origin_key_; }
  uint64_t memory_bytes() const;

  bool InBounds(int x, int y, int z) const {
    return static_cast<uint32_t>(x) < static_cast<uint32_t>(dims_.x()) &&
           static_cast<uint32_t>(y) < static_cast<uint32_t>(dims_.y()) &&
           static_cast<uint32_t>(z) < static_cast<uint32_t>(dims_.z());
  }
  // Occupied voxel at index (x,y,z); false outside the grid.
  bool Occupied(int x, int y, int z) const {
    if (!InBounds(x, y, z)) return false;
    const uint64_t i = LinearIndex(x, y, z);
    return (bits_[i >> 6] >> (i & 63)) & 1u;
  }
  bool Occupied(const VoxelIndex& v) const { return Occupied(v.x, v.y, v.z); }
  // True if any voxel of the brick (bx,by,bz) (brick coordinates = index >> kBrickShift) is occupied.
  bool BrickOccupied(int bx, int by, int bz) const {
    if (bx < 0 || by < 0 || bz < 0 || bx >= bdims_.x() || by >= bdims_.y() || bz >= bdims_.z()) return false;
    const uint64_t i = (uint64_t(bz) * bdims_.y() + by) * bdims_.x() + bx;
    return (brick_bits_[i >> 6] >> (i & 63)) & 1u;
  }
  const Eigen::Vector3i& brick_dims() const { return bdims_; }

  VoxelIndex KeyToIndex(const VoxelKey& k) const {
    return {int(k.x) - origin_key_.x, int(k.y) - origin_key_.y, int(k.z) - origin_key_.z};
  }
  VoxelKey IndexToKey(const VoxelIndex& v) const {
    return {uint16_t(v.x + origin_key_.x), uint16_t(v.y + origin_key_.y), uint16_t(v.z + origin_key_.z)};
  }
  // Continuous index-space coordinates of a world point (floor() of it is the voxel index).
  Eigen::Vector3d WorldToIndexSpace(const WorldPoint& p) const;
  // World point of continuous index-space coordinates.
  WorldPoint IndexSpaceToWorld(const Eigen::Vector3d& u) const;
  // World centre of voxel v.
  WorldPoint VoxelCenter(const VoxelIndex& v) const {
    return IndexSpaceToWorld(Eigen::Vector3d(v.x + 0.5, v.y + 0.5, v.z + 0.5));
  }
  // Voxel index containing world point p (may be out of bounds).
  VoxelIndex WorldToIndex(const WorldPoint& p) const;

 private:
  uint64_t LinearIndex(int x, int y, int z) const {
    return (uint64_t(z) * dims_.y() + y) * dims_.x() + x;
  }

  double resolution_m_ = 0;
  Eigen::Vector3i dims_{0, 0, 0};
  Eigen::Vector3i bdims_{0, 0, 0};
  VoxelKey origin_key_;
  std::vector<uint64_t> bits_;
  std::vector<uint64_t> brick_bits_;
};

// OctoMap's key of a world coordinate at `resolution_m`: floor(c / r) + 32768, computed exactly
// as OctoMap does (multiplying by 1/r in double). False if outside the 16-bit key range.
bool CoordToKey(double resolution_m, const WorldPoint& p, VoxelKey* key);
// World centre of a key's voxel, as OctoMap's keyToCoord.
WorldPoint KeyToCoord(double resolution_m, const VoxelKey& key);

}  // namespace vc
