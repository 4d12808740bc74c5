// PLY reader tests, through vc::ReadScene, on fixtures built in memory.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
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

// Appends `v` to `s` in little- or big-endian order.
template <typename T>
void Put(std::string* s, T v, bool big_endian = false) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian) {
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  s->append(b, sizeof(T));
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(PlyReaderTest, AsciiWithExtraPropertiesFacesAndComments) {
  const std::string ply =
      "ply\n"
      "format ascii 1.0\n"
      "comment made by hand\n"
      "obj_info test\n"
      "element vertex 3\n"
      "property float x\n"
      "property uchar red\n"
      "property float y\n"
      "property float z\n"
      "property list uchar int extra\n"
      "element face 2\n"
      "property list uchar int vertex_indices\n"
      "end_header\n"
      "1 255 2 3 2 7 8\n"
      "-4.5 0 5e1 6 0\n"
      "\n"
      "7 1 8 9 1 4\n"
      "3 0 1 2\n"
      "3 2 1 0\n";
  Result<SceneInput> r = ReadScene(ply, "t.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kPly);
  EXPECT_EQ(r->compression, Compression::kNone);
  EXPECT_EQ(r->detail, "ascii 1.0");
  ASSERT_EQ(r->points.size(), 3u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(r->points[1], Eigen::Vector3f(-4.5f, 50, 6));
  EXPECT_EQ(r->points[2], Eigen::Vector3f(7, 8, 9));
  EXPECT_EQ(r->dropped_nonfinite, 0u);
  EXPECT_FALSE(r->is_octree());
}

TEST(PlyReaderTest, AsciiCrLfLineEndings) {
  const std::string ply =
      "ply\r\nformat ascii 1.0\r\nelement vertex 2\r\nproperty float x\r\nproperty float y\r\n"
      "property float z\r\nend_header\r\n1 2 3\r\n4 5 6\r\n";
  Result<SceneInput> r = ReadScene(ply, "crlf.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_EQ(r->points[1], Eigen::Vector3f(4, 5, 6));
}

// Header for a binary vertex element; `props` are "type name" pairs, then optional extra lines.
std::string BinaryHeader(const std::string& format, int vertices, const std::string& props,
                         const std::string& extra = "") {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) + "\n" + props + extra +
         "end_header\n";
}

void TestBinaryFloat(bool big) {
  std::string ply = BinaryHeader(big ? "binary_big_endian" : "binary_little_endian", 2,
                                 "property float x\nproperty float y\nproperty float z\nproperty uchar red\n",
                                 "element face 2\nproperty list uchar int vertex_indices\nproperty ushort flags\n");
  const float v[2][3] = {{1.5f, -2.25f, 3.0f}, {100.0f, 200.5f, -300.0f}};
  for (const auto& p : v) {
    for (float c : p) Put(&ply, c, big);
    Put<uint8_t>(&ply, 200);
  }
  // face 0: 3 indices; face 1: 0 indices.
  Put<uint8_t>(&ply, 3);
  for (int i : {0, 1, 0}) Put<int32_t>(&ply, i, big);
  Put<uint16_t>(&ply, 9, big);
  Put<uint8_t>(&ply, 0);
  Put<uint16_t>(&ply, 9, big);
  Result<SceneInput> r = ReadScene(ply, "b.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->detail, big ? "binary_big_endian 1.0" : "binary_little_endian 1.0");
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1.5f, -2.25f, 3.0f));
  EXPECT_EQ(r->points[1], Eigen::Vector3f(100.0f, 200.5f, -300.0f));
}

TEST(PlyReaderTest, BinaryLittleEndianWithFaces) { TestBinaryFloat(false); }
TEST(PlyReaderTest, BinaryBigEndianWithFaces) { TestBinaryFloat(true); }

TEST(PlyReaderTest, BinaryDoubleCoordinates) {
  std::string ply = BinaryHeader("binary_big_endian", 1, "property double z\nproperty float64 y\nproperty double x\n");
  Put<double>(&ply, 3.5, true);
  Put<double>(&ply, -2.0, true);
  Put<double>(&ply, 1e6, true);
  Result<SceneInput> r = ReadScene(ply, "d.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->points.size(), 1u);
  // x = 1e6 m: the local frame's origin is there (docs/PLANNING.md "Coordinates").
  EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d(1e6, 0, 0));
  EXPECT_EQ(r->points[0], Eigen::Vector3f(0, -2.0f, 3.5f));
}

TEST(PlyReaderTest, BinaryIntegerCoordinatesOfEveryType) {
  const char* types[][3] = {
      {"char", "uchar", "short"}, {"ushort", "int", "uint"}, {"int8", "uint8", "int16"}, {"uint16", "int32", "uint32"}};
  for (const auto& t : types) {
    SCOPED_TRACE(std::string(t[0]) + " " + t[1] + " " + t[2]);
    std::string ply =
        BinaryHeader("binary_little_endian", 1,
                     std::string("property ") + t[0] + " x\nproperty " + t[1] + " y\nproperty " + t[2] + " z\n");
    auto put = [&](const char* type, int value) {
      const std::string n = type;
      if (n == "char" || n == "int8") Put<int8_t>(&ply, static_cast<int8_t>(value));
      if (n == "uchar" || n == "uint8") Put<uint8_t>(&ply, static_cast<uint8_t>(value));
      if (n == "short" || n == "int16") Put<int16_t>(&ply, static_cast<int16_t>(value));
      if (n == "ushort" || n == "uint16") Put<uint16_t>(&ply, static_cast<uint16_t>(value));
      if (n == "int" || n == "int32") Put<int32_t>(&ply, value);
      if (n == "uint" || n == "uint32") Put<uint32_t>(&ply, static_cast<uint32_t>(value));
    };
    const bool x_signed = std::string(t[0]).find('u') == std::string::npos;
    put(t[0], x_signed ? -7 : 7);
    put(t[1], 200);
    put(t[2], 300);
    Result<SceneInput> r = ReadScene(ply, "i.ply");
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_EQ(r->points.size(), 1u);
    EXPECT_EQ(r->points[0], Eigen::Vector3f(x_signed ? -7 : 7, 200, 300));
  }
}

TEST(PlyReaderTest, SkipsElementsWithListsBeforeTheVertices) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\n"
      "element camera 2\nproperty list int double params\nproperty short id\n"
      "element vertex 1\nproperty float x\nproperty list ushort uchar tags\nproperty float y\n"
      "property float z\nend_header\n";
  Put<int32_t>(&ply, 2);
  Put<double>(&ply, 1.0);
  Put<double>(&ply, 2.0);
  Put<int16_t>(&ply, 1);
  Put<int32_t>(&ply, 0);
  Put<int16_t>(&ply, 2);
  Put<float>(&ply, 4);
  Put<uint16_t>(&ply, 3);
  ply += "abc";
  Put<float>(&ply, 5);
  Put<float>(&ply, 6);
  Result<SceneInput> r = ReadScene(ply, "cam.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->points.size(), 1u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(4, 5, 6));
}

TEST(PlyReaderTest, NonFinitePointsAreDroppedAndCounted) {
  std::string ply = BinaryHeader("binary_little_endian", 4, "property float x\nproperty float y\nproperty double z\n");
  const double values[4][3] = {{1, 2, 3}, {kNaN, 0, 0}, {0, kInf, 0}, {0, 0, 1e300}};
  for (const auto& p : values) {
    Put<float>(&ply, static_cast<float>(p[0]));
    Put<float>(&ply, static_cast<float>(p[1]));
    Put<double>(&ply, p[2]);
  }
  Result<SceneInput> r = ReadScene(ply, "nan.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->points.size(), 1u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(r->dropped_nonfinite, 3u);
}

TEST(PlyReaderTest, AsciiNanIsDroppedAndCounted) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\nnan 1 2\n1 2 3\n";
  Result<SceneInput> r = ReadScene(ply, "nan.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->points.size(), 1u);
  EXPECT_EQ(r->dropped_nonfinite, 1u);
}

TEST(PlyReaderTest, AllPointsNonFiniteIsAnEmptyCloud) {
  std::string ply = BinaryHeader("binary_little_endian", 1, "property float x\nproperty float y\nproperty float z\n");
  for (int i = 0; i < 3; ++i) Put<float>(&ply, kNaN);
  Result<SceneInput> r = ReadScene(ply, "allnan.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("non-finite"));
}

TEST(PlyReaderTest, TruncatedBinaryBodyNamesDeclaredAndPresentCounts) {
  std::string ply =
      BinaryHeader("binary_little_endian", 1000, "property float x\nproperty float y\nproperty float z\n");
  for (int i = 0; i < 312 * 3; ++i) Put<float>(&ply, 1.0f);
  ply += "xy";  // A partial vertex.
  Result<SceneInput> r = ReadScene(ply, "cut.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(r.status().message(),
            "cut.ply: PLY header declares 1000 vertices but the body ends after 312; file "
            "truncated?");
}

TEST(PlyReaderTest, TruncatedAsciiBody) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 5 6\n";
  Result<SceneInput> r = ReadScene(ply, "cut.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("PLY header declares 5 vertices but the body ends after 2"));
}

TEST(PlyReaderTest, TruncatedFaceList) {
  std::string ply = BinaryHeader("binary_little_endian", 1, "property float x\nproperty float y\nproperty float z\n",
                                 "element face 1\nproperty list uchar int vertex_indices\n");
  for (int i = 0; i < 3; ++i) Put<float>(&ply, 1.0f);
  Put<uint8_t>(&ply, 3);
  Put<int32_t>(&ply, 0);
  Result<SceneInput> r = ReadScene(ply, "face.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("list \"vertex_indices\" of 3 items"));
  EXPECT_THAT(r.status().message(), HasSubstr("truncated"));
}

TEST(PlyReaderTest, HugeDeclaredCountFailsWithoutAllocating) {
  std::string ply = BinaryHeader("binary_little_endian", 0, "property float x\nproperty float y\nproperty float z\n");
  ply.replace(ply.find("vertex 0"), 8, "vertex 1000000000000");
  for (int i = 0; i < 3; ++i) Put<float>(&ply, 1.0f);
  // Above the default max_points: a limit error.
  Result<SceneInput> limited = ReadScene(ply, "huge.ply");
  ASSERT_FALSE(limited.ok());
  EXPECT_EQ(limited.status().code(), StatusCode::kResourceExhausted);
  // With the limit raised, the count is checked against the body before any reservation.
  ReadOptions options;
  options.max_points = uint64_t{1} << 50;
  Result<SceneInput> r = ReadScene(ply, "huge.ply", options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("declares 1000000000000 vertices but the body ends after 1;"));
  // Same for ascii.
  std::string ascii = ply.substr(0, ply.find("end_header\n") + 11);
  ascii.replace(ascii.find("binary_little_endian"), 20, "ascii");
  ascii += "1 2 3\n";
  Result<SceneInput> a = ReadScene(ascii, "huge.ply", options);
  ASSERT_FALSE(a.ok());
  EXPECT_THAT(a.status().message(), HasSubstr("declares 1000000000000 vertices but the body ends after 1;"));
}

TEST(PlyReaderTest, ExtraBinaryBytesAreAHeaderBodyMismatch) {
  std::string ply = BinaryHeader("binary_little_endian", 1, "property float x\nproperty float y\nproperty float z\n");
  for (int i = 0; i < 6; ++i) Put<float>(&ply, 1.0f);
  Result<SceneInput> r = ReadScene(ply, "long.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("12 bytes left after the last declared element"));
}

TEST(PlyReaderTest, ExtraAsciiLineIsAMismatch) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 5 6\n";
  Result<SceneInput> r = ReadScene(ply, "long.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("line 9: unexpected data \"4 5 6\""));
}

TEST(PlyReaderTest, AsciiWrongValueCountNamesTheLine) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 5 6 7\n";
  Result<SceneInput> r = ReadScene(ply, "n.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("line 9:"));
  EXPECT_THAT(r.status().message(), HasSubstr("has 4 values, expected 3"));
}

TEST(PlyReaderTest, AsciiBadNumberNamesLineAndToken) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 two 3\n";
  Result<SceneInput> r = ReadScene(ply, "bad.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "bad.ply: line 8: expected a number for vertex property \"y\", found \"two\"");
}

TEST(PlyReaderTest, UnknownPropertyType) {
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property half y\nproperty float z\nend_header\n";
  Result<SceneInput> r = ReadScene(ply, "t.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("line 5: unknown PLY property type \"half\""));
}

