#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "testing/scenes.h"
#include "vc/scene/voxel_scene.h"
#include "vc/synth/synth.h"

namespace vc {
namespace {

using testing::Cloud;

Result<VoxelScene> Accumulate(const std::vector<Eigen::Vector3f>& pts, double r, uint64_t budget) {
  VoxelAccumulator acc(r, budget);
  for (const Eigen::Vector3f& p : pts) acc.Add(p);
  return acc.Finish();
}

// The two scenes are the same in every observable respect.
void ExpectSameScene(const VoxelScene& a, const VoxelScene& b) {
  EXPECT_EQ(a.resolution_m, b.resolution_m);
  EXPECT_EQ(a.frame_origin_m, b.frame_origin_m);
  ASSERT_EQ(a.occupied.size(), b.occupied.size());
  for (size_t i = 0; i < a.occupied.size(); ++i) ASSERT_EQ(a.occupied[i], b.occupied[i]) << i;
  EXPECT_EQ(a.grid.min_index(), b.grid.min_index());
  EXPECT_EQ(a.grid.dims(), b.grid.dims());
  EXPECT_EQ(a.grid.occupied_bricks(), b.grid.occupied_bricks());
  EXPECT_EQ(a.grid.memory_bytes(), b.grid.memory_bytes());
  EXPECT_EQ(a.BoundsMin(), b.BoundsMin());
  EXPECT_EQ(a.BoundsMax(), b.BoundsMax());
  // Every occupied voxel and its 6 neighbours answer alike.
  for (const VoxelKey& k : a.occupied) {
    const VoxelIndex v = KeyToIndex(k);
    for (const VoxelIndex& n :
         {v, VoxelIndex{v.x - 1, v.y, v.z}, VoxelIndex{v.x + 1, v.y, v.z}, VoxelIndex{v.x, v.y - 1, v.z},
          VoxelIndex{v.x, v.y + 1, v.z}, VoxelIndex{v.x, v.y, v.z - 1}, VoxelIndex{v.x, v.y, v.z + 1}}) {
      ASSERT_EQ(a.grid.Occupied(n), b.grid.Occupied(n));
    }
  }
}

std::vector<Eigen::Vector3f> RandomCloud(uint64_t seed, int n, float extent) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < n; ++i) pts.emplace_back(u(rng), u(rng), u(rng) / 4);
  // Points on exact multiples of the resolutions, where rounding matters most, and duplicates.
  for (int i = -200; i < 200; ++i) pts.emplace_back(float(i) * 0.01f, float(i) * 0.005f, float(i % 7) * 0.01f);
  for (int i = 0; i < 1000; ++i) pts.push_back(pts[size_t(i) * 7]);
  std::shuffle(pts.begin(), pts.end(), rng);
  return pts;
}

TEST(VoxelAccumulatorTest, SameSceneAsVoxelizeOnRandomClouds) {
  for (double r : {0.01, 0.05, 0.1, 0.37}) {
    // A box of 240 x 240 x 60 voxels: dense enough for duplicates, small enough to build fast.
    const auto pts = RandomCloud(uint64_t(r * 1000), 200000, float(120 * r));
    VoxelizeOptions opt;
    opt.resolution_m = r;
    auto want = Voxelize(Cloud(pts), opt);
    ASSERT_TRUE(want.ok()) << want.status().ToString();
    auto got = Accumulate(pts, r, kDefaultMemoryBudgetBytes);
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    ExpectSameScene(*got, *want);
  }
}

TEST(VoxelAccumulatorTest, ManyMergesUnderASmallBudgetGiveTheSameScene) {
  // 150k distinct voxels under a 16 MiB budget: the buffer fills and merges many times.
  const auto pts = RandomCloud(3, 300000, 20.0f);
  VoxelizeOptions opt;
  opt.resolution_m = 0.05;
  opt.memory_budget_bytes = uint64_t{16} << 20;
  auto want = Voxelize(Cloud(pts), opt);
  ASSERT_TRUE(want.ok());
  ASSERT_GT(want->occupied.size(), 150000u);
  VoxelAccumulator acc(0.05, opt.memory_budget_bytes);
  for (const auto& p : pts) acc.Add(p);
  EXPECT_TRUE(acc.status().ok()) << acc.status().ToString();
  EXPECT_LE(acc.peak_memory_bytes(), uint64_t{16} << 20);
  auto got = acc.Finish();
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  ExpectSameScene(*got, *want);
}

