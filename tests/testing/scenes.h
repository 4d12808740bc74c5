// Small scenes for tests, built straight from voxel indices.
#pragma once

#include <vector>

#include "vc/core/voxel_scene.h"

namespace vc::testing {

// The scene whose occupied voxels are exactly `voxels` (duplicates allowed) at resolution r (m).
VoxelScene SceneOfVoxels(const std::vector<VoxelIndex>& voxels, double r);

}  // namespace vc::testing