TEST(PlyReaderTest, HeaderErrors) {
  const std::string props = "property float x\nproperty float y\nproperty float z\n";
  struct Case {
    std::string ply;
    std::string expected;
  };
  const Case cases[] = {
      {"ply\nformat ascii 1.0\nelement vertex 1\n" + props, "no \"end_header\" line"},
      {"ply\nelement vertex 1\n" + props + "end_header\n1 2 3\n", "no \"format\" line"},
      {"ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown PLY format"},
      {"ply\nformat ascii 2.0\nend_header\n", "unsupported PLY version \"2.0\""},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int v\nend_header\n3 0 1 2\n",
       "no \"vertex\" element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 "
       "2\n",
       "no \"z\" property"},
      {"ply\nformat ascii 1.0\nelement vertex 0\n" + props + "end_header\n", "declares 0 vertices"},
      {"ply\nformat ascii 1.0\nelement vertex many\n" + props + "end_header\n", "expected \"element <name> <count>\""},
      {"ply\nformat ascii 1.0\nproperty float x\nend_header\n", "before any \"element\" line"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\nend_header\n",
       "list count type must be an integer type"},
      {"ply\nformat ascii 1.0\nbogus line\nend_header\n", "unknown PLY header keyword \"bogus\""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.ply);
    Result<SceneInput> r = ReadScene(c.ply, "h.ply");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr(c.expected));
    EXPECT_THAT(r.status().message(), HasSubstr("h.ply: "));
  }
}

