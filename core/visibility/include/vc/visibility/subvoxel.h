// The sub-voxel selection test (SelectionTest::kSubvoxel; docs/VISIBILITY.md "Sub-voxel surfaces",
// issue 34): visibility judged on the surface patches the input points give each voxel
// (vc/scene/surface_patches.h) instead of on the voxels' cubes.
//
// Voxel v with patch P is seen from o iff o is in range of the grid and in no occupied voxel, the
// aim point a (P's centroid) passes the scanner's limits, and the segment o -> a either meets no
// blocker before it reaches v, or the first blocker it meets lies on the same surface as P. A
// voxel whose patch is not flat is also seen when the same holds for the segment from o to the
// centre of a face of its box (below) that faces o (o strictly outside the face's plane).
// - A blocker is an occupied voxel w != v and what of it stops a beam: its box, the box its points
//   span grown by kSubvoxelBoxPad voxel edges on every side and clipped to w's cube; for a flat
//   patch, the plane through its centroid with its normal within that box (closed); for any other
//   patch, the box itself (a segment that only touches it, with no length inside, is not blocked).
//   So a grazing beam passes over a floor patch, and beside the points of a voxel they only
//   partly fill (an edge, a sparse far surface, clutter).
// - The segment meets w's blocker at the smallest parameter s in [0, 1] where it lies in it (a
//   segment parallel to a flat patch's plane never meets it). The first blocker is the one of
//   least s; at equal s, v is seen if any of them is on its surface.
// - w's blocker is on the same surface as P when the hit point lies within kSameSurfaceTolerance
//   voxel edges of the segment's aim point, or both patches are flat, the hit point lies within
//   kSameSurfaceTolerance of P's plane and the two normals differ by at most
//   kSameSurfaceMaxAngleDeg. This lets the second voxel layer of an oblique surface count.
// - The limits (scanner_limits.h) are judged at a on the cube face whose outward normal is nearest
//   to P's normal turned towards o (for a patch that is not flat: to the direction a -> o), for
//   every segment of the voxel.
// The engine walks the segment (Amanatides & Woo) and tests only the occupied voxels it passes
// through; tests/core/visibility/subvoxel_test.cc checks it against every voxel of small scenes.
// Thread-safe on const inputs.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>

#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"

namespace vc {

// Largest distance (voxel edges) from the hit point to the aim point, or to the target's plane,
// for the same surface.
inline constexpr double kSameSurfaceTolerance = 0.3;
// Largest angle (degrees) between the two patches' normals for the same surface.
inline constexpr double kSameSurfaceMaxAngleDeg = 25.0;
// How far (voxel edges) a blocker's box reaches beyond its points, on every side: about the gap
// between neighbouring samples that the points stand for (measured: docs/VISIBILITY.md).
inline constexpr double kSubvoxelBoxPad = 0.2;

// The aim point of voxel `id` of `scene` (index space, OccupancyGrid::WorldToIndexSpace): its
// patch's centroid, inside the voxel's cube.
Eigen::Vector3d SubvoxelAimIS(const VoxelScene& scene, std::span<const SurfacePatch> patches, size_t id);

// The box of voxel `id` (index space): its points' box (SurfacePatch::box_lo, box_hi) grown by
// kSubvoxelBoxPad edges, within its cube.
Eigen::AlignedBox3d SubvoxelBoxIS(const VoxelScene& scene, std::span<const SurfacePatch> patches, size_t id);

// The test above for voxel `id` seen from world point o, without limits or with `scanner`'s (no
// heading: its hfov_deg is not applied). `patches` holds one patch per voxel id of `scene`
// (ComputeSurfacePatches); false when it does not.
bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id);
bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id,
                       const ScannerModel& scanner);

// Why the test above says what it says for voxel `id` seen from o, under `scanner`'s limits (no
// heading: its hfov_deg is not applied): for diagnostics (vc-validate-bench --explain) and tests.
// For a voxel not seen, the segment to its centroid; for one seen, the segment that sees it.
struct SubvoxelRay {
  enum class Outcome {
    kInvalid,        // o out of range or in an occupied voxel, or patches not one per voxel: not seen
    kOutsideLimits,  // the aim point fails the scanner's limits: not seen
    kClear,          // no blocker before the voxel: seen
    kSameSurface,    // the first blocker is on the voxel's surface: seen
    kBlocked,        // the first blocker is another surface: not seen
  };
  Outcome outcome = Outcome::kInvalid;
  // The first blocker met (voxel id; at a tie, one on the voxel's surface if any), or -1.
  int64_t first_blocker = -1;
  // Where the segment o -> aim meets it (segment parameter in [0, 1]; 1 when none).
  double blocker_s = 1.0;
  bool seen() const { return outcome == Outcome::kClear || outcome == Outcome::kSameSurface; }
};
SubvoxelRay ExplainSubvoxel(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o,
                            size_t id, const ScannerModel& scanner = {});

}  // namespace vc
