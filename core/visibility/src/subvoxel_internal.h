// The sub-voxel test's per-ray core (subvoxel.h), shared by the single queries and the bulk engine
// (visibility.cc). Private to the visibility layer.
#pragma once

#include <Eigen/Core>
#include <span>

#include "vc/scene/surface_patches.h"
#include "vc/scene/voxel_scene.h"
#include "vc/visibility/scanner_limits.h"
#include "vc/visibility/subvoxel.h"

namespace vc::internal {

// The test for voxel `id` seen from `uo` (index space; in range and in no occupied voxel, which the
// caller checks) under `limits`, with the first blocker.
SubvoxelRay TraceSubvoxel(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                          size_t id, const ScannerLimits& limits);
// Whether voxel `id` is seen from `uo` (index space; in range and in no occupied voxel, which the
// caller checks) under `limits`.
bool SubvoxelVisibleFrom(const VoxelScene& scene, std::span<const SurfacePatch> patches, const Eigen::Vector3d& uo,
                         size_t id, const ScannerLimits& limits);

}  // namespace vc::internal