TEST(PlyReaderTest, EveryTruncationOfABinaryFileFailsCleanly) {
  std::string ply = BinaryHeader("binary_big_endian", 3, "property double x\nproperty float y\nproperty int z\n",
                                 "element face 2\nproperty list uchar uint vertex_indices\n");
  for (int i = 0; i < 3; ++i) {
    Put<double>(&ply, i, true);
    Put<float>(&ply, 1, true);
    Put<int32_t>(&ply, 2, true);
  }
  for (int f = 0; f < 2; ++f) {
    Put<uint8_t>(&ply, 3);
    for (uint32_t k = 0; k < 3; ++k) Put<uint32_t>(&ply, k, true);
  }
  ASSERT_TRUE(ReadScene(ply, "full.ply").ok());
  for (size_t n = 0; n < ply.size(); ++n) {
    Result<SceneInput> r = ReadScene(std::string_view(ply).substr(0, n), "cut.ply");
    EXPECT_FALSE(r.ok()) << "prefix of " << n << " bytes";
  }
}

// `points_m` as a binary little-endian PLY of double x, y, z.
std::string DoublePly(const std::vector<Eigen::Vector3d>& points_m) {
  std::string ply = BinaryHeader("binary_little_endian", int(points_m.size()),
                                 "property double x\nproperty double y\nproperty double z\n");
  for (const Eigen::Vector3d& p : points_m) {
    for (int a = 0; a < 3; ++a) Put<double>(&ply, p[a]);
  }
  return ply;
}

