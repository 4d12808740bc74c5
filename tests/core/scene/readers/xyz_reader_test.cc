// ASCII XYZ/CSV/TXT reader tests, through vc::ReadScene.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "testing/survey.h"
#include "vc/scene/scene_input.h"

namespace vc {
namespace {

using ::testing::HasSubstr;
using vc::testing::HoldsInInputFrame;
using vc::testing::kSurveyOrigin;
using vc::testing::Shifted;
using vc::testing::SurveyPoints;

// `points_m` as "x y z" lines in units of `metres_per_unit` metres, to 1e-6 unit.
std::string Xyz(const std::vector<Eigen::Vector3d>& points_m, double metres_per_unit = 1.0) {
  std::string text;
  for (const Eigen::Vector3d& p : points_m) {
    char line[128];
    std::snprintf(line, sizeof line, "%.6f %.6f %.6f\n", p.x() / metres_per_unit, p.y() / metres_per_unit,
                  p.z() / metres_per_unit);
    text += line;
  }
  return text;
}

TEST(XyzReaderTest, SpaceSeparated) {
  Result<SceneInput> r = ReadScene("1 2 3\n  -4.5   +5e-1 6\n7 8 9", "s.xyz");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kXyz);
  EXPECT_EQ(r->detail, "space-separated, 3 columns");
  ASSERT_EQ(r->points.size(), 3u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(r->points[1], Eigen::Vector3f(-4.5f, 0.5f, 6));
  EXPECT_EQ(r->points[2], Eigen::Vector3f(7, 8, 9));
}

TEST(XyzReaderTest, CsvWithHeaderExtraColumnsAndCrLf) {
  const std::string csv = "X,Y,Z,intensity,label\r\n1, 2 ,3,0.5,wall\r\n4,5,6,0.7,floor\r\n";
  Result<SceneInput> r = ReadScene(csv, "c.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->detail, "comma-separated, 5 columns, header line");
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(r->points[1], Eigen::Vector3f(4, 5, 6));
}

TEST(XyzReaderTest, TabSeparatedWithCommentsAndBlankLines) {
  const std::string txt = "# scanner export\n\n1\t2\t3\t255\n// note\n4\t5\t6\t255\n\n";
  Result<SceneInput> r = ReadScene(txt, "t.txt");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->detail, "tab-separated, 4 columns");
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_EQ(r->points[1], Eigen::Vector3f(4, 5, 6));
}

TEST(XyzReaderTest, PointCountFirstLineIsTreatedAsHeader) {
  Result<SceneInput> r = ReadScene("2\n1 2 3\n4 5 6\n", "pts.txt");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->points.size(), 2u);
}

TEST(XyzReaderTest, NonFiniteAndOverflowingPointsAreDropped) {
  Result<SceneInput> r = ReadScene("1 2 3\nnan 0 0\n0 inf 0\n0 0 1e999\n0 0 1e-999\n", "n.xyz");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_EQ(r->points[1], Eigen::Vector3f(0, 0, 0));
  EXPECT_EQ(r->dropped_nonfinite, 3u);
}

TEST(XyzReaderTest, NonNumericValueNamesLineAndColumn) {
  Result<SceneInput> r = ReadScene("x y z\n1 2 3\n4 five 6\n", "bad.xyz");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(r.status().message(), "bad.xyz: line 3: expected a number for y (column 2), found \"five\"");
}

TEST(XyzReaderTest, TooFewColumns) {
  Result<SceneInput> r = ReadScene("1 2 3\n4 5\n", "few.xyz");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "few.xyz: line 2: expected at least 3 columns (x y z), found 2 in \"4 5\"");
}

TEST(XyzReaderTest, EmptyCsvFieldIsAnError) {
  Result<SceneInput> r = ReadScene("1,2,3\n4,,6\n", "e.csv");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("line 2: expected a number for y"));
}

TEST(XyzReaderTest, HeaderOnlyIsEmpty) {
  Result<SceneInput> r = ReadScene("x y z\n\n", "h.xyz");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("no points"));
  EXPECT_THAT(r.status().message(), HasSubstr("only a header line"));
}

TEST(XyzReaderTest, WhitespaceOnlyIsEmpty) {
  Result<SceneInput> r = ReadScene("\n \n\t\n", "w.xyz");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("no points"));
}

TEST(XyzReaderTest, PointLimitIsResourceExhausted) {
  ReadOptions options;
  options.max_points = 2;
  Result<SceneInput> r = ReadScene("1 2 3\n4 5 6\n7 8 9\n", "big.xyz", options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  options.max_points = 3;
  EXPECT_TRUE(ReadScene("1 2 3\n4 5 6\n7 8 9\n", "big.xyz", options).ok());
}

TEST(XyzReaderTest, SurveyCoordinatesReadInAWholeKilometreLocalFrameToTheMillimetre) {
  Result<SceneInput> r = ReadScene(Xyz(SurveyPoints()), "utm.xyz");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));
}

TEST(XyzReaderTest, AWholeKilometreShiftReadsToTheSameLocalPointsAsTheSceneAtItsOrigin) {
  const std::vector<Eigen::Vector3d> near_origin = Shifted(SurveyPoints(), -kSurveyOrigin);
  Result<SceneInput> local = ReadScene(Xyz(near_origin), "local.xyz");
  Result<SceneInput> survey = ReadScene(Xyz(SurveyPoints()), "utm.xyz");
  const Eigen::Vector3d shift(3000, -2000, 1000);
  Result<SceneInput> shifted = ReadScene(Xyz(Shifted(SurveyPoints(), shift)), "shifted.xyz");
  ASSERT_TRUE(local.ok() && survey.ok() && shifted.ok());
  EXPECT_EQ(local->frame_origin_m, Eigen::Vector3d::Zero());
  EXPECT_EQ(shifted->frame_origin_m, kSurveyOrigin + shift);
  EXPECT_EQ(survey->points, local->points);
  EXPECT_EQ(shifted->points, local->points);
  // Near its origin a scene reads as plain floats, as it always did.
  for (size_t i = 0; i < near_origin.size(); ++i) EXPECT_EQ(local->points[i], near_origin[i].cast<float>()) << i;
}

TEST(XyzReaderTest, ANonFiniteFirstPointDoesNotPickTheOrigin) {
  Result<SceneInput> r = ReadScene("nan nan nan\n1e39 0 0\n" + Xyz(SurveyPoints()), "nan-first.xyz");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->dropped_nonfinite, 2u);
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));
}

class XyzUnitsTest : public ::testing::TestWithParam<const char*> {};

TEST_P(XyzUnitsTest, TheUnitsScaleEveryPointToMetres) {
  ReadOptions options;
  options.metres_per_unit = *MetresPerUnit(GetParam());
  Result<SceneInput> r = ReadScene(Xyz(SurveyPoints(), options.metres_per_unit), "units.xyz", options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));
  Result<SceneInput> as_metres = ReadScene(Xyz(SurveyPoints(), options.metres_per_unit), "units.xyz");
  ASSERT_TRUE(as_metres.ok());
  EXPECT_FALSE(HoldsInInputFrame(*as_metres, SurveyPoints(), 1.0));
}

INSTANTIATE_TEST_SUITE_P(Units, XyzUnitsTest, ::testing::Values("mm", "cm", "ft", "us-ft"));

}  // namespace
}  // namespace vc
