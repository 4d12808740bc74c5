// vc/base/parameter.h: CheckParameter's bounds for each ParamCheck, at and just past each bound,
// for doubles and both integer types, with the message naming the parameter, its unit and the
// value. (That every table row is checked, and reaches the flags, the proto and plan.json, is
// tests/client/parameter_flags_test.cc.)
#include "vc/base/parameter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace vc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

ParamInfo Info(ParamCheck check, std::string_view unit = "m") { return {"spacing_m", unit, "spacing", check, "help"}; }

TEST(CheckParameterTest, DoublesAtAndPastEachBound) {
  struct Case {
    ParamCheck check;
    double ok_low, ok_high, bad_low, bad_high;
  };
  const Case cases[] = {
      {ParamCheck::kNonNegative, 0.0, 1e300, -1e-12, -kInf},
      {ParamCheck::kPositive, 1e-300, 1e300, 0.0, -1.0},
      {ParamCheck::kFraction, 1e-12, 1.0, 0.0, 1.0 + 1e-12},
      {ParamCheck::kUnitInterval, 0.0, 1.0, -1e-12, 1.0 + 1e-12},
      {ParamCheck::kElevationDeg, -90.0, 90.0, -90.001, 90.001},
      {ParamCheck::kIncidenceDeg, 1e-9, 90.0, 0.0, 90.001},
      {ParamCheck::kAzimuthSpanDeg, 1e-9, 360.0, 0.0, 360.001},
  };
  for (const Case& c : cases) {
    const ParamInfo info = Info(c.check);
    EXPECT_TRUE(CheckParameter(info, c.ok_low).ok()) << c.ok_low;
    EXPECT_TRUE(CheckParameter(info, c.ok_high).ok()) << c.ok_high;
    EXPECT_EQ(CheckParameter(info, c.bad_low).code(), StatusCode::kInvalidArgument) << c.bad_low;
    EXPECT_EQ(CheckParameter(info, c.bad_high).code(), StatusCode::kInvalidArgument) << c.bad_high;
    EXPECT_FALSE(CheckParameter(info, std::nan("")).ok());
  }
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kAny), -1e300).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kAny), kInf).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kAny), std::nan("")).ok());
}

TEST(CheckParameterTest, TheMessageNamesPrefixParameterRequirementUnitAndValue) {
  Status s = CheckParameter(Info(ParamCheck::kPositive), -2.5, "scanner.");
  EXPECT_EQ(s.message(), "scanner.spacing_m must be > 0 m, got -2.5");
  s = CheckParameter(Info(ParamCheck::kPositive), std::nan(""));
  EXPECT_EQ(s.message(), "spacing_m must be > 0 m, got nan");
  s = CheckParameter(Info(ParamCheck::kFraction, ""), 1.5);
  EXPECT_EQ(s.message(), "spacing_m must be in (0, 1], got 1.5");
  s = CheckParameter(Info(ParamCheck::kFraction, "fraction"), 1.5);
  EXPECT_EQ(s.message(), "spacing_m must be in (0, 1], got 1.5");
  s = CheckParameter(Info(ParamCheck::kElevationDeg, "deg"), 91.0);
  EXPECT_EQ(s.message(), "spacing_m must be in [-90, 90] deg, got 91");
  s = CheckParameter(Info(ParamCheck::kAny), kInf);
  EXPECT_EQ(s.message(), "spacing_m must be a finite number, got inf");
  s = CheckParameter(Info(ParamCheck::kNonNegative, "voxels"), int64_t{-3});
  EXPECT_EQ(s.message(), "spacing_m must be >= 0 voxels, got -3");
  s = CheckParameter(Info(ParamCheck::kPositive, "bytes"), uint64_t{0});
  EXPECT_EQ(s.message(), "spacing_m must be > 0 bytes, got 0");
}

// The client's names: the same check, the field shown as the namer says (a flag), the path
// (prefix + name) as it is without a namer.
TEST(CheckNamedParameterTest, TheNamerChoosesTheName) {
  const FieldNamer flags = [](std::string_view path) {
    return path == "scanner.spacing_m" ? std::string("--spacing") : "?" + std::string(path);
  };
  EXPECT_EQ(CheckNamedParameter(Info(ParamCheck::kPositive), -5.0, flags, "scanner.").message(),
            "--spacing must be > 0 m, got -5");
  EXPECT_EQ(CheckNamedParameter(Info(ParamCheck::kPositive), -5.0, FieldNamer(), "scanner.").message(),
            "scanner.spacing_m must be > 0 m, got -5");
  EXPECT_TRUE(CheckNamedParameter(Info(ParamCheck::kPositive), 5.0, flags).ok());
  EXPECT_EQ(NameOf(flags, "x"), "?x");
  EXPECT_EQ(NameOf(FieldNamer(), "keep_out[2]"), "keep_out[2]");
}

TEST(CheckParameterTest, SignedIntegersAtAndPastEachBound) {
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kAny), std::numeric_limits<int64_t>::min()).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kNonNegative), int64_t{0}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kNonNegative), int64_t{-1}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kPositive), int64_t{1}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kPositive), int64_t{0}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kFraction), int64_t{1}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kFraction), int64_t{2}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kUnitInterval), int64_t{0}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kUnitInterval), int64_t{-1}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kElevationDeg), int64_t{-90}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kElevationDeg), int64_t{91}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kIncidenceDeg), int64_t{90}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kIncidenceDeg), int64_t{0}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kAzimuthSpanDeg), int64_t{360}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kAzimuthSpanDeg), int64_t{361}).ok());
  // int32_t goes through the int64_t overload.
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kNonNegative), int32_t{-1}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kNonNegative), int32_t{7}).ok());
}

TEST(CheckParameterTest, UnsignedIntegersAtAndPastEachBound) {
  const uint64_t big = std::numeric_limits<uint64_t>::max();
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kNonNegative), uint64_t{0}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kPositive), big).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kPositive), uint64_t{0}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kFraction), uint64_t{1}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kFraction), uint64_t{0}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kFraction), uint64_t{2}).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kUnitInterval), uint64_t{0}).ok());
  EXPECT_FALSE(CheckParameter(Info(ParamCheck::kUnitInterval), uint64_t{2}).ok());
}

enum class Colour { kRed, kGreen };

TEST(CheckParameterTest, BoolsAndEnumsTakeAnyValue) {
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kPositive), false).ok());
  EXPECT_TRUE(CheckParameter(Info(ParamCheck::kPositive), Colour::kRed).ok());
}

// The row macros: a table row becomes a field with its default and a ParamInfo with its metadata.
#define TEST_ROWS(X) X(double, width_m, 2.5, "m", "width", kPositive, "the width")

struct Rows {
  TEST_ROWS(VC_DECLARE_PARAMETER)
};

TEST(ParameterMacrosTest, ARowDeclaresItsFieldAndDescribesItself) {
  EXPECT_EQ(Rows{}.width_m, 2.5);
  const ParamInfo info = TEST_ROWS(VC_PARAMETER_INFO);
  EXPECT_EQ(info.name, "width_m");
  EXPECT_EQ(info.unit, "m");
  EXPECT_EQ(info.flag, "width");
  EXPECT_EQ(info.check, ParamCheck::kPositive);
  EXPECT_EQ(info.help, "the width");
}

}  // namespace
}  // namespace vc
