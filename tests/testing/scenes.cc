#include "testing/scenes.h"

#include <algorithm>
#include <cstdint>
#include <utility>

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

}  // namespace vc::testing
