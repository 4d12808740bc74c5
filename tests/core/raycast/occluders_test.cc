// The occluder shortcuts of vc/raycast/occluders.h, each against a brute-force check: boxes by
// enumerating voxels, PassesThroughInterior by the voxels the walk visits and by sampling the
// segment, GrowSolidBox by the set of occupied voxels, and the cache and the directional index by
// FirstOccupied itself.
#include "vc/raycast/occluders.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "vc/raycast/ray_traversal.h"
#include "vc/scene/occupancy_grid.h"

namespace vc::internal {
namespace {

using Eigen::Vector3d;
using Cell = std::tuple<int, int, int>;

Cell T(const VoxelIndex& v) { return {v.x, v.y, v.z}; }

// A random box of 1..span voxels per axis with its low corner in [-range, range].
SolidBox RandomBox(std::mt19937_64& rng, int range, int span) {
  std::uniform_int_distribution<int> c(-range, range), s(0, span - 1);
  SolidBox b;
  b.lo = {c(rng), c(rng), c(rng)};
  b.hi = {b.lo.x + s(rng), b.lo.y + s(rng), b.lo.z + s(rng)};
  return b;
}

// Whether p lies inside the box's cubes shrunk by `margin` on every side (grown for a negative one).
bool InsideShrunk(const SolidBox& box, const Vector3d& p, double margin) {
  return p.x() > box.lo.x + margin && p.x() < box.hi.x + 1 - margin && p.y() > box.lo.y + margin &&
         p.y() < box.hi.y + 1 - margin && p.z() > box.lo.z + margin && p.z() < box.hi.z + 1 - margin;
}

// The occupied voxels of a few random solid boxes, and the grid of them.
struct SolidScene {
  std::set<Cell> cells;
  std::vector<VoxelIndex> voxels;
  OccupancyGrid grid;
};
SolidScene RandomSolidScene(std::mt19937_64& rng, int boxes) {
  SolidScene s;
  for (int k = 0; k < boxes; ++k) {
    const SolidBox b = RandomBox(rng, 20, 9);
    for (int x = b.lo.x; x <= b.hi.x; ++x)
      for (int y = b.lo.y; y <= b.hi.y; ++y)
        for (int z = b.lo.z; z <= b.hi.z; ++z) s.cells.insert({x, y, z});
  }
  for (const auto& [x, y, z] : s.cells) s.voxels.push_back({x, y, z});
  s.grid = *OccupancyGrid::Build(0.1, s.voxels, uint64_t{1} << 24);
  return s;
}

TEST(SolidBoxTest, ContainsAndOverlapsAgreeWithEnumeratingTheVoxels) {
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<int> c(-5, 5);
  for (int n = 0; n < 3000; ++n) {
    const SolidBox a = RandomBox(rng, 3, 4), b = RandomBox(rng, 3, 4);
    const VoxelIndex v{c(rng), c(rng), c(rng)};
    EXPECT_EQ(a.Contains(v),
              v.x >= a.lo.x && v.x <= a.hi.x && v.y >= a.lo.y && v.y <= a.hi.y && v.z >= a.lo.z && v.z <= a.hi.z);
    bool shared = false;
    for (int x = b.lo.x; x <= b.hi.x; ++x)
      for (int y = b.lo.y; y <= b.hi.y; ++y)
        for (int z = b.lo.z; z <= b.hi.z; ++z) shared = shared || a.Contains({x, y, z});
    ASSERT_EQ(a.Overlaps(b.lo, b.hi), shared) << "pair " << n;
  }
}

// Sound: whenever the test says a segment passes through a box, the walk visits a voxel of the
// box, and neither end lies inside it. Complete with a margin: a segment that clearly starts and
// ends outside the box and clearly passes through its inside is recognised.
TEST(PassesThroughInteriorTest, AgreesWithTheWalkAndWithSamplingTheSegment) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-12, 12);
  int proved = 0, clear_crossings = 0;
  for (int n = 0; n < 20000; ++n) {
    const SolidBox box = RandomBox(rng, 4, 5);
    Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    if (n % 5 == 0) b.x() = a.x();  // parallel to an axis plane: a zero direction component
    const bool passes = PassesThroughInterior(Segment(a, b), box);
    if (passes) {
      ++proved;
      EXPECT_FALSE(InsideShrunk(box, a, kInteriorMargin)) << "segment " << n << " starts inside the box";
      EXPECT_FALSE(InsideShrunk(box, b, kInteriorMargin)) << "segment " << n << " ends inside the box";
      bool visits = false;
      for (const VoxelIndex& v : RayTraversal(a, b)) visits = visits || box.Contains(v);
      ASSERT_TRUE(visits) << "segment " << n << " is said to pass through a box its walk misses";
    }
    constexpr double kClear = 0.01;
    if (InsideShrunk(box, a, -kClear) || InsideShrunk(box, b, -kClear)) continue;
    bool deep_inside = false;
    for (int s = 1; s < 4000 && !deep_inside; ++s) deep_inside = InsideShrunk(box, a + (b - a) * (s / 4000.0), kClear);
    if (!deep_inside) continue;
    ++clear_crossings;
    EXPECT_TRUE(passes) << "segment " << n << " clearly crosses the box";
  }
  EXPECT_GT(proved, 500);
  EXPECT_GT(clear_crossings, 500);
}

