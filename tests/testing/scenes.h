// Small scenes for tests, built straight from points or voxel indices.
#pragma once

#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"

namespace vc::testing {

// A point-cloud input holding `points` (world, m).
SceneInput Cloud(std::vector<Eigen::Vector3f> points);

// The scene whose occupied voxels are exactly `voxels` (duplicates allowed) at resolution r (m).
VoxelScene SceneOfVoxels(const std::vector<VoxelIndex>& voxels, double r);

// A scene drawn voxel box by voxel box (inclusive index boxes), then built.
struct VoxelBuilder {
  std::set<std::tuple<int, int, int>> cells;
  // Occupies the inclusive index box.
  void Box(int x0, int y0, int z0, int x1, int y1, int z1);
  // Frees the inclusive index box.
  void Erase(int x0, int y0, int z0, int x1, int y1, int z1);
  // The scene at resolution r (m), every cell moved by `offset` (voxel indices).
  VoxelScene Build(double r, const VoxelIndex& offset = {0, 0, 0}) const;
};

// The synthetic scene `spec` (vc/synth/synth.h) sampled every `spacing_m`, as a point-cloud input.
SceneInput Synthetic(const std::string& spec, double spacing_m = 0.05);

}  // namespace vc::testing
