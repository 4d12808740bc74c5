#include "vc/visibility/subvoxel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "testing/subvoxel_reference.h"
#include "vc/synth/scanner_sim.h"
#include "vc/visibility/validation.h"

namespace vc {
namespace {

using Reference = testing::SubvoxelReference;

// Points of a cluttered little scene: a floor, a tilted board, a wall, a post and a loose blob.
std::vector<Eigen::Vector3f> ClutterPoints(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::normal_distribution<float> noise(0, 0.005f);
  std::vector<Eigen::Vector3f> points;
  const float tilt = 0.3f + 0.5f * u(rng);
  for (int i = 0; i < 6000; ++i) {
    const float x = 2 * u(rng), y = 2 * u(rng);
    points.emplace_back(x, y, 0.03f + noise(rng));  // floor
    if (x > 0.5f && x < 1.4f && y > 0.4f && y < 1.2f)
      points.emplace_back(x, y, 0.3f + tilt * (x - 0.5f) + noise(rng));  // board
    points.emplace_back(1.8f + noise(rng), y, 1.2f * u(rng));            // wall
  }
  for (int i = 0; i < 800; ++i) {
    const float a = 2 * float(std::numbers::pi) * u(rng);
    points.emplace_back(0.4f + 0.07f * std::cos(a), 1.5f + 0.07f * std::sin(a), 1.0f * u(rng));  // post
    points.emplace_back(1.2f + 0.1f * u(rng), 1.6f + 0.15f * u(rng), 0.5f + 0.2f * u(rng));      // blob
  }
  return points;
}

VoxelScene SceneOf(const std::vector<Eigen::Vector3f>& points, double resolution_m) {
  SceneInput input;
  input.points = points;
  VoxelizeOptions options;
  options.resolution_m = resolution_m;
  auto scene = Voxelize(input, options);
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return scene.ok() ? std::move(*scene) : VoxelScene{};
}

// The batched engine's sets from `viewpoints` (0.1 m voxels) equal the per-ray reference's, voxel by
// voxel (`what` names the case in a failure); something is seen and something hidden.
void ExpectEngineMatchesReference(const VoxelScene& scene, const std::vector<SurfacePatch>& patches,
                                  const std::vector<WorldPoint>& viewpoints, const std::string& what) {
  const Reference reference{scene, patches};
  VisibilitySetsOptions options;
  options.test = SelectionTest::kSubvoxel;
  options.surface_patches = patches;
  auto sets = ComputeVisibilitySets(scene, viewpoints, options);
  ASSERT_TRUE(sets.ok()) << sets.status().ToString();
  uint64_t seen = 0;
  for (size_t k = 0; k < viewpoints.size(); ++k) {
    const Eigen::Vector3d uo = viewpoints[k] / 0.1;
    for (size_t id = 0; id < scene.occupied.size(); ++id) {
      const bool expected = reference.Seen(uo, id);
      ASSERT_EQ((*sets)[k].test(id), expected) << what << ", viewpoint " << k << " voxel " << id;
      seen += expected;
    }
  }
  EXPECT_GT(seen, 100u);                                              // something is seen
  EXPECT_GT(viewpoints.size() * scene.occupied.size() - seen, 100u);  // and something is hidden
}

// The bulk engine (batched walks resumed at the first occupied voxel, subvoxel_bulk.cc), the same
// engine one voxel at a time (VisibilitySetsOptions::per_voxel) and the single query all agree with
// the reference, voxel by voxel, on cluttered scenes seen from random points and from candidate-like
// points (voxel centres and corners, where segments pass through lattice edges).
TEST(SubvoxelTest, EngineMatchesThePerRayReferenceOnClutteredScenes) {
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    const std::vector<Eigen::Vector3f> points = ClutterPoints(seed);
    const VoxelScene scene = SceneOf(points, 0.1);
    const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
    const Reference reference{scene, patches};
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<WorldPoint> viewpoints;
    while (viewpoints.size() < 10) {
      WorldPoint o(0.1 + 1.6 * u(rng), 0.1 + 1.8 * u(rng), 0.1 + 1.3 * u(rng));
      if (viewpoints.size() >= 8) o = (o / 0.1).array().floor() * 0.1 + 0.05 * (viewpoints.size() - 7);
      VoxelKey key;
      if (CoordToKey(0.1, o, &key) && scene.IdOf(key) < 0) viewpoints.push_back(o);
    }
    VisibilitySetsOptions options;
    options.test = SelectionTest::kSubvoxel;
    options.surface_patches = patches;
    options.threads = 2;
    auto sets = ComputeVisibilitySets(scene, viewpoints, options);
    ASSERT_TRUE(sets.ok()) << sets.status().ToString();
    options.per_voxel = true;
    auto per_voxel = ComputeVisibilitySets(scene, viewpoints, options);
    ASSERT_TRUE(per_voxel.ok()) << per_voxel.status().ToString();
    uint64_t seen = 0;
    for (size_t k = 0; k < viewpoints.size(); ++k) {
      const Eigen::Vector3d uo = viewpoints[k] / 0.1;
      for (size_t id = 0; id < scene.occupied.size(); ++id) {
        const bool expected = reference.Seen(uo, id);
        ASSERT_EQ((*sets)[k].test(id), expected) << "seed " << seed << " viewpoint " << k << " voxel " << id;
        ASSERT_EQ((*per_voxel)[k].test(id), expected) << "seed " << seed << " viewpoint " << k << " voxel " << id;
        ASSERT_EQ(IsSubvoxelVisible(scene, patches, viewpoints[k], id), expected);
        seen += expected;
      }
    }
    EXPECT_GT(seen, 100u);                                              // something is seen
    EXPECT_GT(viewpoints.size() * scene.occupied.size() - seen, 100u);  // and something is hidden
  }
}

// The same on loose clutter whose patches are random (flat or not, any normal, any box): the
// batched engine's shortcuts (the walks started at the viewpoint's free box, a segment judged by its
// first occupied voxel alone, the box fall-back's segments proved blocked by the voxel's last
// blocker, subvoxel_bulk.cc) meet blockers next to their targets, grazing and at every angle.
TEST(SubvoxelTest, EngineMatchesThePerRayReferenceOnRandomPatches) {
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Eigen::Vector3f> points;
    for (int cell = 0; cell < 500; ++cell) {
      const Eigen::Vector3f c(float(int(16 * u(rng))), float(int(16 * u(rng))), float(int(16 * u(rng))));
      for (int i = 0; i < 3; ++i) {
        points.push_back(0.1f * (c + Eigen::Vector3f(float(u(rng)), float(u(rng)), float(u(rng)))));
      }
    }
    const VoxelScene scene = SceneOf(points, 0.1);
    std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
    for (SurfacePatch& p : patches) {
      p.flat = u(rng) < 0.5;
      p.normal = Eigen::Vector3f(float(u(rng) - 0.5), float(u(rng) - 0.5), float(u(rng) - 0.5)).normalized();
      for (int i = 0; i < 3; ++i) {
        const int a = int(u(rng) * kPatchBoxSteps), b = int(u(rng) * kPatchBoxSteps);
        p.box_lo[i] = uint8_t(std::min(a, b));
        p.box_hi[i] = uint8_t(std::max(a, b));
      }
    }
    std::vector<WorldPoint> viewpoints;
    while (viewpoints.size() < 12) {
      // Random points only: from lattice points the segments meet exact ties, where the engines
      // may differ from the reference (docs/VISIBILITY.md, "Ties").
      const WorldPoint o(-0.2 + 2.0 * u(rng), -0.2 + 2.0 * u(rng), -0.2 + 2.0 * u(rng));
      VoxelKey key;
      if (CoordToKey(0.1, o, &key) && scene.IdOf(key) < 0) viewpoints.push_back(o);
    }
    ExpectEngineMatchesReference(scene, patches, viewpoints, "seed " + std::to_string(seed));
  }
}

