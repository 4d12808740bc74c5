#include "vc/scene/surface_patches.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace vc {
namespace {

// The scene of `points` at 0.1 m.
VoxelScene SceneOf(const std::vector<Eigen::Vector3f>& points) {
  SceneInput input;
  input.points = points;
  VoxelizeOptions options;
  options.resolution_m = 0.1;
  auto scene = Voxelize(input, options);
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return scene.ok() ? std::move(*scene) : VoxelScene{};
}

// A grid of n x n points on the plane z = z0 + slope * x over [x0, x0 + side] x [y0, y0 + side].
std::vector<Eigen::Vector3f> PlanePoints(float x0, float y0, float z0, float slope, float side, int n) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const float x = x0 + side * float(i) / float(n - 1), y = y0 + side * float(j) / float(n - 1);
      points.emplace_back(x, y, z0 + slope * (x - x0));
    }
  }
  return points;
}

TEST(SurfacePatchesTest, PointsOnAPlaneGiveItsNormalCentroidAndAreFlat) {
  const auto points = PlanePoints(0.01f, 0.01f, 0.02f, 0.5f, 0.08f, 9);
  const VoxelScene scene = SceneOf(points);
  ASSERT_EQ(scene.occupied.size(), 1u);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  ASSERT_EQ(patches.size(), 1u);
  const SurfacePatch& p = patches[0];
  const Eigen::Vector3d expected = Eigen::Vector3d(-0.5, 0, 1).normalized();
  EXPECT_NEAR(std::abs(p.normal.cast<double>().dot(expected)), 1.0, 1e-5);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& q : points) mean += q.cast<double>();
  mean /= double(points.size());
  EXPECT_LT((p.centroid_m.cast<double>() - mean).norm(), 1e-6);
  EXPECT_LT(p.thickness_m, 1e-5);
  EXPECT_EQ(p.points, 81);
  EXPECT_TRUE(p.flat);
}

TEST(SurfacePatchesTest, TheBoxHoldsThePointsRoundedOutwards) {
  // Two points of the cube [0, 0.1)^3: the box spans them, in 1/255 edge steps, rounded outwards.
  const std::vector<Eigen::Vector3f> points = {{0.021f, 0.05f, 0.003f}, {0.04f, 0.07f, 0.097f}};
  const VoxelScene scene = SceneOf(points);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  ASSERT_EQ(patches.size(), 1u);
  const SurfacePatch& p = patches[0];
  for (int i = 0; i < 3; ++i) {
    const double lo = std::min(points[0][i], points[1][i]) / 0.1 * kPatchBoxSteps;
    const double hi = std::max(points[0][i], points[1][i]) / 0.1 * kPatchBoxSteps;
    EXPECT_LE(p.box_lo[i], lo) << i;
    EXPECT_GT(p.box_lo[i] + 1, lo) << i;
    EXPECT_GE(p.box_hi[i], hi) << i;
    EXPECT_LT(p.box_hi[i] - 1, hi) << i;
  }
  // A voxel no point fell in keeps the whole cube.
  SurfacePatchBuilder empty(scene);
  const SurfacePatch none = empty.Finish()[0];
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(none.box_lo[i], 0);
    EXPECT_EQ(none.box_hi[i], kPatchBoxSteps);
  }
}

TEST(SurfacePatchesTest, PointsOnALineAreNotFlat) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 20; ++i) points.emplace_back(0.01f + 0.004f * float(i), 0.05f, 0.05f);
  const VoxelScene scene = SceneOf(points);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  ASSERT_EQ(patches.size(), 1u);
  EXPECT_FALSE(patches[0].flat);  // no spread across a plane
  EXPECT_EQ(patches[0].points, 20);
}

TEST(SurfacePatchesTest, PointsFillingTheCubeAreNotFlat) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.001f, 0.099f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 500; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  const VoxelScene scene = SceneOf(points);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  ASSERT_EQ(patches.size(), 1u);
  EXPECT_FALSE(patches[0].flat);
  EXPECT_GT(patches[0].thickness_m, 0.02f);  // ~0.029 m, the RMS of a uniform 0.1 m interval
}

TEST(SurfacePatchesTest, FewerThanThreePointsAreNotFlatAndKeepTheirMean) {
  const std::vector<Eigen::Vector3f> points = {{0.02f, 0.02f, 0.02f}, {0.04f, 0.06f, 0.08f}};
  const VoxelScene scene = SceneOf(points);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  ASSERT_EQ(patches.size(), 1u);
  EXPECT_FALSE(patches[0].flat);
  EXPECT_LT((patches[0].centroid_m - Eigen::Vector3f(0.03f, 0.04f, 0.05f)).norm(), 1e-6f);
}

