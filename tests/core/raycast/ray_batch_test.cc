// FirstOccupiedBatch against FirstOccupied, answer by answer: its lanes kernel forced on every
// instruction set Highway compiled in and this CPU supports, the scalar one included, so the
// kernel is tested on any CI machine, with or without AVX-512.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "testing/test_paths.h"
#include "vc/raycast/ray_traversal.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"

namespace vc {
namespace {

using Eigen::Vector3d;

struct Segments {
  std::vector<Vector3d> a, b;
  void Add(const Vector3d& from, const Vector3d& to) {
    a.push_back(from);
    b.push_back(to);
  }
};

// Runs the batch once per target (each forced through Highway's test mock) and compares every
// answer with the scalar FirstOccupied. Returns how many answers were hits.
int ExpectSameOnEveryTarget(const OccupancyGrid& grid, const Segments& s, const std::string& what) {
  std::vector<std::optional<VoxelIndex>> expect(s.a.size());
  int hits = 0;
  for (size_t i = 0; i < s.a.size(); ++i) {
    expect[i] = FirstOccupied(grid, s.a[i], s.b[i]);
    hits += expect[i].has_value();
  }
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  for (int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    std::vector<std::optional<VoxelIndex>> got(s.a.size(), VoxelIndex{1 << 30, 0, 0});
    const std::string ran = FirstOccupiedBatch(grid, s.a, s.b, got, BatchKernel::kLanes);
    EXPECT_EQ(ran, std::string(hwy::TargetName(target)) + " lanes") << "the dispatch did not run the forced target";
    int differ = 0;
    for (size_t i = 0; i < got.size(); ++i) {
      if (got[i] != expect[i]) {
        if (++differ <= 3) {
          ADD_FAILURE() << what << " on " << ran << ": segment " << i << " (" << s.a[i].transpose() << ") -> ("
                        << s.b[i].transpose() << ") differs";
        }
      }
    }
    EXPECT_EQ(differ, 0) << what << " on " << ran << ", of " << got.size() << " segments";
  }
  hwy::SetSupportedTargetsForTest(0);
  return hits;
}

TEST(FirstOccupiedBatchTest, TheScalarTargetIsCompiledAndTested) {
  bool scalar = false;
  for (int64_t t : hwy::SupportedAndGeneratedTargets()) scalar |= t == HWY_SCALAR || t == HWY_EMU128;
  EXPECT_TRUE(scalar) << "the forced-scalar path is not among the compiled targets";
}

TEST(FirstOccupiedBatchTest, MatchesFirstOccupiedOnRandomGrids) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> c(-30, 30);
  std::uniform_real_distribution<double> u(-36, 36);
  for (int scene = 0; scene < 6; ++scene) {
    std::vector<VoxelIndex> occ;
    for (int i = 0; i < 3000; ++i) occ.push_back({c(rng), c(rng), c(rng) / 2});
    auto grid = OccupancyGrid::Build(0.1, occ, 1 << 24);
    ASSERT_TRUE(grid.ok());
    Segments s;
    for (int r = 0; r < 3000; ++r) s.Add({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
    const int hits = ExpectSameOnEveryTarget(*grid, s, "random grid " + std::to_string(scene));
    EXPECT_GT(hits, 1000);
  }
}

// Sparse scenes with long segments: most of each walk is jumps across free boxes of bricks.
TEST(FirstOccupiedBatchTest, MatchesFirstOccupiedAcrossFreeBoxes) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> c(-200, 200);
  std::uniform_real_distribution<double> u(-230, 230);
  std::vector<VoxelIndex> occ;
  for (int i = 0; i < 60; ++i) {
    const VoxelIndex base{c(rng), c(rng), c(rng) / 4};
    for (int d = 0; d < 36; ++d) occ.push_back({base.x + d % 6, base.y + d / 6, base.z});
  }
  for (int y = -150; y <= 150; ++y)
    for (int z = -30; z <= 30; ++z) occ.push_back({41, y, z});
  auto grid = OccupancyGrid::Build(0.1, occ, 1 << 26);
  ASSERT_TRUE(grid.ok());
  Segments s;
  for (int r = 0; r < 20000; ++r) s.Add({u(rng), u(rng), u(rng) / 4}, {u(rng), u(rng), u(rng) / 4});
  EXPECT_GT(ExpectSameOnEveryTarget(*grid, s, "sparse scene"), 3000);
}

// Exact ties: endpoints on lattice points and voxel centres, axis-aligned and diagonal segments,
// zero-length segments, segments that start or end outside the grid's box, and segments that
// start inside an occupied voxel.
TEST(FirstOccupiedBatchTest, MatchesFirstOccupiedOnTiesAndEdgeCases) {
  std::vector<VoxelIndex> occ;
  for (int x = -8; x <= 8; ++x)
    for (int y = -8; y <= 8; ++y) {
      occ.push_back({x, y, -8});                       // floor
      if ((x + y) % 3 == 0) occ.push_back({x, y, 4});  // a perforated slab
    }
  for (int z = -8; z <= 8; ++z) occ.push_back({0, 0, z});  // a post
  auto grid = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(grid.ok());
  Segments s;
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<int> p(-20, 20);
  for (int r = 0; r < 6000; ++r) {
    const double ha = (r % 3 == 0) ? 0.5 : 0.0, hb = (r % 2 == 0) ? 0.5 : 0.0;
    s.Add({p(rng) + ha, p(rng) + ha, p(rng) + ha}, {p(rng) + hb, p(rng) + hb, p(rng) + hb});
  }
  for (int i = -20; i <= 20; ++i) {
    const double k = i;
    s.Add({k + 0.5, 0.5, 20.5}, {k + 0.5, 0.5, -20.5});  // straight down
    s.Add({-20.0, k, k}, {20.0, -k, -k});                // through edges and corners
    s.Add({k, k, k}, {k, k, k});                         // zero length
    s.Add({0.5, 0.5, 0.5}, {k, 20.0, 3.0});              // starts inside the post
    s.Add({-3e4, k, 2.5}, {3e4, -k, 2.5});               // far outside at both ends
  }
  EXPECT_GT(ExpectSameOnEveryTarget(*grid, s, "ties and edge cases"), 1000);  // seen: 1664
}

// The real geb079 map: segments between random points in and around the building.
TEST(FirstOccupiedBatchTest, MatchesFirstOccupiedOnGeb079) {
  auto input = ReadSceneFile(testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(input.ok()) << input.status().ToString();
  auto scene = Voxelize(*input, {});
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const double r = scene->resolution_m;
  std::mt19937_64 rng(2014);
  std::uniform_real_distribution<double> ux(-8.0, 31.0), uy(-7.5, 7.4), uz(-0.3, 2.8);
  Segments s;
  for (int n = 0; n < 20000; ++n) {
    s.Add(Vector3d(ux(rng), uy(rng), uz(rng)) / r, Vector3d(ux(rng), uy(rng), uz(rng)) / r);
  }
  EXPECT_GT(ExpectSameOnEveryTarget(scene->grid, s, "geb079"), 5000);
}

// Near-ties: lattice-point and voxel-centre endpoints moved by a few ulps, by 2^-30 and by 1e-7
// of a voxel, so that crossings of different axes fall just inside and just outside the lanes'
// margin (2^-20 of the segment) on both sides of exact ties.
TEST(FirstOccupiedBatchTest, MatchesFirstOccupiedOnNearTies) {
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<int> c(-12, 12), p(-16, 16), way(0, 5);
  std::vector<VoxelIndex> occ;
  for (int i = 0; i < 700; ++i) occ.push_back({c(rng), c(rng), c(rng)});
  auto grid = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(grid.ok());
  const double nudges[] = {0.0, 0x1p-50, 0x1p-30, 1e-7, 3e-6};
  auto nudge = [&](double v) {
    switch (way(rng)) {
      case 0:
        return std::nextafter(v, 1e9);
      case 1:
        return std::nextafter(std::nextafter(v, -1e9), -1e9);
      default:
        return v + (way(rng) % 2 ? 1 : -1) * nudges[way(rng) % 5];
    }
  };
  Segments s;
  for (int r = 0; r < 12000; ++r) {
    const double h = (r % 4 == 0) ? 0.5 : 0.0;
    Vector3d a(p(rng) + h, p(rng) + h, p(rng) + h), b(p(rng), p(rng), p(rng));
    for (int i = 0; i < 3; ++i) a[i] = nudge(a[i]), b[i] = nudge(b[i]);
    s.Add(a, b);
  }
  EXPECT_GT(ExpectSameOnEveryTarget(*grid, s, "near-ties"), 2000);
}

// What the lanes leave to FirstOccupied: every segment whose walk meets an exact tie before it
// ends, and every segment too long or too far out for their float and int32 arithmetic; of
// generic rays, few.
TEST(FirstOccupiedBatchTest, ExactTiesAndOversizedSegmentsAreLeftToFirstOccupied) {
  std::vector<VoxelIndex> occ;
  for (int x = -40; x <= 40; ++x)
    for (int y = -40; y <= 40; ++y) occ.push_back({x, y, -20});  // a floor
  Segments ties, oversized, generic;
  for (int k = -10; k <= 10; ++k) {
    // Through voxel corners: all three axes cross together at every step.
    ties.Add({double(k), double(k), 0.0}, {double(k) + 30, double(k) - 30, -30.0});
    // Through edges: x and z cross together.
    ties.Add({double(k), 0.5, 0.0}, {double(k) - 30, 0.5, -30.0});
  }
  // Each starts inside the grid's box (a voxel at z = 20 makes it span z = -20..20) and leaves it
  // or hits the floor within a few dozen steps, so FirstOccupied is quick on them (it walks a
  // segment that starts far outside the box voxel by voxel up to the box).
  occ.push_back({0, 0, 20});
  oversized.Add({0.5, 0.5, 10.5}, {5e6, 0.5, -1e4});  // 5e6 steps along x (> 2^22)
  oversized.Add({0.5, 0.5, 10.5}, {0.5, 0.5, -6e6});  // 6e6 steps along z, hits the floor
  oversized.Add({0.5, 0.5, 10.5}, {2e9, 0.5, 10.5});  // an end beyond 2^30
  oversized.Add({0.5, 0.5, 10.5}, {0.5, -2e9, -30.5});
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-45, 45);
  for (int r = 0; r < 4000; ++r) generic.Add({u(rng), u(rng), u(rng) / 2 + 5}, {u(rng), u(rng), -25.0});
  auto grid = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(grid.ok());
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    const std::string name = hwy::TargetName(target);
    for (const Segments* set : {&ties, &oversized, &generic}) {
      std::vector<std::optional<VoxelIndex>> got(set->a.size());
      std::vector<char> certified(set->a.size(), 7);
      size_t rechecked = 99999;
      FirstOccupiedBatch(*grid, set->a, set->b, got, BatchKernel::kLanes, &rechecked, certified);
      size_t uncertified = 0;
      for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i], FirstOccupied(*grid, set->a[i], set->b[i])) << name << ", segment " << i;
        ASSERT_TRUE(certified[i] == 0 || certified[i] == 1) << name << ", segment " << i;
        uncertified += certified[i] == 0;
      }
      // The segments left to FirstOccupied are exactly those not certified.
      EXPECT_EQ(uncertified, rechecked) << name;
      if (set == &generic) {
        EXPECT_LT(rechecked, got.size() / 20) << name << ": generic rays should rarely be near-ties";
      } else {
        EXPECT_EQ(rechecked, got.size()) << name << (set == &ties ? ": exact ties" : ": oversized segments");
      }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

// Where the lanes do not run (kAuto below AVX-512), no segment is certified: FirstOccupied walked
// them all; where they do, the generic segments are.
TEST(FirstOccupiedBatchTest, CertifiedOnlyWhereTheLanesAnswered) {
  std::vector<VoxelIndex> occ;
  for (int x = -20; x <= 20; ++x)
    for (int y = -20; y <= 20; ++y) occ.push_back({x, y, -10});
  auto grid = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(grid.ok());
  Segments s;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-18, 18);
  for (int r = 0; r < 500; ++r) s.Add({u(rng), u(rng), 5.3}, {u(rng), u(rng), -9.5});
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (const BatchKernel kernel : {BatchKernel::kAuto, BatchKernel::kLanes}) {
      std::vector<std::optional<VoxelIndex>> got(s.a.size());
      std::vector<char> certified(s.a.size(), 1);
      size_t rechecked = 0;
      const std::string ran = FirstOccupiedBatch(*grid, s.a, s.b, got, kernel, &rechecked, certified);
      size_t count = 0;
      for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i], FirstOccupied(*grid, s.a[i], s.b[i])) << ran << ", segment " << i;
        count += certified[i] == 1;
      }
      if (ran.ends_with(" lanes")) {
        // Exactly the segments not left to FirstOccupied are certified.
        EXPECT_EQ(count + rechecked, got.size()) << ran;
        EXPECT_GT(count, got.size() * 19 / 20) << ran;
      } else {
        EXPECT_EQ(count, 0u) << ran;
      }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