TEST(PassesThroughInteriorTest, ASegmentThatStartsOrEndsInsideTheBoxOrGrazesAFaceProvesNothing) {
  const SolidBox box{{0, 0, 0}, {3, 3, 3}};
  EXPECT_TRUE(PassesThroughInterior(Segment(Vector3d(-2, 1.5, 1.5), Vector3d(6, 1.5, 1.5)), box));
  EXPECT_FALSE(PassesThroughInterior(Segment(Vector3d(1, 1.5, 1.5), Vector3d(6, 1.5, 1.5)), box));
  EXPECT_FALSE(PassesThroughInterior(Segment(Vector3d(-2, 1.5, 1.5), Vector3d(2, 1.5, 1.5)), box));
  // Grazing a face (within the margin) proves nothing either: along the face, or slanting towards
  // it and leaving the box (at x = 4) while still within 1e-5 of it, just outside or just inside.
  EXPECT_FALSE(PassesThroughInterior(Segment(Vector3d(-2, 4.0 - 1e-7, 1.5), Vector3d(6, 4.0 - 1e-7, 1.5)), box));
  EXPECT_FALSE(PassesThroughInterior(Segment(Vector3d(-2, -1e-3, 1.5), Vector3d(6, 3.4e-4, 1.5)), box));
  EXPECT_FALSE(PassesThroughInterior(Segment(Vector3d(-2, 1.5, 4 + 1e-3), Vector3d(6, 1.5, 4 - 3.4e-4)), box));
  EXPECT_TRUE(PassesThroughInterior(Segment(Vector3d(-2, -1e-3, 1.5), Vector3d(6, 3.4e-2, 1.5)), box));
}

// The box grown from an occupied voxel is all occupied, holds it, stays within the limit, and no
// side can move out by one more layer within the limit (the next layer has a free voxel).
TEST(GrowSolidBoxTest, IsSolidWithinTheLimitAndNoSideCanGrowByOneLayer) {
  std::mt19937_64 rng(3);
  int grown = 0;
  for (int scene = 0; scene < 8; ++scene) {
    const SolidScene s = RandomSolidScene(rng, 10);
    std::uniform_int_distribution<size_t> pick(0, s.voxels.size() - 1);
    for (int n = 0; n < 60; ++n) {
      const VoxelIndex h = s.voxels[pick(rng)];
      const int limit = std::vector<int>{1, 3, 8, 40}[n % 4];
      const SolidBox box = GrowSolidBox(s.grid, h, limit);
      ASSERT_TRUE(box.Contains(h));
      const int lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
      const int h3[3] = {h.x, h.y, h.z};
      auto solid = [&](int l0, int l1, int l2, int u0, int u1, int u2) {
        for (int x = l0; x <= u0; ++x)
          for (int y = l1; y <= u1; ++y)
            for (int z = l2; z <= u2; ++z)
              if (!s.cells.count({x, y, z})) return false;
        return true;
      };
      ASSERT_TRUE(solid(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2])) << "a free voxel in the grown box";
      for (int axis = 0; axis < 3; ++axis) {
        ASSERT_GE(lo[axis], h3[axis] - limit);
        ASSERT_LE(hi[axis], h3[axis] + limit);
        for (int side = 0; side < 2; ++side) {
          int l[3] = {lo[0], lo[1], lo[2]}, u[3] = {hi[0], hi[1], hi[2]};
          if (side == 0) {
            if (lo[axis] == h3[axis] - limit) continue;
            l[axis] = u[axis] = lo[axis] - 1;
          } else {
            if (hi[axis] == h3[axis] + limit) continue;
            l[axis] = u[axis] = hi[axis] + 1;
          }
          EXPECT_FALSE(solid(l[0], l[1], l[2], u[0], u[1], u[2]))
              << "side " << side << " of axis " << axis << " could grow by one more layer";
        }
      }
      grown += lo[0] != hi[0] || lo[1] != hi[1] || lo[2] != hi[2];
    }
  }
  EXPECT_GT(grown, 200);
}

