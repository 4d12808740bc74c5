// Inputs the fuzzers (fuzz/, docs/RELIABILITY.md) found crashing, leaking or hanging, kept in
// tests/data/fuzz-regressions/ and read through vc::ReadScene: each must give its clean error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "testing/test_paths.h"
#include "vc/scene/scene_input.h"

namespace vc {
namespace {

using ::testing::HasSubstr;

struct Regression {
  const char* file;     // in tests/data/fuzz-regressions/
  StatusCode code;      // the status ReadScene must return
  const char* message;  // a part of its message
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class FuzzRegressionTest : public ::testing::TestWithParam<Regression> {};

TEST_P(FuzzRegressionTest, GivesACleanError) {
  const Regression& r = GetParam();
  const std::string bytes = Slurp(testing::TestDataPath(std::string("fuzz-regressions/") + r.file));
  ASSERT_FALSE(bytes.empty()) << r.file;
  Result<SceneInput> read = ReadScene(bytes, r.file, ReadLimits(uint64_t{64} << 10, uint64_t{64} << 20));
  ASSERT_FALSE(read.ok()) << r.file;
  EXPECT_EQ(read.status().code(), r.code) << read.status().ToString();
  EXPECT_THAT(read.status().message(), HasSubstr(r.message));
}

INSTANTIATE_TEST_SUITE_P(Found, FuzzRegressionTest,
                         ::testing::Values(
                             // read_scene_fuzzer: a VLR length past the end of the file made the next VLR's bounds
                             // check underflow, and substr threw std::out_of_range (uncaught: abort).
                             Regression{"las-vlr-past-end.las", StatusCode::kInvalidArgument,
                                        "variable length records but record 5 at byte 66032 runs past"},
                             // las_fuzzer, the same bug from a LAS 1.2 header.
                             Regression{"las-vlr-past-end-2.las", StatusCode::kInvalidArgument,
                                        "variable length records but record 1 at byte 381 runs past"}));

}  // namespace
}  // namespace vc
