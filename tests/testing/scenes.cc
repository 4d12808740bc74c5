#include "testing/scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <utility>

#include "vc/synth/synth.h"

namespace vc::testing {

SceneInput Cloud(std::vector<Eigen::Vector3f> points) {
  SceneInput in;
  in.points = std::move(points);
  return in;
}

VoxelScene SceneOfVoxels(const std::vector<VoxelIndex>& voxels, double r) {
  VoxelScene s;
  s.resolution_m = r;
  for (const auto& v : voxels) s.occupied.push_back(IndexToKey(v));
  std::sort(s.occupied.begin(), s.occupied.end());
  s.occupied.erase(std::unique(s.occupied.begin(), s.occupied.end()), s.occupied.end());
  std::vector<VoxelIndex> idx;
  for (const auto& k : s.occupied) idx.push_back(KeyToIndex(k));
  s.grid = *OccupancyGrid::Build(r, idx, uint64_t{1} << 26);
  return s;
}

void VoxelBuilder::Box(int x0, int y0, int z0, int x1, int y1, int z1) {
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) cells.insert({x, y, z});
}

void VoxelBuilder::Erase(int x0, int y0, int z0, int x1, int y1, int z1) {
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) cells.erase({x, y, z});
}

VoxelScene VoxelBuilder::Build(double r, const VoxelIndex& offset) const {
  std::vector<VoxelIndex> v;
  for (const auto& [x, y, z] : cells) v.push_back({x + offset.x, y + offset.y, z + offset.z});
  return SceneOfVoxels(v, r);
}

SceneInput Synthetic(const std::string& spec, double spacing_m) {
  SynthOptions o;
  o.spacing_m = spacing_m;
  Result<std::vector<Eigen::Vector3f>> points = GenerateScene(spec, o);
  EXPECT_TRUE(points.ok()) << points.status().ToString();
  SceneInput in;
  if (points.ok()) in.points = std::move(*points);
  return in;
}

}  // namespace vc::testing