TEST(SubvoxelTest, ScannerLimitsApplyAtTheAimPoint) {
  const std::vector<Eigen::Vector3f> points = ClutterPoints(7);
  const VoxelScene scene = SceneOf(points, 0.1);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  const WorldPoint o(1.0, 1.0, 1.4);
  ScannerModel scanner;
  scanner.min_range_m = 0.5;
  scanner.max_range_m = 1.2;
  VisibilitySetsOptions options;
  options.test = SelectionTest::kSubvoxel;
  options.surface_patches = patches;
  options.scanner = scanner;
  auto sets = ComputeVisibilitySets(scene, {o}, options);
  ASSERT_TRUE(sets.ok()) << sets.status().ToString();
  uint64_t seen = 0;
  for (size_t id = 0; id < scene.occupied.size(); ++id) {
    const double d = (patches[id].centroid_m.cast<double>() - o).norm();
    const bool unlimited = IsSubvoxelVisible(scene, patches, o, id);
    // Away from the range's ends (rounding), the limited test is the unlimited one within range.
    if (std::abs(d - 0.5) > 1e-6 && std::abs(d - 1.2) > 1e-6) {
      EXPECT_EQ((*sets)[0].test(id), unlimited && d >= 0.5 && d <= 1.2) << id;
    }
    EXPECT_EQ((*sets)[0].test(id), IsSubvoxelVisible(scene, patches, o, id, scanner));
    seen += (*sets)[0].test(id);
  }
  EXPECT_GT(seen, 10u);
}

