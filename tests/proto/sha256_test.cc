// vc/wire/sha256.h: the FIPS 180-2 test vectors, bytes that are not text, and what IsSha256Hex
// accepts.
#include "vc/wire/sha256.h"

#include <gtest/gtest.h>

#include <string>

namespace vc::wire {
namespace {

TEST(Sha256HexTest, KnownTestVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1'000'000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256HexTest, HashesEveryByteIncludingZeros) {
  const std::string zeros(3, '\0');
  EXPECT_EQ(Sha256Hex(zeros), "709e80c88487a2411e1ee4dfb9f22a861492d20c4765150c0c794abd70f8147c");
  EXPECT_NE(Sha256Hex(zeros), Sha256Hex(std::string(2, '\0')));
  EXPECT_TRUE(IsSha256Hex(Sha256Hex(zeros)));
}

TEST(IsSha256HexTest, OnlySixtyFourLowerCaseHexDigits) {
  const std::string good = Sha256Hex("abc");
  EXPECT_TRUE(IsSha256Hex(good));
  EXPECT_FALSE(IsSha256Hex(""));
  EXPECT_FALSE(IsSha256Hex(good.substr(1)));
  EXPECT_FALSE(IsSha256Hex(good + "0"));
  std::string upper = good;
  upper[0] = 'B';
  EXPECT_FALSE(IsSha256Hex(upper));
  std::string not_hex = good;
  not_hex[63] = 'g';
  EXPECT_FALSE(IsSha256Hex(not_hex));
}

}  // namespace
}  // namespace vc::wire
