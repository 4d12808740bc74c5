// VoxelScene: a scene at the working resolution, ready for visibility queries (ALGORITHM.md s.1).
//
// From a point cloud: a voxel is occupied iff it contains at least one point (OctoMap's keys).
// From an octree: a voxel is occupied iff its cube overlaps, with positive volume, an occupied
// leaf's cube, so a coarse occupied leaf occupies every voxel it contains; by default the working
// resolution is the tree's own. Everything else is free. Immutable once built; share freely.
//
// Two ways in. Voxelize takes a SceneInput already in memory. VoxelAccumulator takes points one at
// a time, for clouds too large to hold (the hall at 0.005 m spacing is ~2e8 points): it keeps
// packed 48-bit keys in one buffer, sorts and de-duplicates the buffer's unsorted tail whenever it
// fills and merges it into the sorted prefix, so its memory grows with the number of occupied
// voxels (16 bytes each at most), never with the number of points. Both produce the same VoxelScene
// from the same points. A VoxelAccumulator is not thread-safe; use one per thread.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/occupancy_grid.h"
#include "vc/scene/scene_input.h"

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
  // Scanner origins carried from the input (.graph, .e57), in metres, local frame; may be empty.
  std::vector<WorldPoint> scan_origins;
  // The input frame's coordinates of this scene's origin (SceneInput::frame_origin_m): every
  // position here is local; add this to write it in the input's own frame.
  WorldPoint frame_origin_m = WorldPoint::Zero();

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
Result<std::vector<VoxelKey>> OccupiedKeys(const SceneInput& input, double resolution_m, uint64_t memory_budget_bytes,
                                           const JobContext& ctx = {});

// Builds the scene at the working resolution. Errors as OccupiedKeys and OccupancyGrid::Build.
Result<VoxelScene> Voxelize(const SceneInput& input, const VoxelizeOptions& options, const JobContext& ctx = {});

// Resolution actually used for `input` under `options` (resolves the 0 default).
double WorkingResolution(const SceneInput& input, const VoxelizeOptions& options);

// Streaming voxeliser of a point cloud (see the file comment). Finish gives exactly the VoxelScene
// that Voxelize gives for a SceneInput holding the same finite points.
class VoxelAccumulator {
 public:
  // Voxels of edge `resolution_m` (m). `memory_budget_bytes` bounds the key buffer while points are
  // added and, in Finish, the scene as in VoxelizeOptions. A bad resolution is reported by status().
  explicit VoxelAccumulator(double resolution_m, uint64_t memory_budget_bytes = kDefaultMemoryBudgetBytes);

  // The input frame's coordinates of the local frame the added points are in (m;
  // SceneInput::frame_origin_m). Finish copies it into the scene. Zero unless set.
  void set_frame_origin_m(const WorldPoint& frame_origin_m) { frame_origin_m_ = frame_origin_m; }
  const WorldPoint& frame_origin_m() const { return frame_origin_m_; }

  // Adds one point (local frame, m). Points with a NaN or infinite coordinate are dropped and counted;
  // once status() is not OK, points are ignored.
  void Add(const Eigen::Vector3f& point_m);

  // OK, or the error Finish will return: INVALID_ARGUMENT for a bad resolution or a point outside
  // OctoMap's key range; RESOURCE_EXHAUSTED (with the extent and a resolution that fits) when the
  // occupied voxels seen so far would exceed the budget. Poll it to stop a long stream early.
  const Status& status() const { return status_; }
  double resolution_m() const { return resolution_m_; }
  // Finite points added so far.
  uint64_t points_added() const { return points_added_; }
  // Points dropped because a coordinate was NaN or infinite.
  uint64_t dropped_nonfinite() const { return dropped_nonfinite_; }
  // Bytes the accumulator holds now, and the most it held at any moment (merge scratch included).
  uint64_t memory_bytes() const;
  uint64_t peak_memory_bytes() const { return peak_memory_bytes_; }

  // Builds the scene and releases the buffer; call once (FAILED_PRECONDITION afterwards).
  // Errors: status(); INVALID_ARGUMENT if no finite point was added; otherwise as Voxelize
  // (RESOURCE_EXHAUSTED for a scene over the budget); CANCELLED / DEADLINE_EXCEEDED from ctx.
  Result<VoxelScene> Finish(const JobContext& ctx = {});

 private:
  // Sorts and de-duplicates the unsorted tail and merges it into the sorted prefix.
  void Merge();
  // Makes room for more points after a merge, or sets status_ to RESOURCE_EXHAUSTED.
  void Grow();
  void NotePeak(uint64_t bytes) { peak_memory_bytes_ = std::max(peak_memory_bytes_, bytes); }

  double resolution_m_;
  double inv_resolution_;
  uint64_t memory_budget_bytes_;
  WorldPoint frame_origin_m_ = WorldPoint::Zero();
  Status status_;
  bool finished_ = false;
  // Packed keys (z, y, x; 16 bits each): [0, sorted_) sorted and unique, then the unsorted tail.
  std::vector<uint64_t> keys_;
  size_t sorted_ = 0;
  // The last key added, and a direct-mapped cache of recent ones: a point whose key is either
  // adds nothing.
  uint64_t last_key_ = ~uint64_t{0};
  std::vector<uint64_t> recent_;
  // Bounding box of the finite points, in metres (float, as the points).
  Eigen::Vector3f lo_m_;
  Eigen::Vector3f hi_m_;
  uint64_t points_added_ = 0;
  uint64_t dropped_nonfinite_ = 0;
  uint64_t peak_memory_bytes_ = 0;
};

}  // namespace vc