TEST(VoxelAccumulatorTest, MergesAtFullCapacityWithRepeatedKeysGiveTheSameScene) {
  // 2 million points drawn at random from 30000 voxels under a 1 MiB budget (57344 keys): the
  // buffer runs at its cap and every merge meets keys the sorted prefix already holds.
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<int> cell(0, 29999);
  std::uniform_real_distribution<float> u(0.0f, 0.0999f);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 2000000; ++i) {
    const int c = cell(rng);
    pts.emplace_back(float(c % 50) * 0.1f + u(rng), float((c / 50) % 30) * 0.1f + u(rng),
                     float(c / 1500) * 0.1f + u(rng));
  }
  VoxelAccumulator acc(0.1, uint64_t{1} << 20);
  for (const auto& p : pts) acc.Add(p);
  EXPECT_TRUE(acc.status().ok()) << acc.status().ToString();
  EXPECT_LE(acc.peak_memory_bytes(), uint64_t{1} << 20);
  auto got = acc.Finish();
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_EQ(got->occupied.size(), 30000u);
  VoxelizeOptions opt;
  opt.resolution_m = 0.1;
  opt.memory_budget_bytes = uint64_t{64} << 20;  // Voxelize holds 8 bytes per point
  auto want = Voxelize(Cloud(pts), opt);
  ASSERT_TRUE(want.ok()) << want.status().ToString();
  EXPECT_EQ(want->occupied.size(), 30000u);
  ExpectSameScene(*got, *want);
}

TEST(VoxelAccumulatorTest, SameSceneAsVoxelizeOnTheHall) {
  SynthOptions synth;
  synth.spacing_m = 0.05;
  auto pts = GenerateScene("hall", synth);
  ASSERT_TRUE(pts.ok());
  VoxelizeOptions opt;
  opt.resolution_m = 0.1;
  auto want = Voxelize(Cloud(*pts), opt);
  ASSERT_TRUE(want.ok());
  VoxelAccumulator acc(0.1);
  ASSERT_TRUE(ForEachScenePoint("hall", synth, [&](const Eigen::Vector3f& p) { acc.Add(p); }).ok());
  EXPECT_EQ(acc.points_added(), pts->size());
  auto got = acc.Finish();
  ASSERT_TRUE(got.ok());
  ExpectSameScene(*got, *want);
}

TEST(VoxelAccumulatorTest, MemoryGrowsWithOccupiedVoxelsNotPoints) {
  // 4 million points in 1000 voxels: 32 MB of keys if held per point, yet a 2 MiB budget suffices
  // (Voxelize of the same cloud refuses it).
  constexpr uint64_t kBudget = uint64_t{2} << 20;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 0.999f);
  VoxelAccumulator acc(0.1, kBudget);
  std::vector<Eigen::Vector3f> first;
  for (int i = 0; i < 4000000; ++i) {
    const Eigen::Vector3f p(float(i % 10) * 0.1f + 0.1f * u(rng), float((i / 10) % 10) * 0.1f + 0.1f * u(rng),
                            float((i / 100) % 10) * 0.1f + 0.1f * u(rng));
    if (first.size() < 500000) first.push_back(p);
    acc.Add(p);
  }
  EXPECT_LE(acc.peak_memory_bytes(), kBudget);
  auto got = acc.Finish();
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_EQ(got->occupied.size(), 1000u);
  VoxelizeOptions opt;
  opt.resolution_m = 0.1;
  opt.memory_budget_bytes = kBudget;
  EXPECT_EQ(Voxelize(Cloud(first), opt).status().code(), StatusCode::kResourceExhausted);
}

TEST(VoxelAccumulatorTest, RefusesBeforeExceedingTheBudgetWithAResolutionThatFits) {
  constexpr uint64_t kBudget = uint64_t{4} << 20;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 30.0f);
  VoxelAccumulator acc(0.01, kBudget);
  uint64_t added = 0;
  while (acc.status().ok() && added < 5000000) {
    acc.Add(Eigen::Vector3f(u(rng), u(rng), 0.005f));  // a 30 x 30 m floor at 0.01 m: 9e6 voxels
    ++added;
  }
  ASSERT_EQ(acc.status().code(), StatusCode::kResourceExhausted);
  EXPECT_LT(added, 5000000u);
  EXPECT_LE(acc.peak_memory_bytes(), kBudget);
  const std::string& msg = acc.status().message();
  EXPECT_NE(msg.find("use a resolution of at least"), std::string::npos) << msg;
  EXPECT_NE(msg.find(" m and has more than"), std::string::npos) << msg;
  auto finished = acc.Finish();
  EXPECT_EQ(finished.status().code(), StatusCode::kResourceExhausted);
  // The suggestion is coarser than the resolution refused (a lower bound: the stream was cut short).
  const double suggested = std::stod(msg.substr(msg.find("at least ") + 9));
  EXPECT_GT(suggested, 0.01);
  EXPECT_LT(suggested, 0.1);
}

