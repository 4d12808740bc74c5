// The huge-page helpers change only where memory comes from: the values, sizes and the
// no-reallocation promise are those of plain vectors, for sizes below, at and above 2 MiB.
#include "vc/base/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>

namespace vc::internal {
namespace {

TEST(HugePagesTest, FilledHoldsNCopiesOfTheValue) {
  for (size_t n : {size_t{0}, size_t{1}, size_t{1000}, (size_t{2} << 20) / sizeof(double), size_t{3} << 20}) {
    const std::vector<double> v = FilledOnHugePages(n, 2.5);
    ASSERT_EQ(v.size(), n);
    for (size_t i = 0; i < n; ++i) ASSERT_EQ(v[i], 2.5) << "n " << n << " at " << i;
  }
  struct Pair {
    float a;
    int32_t b;
  };
  const std::vector<Pair> p = FilledOnHugePages(size_t{1} << 20, Pair{0.5f, -1});
  ASSERT_EQ(p.size(), size_t{1} << 20);
  for (const Pair& x : p) ASSERT_TRUE(x.a == 0.5f && x.b == -1);
}

TEST(HugePagesTest, ReservedRoomIsFilledByResizeWithoutMovingIt) {
  for (size_t n : {size_t{10}, size_t{5} << 20}) {
    std::vector<float> v;
    ReserveOnHugePages(v, n);
    EXPECT_TRUE(v.empty());
    ASSERT_GE(v.capacity(), n);
    const float* where = v.data();
    v.resize(n);
    EXPECT_EQ(v.data(), where);
    for (size_t i = 0; i < n; ++i) ASSERT_EQ(v[i], 0.0f) << i;
  }
}

}  // namespace
}  // namespace vc::internal
