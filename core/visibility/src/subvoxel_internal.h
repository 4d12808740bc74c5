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
// same doubles the single queries compute, and its aim point (SubvoxelAimIS). 100 bytes per
// occupied voxel and 4 per non-empty brick.
class SubvoxelTables {
 public:
  SubvoxelTables(const VoxelScene& scene, std::span<const SurfacePatch> patches);
  // The id of the occupied voxel at `rel` (relative to the grid's smallest index) in brick `slot`.
  int64_t Id(uint32_t slot, const uint32_t rel[3]) const { return ids_[start_[slot - 1] + Rank(slot, rel)]; }
  const Eigen::AlignedBox3d& Box(size_t id) const { return boxes_[id]; }
  const Eigen::Vector3d& Centroid(size_t id) const { return centroids_[id]; }
  const Eigen::Vector3d& Aim(size_t id) const { return aims_[id]; }

 private:
  uint32_t Rank(uint32_t slot, const uint32_t rel[3]) const;
  const OccupancyGrid* grid_;
  std::vector<uint32_t> start_;
  std::vector<uint32_t> ids_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  std::vector<Eigen::Vector3d> centroids_;
  std::vector<Eigen::Vector3d> aims_;
};

// TraceSubvoxel in parts, for the bulk engine (subvoxel_bulk.cc), which walks the segments in SIMD
// batches first:
// - whether the aim point of voxel `id` passes `limits`, and the aim point (index space);
bool SubvoxelAimPasses(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                       size_t id, const ScannerLimits& limits, Eigen::Vector3d* aim);
//   the same for a target patch whose aim point (SubvoxelAimIS) is known;
bool SubvoxelAimPasses(const SurfacePatch& target, const Eigen::Vector3d& aim, const Eigen::Vector3d& uo,
                       const ScannerLimits& limits);
// - the ends of the segments of the box fall-back (a voxel that is not flat; none otherwise), in
//   TraceSubvoxel's order; returns how many (at most 3); `tables` (may be null) hold the box;
int SubvoxelFaceAims(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                     size_t id, Eigen::Vector3d faces[3], const SubvoxelTables* tables = nullptr);
// - one segment uo -> end (end inside voxel id's cube) judged by the test, walked from its parameter
//   `s_start` (0: from uo; the caller knows that the part before it passes through no occupied
//   voxel); `tables` (may be null) speed up the walk.
SubvoxelRay TraceSubvoxelSegment(const VoxelScene& scene, std::span<const SurfacePatch> patches,
                                 const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, double s_start,
                                 const SubvoxelTables* tables);
// How far before the cube of a segment's first occupied voxel (segment parameter) the bulk
// engine resumes its trace.
inline constexpr double kResumeMargin = 1e-6;

// The parameter t >= 0 at which the segment uo + t d enters the cube of voxel w: the largest of the
// nearer faces' parameters per axis, min((lo - uo) / d, (lo + 1 - uo) / d) bit for bit (rounding and
// one division by d keep the order of the two), and in *axis that face's axis (-1 where none lies
// past uo: t = 0).
inline double CubeEntry(const Eigen::Vector3d& uo, const Eigen::Vector3d& d, const VoxelIndex& w, int* axis) {
  const double lo[3] = {double(w.x), double(w.y), double(w.z)};
  double enter = 0;
  *axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0) continue;
    const double t = ((d[i] > 0 ? lo[i] : lo[i] + 1) - uo[i]) / d[i];
    if (t > enter) {
      enter = t;
      *axis = i;
    }
  }
  return enter;
}
// The segment uo -> end (end inside voxel id's cube) judged by the blocker of `first` alone, the
// first occupied voxel FirstOccupiedBatch found on it (not voxel id), where that gives the answer
// TraceSubvoxelSegment resumed kResumeMargin before `first`'s cube would: the segment meets that
// blocker, and from the resumed start to the hit it stays in `first`'s cube and the free cube
// before it, at least 1e-4 voxels from every other face (so the trace's walk visits only those two
// and stops after `first`). Where the segment misses that blocker, the cubes after `first` are
// followed as the trace's walk takes them (each exit at least 1e-4 voxels from the other faces),
// for at most 4: reaching voxel id's cube first is clear (seen), and the blocker of an occupied
// cube met well inside it judges as `first`'s would. 1: seen (clear, or the blocker is on voxel
// id's surface), 0: blocked, -1: not decided (then trace). Only for segments of at most
// kMaxShortcutLength voxels. Where decided, `*blocker` is the deciding blocker's voxel id (-1 when
// clear), as the trace reports it. Where not decided because the cubes ran out (each left with the
// margin), `*resume` is a parameter of the segment just past the last exit, in the next cube, from
// which the segment may be walked on: every cube before it is free or has a blocker the segment
// misses. Otherwise (and where decided) `*resume` is -1.
int SubvoxelJudgeAtFirst(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                         const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, const VoxelIndex& first,
                         int64_t* blocker, double* resume);
// A certificate that the segment uo -> end (end inside voxel id's cube) is blocked under the test,
// by voxel `w` (any occupied voxel but id; -1: none), without a walk: the segment meets w's blocker
// at parameter s; it passes through w's cube at least 1e-4 voxels inside all its faces (at the
// middle of its chord), and both that and s come at least 1e-4 voxels before it enters id's cube, so
// every walk tests w's blocker (or has stopped at an earlier hit) before it reaches id; and no point
// of the segment up to s can be on id's surface: it is farther than kSameSurfaceTolerance + 1e-4
// from `end`, and for a flat id as far from id's plane through `end`, on the viewpoint's side. So
// the first blocker comes at or before s and is not on id's surface: blocked, for the trace from uo
// and for one resumed anywhere before w. Only for segments of at most kMaxShortcutLength voxels.
bool SubvoxelBlockedBy(const VoxelScene& scene, std::span<const SurfacePatch> patches, const SubvoxelTables& tables,
                       const Eigen::Vector3d& uo, size_t id, const Eigen::Vector3d& end, int64_t w);
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
