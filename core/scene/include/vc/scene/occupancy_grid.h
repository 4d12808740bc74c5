// OccupancyGrid: the traversal structure for fast, exact ray casting.
//
// A bricked bitset over the bounding box of the occupied voxels: the box is cut into bricks of
// 8x8x8 voxels; a dense array holds one 32-bit entry per brick and only non-empty bricks store
// their 512 bits. Empty bricks cost 4 bytes. A non-empty brick's entry is its slot (1 + its number
// among the non-empty bricks); an empty brick's entry is, negated, its Chebyshev distance in bricks
// to the nearest non-empty brick (capped at 255), for empty-space skipping: a ray in a brick at
// distance k may jump across the (2k-1)^3-brick box around it untested. One load thus tells a ray
// both whether to test bits and how far it may jump. The entry's higher bits widen that cube, side
// by side, into a larger free box (ExtraBricks), which the rays jump across: a ray along a floor
// or a wall jumps far along it, not just as far as the surface is near.
// (A per-voxel distance field was tried and removed: its byte per voxel of the box falls out of
// cache, and traversal was 1.2-2x slower in wall time than with these brick distances.) It answers "is voxel (x,y,z)
// occupied" exactly as the octree at resolution r does (ALGORITHM.md section 1); anything outside the box is free.
// Memory is computed and checked against a budget before anything is allocated: a scene that does not fit is refused
// with RESOURCE_EXHAUSTED and a message stating the extent and a resolution that would fit.
//
// Index space ("IS"): voxel (x,y,z) (a VoxelIndex, = OctoMap key - 32768) covers
// [x, x+1) x [y, y+1) x [z, z+1) in continuous coordinates u = p / r, where p is the world point in
// metres. floor(p * (1/r)) is computed exactly as OctoMap's coordToKey, so keys always agree.
// Immutable after Build; safe to share across threads.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/status.h"

namespace vc {

class OccupancyGrid {
 public:
  static constexpr int kBrickShift = 3;  // bricks of 8x8x8 voxels
  static constexpr int kBrick = 1 << kBrickShift;

  OccupancyGrid() = default;

  // Bytes a grid over [min, max] (inclusive voxel indices) with `occupied_bricks` non-empty
  // bricks needs.
  static uint64_t BytesNeeded(const VoxelIndex& min, const VoxelIndex& max, uint64_t occupied_bricks);

  // Builds the grid of `occupied` (any order, duplicates allowed) at `resolution_m`.
  // RESOURCE_EXHAUSTED if it needs more than `memory_budget_bytes`; INVALID_ARGUMENT if
  // `occupied` is empty or the resolution is not positive and finite.
  static Result<OccupancyGrid> Build(double resolution_m, const std::vector<VoxelIndex>& occupied,
                                     uint64_t memory_budget_bytes);

  double resolution_m() const { return resolution_m_; }
  double inv_resolution() const { return inv_resolution_; }
  // Smallest voxel index of the box, and its size in voxels per axis (a multiple of 8).
  const VoxelIndex& min_index() const { return min_; }
  const Eigen::Vector3i& dims() const { return dims_; }
  const Eigen::Vector3i& brick_dims() const { return bdims_; }
  // Linear brick number of brick (bx,by,bz) (relative brick coordinates, in range).
  uint64_t BrickLinear(uint32_t bx, uint32_t by, uint32_t bz) const {
    return (uint64_t(bz) * uint64_t(bdims_.y()) + by) * uint64_t(bdims_.x()) + bx;
  }
  // Payload slot of a brick (0 = empty) and its distance to the nearest non-empty brick (0 for a
  // non-empty brick).
  uint32_t BrickSlot(uint64_t brick) const { return uint32_t(std::max(bricks_[brick], 0)); }
  uint8_t BrickDistance(uint64_t brick) const { return uint8_t(std::max(-bricks_[brick], 0) & 0xff); }
  // An empty brick's free box: the cube of bricks within BrickDistance - 1 of it, widened by
  // ExtraBricks(brick, side) more layers of bricks on each side (side 2i: +axis i, 2i+1: -axis i),
  // each 0..kMaxExtra; every brick in it is empty or outside the grid. The entry holds minus
  // (distance | extras << kExtraShift), kExtraBits an extra. ExtraBricks is 0 for a non-empty
  // brick. FirstOccupied (walk.h) and the SIMD kernel (ray_batch.cc) jump across the whole box.
  static constexpr int kExtraShift = 8, kExtraBits = 3, kMaxExtra = (1 << kExtraBits) - 1;
  int ExtraBricks(uint64_t brick, int side) const {
    return (std::max(-bricks_[brick], 0) >> (kExtraShift + kExtraBits * side)) & kMaxExtra;
  }
  // The 8 words of a non-empty brick's bits (word z, bit y*8+x).
  const uint64_t* BrickBits(uint32_t slot) const { return &payload_[uint64_t(slot - 1) * kBrick]; }
  // Raw arrays for vectorised kernels: brick_count() entries, each the slot if positive, else
  // minus (the distance | the extra layers << kExtraShift).
  uint64_t brick_count() const { return bricks_.size(); }
  const int32_t* brick_entries() const { return bricks_.data(); }
  const uint64_t* payload() const { return payload_.data(); }
  uint64_t memory_bytes() const;
  uint64_t occupied_bricks() const { return payload_.size() / kBrick; }