// Lanes step through empty bricks too (they jump across them only in some passes), and every such
// step is a certified decision like any other: an exact tie met in an empty brick must go to
// FirstOccupied even when the lane's next voxels are free. Here each segment runs diagonally
// through voxel corners (x and y cross together at every step) out of an empty brick, whose
// corner voxel (7,7) is followed, by FirstOccupied's tie rule (y before x), by (7,8), occupied. A
// lane that stepped both axes at once, as it would if it did not treat the tie as one, would skip
// (7,8) and hit (8,8) instead.
TEST(FirstOccupiedBatchTest, TiesMetInEmptyBricksAreLeftToFirstOccupied) {
  const std::vector<VoxelIndex> occ = {{7, 8, 0}, {8, 8, 0}, {20, 0, 0}};  // brick (0,0,0) is empty
  auto grid = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(grid.ok());
  ASSERT_EQ(grid->BrickSlot(grid->BrickLinear(0, 0, 0)), 0u);
  Segments s;
  for (int k = 1; k <= 6; ++k) s.Add({8.0 - k, 8.0 - k, 0.5}, {16.0, 16.0, 0.5});
  for (size_t i = 0; i < s.a.size(); ++i) {
    ASSERT_EQ(FirstOccupied(*grid, s.a[i], s.b[i]), (VoxelIndex{7, 8, 0})) << "segment " << i;
  }
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    std::vector<std::optional<VoxelIndex>> got(s.a.size());
    size_t rechecked = 0;
    FirstOccupiedBatch(*grid, s.a, s.b, got, BatchKernel::kLanes, &rechecked);
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i], (VoxelIndex{7, 8, 0})) << hwy::TargetName(target) << ", segment " << i;
    }
    EXPECT_EQ(rechecked, got.size()) << hwy::TargetName(target);
  }
  hwy::SetSupportedTargetsForTest(0);
}

