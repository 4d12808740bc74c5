#include "vc/scene/voxel_scene.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <random>

#include "testing/scenes.h"
#include "testing/test_paths.h"
#include "vc/scene/octomap_adapter.h"

namespace vc {
namespace {

using testing::Cloud;

TEST(VoxelizeTest, CloudKeysMatchOctomapKeys) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<float> u(-30.0f, 30.0f);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 20000; ++i) pts.emplace_back(u(rng), u(rng), u(rng) / 5);
  // Points on exact multiples of the resolution, where rounding matters most.
  for (int i = -50; i < 50; ++i) pts.emplace_back(float(i) * 0.1f, float(i) * 0.3f, 0.7f);
  VoxelizeOptions opt;
  opt.resolution_m = 0.1;
  auto scene = Voxelize(Cloud(pts), opt);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  octomap::OcTree tree(0.1);
  std::set<std::tuple<int, int, int>> expect;
  for (const auto& p : pts) {
    const octomap::OcTreeKey k = tree.coordToKey(octomap::point3d(p.x(), p.y(), p.z()));
    expect.insert({k[0], k[1], k[2]});
  }
  ASSERT_EQ(scene->occupied.size(), expect.size());
  for (const VoxelKey& k : scene->occupied) EXPECT_TRUE(expect.count({k.x, k.y, k.z}));
  for (const VoxelKey& k : scene->occupied) EXPECT_TRUE(scene->grid.Occupied(KeyToIndex(k)));
  EXPECT_TRUE(std::is_sorted(scene->occupied.begin(), scene->occupied.end()));
  EXPECT_EQ(scene->IdOf(scene->occupied[17]), 17);
}

TEST(VoxelizeTest, Geb079AtItsOwnResolutionHasOneVoxelPerOccupiedLeafVolume) {
  auto input = ReadSceneFile(testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(input.ok()) << input.status().ToString();
  ASSERT_TRUE(input->octree);
  EXPECT_EQ(CountOccupiedLeaves(*input->octree), 143729u);
  auto scene = Voxelize(*input, {});
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  EXPECT_DOUBLE_EQ(scene->resolution_m, 0.08);
  // Every occupied leaf's voxels are occupied, and nothing else.
  uint64_t volume_voxels = 0;
  ForEachOccupiedLeaf(*input->octree, [&](const WorldPoint&, double edge) {
    const double n = std::round(edge / 0.08);
    volume_voxels += uint64_t(n * n * n);
  });
  EXPECT_EQ(scene->occupied.size(), volume_voxels);
  for (auto it = input->octree->begin_leafs(); it != input->octree->end_leafs(); ++it) {
    if (it.getDepth() != 16) continue;
    const VoxelKey k{it.getKey()[0], it.getKey()[1], it.getKey()[2]};
    ASSERT_EQ(scene->grid.Occupied(KeyToIndex(k)), input->octree->isNodeOccupied(*it));
  }
}

TEST(VoxelizeTest, CoarserResolutionUsesOverlapRule) {
  // One occupied voxel at 0.1 m covering [0,0.1)^3: at 0.2 m it occupies exactly one voxel; at
  // 0.05 m exactly eight.
  SceneInput in;
  in.octree = BuildOctree(0.1, {VoxelKey{32768, 32768, 32768}});
  auto coarse = OccupiedKeys(in, 0.2, 1 << 20);
  ASSERT_TRUE(coarse.ok());
  EXPECT_EQ(coarse->size(), 1u);
  auto fine = OccupiedKeys(in, 0.05, 1 << 20);
  ASSERT_TRUE(fine.ok());
  EXPECT_EQ(fine->size(), 8u);
  // 0.15 m voxels: [0,0.15) overlaps [0,0.1) only: one voxel.
  auto odd = OccupiedKeys(in, 0.15, 1 << 20);
  ASSERT_TRUE(odd.ok());
  EXPECT_EQ(odd->size(), 1u);
}

TEST(VoxelizeTest, RefusesAbsurdExtentsBeforeAllocating) {
  auto far = Voxelize(Cloud({{0, 0, 0}, {5000, 0, 0}}), {});
  ASSERT_FALSE(far.ok());
  EXPECT_EQ(far.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(far.status().message().find("key range"), std::string::npos) << far.status().message();
  VoxelizeOptions small;
  small.resolution_m = 0.01;
  small.memory_budget_bytes = 1 << 20;
  auto big = Voxelize(Cloud({{0, 0, 0}, {300, 300, 30}}), small);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.status().code(), StatusCode::kResourceExhausted);
  EXPECT_NE(big.status().message().find("use a resolution of at least"), std::string::npos);
}

TEST(VoxelizeTest, BadResolutionAndEmptyInputAreInvalid) {
  VoxelizeOptions o;
  o.resolution_m = -0.1;
  EXPECT_EQ(Voxelize(Cloud({{0, 0, 0}}), o).status().code(), StatusCode::kInvalidArgument);
  o.resolution_m = std::nan("");
  EXPECT_EQ(Voxelize(Cloud({{0, 0, 0}}), o).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(Voxelize(Cloud({}), {}).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace vc