TEST(SubvoxelTest, AGrazingBeamPassesOverAFloorPatch) {
  // A floor at the boundary of two voxel layers (z = 0.1 m, 5 mm of noise), so its voxels lie in
  // both layers; a scanner 5 cm above it, 0.3 m before it. The upper layer's cubes hide much of the lower one.
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0, 0.005f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 400; ++i) {
    for (int j = 0; j < 40; ++j)
      points.emplace_back(0.3f + 0.005f * float(i), -0.1f + 0.005f * float(j), 0.1f + noise(rng));
  }
  const VoxelScene scene = SceneOf(points, 0.1);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  const WorldPoint o(0.05, 0.0, 0.15);
  VisibilitySetsOptions surface;
  VisibilitySetsOptions subvoxel;
  subvoxel.test = SelectionTest::kSubvoxel;
  subvoxel.surface_patches = patches;
  auto cubes = ComputeVisibilitySets(scene, {o}, surface);
  auto sets = ComputeVisibilitySets(scene, {o}, subvoxel);
  ASSERT_TRUE(cubes.ok() && sets.ok());
  const double n = double(scene.occupied.size());
  // Measured: 100 of the 120 floor voxels under the sub-voxel test, 6 under surface visibility.
  EXPECT_GE(double((*sets)[0].count()), 0.8 * n);
  EXPECT_LT(double((*cubes)[0].count()), 0.2 * n);
}

// Beams grazing a bumpy floor from just above it: most segments miss the patch of their first
// occupied voxel and go on to their target or to the next voxel's patch, which the batched engine
// judges by following the cubes after the first (JudgePastMissed, core/visibility/src/subvoxel.cc)
// instead of tracing; every answer is the reference's.
TEST(SubvoxelTest, EngineMatchesThePerRayReferenceOverAGrazedFloor) {
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0, 0.02f);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 300; ++i) {
    for (int j = 0; j < 60; ++j)
      points.emplace_back(0.3f + 0.005f * float(i), -0.15f + 0.005f * float(j), 0.1f + noise(rng));
  }
  const VoxelScene scene = SceneOf(points, 0.1);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  std::vector<WorldPoint> viewpoints;
  for (int k = 0; k < 12; ++k) viewpoints.emplace_back(0.01 + 0.2 * u(rng), -0.1 + 0.2 * u(rng), 0.15 + 0.1 * u(rng));
  ExpectEngineMatchesReference(scene, patches, viewpoints, "grazed floor");
}

// Patches from `points` at 0.1 m, for the hand-made scenes below.
struct Scene {
  std::vector<Eigen::Vector3f> points;
  VoxelScene scene;
  std::vector<SurfacePatch> patches;
  explicit Scene(std::vector<Eigen::Vector3f> p)
      : points(std::move(p)), scene(SceneOf(points, 0.1)), patches(ComputeSurfacePatches(scene, points)) {}
  size_t Id(const WorldPoint& p) const {
    VoxelKey key;
    EXPECT_TRUE(CoordToKey(0.1, p, &key));
    const int64_t id = scene.IdOf(key);
    EXPECT_GE(id, 0);
    return size_t(id);
  }
};