// True exactly when the farthest corner of the grid's box is within kMaxShortcutLength of uo.
TEST(ShortcutsHoldTest, OnlyWithinTheLengthTheMarginsAllowAndForFiniteOrigins) {
  const OccupancyGrid grid = *OccupancyGrid::Build(0.1, {{0, 0, 0}, {20, 10, 5}}, uint64_t{1} << 20);
  const VoxelIndex& lo = grid.min_index();
  auto farthest = [&](const Vector3d& uo) {
    double best = 0;
    for (int corner = 0; corner < 8; ++corner) {
      const Vector3d c(lo.x + ((corner & 1) ? grid.dims().x() : 0), lo.y + ((corner & 2) ? grid.dims().y() : 0),
                       lo.z + ((corner & 4) ? grid.dims().z() : 0));
      best = std::max(best, (c - uo).norm());
    }
    return best;
  };
  EXPECT_TRUE(ShortcutsHold(grid, Vector3d(3, 4, 5)));
  for (const double x : {16000.0, 16300.0, 16370.0, 16380.0, 16400.0, -16380.0, -16360.0, 30000.0}) {
    const Vector3d uo(x, 2, 1);
    EXPECT_EQ(ShortcutsHold(grid, uo), farthest(uo) <= kMaxShortcutLength) << "x " << x;
  }
  EXPECT_FALSE(ShortcutsHold(grid, Vector3d(std::nan(""), 0, 0)));
  EXPECT_FALSE(ShortcutsHold(grid, Vector3d(0, std::numeric_limits<double>::infinity(), 0)));
}

TEST(OccluderCacheTest, BlocksOnlyThroughACachedBoxThatKeepsNoTransparentVoxel) {
  const Vector3d a(-5, 1.5, 1.5), b(10, 1.5, 1.5);
  OccluderCache cache;
  EXPECT_FALSE(cache.Blocks(a, b, VoxelIndex{9, 1, 1})) << "an empty cache proves nothing";
  cache.Add(SolidBox{{2, 0, 0}, {4, 3, 3}});
  EXPECT_TRUE(cache.Blocks(a, b, VoxelIndex{9, 1, 1}));
  EXPECT_FALSE(cache.Blocks(a, b, VoxelIndex{3, 1, 1})) << "the kept voxel is inside the box";
  EXPECT_FALSE(cache.Blocks(a, b, VoxelIndex{0, 0, 0}, VoxelIndex{2, 1, 1})) << "the kept box overlaps it";
  EXPECT_FALSE(cache.Blocks(Vector3d(-5, 8.5, 1.5), Vector3d(10, 8.5, 1.5), VoxelIndex{9, 8, 1})) << "misses the box";

  OccluderCache disabled(false);
  disabled.Add(SolidBox{{2, 0, 0}, {4, 3, 3}});
  EXPECT_FALSE(disabled.enabled());
  EXPECT_FALSE(disabled.Blocks(a, b, VoxelIndex{9, 1, 1}));
  EXPECT_EQ(disabled.Find(VoxelIndex{3, 1, 1}), nullptr);
}

