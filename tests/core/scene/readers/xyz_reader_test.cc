// ASCII XYZ/CSV/TXT reader tests, through vc::ReadScene.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "vc/scene/scene_input.h"

namespace vc {
namespace {

using ::testing::HasSubstr;

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

}  // namespace
}  // namespace vc