TEST(SubvoxelTest, AVoxelBlocksOnlyOverItsPointsBox) {
  // A clump of points in the low corner of the cube [1, 1.1) x [0, 0.1) x [0, 0.1) (not flat), and a
  // target clump 0.5 m behind it along +x. A beam through the clump is blocked; one through the
  // cube's far corner, 0.05 m from the clump (more than kSubvoxelBoxPad edges beyond its box), is not.
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 0.02f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 40; ++i) points.emplace_back(1.0f + u(rng), u(rng), u(rng));
  for (int i = 0; i < 40; ++i) points.emplace_back(1.5f + u(rng), 0.005f + u(rng), 0.005f + u(rng));
  const Scene s(points);
  ASSERT_EQ(s.scene.occupied.size(), 2u);
  const size_t clump = s.Id({1.01, 0.01, 0.01}), target = s.Id({1.51, 0.01, 0.01});
  ASSERT_FALSE(s.patches[clump].flat);
  const Eigen::AlignedBox3d box = SubvoxelBoxIS(s.scene, s.patches, clump);
  EXPECT_DOUBLE_EQ(box.min().x(), 10.0);  // clipped to the cube
  EXPECT_LT(box.max().y(), 0.2 + kSubvoxelBoxPad + 0.01);
  const Eigen::Vector3d aim = SubvoxelAimIS(s.scene, s.patches, target);
  // From straight behind the target's centroid along -x, through the clump's box: blocked by it.
  const WorldPoint through(0.2, aim.y() * 0.1, aim.z() * 0.1);
  const SubvoxelRay blocked = ExplainSubvoxel(s.scene, s.patches, through, target);
  EXPECT_EQ(blocked.outcome, SubvoxelRay::Outcome::kBlocked);
  EXPECT_EQ(blocked.first_blocker, int64_t(clump));
  EXPECT_FALSE(IsSubvoxelVisible(s.scene, s.patches, through, target));
  // From a point whose beam to the centroid crosses the clump's cube at its far corner: clear.
  const Eigen::Vector3d corner(1.05, 0.09, 0.09);  // in the clump's cube, beyond its box
  const WorldPoint past = corner + (corner - aim * 0.1) * 2;
  const SubvoxelRay clear = ExplainSubvoxel(s.scene, s.patches, past, target);
  EXPECT_EQ(clear.outcome, SubvoxelRay::Outcome::kClear);
  EXPECT_EQ(clear.first_blocker, -1);
  EXPECT_TRUE(IsSubvoxelVisible(s.scene, s.patches, past, target));
  // The reference agrees on both.
  const testing::SubvoxelReference reference{s.scene, s.patches};
  EXPECT_FALSE(reference.Seen(through / 0.1, target));
  EXPECT_TRUE(reference.Seen(past / 0.1, target));
}

TEST(SubvoxelTest, ASparselySampledWallStillHidesWhatIsBehindIt) {
  // A wall at x = 2.05 m sampled every 5 cm (half an edge: its points' boxes alone would leave gaps
  // between voxels) before a densely sampled wall at x = 3.05 m: the boxes of the front wall reach
  // the faces they share with occupied neighbours, so no beam passes between them.
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) points.emplace_back(2.05f, -1.0f + 0.05f * float(i), -1.0f + 0.05f * float(j));
  }
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 100; ++j) points.emplace_back(3.05f, -0.5f + 0.01f * float(i), -0.5f + 0.01f * float(j));
  }
  const Scene s(points);
  const WorldPoint o(0.05, 0.03, 0.02);
  VisibilitySetsOptions options;
  options.test = SelectionTest::kSubvoxel;
  options.surface_patches = s.patches;
  auto sets = ComputeVisibilitySets(s.scene, {o}, options);
  ASSERT_TRUE(sets.ok()) << sets.status().ToString();
  uint64_t front_seen = 0, back_seen = 0;
  for (size_t id = 0; id < s.scene.occupied.size(); ++id) {
    const bool back = KeyToIndex(s.scene.occupied[id]).x == 30;
    if ((*sets)[0].test(id)) ++(back ? back_seen : front_seen);
  }
  EXPECT_EQ(back_seen, 0u);
  EXPECT_GT(double(front_seen), 0.95 * 400);  // of the front wall's 20 x 20 voxels
}