TEST(OccluderCacheTest, KeepsTheFourMostRecentlyUsedBoxes) {
  auto unit = [](int x) { return SolidBox{{x, 0, 0}, {x, 0, 0}}; };
  OccluderCache cache;
  for (int x = 0; x < 4; ++x) cache.Add(unit(x));
  ASSERT_NE(cache.Find(VoxelIndex{0, 0, 0}), nullptr);  // box 0, the oldest, is used again
  cache.Add(unit(4));                                   // evicts box 1, now the least recently used
  EXPECT_EQ(cache.Find(VoxelIndex{1, 0, 0}), nullptr);
  for (int x : {0, 2, 3, 4}) EXPECT_NE(cache.Find(VoxelIndex{x, 0, 0}), nullptr) << x;
  // Adding a voxel a cached box holds adds nothing (so nothing is evicted).
  cache.Add(VoxelIndex{3, 0, 0});
  for (int x : {0, 2, 3, 4}) EXPECT_NE(cache.Find(VoxelIndex{x, 0, 0}), nullptr) << x;
  const SolidBox* found = cache.Find(VoxelIndex{2, 0, 0});
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(T(found->lo), T(VoxelIndex{2, 0, 0}));
}

// The 4 boxes the cache dropped last still prove segments blocked (Blocks alone tries them), and a
// box that does goes back to the front; FindIf and Find see only the 4 in the cache; a cache made
// with keep_dropped false forgets them.
TEST(OccluderCacheTest, BlocksAlsoTriesTheFourBoxesDroppedLast) {
  auto wall = [](int x) { return SolidBox{{x, 0, 0}, {x, 3, 3}}; };  // crosses y = z = 1.5 at x..x+1
  auto through = [](int x) { return std::pair{Vector3d(x - 5.0, 1.5, 1.5), Vector3d(x + 5.0, 1.5, 1.5)}; };
  OccluderCache cache, forgetful(true, /*keep_dropped=*/false);
  for (int k = 0; k < 8; ++k) {
    cache.Add(wall(20 * k));
    forgetful.Add(wall(20 * k));
  }
  // Walls 0..3 (x = 0, 20, 40, 60) were dropped, the oldest first.
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(cache.Find(VoxelIndex{20 * k, 1, 1}), nullptr) << k;
    const auto [a, b] = through(20 * k);
    const VoxelIndex end{20 * k + 5, 1, 1};
    EXPECT_FALSE(forgetful.Blocks(a, b, end)) << k;
    EXPECT_FALSE(cache.Blocks(a, b, VoxelIndex{20 * k, 1, 1})) << "the kept voxel is inside the dropped box";
  }
  const auto [a2, b2] = through(40);
  EXPECT_TRUE(cache.Blocks(a2, b2, VoxelIndex{45, 1, 1}));
  ASSERT_NE(cache.Find(VoxelIndex{40, 1, 1}), nullptr) << "wall 2 is back in the cache";
  // It pushed out the least recently used box (wall 4), which is now one of the dropped ones.
  EXPECT_EQ(cache.Find(VoxelIndex{80, 1, 1}), nullptr);
  const auto [a4, b4] = through(80);
  EXPECT_TRUE(cache.Blocks(a4, b4, VoxelIndex{85, 1, 1}));
  // A segment along an axis plane of a dropped box (an axis with no extent: inv = 0) proves
  // nothing unless it runs inside the box by the margin.
  const auto [a1, b1] = through(20);
  EXPECT_TRUE(cache.Blocks(a1, b1, VoxelIndex{25, 1, 1}));
  EXPECT_FALSE(cache.Blocks(Vector3d(55, 0.0, 1.5), Vector3d(65, 0.0, 1.5), VoxelIndex{65, 0, 1}))
      << "on the face y = 0 of wall 3";
  // A segment that enters a dropped box within the margin of its start proves nothing.
  EXPECT_FALSE(cache.Blocks(Vector3d(60 - 5e-6, 1.5, 1.5), Vector3d(70, 1.5, 1.5), VoxelIndex{70, 1, 1}));
  EXPECT_TRUE(cache.Blocks(Vector3d(59.9, 1.5, 1.5), Vector3d(70, 1.5, 1.5), VoxelIndex{70, 1, 1}));
}

