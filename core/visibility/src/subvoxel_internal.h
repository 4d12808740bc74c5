// The sub-voxel test's per-ray core (subvoxel.h), shared by the single queries, the per-voxel sets
// (visibility.cc) and the batched engine (subvoxel_bulk.cc). Private to the visibility layer.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/scanner_limits.h"
#include "vc/visibility/subvoxel.h"
#include "vc/visibility/voxel_set.h"

namespace vc::internal {

// The test for voxel `id` seen from `uo` (index space; in range and in no occupied voxel, which the
// caller checks) under `limits`, with the first blocker.
SubvoxelRay TraceSubvoxel(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                          size_t id, const ScannerLimits& limits);
// What the bulk engine's walks look up per occupied voxel they meet, computed once per call: the
// voxel ids by brick (per non-empty brick of the grid, the ids of its occupied voxels in bit order,
// word z then bit y * 8 + x, so that a voxel's id is a popcount away instead of a binary search,
// VoxelScene::IdOf), and each voxel's blocking box (SubvoxelBoxIS) and centroid (index space), the
// same doubles the single queries compute. 76 bytes per occupied voxel and 4 per non-empty brick.
class SubvoxelTables {
 public:
  SubvoxelTables(const VoxelScene& scene, std::span<const SurfacePatch> patches);
  // The id of the occupied voxel at `rel` (relative to the grid's smallest index) in brick `slot`.
  int64_t Id(uint32_t slot, const uint32_t rel[3]) const { return ids_[start_[slot - 1] + Rank(slot, rel)]; }
  const Eigen::AlignedBox3d& Box(size_t id) const { return boxes_[id]; }
  const Eigen::Vector3d& Centroid(size_t id) const { return centroids_[id]; }

 private:
  uint32_t Rank(uint32_t slot, const uint32_t rel[3]) const;
  const OccupancyGrid* grid_;
  std::vector<uint32_t> start_;
  std::vector<uint32_t> ids_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  std::vector<Eigen::Vector3d> centroids_;
};

// TraceSubvoxel in parts, for the bulk engine (subvoxel_bulk.cc), which walks the segments in SIMD
// batches first:
// - whether the aim point of voxel `id` passes `limits`, and the aim point (index space);
bool SubvoxelAimPasses(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                       size_t id, const ScannerLimits& limits, Eigen::Vector3d* aim);
// - the ends of the segments of the box fall-back (a voxel that is not flat; none otherwise), in
//   TraceSubvoxel's order; returns how many (at most 3);
int SubvoxelFaceAims(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                     size_t id, Eigen::Vector3d faces[3]);
// - one segment uo -> end (end inside voxel id's cube) judged by the test, walked from its parameter
//   `s_start` (0: from uo; the caller knows that the part before it passes through no occupied
//   voxel); `tables` (may be null) speed up the walk.
SubvoxelRay TraceSubvoxelSegment(const VoxelScene& scene, std::span<const SurfacePatch> patches,
                                 const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, double s_start,
                                 const SubvoxelTables* tables);
// The sub-voxel test from `uo` (index space; in range and in no occupied voxel) under `limits`, for
// the voxels `ids`: the bit of each voxel seen is set in `set` (subvoxel_bulk.cc). The same answers
// as TraceSubvoxel but at exact ties (subvoxel_bulk.cc says which).
void SubvoxelVisibleAmong(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                          const Eigen::Vector3d& uo, const ScannerLimits& limits, std::span<const uint32_t> ids,
                          VoxelSet& set);

// Whether voxel `id` is seen from `uo` (index space; in range and in no occupied voxel, which the
// caller checks) under `limits`.
bool SubvoxelVisibleFrom(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                         size_t id, const ScannerLimits& limits);

}  // namespace vc::internal
