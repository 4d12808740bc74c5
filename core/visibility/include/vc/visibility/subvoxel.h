// The sub-voxel selection test (SelectionTest::kSubvoxel; docs/VISIBILITY.md "Sub-voxel surfaces",
// issue 34): visibility judged on the surface patches the input points give each voxel
// (vc/scene/surface_patches.h) instead of on the voxels' cubes.
//
// Voxel v with patch P is seen from o iff o is in range of the grid and in no occupied voxel, the
// aim point a (P's centroid) passes the scanner's limits, and the segment o -> a either meets no
// blocker before it reaches v, or the first blocker it meets lies on the same surface as P.
// - A blocker is an occupied voxel w != v and the part of its cube that stops a beam: for a flat
//   patch, the plane through its centroid with its normal, clipped to w's closed cube; for any
//   other patch, the whole cube (a cube the segment only touches along an edge or at a corner, with
//   no length inside, does not block). So a grazing beam passes over a floor patch.
// - The segment meets w's blocker at the smallest parameter s in [0, 1] where it lies in it (a
//   segment parallel to a flat patch's plane never meets it). The first blocker is the one of
//   least s; at equal s, v is seen if any of them is on its surface.
// - w's blocker is on the same surface as P when both patches are flat, the hit point lies within
//   kSameSurfaceTolerance voxel edges of P's plane and the two normals differ by at most
//   kSameSurfaceMaxAngleDeg. This lets the second voxel layer of an oblique surface count.
// - The limits (scanner_limits.h) are judged at a on the cube face whose outward normal is nearest
//   to P's normal turned towards o (for a patch that is not flat: to the direction a -> o).
// The engine walks the segment (Amanatides & Woo) and tests only the occupied voxels it passes
// through; tests/core/visibility/subvoxel_test.cc checks it against every voxel of small scenes.
// Thread-safe on const inputs.
#pragma once

#include <Eigen/Core>
#include <span>

#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/visibility.h"

namespace vc {

// Largest distance (voxel edges) from the hit point to the target's plane for the same surface.
inline constexpr double kSameSurfaceTolerance = 0.3;
// Largest angle (degrees) between the two patches' normals for the same surface.
inline constexpr double kSameSurfaceMaxAngleDeg = 25.0;

// The aim point of voxel `id` of `scene` (index space, OccupancyGrid::WorldToIndexSpace): its
// patch's centroid, inside the voxel's cube.
Eigen::Vector3d SubvoxelAimIS(const VoxelScene& scene, std::span<const SurfacePatch> patches, size_t id);

// The test above for voxel `id` seen from world point o, without limits or with `scanner`'s (no
// heading: its hfov_deg is not applied). `patches` holds one patch per voxel id of `scene`
// (ComputeSurfacePatches); false when it does not.
bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id);
bool IsSubvoxelVisible(const VoxelScene& scene, std::span<const SurfacePatch> patches, const WorldPoint& o, size_t id,
                       const ScannerModel& scanner);

}  // namespace vc
