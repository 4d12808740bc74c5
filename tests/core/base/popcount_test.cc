// vc/base/popcount.h: a function built with VC_POPCOUNT_CLONES (a POPCNT copy and a baseline
// copy, one picked when the program loads) counts bits exactly as a plain loop does.
#include "vc/base/popcount.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <vector>

namespace vc {
namespace {

VC_POPCOUNT_CLONES uint64_t CountBits(const std::vector<uint64_t>& words) {
  uint64_t n = 0;
  for (const uint64_t w : words) n += uint64_t(std::popcount(w));
  return n;
}

uint64_t CountBitsOneByOne(const std::vector<uint64_t>& words) {
  uint64_t n = 0;
  for (uint64_t w : words) {
    for (; w != 0; w >>= 1) n += w & 1;
  }
  return n;
}

TEST(PopcountClonesTest, CountsAsAPlainLoop) {
  EXPECT_EQ(CountBits({}), 0u);
  EXPECT_EQ(CountBits({0, ~uint64_t{0}, uint64_t{1} << 63, 1}), 66u);
  std::mt19937_64 rng(8);
  for (int n = 0; n < 200; ++n) {
    std::vector<uint64_t> words(n);
    for (uint64_t& w : words) w = n % 2 ? rng() & rng() : rng() | rng();  // sparser and denser words
    ASSERT_EQ(CountBits(words), CountBitsOneByOne(words)) << n << " words";
  }
}

}  // namespace
}  // namespace vc