TEST(VoxelAccumulatorTest, RefusesAGridThatCannotFitAsVoxelizeDoes) {
  VoxelizeOptions small;
  small.resolution_m = 0.01;
  small.memory_budget_bytes = 1 << 20;
  const std::vector<Eigen::Vector3f> pts = {{0, 0, 0}, {300, 300, 30}};
  auto want = Voxelize(Cloud(pts), small);
  auto got = Accumulate(pts, 0.01, 1 << 20);
  ASSERT_EQ(got.status().code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(got.status(), want.status());
}

TEST(VoxelAccumulatorTest, DropsAndCountsNonFinitePoints) {
  const auto pts = RandomCloud(8, 5000, 3.0f);
  std::vector<Eigen::Vector3f> dirty = pts;
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  dirty.insert(dirty.begin() + 10, Eigen::Vector3f(nan, 0, 0));
  dirty.insert(dirty.begin() + 20, Eigen::Vector3f(0, inf, 0));
  dirty.emplace_back(0, 0, -inf);
  VoxelAccumulator acc(0.1);
  for (const auto& p : dirty) acc.Add(p);
  EXPECT_EQ(acc.dropped_nonfinite(), 3u);
  EXPECT_EQ(acc.points_added(), pts.size());
  auto got = acc.Finish();
  ASSERT_TRUE(got.ok());
  VoxelizeOptions opt;
  opt.resolution_m = 0.1;
  ExpectSameScene(*got, *Voxelize(Cloud(pts), opt));
}

TEST(VoxelAccumulatorTest, EmptyOrAllNonFiniteCloudIsInvalid) {
  VoxelAccumulator empty(0.1);
  EXPECT_EQ(empty.Finish().status().code(), StatusCode::kInvalidArgument);
  VoxelAccumulator nans(0.1);
  nans.Add(Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  auto r = nans.Finish();
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("1 non-finite"), std::string::npos) << r.status().message();
}

TEST(VoxelAccumulatorTest, BadResolutionIsInvalid) {
  for (double r : {0.0, -0.1, std::nan(""), 1e-5}) {
    VoxelAccumulator acc(r);
    EXPECT_EQ(acc.status().code(), StatusCode::kInvalidArgument) << r;
    acc.Add(Eigen::Vector3f(1, 2, 3));
    EXPECT_EQ(acc.points_added(), 0u);
    EXPECT_EQ(acc.Finish().status().code(), StatusCode::kInvalidArgument);
  }
}

TEST(VoxelAccumulatorTest, PointOutsideTheKeyRangeIsInvalidAsInVoxelize) {
  const std::vector<Eigen::Vector3f> pts = {{0, 0, 0}, {5000, 0, 0}, {1, 1, 1}};
  auto want = Voxelize(Cloud(pts), {});
  VoxelAccumulator acc(0.1);
  for (const auto& p : pts) acc.Add(p);
  EXPECT_EQ(acc.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(acc.status().message().find("key range"), std::string::npos) << acc.status().message();
  EXPECT_EQ(acc.points_added(), 2u);  // the third point is ignored after the error
  EXPECT_EQ(acc.Finish().status().code(), want.status().code());
}

TEST(VoxelAccumulatorTest, FinishKeepsTheFrameOriginItWasTold) {
  VoxelAccumulator survey(0.1);
  EXPECT_EQ(survey.frame_origin_m(), WorldPoint::Zero());
  survey.set_frame_origin_m({512000, 5612000, 1000});
  survey.Add(Eigen::Vector3f(345.5f, 330.25f, -687.5f));
  Result<VoxelScene> scene = survey.Finish();
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  EXPECT_EQ(scene->frame_origin_m, WorldPoint(512000, 5612000, 1000));
  SceneInput same = Cloud({{345.5f, 330.25f, -687.5f}});
  same.frame_origin_m = {512000, 5612000, 1000};
  ExpectSameScene(*scene, *Voxelize(same, {}));
}

TEST(VoxelAccumulatorTest, FinishTwiceIsAFailedPrecondition) {
  VoxelAccumulator acc(0.1);
  acc.Add(Eigen::Vector3f(1, 2, 3));
  ASSERT_TRUE(acc.Finish().ok());
  EXPECT_EQ(acc.Finish().status().code(), StatusCode::kFailedPrecondition);
}

TEST(VoxelAccumulatorTest, FinishHonoursCancellation) {
  VoxelAccumulator acc(0.1);
  acc.Add(Eigen::Vector3f(1, 2, 3));
  CancelToken token;
  token.Cancel();
  JobContext ctx;
  ctx.cancel = &token;
  EXPECT_EQ(acc.Finish(ctx).status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace vc