  // Occupied voxel at index (x,y,z); false outside the box.
  bool Occupied(int x, int y, int z) const {
    const uint32_t rx = uint32_t(x - min_.x), ry = uint32_t(y - min_.y), rz = uint32_t(z - min_.z);
    if (rx >= uint32_t(dims_.x()) || ry >= uint32_t(dims_.y()) || rz >= uint32_t(dims_.z())) return false;
    const int32_t slot = bricks_[BrickLinear(rx >> kBrickShift, ry >> kBrickShift, rz >> kBrickShift)];
    if (slot <= 0) return false;
    const uint64_t word = payload_[uint64_t(slot - 1) * kBrick + (rz & 7)];
    return (word >> (((ry & 7) << 3) | (rx & 7))) & 1u;
  }
  bool Occupied(const VoxelIndex& v) const { return Occupied(v.x, v.y, v.z); }

  // Whether brick (bx,by,bz) (brick coordinates relative to min_index(), i.e. (x - min.x) >> 3)
  // holds any occupied voxel; false outside.
  bool BrickOccupied(int bx, int by, int bz) const {
    if (uint32_t(bx) >= uint32_t(bdims_.x()) || uint32_t(by) >= uint32_t(bdims_.y()) ||
        uint32_t(bz) >= uint32_t(bdims_.z()))
      return false;
    return bricks_[BrickLinear(bx, by, bz)] > 0;
  }

  // Whether any voxel of the box [lo, hi] (inclusive voxel indices) is occupied. Bricks are
  // tested a word (an 8x8 slice) at a time; empty bricks cost one load.
  bool AnyOccupied(const VoxelIndex& lo, const VoxelIndex& hi) const {
    return ScanBox(lo, hi, [](uint64_t bits, uint64_t, int, int, int) { return bits != 0; });
  }
  // Whether every voxel of the box [lo, hi] is occupied (false if any of it lies outside the
  // grid). Tested a word at a time, as AnyOccupied.
  bool AllOccupied(const VoxelIndex& lo, const VoxelIndex& hi) const {
    if (lo.x < min_.x || lo.y < min_.y || lo.z < min_.z || hi.x - min_.x >= dims_.x() || hi.y - min_.y >= dims_.y() ||
        hi.z - min_.z >= dims_.z() || lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) {
      return false;
    }
    return !ScanBox</*kEmptyBricks=*/true>(lo, hi,
                                           [](uint64_t bits, uint64_t mask, int, int, int) { return bits != mask; });
  }
  // Whether some occupied voxel v of the box [lo, hi] has pred(v) true. Stops at the first one.
  template <typename Pred>
  bool AnyOccupiedWhere(const VoxelIndex& lo, const VoxelIndex& hi, Pred&& pred) const {
    return ScanBox(lo, hi, [&](uint64_t bits, uint64_t, int x0, int y0, int z) {
      for (; bits; bits &= bits - 1) {
        const int p = std::countr_zero(bits);
        if (pred(VoxelIndex{x0 + (p & 7), y0 + (p >> 3), z})) return true;
      }
      return false;
    });
  }

  // Continuous index-space coordinates of a world point (metres).
  Eigen::Vector3d WorldToIndexSpace(const WorldPoint& p) const { return p * inv_resolution_; }
  // World point (metres) of continuous index-space coordinates.
  WorldPoint IndexSpaceToWorld(const Eigen::Vector3d& u) const { return u * resolution_m_; }
  // World centre of voxel v, as OctoMap's keyToCoord.
  WorldPoint VoxelCenter(const VoxelIndex& v) const;
  // The voxel containing world point p, as OctoMap's coordToKey (may lie outside the box).
  VoxelIndex WorldToIndex(const WorldPoint& p) const;