// The lanes set segments up in double lanes, a chunk of 128 at a time: every batch size around a
// vector's and a chunk's length gives FirstOccupied's answers, and a segment whose crossing
// parameters do not fit a float (an axis crossed once over a length of 2^-130 voxels) is left to
// FirstOccupied wherever it falls in its vector.
TEST(FirstOccupiedBatchTest, EveryBatchSizeAndAxesTooSteepForFloats) {
  std::vector<VoxelIndex> occ;
  for (int x = -12; x <= 12; ++x)
    for (int y = -12; y <= 12; ++y) {
      occ.push_back({x, y, -6});
      if ((x * y) % 5 == 1) occ.push_back({x, y, 2});
    }
  auto grid = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(grid.ok());
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-15, 15);
  Segments all;
  for (int r = 0; r < 400; ++r) all.Add({u(rng), u(rng), u(rng) / 3 + 4}, {u(rng), u(rng), u(rng) / 3 - 4});
  const double tiny = std::ldexp(1.0, -130);
  for (size_t i = 5; i < all.a.size(); i += 37) {  // z crosses 0 once: t_delta ~ 2^129
    all.a[i] = {u(rng), u(rng), -tiny};
    all.b[i] = {u(rng), u(rng), tiny / 2};
  }
  for (size_t n : {size_t{1}, size_t{2}, size_t{3}, size_t{7}, size_t{8}, size_t{9}, size_t{15}, size_t{16}, size_t{17},
                   size_t{31}, size_t{33}, size_t{127}, size_t{128}, size_t{129}, size_t{255}, size_t{256}, size_t{257},
                   size_t{400}}) {
    Segments s;
    s.a.assign(all.a.begin(), all.a.begin() + long(n));
    s.b.assign(all.b.begin(), all.b.begin() + long(n));
    ExpectSameOnEveryTarget(*grid, s, std::to_string(n) + " segments");
  }
  Segments steep;
  for (int r = 0; r < 40; ++r) steep.Add({u(rng), u(rng), -tiny}, {u(rng), u(rng), tiny / 2});
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    std::vector<std::optional<VoxelIndex>> got(steep.a.size());
    size_t rechecked = 0;
    FirstOccupiedBatch(*grid, steep.a, steep.b, got, BatchKernel::kLanes, &rechecked);
    EXPECT_EQ(rechecked, steep.a.size()) << hwy::TargetName(target);
    for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], FirstOccupied(*grid, steep.a[i], steep.b[i]));
  }
  hwy::SetSupportedTargetsForTest(0);
}