TEST(SurfacePatchesTest, PointsOutsideTheSceneAreIgnoredAndCounted) {
  const auto points = PlanePoints(0.01f, 0.01f, 0.05f, 0.0f, 0.08f, 5);
  const VoxelScene scene = SceneOf(points);
  SurfacePatchBuilder builder(scene);
  for (const auto& p : points) builder.Add(p);
  builder.Add({1.0f, 1.0f, 1.0f});
  builder.Add({std::nanf(""), 0.0f, 0.0f});
  EXPECT_EQ(builder.ignored(), 2u);
  const std::vector<SurfacePatch> patches = builder.Finish();
  ASSERT_EQ(patches.size(), 1u);
  EXPECT_EQ(patches[0].points, 25);
}

TEST(SurfacePatchesTest, AVoxelWithNoPointKeepsItsCentreAndIsNotFlat) {
  const auto points = PlanePoints(0.01f, 0.01f, 0.05f, 0.0f, 0.18f, 10);
  const VoxelScene scene = SceneOf(points);
  ASSERT_EQ(scene.occupied.size(), 4u);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, {});
  ASSERT_EQ(patches.size(), 4u);
  for (size_t id = 0; id < patches.size(); ++id) {
    EXPECT_EQ(patches[id].points, 0);
    EXPECT_FALSE(patches[id].flat);
    EXPECT_LT((patches[id].centroid_m.cast<double>() - scene.Center(id)).norm(), 1e-6);
  }
}

TEST(SurfacePatchesTest, PassesPerScanGiveTheSamePatchesAsOne) {
  auto points = PlanePoints(0.01f, 0.01f, 0.03f, 0.3f, 0.35f, 30);
  const VoxelScene scene = SceneOf(points);
  const std::vector<SurfacePatch> once = ComputeSurfacePatches(scene, points);
  SurfacePatchBuilder builder(scene);
  for (size_t i = 0; i < points.size(); i += 2) builder.Add(points[i]);
  for (size_t i = 1; i < points.size(); i += 2) builder.Add(points[i]);
  const std::vector<SurfacePatch> twice = builder.Finish();
  ASSERT_EQ(once.size(), twice.size());
  for (size_t id = 0; id < once.size(); ++id) {
    EXPECT_EQ(once[id].points, twice[id].points);
    EXPECT_EQ(once[id].flat, twice[id].flat);
    EXPECT_LT((once[id].centroid_m - twice[id].centroid_m).norm(), 1e-6f);
  }
}

TEST(SurfacePatchesTest, ASliverTakesTheFlatNeighboursPlaneItsPointsLieOn) {
  // The plane z = 0.05 + 0.2 (x - 0.01) over one voxel, and two more of its points in the next one.
  std::vector<Eigen::Vector3f> points = PlanePoints(0.01f, 0.01f, 0.05f, 0.2f, 0.08f, 9);
  points.emplace_back(0.12f, 0.03f, 0.05f + 0.2f * 0.11f);
  points.emplace_back(0.12f, 0.06f, 0.05f + 0.2f * 0.11f);
  const VoxelScene scene = SceneOf(points);
  ASSERT_EQ(scene.occupied.size(), 2u);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  const size_t plane = patches[0].points > patches[1].points ? 0 : 1, sliver = 1 - plane;
  EXPECT_LE(patches[sliver].points, 2);
  EXPECT_TRUE(patches[plane].flat);
  EXPECT_FALSE(patches[plane].borrowed);
  EXPECT_TRUE(patches[sliver].flat);
  EXPECT_TRUE(patches[sliver].borrowed);
  EXPECT_EQ(patches[sliver].normal, patches[plane].normal);
  EXPECT_LT(patches[sliver].thickness_m, 1e-5f);
}

TEST(SurfacePatchesTest, PointsOffTheNeighboursPlaneBorrowNothing) {
  std::vector<Eigen::Vector3f> points = PlanePoints(0.01f, 0.01f, 0.05f, 0.0f, 0.08f, 9);
  points.emplace_back(0.15f, 0.05f, 0.01f);  // 4 cm below the plane's level, in the next voxel
  points.emplace_back(0.16f, 0.05f, 0.09f);  // and 4 cm above it
  const VoxelScene scene = SceneOf(points);
  ASSERT_EQ(scene.occupied.size(), 2u);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  const size_t odd = patches[0].points == 2 ? 0 : 1;
  EXPECT_FALSE(patches[odd].flat);
  EXPECT_FALSE(patches[odd].borrowed);
}

}  // namespace
}  // namespace vc
