#include "vc/scene/occupancy_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>

namespace vc {
namespace {

TEST(OccupancyGridTest, AnswersExactlyTheOccupiedSet) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> c(-40, 40);
  std::vector<VoxelIndex> occ;
  std::set<std::tuple<int, int, int>> truth;
  for (int i = 0; i < 3000; ++i) {
    VoxelIndex v{c(rng), c(rng), c(rng) / 4};
    occ.push_back(v);
    truth.insert({v.x, v.y, v.z});
  }
  auto g = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(g.ok()) << g.status().ToString();
  int count = 0;
  for (int z = -15; z <= 15; ++z)
    for (int y = -45; y <= 45; ++y)
      for (int x = -45; x <= 45; ++x) {
        const bool want = truth.count({x, y, z}) > 0;
        ASSERT_EQ(g->Occupied(x, y, z), want) << x << "," << y << "," << z;
        count += want;
      }
  EXPECT_EQ(count, int(truth.size()));
  EXPECT_GT(g->occupied_bricks(), 0u);
  EXPECT_FALSE(g->Occupied(100000, 0, 0));
}

TEST(OccupancyGridTest, BrickDistancesAreTheExactChessboardDistanceBetweenBricks) {
  std::mt19937_64 rng(8);
  std::uniform_int_distribution<int> c(0, 120);
  std::vector<VoxelIndex> occ;
  for (int i = 0; i < 12; ++i) occ.push_back({c(rng), c(rng), c(rng) / 3});
  auto g = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(g.ok());
  const Eigen::Vector3i bd = g->brick_dims();
  int max_seen = 0;
  for (int bz = 0; bz < bd.z(); ++bz)
    for (int by = 0; by < bd.y(); ++by)
      for (int bx = 0; bx < bd.x(); ++bx) {
        int want = 255;
        for (int oz = 0; oz < bd.z(); ++oz)
          for (int oy = 0; oy < bd.y(); ++oy)
            for (int ox = 0; ox < bd.x(); ++ox)
              if (g->BrickOccupied(ox, oy, oz))
                want = std::min(want, std::max({std::abs(bx - ox), std::abs(by - oy), std::abs(bz - oz)}));
        ASSERT_EQ(int(g->BrickDistance(g->BrickLinear(bx, by, bz))), want) << bx << "," << by << "," << bz;
        max_seen = std::max(max_seen, want);
      }
  EXPECT_GT(max_seen, 3);
}

// Each empty brick's free box (the cube of its distance, widened by ExtraBricks layers a side)
// holds no non-empty brick, and every side that stopped short of kMaxExtra stopped at a layer
// that holds one: the boxes are free and cannot grow on any side.
TEST(OccupancyGridTest, FreeBoxesAreFreeAndStopOnlyAtANonEmptyLayer) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> c(0, 150);
  std::vector<VoxelIndex> occ;
  for (int x = 0; x <= 150; ++x)
    for (int y = 0; y <= 100; ++y) occ.push_back({x, y, 0});  // a floor
  for (int i = 0; i < 25; ++i) occ.push_back({c(rng), c(rng) * 2 / 3, c(rng) / 4});
  auto g = OccupancyGrid::Build(0.1, occ, 1 << 24);
  ASSERT_TRUE(g.ok());
  const Eigen::Vector3i bd = g->brick_dims();
  auto box_has_brick = [&](const int lo[3], const int hi[3]) {
    for (int z = std::max(lo[2], 0); z <= std::min(hi[2], bd.z() - 1); ++z)
      for (int y = std::max(lo[1], 0); y <= std::min(hi[1], bd.y() - 1); ++y)
        for (int x = std::max(lo[0], 0); x <= std::min(hi[0], bd.x() - 1); ++x)
          if (g->BrickOccupied(x, y, z)) return true;
    return false;
  };
  int widened = 0, empty = 0;
  for (int bz = 0; bz < bd.z(); ++bz)
    for (int by = 0; by < bd.y(); ++by)
      for (int bx = 0; bx < bd.x(); ++bx) {
        const uint64_t b = g->BrickLinear(bx, by, bz);
        if (g->BrickOccupied(bx, by, bz)) {
          for (int side = 0; side < 6; ++side) ASSERT_EQ(g->ExtraBricks(b, side), 0);
          continue;
        }
        ++empty;
        const int k = g->BrickDistance(b) - 1, at[3] = {bx, by, bz};
        int lo[3], hi[3];
        for (int i = 0; i < 3; ++i) {
          lo[i] = at[i] - k - g->ExtraBricks(b, 2 * i + 1);
          hi[i] = at[i] + k + g->ExtraBricks(b, 2 * i);
        }
        ASSERT_FALSE(box_has_brick(lo, hi)) << "brick " << bx << "," << by << "," << bz;
        for (int side = 0; side < 6; ++side) {
          widened += g->ExtraBricks(b, side) > 0;
          if (g->ExtraBricks(b, side) == OccupancyGrid::kMaxExtra) continue;
          int llo[3] = {lo[0], lo[1], lo[2]}, lhi[3] = {hi[0], hi[1], hi[2]};
          const int axis = side / 2;
          llo[axis] = lhi[axis] = side % 2 == 0 ? hi[axis] + 1 : lo[axis] - 1;
          EXPECT_TRUE(box_has_brick(llo, lhi))
              << "brick " << bx << "," << by << "," << bz << " could grow on side " << side;
        }
      }
  EXPECT_GT(empty, 100);
  EXPECT_GT(widened, empty);  // most boxes above the floor widen along it
}