// The dropped boxes' test is PassesThroughInterior's, box for box: on random boxes and segments
// (a third of them along an axis), a cache of 8 boxes (4 kept, 4 dropped) proves a segment blocked
// exactly when one of the 8 does by PassesThroughInterior outside the keep box.
TEST(OccluderCacheTest, TheDroppedBoxesTestIsPassesThroughInteriors) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-12, 14);
  std::uniform_int_distribution<int> axis_pick(0, 2), lattice(-12, 14);
  int blocked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    OccluderCache cache;
    std::vector<SolidBox> boxes;
    for (int k = 0; k < 8; ++k) {
      boxes.push_back(RandomBox(rng, 8, 6));
      cache.Add(boxes.back());
    }
    for (int n = 0; n < 50; ++n) {
      Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
      if (n % 3 == 0) {  // along an axis, on a lattice plane or a voxel's middle
        const int ax = axis_pick(rng);
        for (int i = 0; i < 3; ++i) {
          if (i != ax) b[i] = a[i] = lattice(rng) + (n % 2 ? 0.5 : 0.0);
        }
      }
      const VoxelIndex keep{int(std::floor(b.x())), int(std::floor(b.y())), int(std::floor(b.z()))};
      const Segment seg(a, b);
      bool expected = false;
      for (const SolidBox& box : boxes)
        expected = expected || (!box.Overlaps(keep, keep) && PassesThroughInterior(seg, box));
      OccluderCache copy = cache;  // Blocks reorders the cache
      ASSERT_EQ(copy.Blocks(a, b, keep), expected) << "trial " << trial << " segment " << n;
      blocked += expected;
    }
  }
  EXPECT_GT(blocked, 1000);
}

// The property the visibility engine relies on: whenever the cache says a segment is blocked, the
// exact walk (FirstOccupied with the kept voxel transparent) meets an occupied voxel.
TEST(OccluderCacheTest, ABlockedSegmentAlwaysMeetsAnOccupiedVoxel) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-25, 30);
  int blocked = 0;
  for (int scene = 0; scene < 6; ++scene) {
    const SolidScene s = RandomSolidScene(rng, 12);
    std::uniform_int_distribution<size_t> pick(0, s.voxels.size() - 1);
    OccluderCache cache;
    for (int k = 0; k < 8; ++k) cache.Add(GrowSolidBox(s.grid, s.voxels[pick(rng)], 16));  // 4 kept, 4 dropped
    for (int n = 0; n < 6000; ++n) {
      const Vector3d a(u(rng), u(rng), u(rng));
      const VoxelIndex target = s.voxels[pick(rng)];
      const Vector3d b(target.x + 0.5, target.y + 0.5, target.z + 0.5);
      if (!cache.Blocks(a, b, target)) continue;
      ++blocked;
      ASSERT_TRUE(FirstOccupied(s.grid, a, b, &target).has_value())
          << "scene " << scene << " segment " << n << " is blocked by the cache but not by the walk";
    }
  }
  EXPECT_GT(blocked, 1000);
}