// The default kernel: lanes where they pay (AVX-512), FirstOccupied per segment elsewhere.
TEST(FirstOccupiedBatchTest, AutoUsesLanesOnlyWhereTheyPay) {
  auto grid = OccupancyGrid::Build(0.1, {{0, 0, 0}, {3, 0, 0}}, 1 << 20);
  ASSERT_TRUE(grid.ok());
  std::vector<Vector3d> a = {{-5, 0.5, 0.5}, {1.5, 0.5, 0.5}}, b = {{5, 0.5, 0.5}, {9, 0.5, 0.5}};
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    std::vector<std::optional<VoxelIndex>> out(2);
    const std::string ran = FirstOccupiedBatch(*grid, a, b, out);
    const bool pays = target == HWY_AVX3 || target == HWY_AVX3_DL;
    EXPECT_EQ(ran, std::string(hwy::TargetName(target)) + (pays ? " lanes" : " per segment"));
    EXPECT_EQ(out[0], (VoxelIndex{0, 0, 0}));
    EXPECT_EQ(out[1], (VoxelIndex{3, 0, 0}));
  }
  hwy::SetSupportedTargetsForTest(0);
}

// A grid far from the origin (here at the lanes' parking voxel, -2^30 on every axis) is walked per
// segment, with FirstOccupied's answers (review finding: the lanes would have hit it).
TEST(FirstOccupiedBatchTest, GridsFarOutAreWalkedPerSegment) {
  const int far = -(1 << 30);
  auto grid = OccupancyGrid::Build(0.1, {{far, far, far}, {far + 3, far, far}}, 1 << 20);
  ASSERT_TRUE(grid.ok());
  const std::vector<Vector3d> a = {{far + 1.5, far + 0.5, far + 0.5}, {far - 5.0, far + 0.5, far + 0.5}};
  const std::vector<Vector3d> b = {{far + 9.5, far + 0.5, far + 0.5}, {far + 1.5, far + 0.5, far + 0.5}};
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    std::vector<std::optional<VoxelIndex>> out(2);
    EXPECT_EQ(FirstOccupiedBatch(*grid, a, b, out, BatchKernel::kLanes),
              "per segment (grid too large or too far out for the lanes)");
    EXPECT_EQ(out[0], (VoxelIndex{far + 3, far, far}));
    EXPECT_EQ(out[1], (VoxelIndex{far, far, far}));
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(FirstOccupiedBatchTest, EmptyAndUnevenSpans) {
  auto grid = OccupancyGrid::Build(0.1, {{0, 0, 0}}, 1 << 20);
  ASSERT_TRUE(grid.ok());
  std::vector<Vector3d> a = {{-5, 0.5, 0.5}, {-5, 3.5, 0.5}}, b = {{5, 0.5, 0.5}};
  std::vector<std::optional<VoxelIndex>> out(3, VoxelIndex{7, 7, 7});
  FirstOccupiedBatch(*grid, a, b, out, BatchKernel::kLanes);  // one segment: the shortest span decides
  ASSERT_TRUE(out[0].has_value());
  EXPECT_EQ(*out[0], (VoxelIndex{0, 0, 0}));
  EXPECT_EQ(out[1], (VoxelIndex{7, 7, 7}));  // untouched
  FirstOccupiedBatch(*grid, std::span<const Vector3d>(), std::span<const Vector3d>(), out, BatchKernel::kLanes);
  EXPECT_EQ(out[1], (VoxelIndex{7, 7, 7}));
}

}  // namespace
}  // namespace vc