TEST(OccupancyGridTest, AnyOccupiedAgreesWithVoxelByVoxelOnRandomBoxes) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> c(-20, 20), len(0, 19);
  std::vector<VoxelIndex> v;
  for (int i = 0; i < 150; ++i) v.push_back({c(rng), c(rng), c(rng)});
  const OccupancyGrid g = *OccupancyGrid::Build(0.1, v, 1 << 24);
  int hits = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    // Boxes inside, across and outside the grid's box (which spans about [-24, 23]).
    const VoxelIndex lo{c(rng) - 10, c(rng) - 10, c(rng) - 10};
    const VoxelIndex hi{lo.x + len(rng), lo.y + len(rng), lo.z + len(rng)};
    bool want = false;
    for (int z = lo.z; z <= hi.z && !want; ++z)
      for (int y = lo.y; y <= hi.y && !want; ++y)
        for (int x = lo.x; x <= hi.x && !want; ++x) want = g.Occupied(x, y, z);
    ASSERT_EQ(g.AnyOccupied(lo, hi), want) << trial;
    hits += want;
  }
  EXPECT_GT(hits, 300);
  EXPECT_LT(hits, 2700);
  // A single voxel box, and an empty (inverted) box.
  EXPECT_TRUE(g.AnyOccupied(v[0], v[0]));
  EXPECT_FALSE(g.AnyOccupied({5, 5, 5}, {4, 5, 5}));
}

// A solid block with scattered holes, so that many boxes are full; boxes inside, across its
// edges and outside the grid, and crossing brick boundaries.
TEST(OccupancyGridTest, AllOccupiedAgreesWithVoxelByVoxelOnRandomBoxes) {
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<int> c(-17, 17), len(0, 9), hole(-13, 13);
  std::set<std::tuple<int, int, int>> holes;
  for (int i = 0; i < 40; ++i) holes.insert({hole(rng), hole(rng), hole(rng)});
  std::vector<VoxelIndex> v;
  for (int z = -13; z <= 13; ++z)
    for (int y = -13; y <= 13; ++y)
      for (int x = -13; x <= 13; ++x)
        if (!holes.count({x, y, z})) v.push_back({x, y, z});
  const OccupancyGrid g = *OccupancyGrid::Build(0.1, v, 1 << 24);
  int full = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const VoxelIndex lo{c(rng), c(rng), c(rng)};
    const VoxelIndex hi{lo.x + len(rng), lo.y + len(rng), lo.z + len(rng)};
    bool want = true;
    for (int z = lo.z; z <= hi.z && want; ++z)
      for (int y = lo.y; y <= hi.y && want; ++y)
        for (int x = lo.x; x <= hi.x && want; ++x) want = g.Occupied(x, y, z);
    ASSERT_EQ(g.AllOccupied(lo, hi), want) << trial;
    full += want;
  }
  EXPECT_GT(full, 300);
  EXPECT_LT(full, 3700);
  EXPECT_TRUE(g.AllOccupied(v[0], v[0]));
  EXPECT_FALSE(g.AllOccupied({5, 5, 5}, {4, 5, 5}));  // an empty (inverted) box
}

