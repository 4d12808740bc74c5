// VoxelScene: a scene at the working resolution, ready for visibility queries (ALGORITHM.md s.1).
//
// From a point cloud: a voxel is occupied iff it contains at least one point (OctoMap's keys).
// From an octree: a voxel is occupied iff its cube overlaps, with positive volume, an occupied
// leaf's cube, so a coarse occupied leaf occupies every voxel it contains; by default the working
// resolution is the tree's own. Everything else is free. Immutable once built; share freely.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "vc/core/geometry.h"
#include "vc/core/occupancy_grid.h"
#include "vc/core/progress.h"
#include "vc/core/scene_input.h"
#include "vc/core/status.h"

namespace vc {

inline constexpr double kDefaultResolutionM = 0.1;
inline constexpr uint64_t kDefaultMemoryBudgetBytes = uint64_t{4} << 30;

struct VoxelizeOptions {
  // Working resolution in metres; 0 = the octree's own resolution, or 0.1 m for point clouds.
  double resolution_m = 0.0;
  // Upper bound on the traversal structure and voxel lists, in bytes (default 4 GiB).
  uint64_t memory_budget_bytes = kDefaultMemoryBudgetBytes;
};

struct VoxelScene {
  double resolution_m = 0.0;
  // Occupied voxels, sorted (VoxelKey's order) and unique. Their position here is the voxel id
  // used by visibility bitsets and reports.
  std::vector<VoxelKey> occupied;
  OccupancyGrid grid;
  // Scanner origins carried from the input (.graph), in metres; may be empty.
  std::vector<WorldPoint> scan_origins;

  // Id of an occupied voxel, or -1 if `key` is not occupied.
  int64_t IdOf(const VoxelKey& key) const;
  WorldPoint Center(size_t id) const { return KeyToCoord(resolution_m, occupied[id]); }
  // Metric bounding box of the occupied voxels' cubes.
  WorldPoint BoundsMin() const;
  WorldPoint BoundsMax() const;
};

// Occupied keys of `input` at `resolution_m` by the rules above, sorted and unique.
// INVALID_ARGUMENT for a bad resolution or an empty scene; RESOURCE_EXHAUSTED (with the extent and
// a resolution that would fit) when the result would exceed `memory_budget_bytes`.
Result<std::vector<VoxelKey>> OccupiedKeys(const SceneInput& input, double resolution_m,
                                           uint64_t memory_budget_bytes, const JobContext& ctx = {});

// Builds the scene at the working resolution. Errors as OccupiedKeys and OccupancyGrid::Build.
Result<VoxelScene> Voxelize(const SceneInput& input, const VoxelizeOptions& options,
                            const JobContext& ctx = {});

// Resolution actually used for `input` under `options` (resolves the 0 default).
double WorkingResolution(const SceneInput& input, const VoxelizeOptions& options);

}  // namespace vc