TEST(PlyReaderTest, DoublePropertiesAtSurveyCoordinatesReadInALocalFrameToTheMillimetre) {
  Result<SceneInput> r = ReadScene(DoublePly(SurveyPoints()), "utm.ply");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));

  std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty double y\n"
      "property double z\nend_header\n";
  for (const Eigen::Vector3d& p : SurveyPoints()) {
    char line[96];
    std::snprintf(line, sizeof line, "%.4f %.4f %.4f\n", p.x(), p.y(), p.z());
    ascii += line;
  }
  Result<SceneInput> a = ReadScene(ascii, "utm-ascii.ply");
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_EQ(a->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*a, SurveyPoints(), 1e-3));
}

TEST(PlyReaderTest, AWholeKilometreShiftReadsToTheSameLocalPoints) {
  const Eigen::Vector3d shift(-7000, 12000, 0);
  Result<SceneInput> survey = ReadScene(DoublePly(SurveyPoints()), "utm.ply");
  Result<SceneInput> shifted = ReadScene(DoublePly(Shifted(SurveyPoints(), shift)), "shifted.ply");
  ASSERT_TRUE(survey.ok() && shifted.ok());
  EXPECT_EQ(shifted->frame_origin_m, kSurveyOrigin + shift);
  EXPECT_EQ(shifted->points, survey->points);
}

TEST(PlyReaderTest, UnitsScaleDoubleProperties) {
  ReadOptions options;
  options.metres_per_unit = *MetresPerUnit("cm");
  std::vector<Eigen::Vector3d> in_cm = SurveyPoints();
  for (Eigen::Vector3d& p : in_cm) p *= 100;
  Result<SceneInput> r = ReadScene(DoublePly(in_cm), "cm.ply", options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));
}

}  // namespace
}  // namespace vc