TEST(OccupancyGridTest, AnyOccupiedWhereVisitsExactlyTheOccupiedVoxelsOfTheBox) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> c(-20, 20), len(0, 19);
  std::vector<VoxelIndex> v;
  for (int i = 0; i < 400; ++i) v.push_back({c(rng), c(rng), c(rng)});
  const OccupancyGrid g = *OccupancyGrid::Build(0.1, v, 1 << 24);
  auto key = [](const VoxelIndex& a) { return std::tuple(a.x, a.y, a.z); };
  for (int trial = 0; trial < 1000; ++trial) {
    const VoxelIndex lo{c(rng) - 10, c(rng) - 10, c(rng) - 10};
    const VoxelIndex hi{lo.x + len(rng), lo.y + len(rng), lo.z + len(rng)};
    std::vector<std::tuple<int, int, int>> want, got;
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x)
          if (g.Occupied(x, y, z)) want.push_back({x, y, z});
    // A predicate that is never true sees every occupied voxel of the box, once.
    EXPECT_FALSE(g.AnyOccupiedWhere(lo, hi, [&](const VoxelIndex& a) {
      got.push_back(key(a));
      return false;
    }));
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, want) << trial;
    // One that picks a single voxel is true exactly when that voxel is in the box.
    if (!want.empty()) {
      const auto pick = want[want.size() / 2];
      EXPECT_TRUE(g.AnyOccupiedWhere(lo, hi, [&](const VoxelIndex& a) { return key(a) == pick; }));
      EXPECT_FALSE(g.AnyOccupiedWhere({lo.x, lo.y, std::get<2>(pick) + 1}, hi,
                                      [&](const VoxelIndex& a) { return key(a) == pick; }));
    }
  }
}

TEST(OccupancyGridTest, RefusesOverBudgetWithExtentAndAResolutionThatFits) {
  std::vector<VoxelIndex> occ = {{0, 0, 0}, {20000, 20000, 20000}};
  auto g = OccupancyGrid::Build(0.01, occ, uint64_t{1} << 30);
  ASSERT_FALSE(g.ok());
  EXPECT_EQ(g.status().code(), StatusCode::kResourceExhausted);
  EXPECT_NE(g.status().message().find("200 x 200 x 200 m"), std::string::npos) << g.status().message();
  EXPECT_NE(g.status().message().find("use a resolution of at least"), std::string::npos);
}

TEST(OccupancyGridTest, RejectsEmptyAndBadResolution) {
  EXPECT_EQ(OccupancyGrid::Build(0.1, {}, 1 << 20).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(OccupancyGrid::Build(0.0, {{0, 0, 0}}, 1 << 20).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(OccupancyGrid::Build(std::nan(""), {{0, 0, 0}}, 1 << 20).status().code(), StatusCode::kInvalidArgument);
}

TEST(OccupancyGridTest, KeysMatchOctomapConventions) {
  VoxelKey k;
  ASSERT_TRUE(CoordToKey(0.1, WorldPoint(0.05, -0.05, 3.27), &k));
  EXPECT_EQ(k.x, 32768);
  EXPECT_EQ(k.y, 32767);
  EXPECT_EQ(k.z, 32768 + 32);
  const WorldPoint c = KeyToCoord(0.1, k);
  EXPECT_NEAR(c.x(), 0.05, 1e-12);
  EXPECT_NEAR(c.y(), -0.05, 1e-12);
  EXPECT_NEAR(c.z(), 3.25, 1e-12);
  EXPECT_FALSE(CoordToKey(0.1, WorldPoint(1e6, 0, 0), &k));
  EXPECT_FALSE(CoordToKey(0.1, WorldPoint(std::nan(""), 0, 0), &k));
}

}  // namespace
}  // namespace vc