 private:
  void ComputeBrickDistances();
  // The extra layers of each empty brick's free box (ExtraBricks), grown greedily one layer a side
  // at a time, round the six sides, while the layer holds no non-empty brick. Skipped (boxes stay
  // cubes) when its transient prefix-sum table would exceed kMaxExtentTable entries.
  void ComputeFreeExtents();
  static constexpr uint64_t kMaxExtentTable = uint64_t{1} << 24;
  // Calls fn(bits, mask, x0, y0, z) for each word (an 8x8 slice of a non-empty brick) that meets
  // the box [lo, hi], with mask the word's bits inside the box and bits the occupied ones among
  // them (bit y*8+x is voxel (x0 + x, y0 + y, z), in index space); true as soon as fn returns
  // true. kEmptyBricks: empty bricks are visited too, once each, with bits 0 and the mask of
  // their first word in the box.
  template <bool kEmptyBricks = false, typename Fn>
  bool ScanBox(const VoxelIndex& lo, const VoxelIndex& hi, Fn&& fn) const;

  double resolution_m_ = 0;
  double inv_resolution_ = 0;
  VoxelIndex min_;
  Eigen::Vector3i dims_{0, 0, 0};
  Eigen::Vector3i bdims_{0, 0, 0};
  std::vector<int32_t> bricks_;    // per brick: 1 + payload brick number, or minus the distance
  std::vector<uint64_t> payload_;  // 8 words per non-empty brick: word z, bit (y*8 + x)
};

template <bool kEmptyBricks, typename Fn>
bool OccupancyGrid::ScanBox(const VoxelIndex& lo, const VoxelIndex& hi, Fn&& fn) const {
  const int lo3[3] = {lo.x - min_.x, lo.y - min_.y, lo.z - min_.z};
  const int hi3[3] = {hi.x - min_.x, hi.y - min_.y, hi.z - min_.z};
  int r0[3], r1[3];
  for (int i = 0; i < 3; ++i) {
    r0[i] = std::max(lo3[i], 0);
    r1[i] = std::min(hi3[i], dims_[i] - 1);
    if (r0[i] > r1[i]) return false;  // the box misses the grid: all free
  }
  for (int bz = r0[2] >> kBrickShift; bz <= r1[2] >> kBrickShift; ++bz) {
    const int z0 = std::max(r0[2] - bz * kBrick, 0), z1 = std::min(r1[2] - bz * kBrick, kBrick - 1);
    for (int by = r0[1] >> kBrickShift; by <= r1[1] >> kBrickShift; ++by) {
      const int y0 = std::max(r0[1] - by * kBrick, 0), y1 = std::min(r1[1] - by * kBrick, kBrick - 1);
      // Bits y0..y1 of a word's 8-bit rows.
      const uint64_t rows =
          (y1 == kBrick - 1 ? ~uint64_t{0} : (uint64_t{1} << (8 * (y1 + 1))) - 1) & ~((uint64_t{1} << (8 * y0)) - 1);
      for (int bx = r0[0] >> kBrickShift; bx <= r1[0] >> kBrickShift; ++bx) {
        const int32_t slot = bricks_[BrickLinear(uint32_t(bx), uint32_t(by), uint32_t(bz))];
        if (slot <= 0 && !kEmptyBricks) continue;
        const int x0 = std::max(r0[0] - bx * kBrick, 0), x1 = std::min(r1[0] - bx * kBrick, kBrick - 1);
        const uint64_t mask = rows & (((uint64_t{2} << x1) - (uint64_t{1} << x0)) * 0x0101010101010101ull);
        if (slot <= 0) {
          if (fn(uint64_t{0}, mask, min_.x + bx * kBrick, min_.y + by * kBrick, min_.z + bz * kBrick + z0)) return true;
          continue;
        }
        const uint64_t* words = BrickBits(slot);
        for (int z = z0; z <= z1; ++z) {
          if (fn(words[z] & mask, mask, min_.x + bx * kBrick, min_.y + by * kBrick, min_.z + bz * kBrick + z))
            return true;
        }
      }
    }
  }
  return false;
}

// OctoMap's key of world point p at `resolution_m`: floor(p * (1/r)) + 32768 per axis, computed
// exactly as OctoMap does. False if outside the 16-bit key range.
bool CoordToKey(double resolution_m, const WorldPoint& p, VoxelKey* key);
// World centre of a key's voxel, exactly as OctoMap's keyToCoord.
WorldPoint KeyToCoord(double resolution_m, const VoxelKey& key);
inline VoxelIndex KeyToIndex(const VoxelKey& k) {
  return {int(k.x) - kKeyOffset, int(k.y) - kKeyOffset, int(k.z) - kKeyOffset};
}
inline VoxelKey IndexToKey(const VoxelIndex& v) {
  return {uint16_t(v.x + kKeyOffset), uint16_t(v.y + kKeyOffset), uint16_t(v.z + kKeyOffset)};
}

}  // namespace vc
