// Small scenes for tests, built straight from points or voxel indices.
#pragma once

#include <vector>

#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"

namespace vc::testing {

// A point-cloud input holding `points` (world, m).
SceneInput Cloud(std::vector<Eigen::Vector3f> points);

// The scene whose occupied voxels are exactly `voxels` (duplicates allowed) at resolution r (m).
VoxelScene SceneOfVoxels(const std::vector<VoxelIndex>& voxels, double r);

}  // namespace vc::testing
