#include "vc/scene/voxel_scene.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cstdio>
#include <random>
#include <string>

#include "testing/scenes.h"
#include "testing/test_paths.h"
#include "vc/scene/octomap_adapter.h"

namespace vc {
namespace {

using testing::Cloud;
using ::testing::HasSubstr;
using ::testing::Not;

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

TEST(VoxelizeTest, TheKeyRangeMessageNamesTheExtentAndAResolutionThatFits) {
  auto far = Voxelize(Cloud({{0, 0, 0}, {5000, 0, 0}}), {});
  ASSERT_FALSE(far.ok());
  EXPECT_THAT(far.status().message(), HasSubstr("the scene spans 5,000 x 0 x 0 m and does not fit"));
  EXPECT_THAT(far.status().message(), HasSubstr("a resolution of at least 0.153 m fits"));
  EXPECT_THAT(far.status().message(), Not(HasSubstr("origin. ")));
  EXPECT_THAT(far.status().message(), Not(HasSubstr("millimetres")));
}

// A cloud read as metres that spans more than any site is told what it probably is: millimetres
// when a thousandth of it is a plausible site, else stray points.
TEST(VoxelizeTest, AnImplausibleExtentNamesTheLikelyUnits) {
  auto mm = Voxelize(Cloud({{0, 0, 0}, {27400, 18200, 3100}}), {});
  ASSERT_EQ(mm.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(mm.status().message(), HasSubstr("the scene spans 27,400 x 18,200 x 3,100 m as metres"));
  EXPECT_THAT(mm.status().message(), HasSubstr("is the file in millimetres (it would span 27.4 x 18.2 x 3.1 m)?"));
  EXPECT_THAT(mm.status().message(), HasSubstr("vc-client --units mm"));
  VoxelizeOptions coarse;
  coarse.resolution_m = 2;
  coarse.memory_budget_bytes = 1 << 20;
  auto memory = Voxelize(Cloud({{0, 0, 0}, {27400, 18200, 3100}}), coarse);
  ASSERT_EQ(memory.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(memory.status().message(), HasSubstr("for centimetres). As metres it needs "));
  EXPECT_THAT(memory.status().message(), HasSubstr("MiB for its traversal grid alone at resolution 2 m, over the"));
  auto stray = Voxelize(Cloud({{0, 0, 0}, {0, 9e6, 0}}), {});
  ASSERT_EQ(stray.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(stray.status().message(), HasSubstr("stray points"));
  EXPECT_THAT(stray.status().message(), Not(HasSubstr("millimetres")));
}

TEST(VoxelizeTest, AMillimetreCopyOfTheHallScanIsToldItsUnitsAndReadsWithThem) {
  Result<SceneInput> hall = ReadSceneFile(testing::SharedDataPath("hall-scan/scan.dat.bz2"));
  ASSERT_TRUE(hall.ok()) << hall.status().ToString();
  std::string in_mm;
  for (const Eigen::Vector3f& p : hall->points) {
    char line[96];
    std::snprintf(line, sizeof line, "%.3f %.3f %.3f\n", 1000.0 * p.x(), 1000.0 * p.y(), 1000.0 * p.z());
    in_mm += line;
  }
  Result<SceneInput> as_metres = ReadScene(in_mm, "hall-mm.xyz");
  ASSERT_TRUE(as_metres.ok()) << as_metres.status().ToString();
  auto refused = Voxelize(*as_metres, {});
  ASSERT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("is the file in millimetres"));
  EXPECT_THAT(refused.status().message(), HasSubstr("--units mm"));

  ReadOptions mm;
  mm.metres_per_unit = *MetresPerUnit("mm");
  Result<SceneInput> with_units = ReadScene(in_mm, "hall-mm.xyz", mm);
  ASSERT_TRUE(with_units.ok()) << with_units.status().ToString();
  EXPECT_EQ(with_units->frame_origin_m, Eigen::Vector3d::Zero());
  Result<VoxelScene> original = Voxelize(*hall, {}), from_mm = Voxelize(*with_units, {});
  ASSERT_TRUE(original.ok() && from_mm.ok()) << from_mm.status().ToString();
  EXPECT_EQ(from_mm->occupied, original->occupied);
}

TEST(VoxelizeTest, TheSceneKeepsTheInputsFrameOrigin) {
  SceneInput survey = Cloud({{0.5f, 0.5f, 0.5f}, {3.25f, -1.5f, 2}});
  survey.frame_origin_m = {512000, 5612000, 0};
  Result<VoxelScene> scene = Voxelize(survey, {});
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  EXPECT_EQ(scene->frame_origin_m, WorldPoint(512000, 5612000, 0));
  EXPECT_EQ(scene->occupied.size(), 2u);
  EXPECT_EQ(Voxelize(Cloud({{0, 0, 0}}), {})->frame_origin_m, WorldPoint::Zero());
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
