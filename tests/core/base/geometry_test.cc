// vc/base/geometry.h: VoxelKey's order (z, then y, then x), equality and hash.
#include "vc/base/geometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <unordered_set>
#include <vector>

namespace vc {
namespace {

TEST(VoxelKeyTest, OrdersByZThenYThenX) {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> c(0, 3);  // small: many equal components
  for (int n = 0; n < 5000; ++n) {
    const VoxelKey a{uint16_t(c(rng)), uint16_t(c(rng)), uint16_t(c(rng))};
    const VoxelKey b{uint16_t(c(rng)), uint16_t(c(rng)), uint16_t(c(rng))};
    ASSERT_EQ(a < b, std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x));
    ASSERT_EQ(a == b, std::tie(a.x, a.y, a.z) == std::tie(b.x, b.y, b.z));
    ASSERT_EQ(a != b, !(a == b));
  }
  EXPECT_TRUE((VoxelKey{65535, 65535, 0} < VoxelKey{0, 0, 1}));
}

TEST(VoxelKeyTest, DistinctKeysHashDistinctly) {
  // Keys across the whole 16-bit range of each component, corners included.
  std::mt19937 rng(2);
  std::uniform_int_distribution<int> c(0, 65535);
  std::vector<VoxelKey> keys = {{0, 0, 0}, {65535, 65535, 65535}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int n = 0; n < 20000; ++n) keys.push_back({uint16_t(c(rng)), uint16_t(c(rng)), uint16_t(c(rng))});
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::unordered_set<size_t> hashes;
  for (const VoxelKey& k : keys) hashes.insert(VoxelKeyHash{}(k));
  EXPECT_EQ(hashes.size(), keys.size());
}

TEST(VoxelIndexTest, EqualityComparesEveryComponent) {
  EXPECT_EQ((VoxelIndex{-1, 2, 3}), (VoxelIndex{-1, 2, 3}));
  EXPECT_NE((VoxelIndex{-1, 2, 3}), (VoxelIndex{1, 2, 3}));
  EXPECT_NE((VoxelIndex{-1, 2, 3}), (VoxelIndex{-1, -2, 3}));
  EXPECT_NE((VoxelIndex{-1, 2, 3}), (VoxelIndex{-1, 2, -3}));
}

}  // namespace
}  // namespace vc
