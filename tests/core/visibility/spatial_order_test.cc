// Tests vc/visibility/spatial_order.h: the orders of the targets' bricks and of the corner rays.
#include "vc/visibility/spatial_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <vector>

namespace vc::internal {
namespace {

// Against interleaving bit by bit, on hand values and random ones over the whole input range.
TEST(SpatialOrderTest, ZOrderInterleavesTheBits) {
  EXPECT_EQ(SpreadBits2(0b1011), 0b1000101u);
  EXPECT_EQ(SpreadBits2(0xffffffffu), 0x5555555555555555ull);
  EXPECT_EQ(SpreadBits3(0b1011), 0b1000001001u);
  EXPECT_EQ(SpreadBits3(0x1fffff), 0x1249249249249249ull);
  EXPECT_EQ(ZOrder2(2, 1), 0b110u);
  EXPECT_EQ(ZOrder3(1, 0, 1), 0b101u);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 1000; ++i) {
    const uint64_t x = rng() & 0x1fffff, y = rng() & 0x1fffff, z = rng() & 0x1fffff, w = rng() & 0xffffffff;
    uint64_t two = 0, three = 0;
    for (int b = 0; b < 32; ++b) two |= ((w >> b) & 1) << (2 * b) | ((x >> b) & 1) << (2 * b + 1);
    for (int b = 0; b < 21; ++b)
      three |= ((x >> b) & 1) << (3 * b) | ((y >> b) & 1) << (3 * b + 1) | ((z >> b) & 1) << (3 * b + 2);
    ASSERT_EQ(ZOrder2(w, x), two) << w << " " << x;
    ASSERT_EQ(ZOrder3(x, y, z), three) << x << " " << y << " " << z;
  }
}

TEST(SpatialOrderTest, NoCornersNoOrder) {
  const std::vector<VoxelIndex> none;
  EXPECT_TRUE(CornersByBrick(0, [&](size_t i) { return none[i]; }).empty());
}

// Corners sorted by (z, y, x), some negative, over several slabs and columns of bricks: the order
// is a permutation; slabs come in turn, a slab's bricks along the Z-order curve of their columns,
// each brick's corners together and in their own order.
TEST(SpatialOrderTest, BrickBySlabAndZOrderEachBricksCornersInTheirOrder) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(-37, 60), y(-20, 45), z(-9, 30);
  std::vector<VoxelIndex> corners;
  for (int i = 0; i < 4000; ++i) corners.push_back({x(rng), y(rng), z(rng)});
  auto zyx = [](const VoxelIndex& c) { return std::make_tuple(c.z, c.y, c.x); };
  std::sort(corners.begin(), corners.end(), [&](const VoxelIndex& a, const VoxelIndex& b) { return zyx(a) < zyx(b); });
  corners.erase(std::unique(corners.begin(), corners.end(),
                            [&](const VoxelIndex& a, const VoxelIndex& b) { return zyx(a) == zyx(b); }),
                corners.end());
  int lo[3] = {corners[0].x, corners[0].y, corners[0].z};
  for (const VoxelIndex& c : corners) lo[0] = std::min(lo[0], c.x), lo[1] = std::min(lo[1], c.y);
  lo[2] = corners.front().z;

  const std::vector<uint32_t> order = CornersByBrick(corners.size(), [&](size_t i) { return corners[i]; });
  ASSERT_EQ(order.size(), corners.size());
  std::vector<uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);

  // Each corner's key: slab, then the Z-order code of its column; the order must not decrease in
  // it, and within one brick (equal keys) positions must ascend.
  auto key = [&](const VoxelIndex& c) {
    const uint64_t bx = uint64_t(c.x - lo[0]) >> 3, by = uint64_t(c.y - lo[1]) >> 3, bz = uint64_t(c.z - lo[2]) >> 3;
    return std::make_pair(bz, ZOrder2(bx, by));
  };
  size_t bricks = 0;
  for (size_t i = 1; i < order.size(); ++i) {
    const auto a = key(corners[order[i - 1]]), b = key(corners[order[i]]);
    ASSERT_LE(a, b) << "at " << i;
    if (a == b) {
      ASSERT_LT(order[i - 1], order[i]) << "at " << i;
    } else {
      ++bricks;
    }
  }
  // Every brick is one run: as many runs as distinct bricks.
  std::vector<std::pair<uint64_t, uint64_t>> keys;
  for (const VoxelIndex& c : corners) keys.push_back(key(c));
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(bricks + 1, size_t(std::unique(keys.begin(), keys.end()) - keys.begin()));
  EXPECT_GT(bricks, 100u);
}

}  // namespace
}  // namespace vc::internal