// The directional index finds a box long after the LRU cache would have dropped it, in the bins its
// corners project to, and nowhere else; a box that spans two cube faces is not indexed.
TEST(DirectionalOccludersTest, FindsEachOfManyBoxesBehindWhichTheirTargetsLie) {
  const Vector3d viewpoint(0.5, 0.5, 0.5);
  DirectionalOccluders index(viewpoint);
  EXPECT_FALSE(index.Blocks(Vector3d(40, 0.5, 0.5), VoxelIndex{40, 0, 0}, VoxelIndex{40, 0, 0})) << "empty";
  // 16 walls around the viewpoint, each 3 voxels thick, 4 wide and 4 high, 40 voxels out along +x,
  // -x, +y and -y (each spans at most 5 x 5 bins, so each is indexed).
  std::vector<SolidBox> walls;
  for (int side = 0; side < 4; ++side) {
    for (int k = 0; k < 4; ++k) {
      const int across = -8 + 4 * k;
      SolidBox box;
      if (side < 2) {
        const int x = side == 0 ? 40 : -43;
        box = SolidBox{{x, across, -2}, {x + 2, across + 3, 1}};
      } else {
        const int y = side == 2 ? 40 : -43;
        box = SolidBox{{across, y, -2}, {across + 3, y + 2, 1}};
      }
      walls.push_back(box);
      index.Add(box);
    }
  }
  for (const SolidBox& box : walls) {
    // A target 10 voxels behind the wall's middle, on the ray from the viewpoint through it.
    const Vector3d mid((box.lo.x + box.hi.x + 1) / 2.0, (box.lo.y + box.hi.y + 1) / 2.0, 0.5);
    const Vector3d target = viewpoint + (mid - viewpoint) * 1.6;
    const VoxelIndex keep{int(std::floor(target.x())), int(std::floor(target.y())), int(std::floor(target.z()))};
    EXPECT_TRUE(index.Blocks(target, keep, keep)) << box.lo.x << " " << box.lo.y;
    EXPECT_FALSE(index.Blocks(target, box.lo, box.hi)) << "the kept box overlaps it";
    // In front of the wall, the same direction: nothing to prove.
    const Vector3d front = viewpoint + (mid - viewpoint) * 0.5;
    const VoxelIndex fk{int(std::floor(front.x())), int(std::floor(front.y())), int(std::floor(front.z()))};
    EXPECT_FALSE(index.Blocks(front, fk, fk));
  }
  // Straight up, no wall there.
  EXPECT_FALSE(index.Blocks(Vector3d(0.5, 0.5, 60.5), VoxelIndex{0, 0, 60}, VoxelIndex{0, 0, 60}));

  DirectionalOccluders corner_index(viewpoint);
  const SolidBox diagonal{{10, 9, -2}, {12, 12, 2}};  // its corners fall on the +x and the +y faces
  corner_index.Add(diagonal);
  EXPECT_FALSE(corner_index.Blocks(Vector3d(23.5, 22.5, 0.5), VoxelIndex{23, 22, 0}, VoxelIndex{23, 22, 0}));
  OccluderCache lru;
  lru.Add(diagonal);
  EXPECT_TRUE(lru.Blocks(viewpoint, Vector3d(23.5, 22.5, 0.5), VoxelIndex{23, 22, 0}))
      << "the segment does pass through it: only the index leaves it out";
}

// As for the cache: whenever the index says a segment from its viewpoint is blocked, the exact walk
// meets an occupied voxel; and it proves some of the segments the walk finds blocked.
TEST(DirectionalOccludersTest, ABlockedSegmentAlwaysMeetsAnOccupiedVoxel) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-25, 30);
  int blocked = 0, walked_blocked = 0;
  std::normal_distribution<double> n01;
  for (int scene = 0; scene < 6; ++scene) {
    const SolidScene s = RandomSolidScene(rng, 12);
    std::uniform_int_distribution<size_t> pick(0, s.voxels.size() - 1);
    for (int view = 0; view < 4; ++view) {
      // Viewpoints 120-200 voxels from the scene's middle, where its boxes span few bins.
      const Vector3d dir = Vector3d(n01(rng), n01(rng), n01(rng)).normalized();
      const Vector3d a = Vector3d(2.5, 2.5, 2.5) + dir * (120 + u(rng) + 25);
      DirectionalOccluders index(a);
      for (int k = 0; k < 40; ++k) index.Add(GrowSolidBox(s.grid, s.voxels[pick(rng)], 8));
      for (int n = 0; n < 1500; ++n) {
        const VoxelIndex target = s.voxels[pick(rng)];
        const Vector3d b(target.x + 0.5, target.y + 0.5, target.z + 0.5);
        const bool walk = FirstOccupied(s.grid, a, b, &target).has_value();
        walked_blocked += walk;
        if (!index.Blocks(b, target, target)) continue;
        ++blocked;
        ASSERT_TRUE(walk) << "scene " << scene << " segment " << n << " is blocked by the index but not by the walk";
      }
    }
  }
  EXPECT_GT(blocked, 1000) << blocked << " of " << walked_blocked;  // 1,895 of 28,905 when written
}

}  // namespace
}  // namespace vc::internal