TEST(SubvoxelTest, AVoxelThatIsNotFlatIsSeenByAFaceOfItsBox) {
  // A cluster of points filling the middle of the cube [2.0, 2.1) x [0, 0.1) x [0, 0.1) (not flat),
  // seen from o = (1, 1, 0.05); a sliver of points at y in [0.10, 0.11] in the cube before it,
  // [1.9, 2.0) x [0.1, 0.2), lies across the segment to the cluster's centroid but not across the one
  // to the centre of the cluster's box face at y = 0.1 (which faces o).
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 200; ++i)
    points.emplace_back(2.02f + 0.06f * u(rng), 0.02f + 0.06f * u(rng), 0.02f + 0.06f * u(rng));
  for (int i = 0; i < 100; ++i)
    points.emplace_back(1.96f + 0.03f * u(rng), 0.10f + 0.01f * u(rng), 0.02f + 0.06f * u(rng));
  const Scene s(points);
  ASSERT_EQ(s.scene.occupied.size(), 2u);
  const size_t cluster = s.Id({2.05, 0.05, 0.05}), sliver = s.Id({1.975, 0.105, 0.05});
  ASSERT_FALSE(s.patches[cluster].flat);
  const WorldPoint o(1.0, 1.0, 0.05);
  const Eigen::Vector3d uo = o / 0.1;
  const testing::SubvoxelReference reference{s.scene, s.patches};
  const SubvoxelRay centroid = ExplainSubvoxel(s.scene, s.patches, o, sliver);
  EXPECT_TRUE(centroid.seen());  // the sliver itself is in view
  EXPECT_FALSE(reference.SegmentSees(uo, SubvoxelAimIS(s.scene, s.patches, cluster), cluster));
  const Eigen::AlignedBox3d box = SubvoxelBoxIS(s.scene, s.patches, cluster);
  EXPECT_NEAR(box.max().y(), 1.0, 0.01);  // the points' box (y <= 0.08 m) grown by kSubvoxelBoxPad
  EXPECT_TRUE(reference.SegmentSees(uo, Eigen::Vector3d(box.center().x(), box.max().y(), box.center().z()), cluster));
  EXPECT_TRUE(reference.Seen(uo, cluster));
  EXPECT_TRUE(IsSubvoxelVisible(s.scene, s.patches, o, cluster));
  EXPECT_TRUE(ExplainSubvoxel(s.scene, s.patches, o, cluster).seen());
}

TEST(SubvoxelTest, ExplainNamesTheOutcome) {
  const std::vector<Eigen::Vector3f> points = ClutterPoints(4);
  const VoxelScene scene = SceneOf(points, 0.1);
  const std::vector<SurfacePatch> patches = ComputeSurfacePatches(scene, points);
  const WorldPoint o(1.0, 1.0, 1.0);
  ScannerModel scanner;
  scanner.min_range_m = 0.0;
  scanner.max_range_m = 1.2;
  uint64_t outside = 0, blocked = 0, seen = 0;
  for (const WorldPoint& from : {o, WorldPoint(0.25, 1.2, 0.3), WorldPoint(1.0, 0.2, 0.15)})
    for (size_t id = 0; id < scene.occupied.size(); ++id) {
      const SubvoxelRay ray = ExplainSubvoxel(scene, patches, from, id, scanner);
      EXPECT_EQ(ray.seen(), IsSubvoxelVisible(scene, patches, from, id, scanner)) << id;
      outside += ray.outcome == SubvoxelRay::Outcome::kOutsideLimits;
      if (ray.outcome == SubvoxelRay::Outcome::kBlocked) {
        ++blocked;
        ASSERT_GE(ray.first_blocker, 0);
        EXPECT_NE(size_t(ray.first_blocker), id);
        EXPECT_GE(ray.blocker_s, 0.0);
        EXPECT_LE(ray.blocker_s, 1.0);
      }
      seen += ray.seen();
    }
  EXPECT_GT(outside, 100u);
  EXPECT_GT(blocked, 10u);
  EXPECT_GT(seen, 10u);
  // Invalid: a viewpoint inside an occupied voxel, and patches that are not one per voxel.
  const WorldPoint inside = scene.Center(0);
  EXPECT_EQ(ExplainSubvoxel(scene, patches, inside, 1).outcome, SubvoxelRay::Outcome::kInvalid);
  EXPECT_EQ(ExplainSubvoxel(scene, std::span<const SurfacePatch>(patches).first(3), o, 1).outcome,
            SubvoxelRay::Outcome::kInvalid);
}

TEST(SubvoxelTest, WithoutPatchesTheSurfaceTestRuns) {
  const std::vector<Eigen::Vector3f> points = ClutterPoints(2);
  const VoxelScene scene = SceneOf(points, 0.1);
  VisibilitySetsOptions surface;
  VisibilitySetsOptions subvoxel;
  subvoxel.test = SelectionTest::kSubvoxel;
  const std::vector<WorldPoint> viewpoints = {{1.0, 1.0, 1.0}, {0.3, 0.3, 0.6}};
  auto a = ComputeVisibilitySets(scene, viewpoints, surface);
  auto b = ComputeVisibilitySets(scene, viewpoints, subvoxel);
  ASSERT_TRUE(a.ok() && b.ok());
  for (size_t k = 0; k < viewpoints.size(); ++k) {
    EXPECT_GT((*a)[k].count(), 0u);
    EXPECT_EQ((*a)[k].count(), (*b)[k].count()) << k;
    EXPECT_EQ((*a)[k].CountAnd((*b)[k]), (*a)[k].count()) << k;
  }
}

