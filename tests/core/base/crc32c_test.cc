// CRC32C (vc/base/crc32c.h): the known check values, and incremental updates at every split.
#include "vc/base/crc32c.h"

#include <gtest/gtest.h>

#include <string>

namespace vc {
namespace {

TEST(Crc32c, KnownVectors) {
  EXPECT_EQ(ComputeCrc32c("123456789"), 0xE3069283u);
  EXPECT_EQ(ComputeCrc32c(""), 0u);
  EXPECT_EQ(ComputeCrc32c(std::string(32, '\0')), 0x8A9136AAu);  // RFC 3720 B.4
}

TEST(Crc32c, IncrementalEqualsOneShotAtEverySplit) {
  std::string s;
  for (int i = 0; i < 100; ++i) s += char(i * 37 + 11);
  const uint32_t whole = ComputeCrc32c(s);
  for (size_t cut = 0; cut <= s.size(); ++cut) {
    Crc32c c;
    c.Update(std::string_view(s).substr(0, cut));
    c.Update(std::string_view(s).substr(cut));
    ASSERT_EQ(c.value(), whole) << cut;
  }
}

}  // namespace
}  // namespace vc
