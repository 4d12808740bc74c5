// Basic geometric types. World coordinates are metres, right-handed, z up (ALGORITHM.md).
// Voxel keys are OctoMap's: key = floor(coordinate / resolution) + 32768 per axis, so a point lands
// in the same voxel here and in an octomap::OcTree of the same resolution.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>

namespace vc {

// A point in the world frame, in metres.
using WorldPoint = Eigen::Vector3d;

// OctoMap's key of a voxel at some resolution (the same numbers as octomap::OcTreeKey).
struct VoxelKey {
  uint16_t x = 0, y = 0, z = 0;
  friend bool operator==(const VoxelKey& a, const VoxelKey& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
  friend bool operator!=(const VoxelKey& a, const VoxelKey& b) { return !(a == b); }
  // Orders by z, then y, then x (the order of occupied-voxel lists).
  friend bool operator<(const VoxelKey& a, const VoxelKey& b) {
    if (a.z != b.z) return a.z < b.z;
    if (a.y != b.y) return a.y < b.y;
    return a.x < b.x;
  }
};

// OctoMap's key offset (tree_max_val for the 16-level tree).
inline constexpr int kKeyOffset = 32768;

// Signed integer coordinates of a voxel at some resolution: index = key - 32768, so voxel
// (x,y,z) covers [x*r, (x+1)*r) x ... in world metres. Distinct from VoxelKey (unsigned, offset).
struct VoxelIndex {
  int32_t x = 0, y = 0, z = 0;
  friend bool operator==(const VoxelIndex& a, const VoxelIndex& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
  friend bool operator!=(const VoxelIndex& a, const VoxelIndex& b) { return !(a == b); }
};

struct VoxelKeyHash {
  size_t operator()(const VoxelKey& k) const {
    return (size_t{k.x} << 32) ^ (size_t{k.y} << 16) ^ size_t { k.z };
  }
};

}  // namespace vc