TEST(SubvoxelTest, PatchesNotOnePerVoxelAreRefused) {
  const std::vector<Eigen::Vector3f> points = ClutterPoints(2);
  const VoxelScene scene = SceneOf(points, 0.1);
  const std::vector<SurfacePatch> patches(3);
  VisibilitySetsOptions options;
  options.test = SelectionTest::kSubvoxel;
  options.surface_patches = patches;
  auto sets = ComputeVisibilitySets(scene, {{1.0, 1.0, 1.0}}, options);
  ASSERT_FALSE(sets.ok());
  EXPECT_EQ(sets.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(sets.status().message().find("surface patches"), std::string::npos);
  EXPECT_FALSE(IsSubvoxelVisible(scene, patches, {1.0, 1.0, 1.0}, 0));
}

TEST(SubvoxelTest, NameIsSubvoxel) { EXPECT_EQ(SelectionTestName(SelectionTest::kSubvoxel), "subvoxel"); }

// A scan of `scene` from `position_m` (0.1 deg step, the given range noise, no dropout).
CapturedScan Scan(const AnalyticScene& scene, const WorldPoint& position_m, double noise_m, const std::string& name,
                  double hfov_deg = 360.0) {
  SimulatedScanner scanner;
  scanner.position_m = position_m;
  scanner.hfov_deg = hfov_deg;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.1;
  scanner.range_noise_sigma_m = noise_m;
  auto scan = SimulateScan(scene, scanner);
  EXPECT_TRUE(scan.ok()) << scan.status().ToString();
  return {name, position_m, scan.ok() ? scan->points_m : std::vector<Eigen::Vector3f>{}};
}

double Recall(const std::vector<CapturedScan>& scans, SelectionTest test) {
  ValidationOptions options;
  options.selection_test = test;
  auto report = ValidateAgainstScans(scans, options);
  EXPECT_TRUE(report.ok()) << report.status().ToString();
  return report.ok() ? report->scans[0].recall : 0.0;
}

TEST(SubvoxelTest, APlaneFullyInViewIsFullyPredictedAtEveryTilt) {
  for (const double noise_m : {0.0, 0.01}) {
    for (const double tilt_deg : {0.0, 30.0, 45.0, 60.0}) {
      auto scene = TiltedPlaneScene(tilt_deg, 3.05);
      ASSERT_TRUE(scene.ok());
      const std::vector<CapturedScan> scans = {Scan(*scene, {0, 0, 0}, noise_m, "plane", 100.0)};
      const double surface = Recall(scans, SelectionTest::kSurfaceVisibility);
      const double subvoxel = Recall(scans, SelectionTest::kSubvoxel);
      SCOPED_TRACE("tilt " + std::to_string(tilt_deg) + " noise " + std::to_string(noise_m));
      // Measured (docs/VISIBILITY.md): 1.000 without noise; 0.987-1.000 with 1 cm of noise. The
      // issue's target: 0.95.
      EXPECT_GE(subvoxel, noise_m == 0 ? 0.99 : 0.95);
      EXPECT_GE(subvoxel, surface);
      if (tilt_deg >= 30) {  // the second layer counts
        EXPECT_GT(subvoxel, surface + 0.2);
      }
    }
  }
}

TEST(SubvoxelTest, AVoxelBehindAWallIsNeverPredicted) {
  const Eigen::Vector3d y(0, 1, 0), z(0, 0, 1);
  const AnalyticScene scene{{Rectangle({2, 0, 0}, 3 * y, 3 * z), Rectangle({4, 0, 0}, 2 * y, 2 * z)}};
  ValidationOptions options;
  options.keep_sets = true;
  options.selection_test = SelectionTest::kSubvoxel;
  auto report =
      ValidateAgainstScans({Scan(scene, {0, 0, 0}, 0.01, "front"), Scan(scene, {6, 0, 0}, 0.01, "back")}, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const ScanAgreement& front = report->scans[0];
  const ScanAgreement& back = report->scans[1];
  ASSERT_GT(back.captured, 1000u);
  EXPECT_FALSE(front.captured_set.Intersects(back.captured_set));
  EXPECT_FALSE(front.predicted_set.Intersects(back.captured_set));
  EXPECT_FALSE(back.predicted_set.Intersects(front.captured_set));
  EXPECT_GE(front.recall, 0.95);
  EXPECT_GE(back.recall, 0.95);
}

}  // namespace
}  // namespace vc
