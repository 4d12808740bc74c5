// PCD reader tests, through vc::ReadScene, on fixtures built in memory.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
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

template <typename T>
void Put(std::string* s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  s->append(b, sizeof(T));
}

// A small greedy LZF compressor (liblzf's format): back-references of 3..264 bytes within 8 KiB,
// literal runs of up to 32 bytes.
std::string LzfCompress(const std::string& in) {
  std::string out;
  std::string literal;
  auto flush = [&] {
    for (size_t i = 0; i < literal.size(); i += 32) {
      const size_t n = std::min<size_t>(32, literal.size() - i);
      out += static_cast<char>(n - 1);
      out += literal.substr(i, n);
    }
    literal.clear();
  };
  size_t i = 0;
  while (i < in.size()) {
    size_t best_len = 0, best_dist = 0;
    for (size_t d = 1; d <= std::min<size_t>(i, 8192); ++d) {
      size_t len = 0;
      while (i + len < in.size() && len < 264 && in[i + len] == in[i - d + len]) ++len;
      if (len > best_len) {
        best_len = len;
        best_dist = d;
      }
    }
    if (best_len < 3) {
      literal += in[i++];
      continue;
    }
    flush();
    const size_t len = best_len - 2;
    const size_t off = best_dist - 1;
    if (len < 7) {
      out += static_cast<char>((len << 5) | (off >> 8));
    } else {
      out += static_cast<char>((7 << 5) | (off >> 8));
      out += static_cast<char>(len - 7);
    }
    out += static_cast<char>(off & 0xff);
    i += best_len;
  }
  flush();
  return out;
}

std::string Header(const std::string& fields, const std::string& size, const std::string& type,
                   const std::string& count, int points, const std::string& data) {
  return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " +
         type + "\nCOUNT " + count + "\nWIDTH " + std::to_string(points) +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) + "\nDATA " + data + "\n";
}

TEST(PcdReaderTest, AsciiWithOddFieldOrderAndCounts) {
  const std::string pcd = Header("normal z hist y x", "4 4 4 8 4", "F F U F F", "3 1 2 1 1", 2, "ascii") +
                          "0 0 1 3 7 8 2 1\n"
                          "0.5 0.5 0.5 -6 1 2 5e-1 4\n";
  Result<SceneInput> r = ReadScene(pcd, "a.pcd");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kPcd);
  EXPECT_EQ(r->detail, "ascii");
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(r->points[1], Eigen::Vector3f(4, 0.5f, -6));
}

TEST(PcdReaderTest, AsciiNanPointsAreDropped) {
  const std::string pcd = Header("x y z", "4 4 4", "F F F", "1 1 1", 3, "ascii") + "nan nan nan\n1 2 3\n4 inf 6\n";
  Result<SceneInput> r = ReadScene(pcd, "nan.pcd");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->points.size(), 1u);
  EXPECT_EQ(r->dropped_nonfinite, 2u);
}

// One point of fields "rgb(U4) z(F8) pad(I2 x3) x(F4) y(I4)".
void PutMixedPoint(std::string* s, double x, double y, double z) {
  Put<uint32_t>(s, 0xffeeddcc);
  Put<double>(s, z);
  for (int i = 0; i < 3; ++i) Put<int16_t>(s, -1);
  Put<float>(s, static_cast<float>(x));
  Put<int32_t>(s, static_cast<int32_t>(y));
}

const char* kMixedFields = "rgb z _ x y";

TEST(PcdReaderTest, BinaryHonoursSizeTypeAndCount) {
  std::string pcd = Header(kMixedFields, "4 8 2 4 4", "U F I F I", "1 1 3 1 1", 2, "binary");
  PutMixedPoint(&pcd, 1.5, -2, 3.25);
  PutMixedPoint(&pcd, 10, 20, std::numeric_limits<double>::quiet_NaN());
  Result<SceneInput> r = ReadScene(pcd, "b.pcd");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->detail, "binary");
  ASSERT_EQ(r->points.size(), 1u);
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1.5f, -2, 3.25f));
  EXPECT_EQ(r->dropped_nonfinite, 1u);
}

// binary_compressed body: fields one after another (all rgb, all z, all pads, all x, all y).
std::string CompressedMixed(const std::vector<Eigen::Vector3d>& pts) {
  std::string soa;
  for (size_t i = 0; i < pts.size(); ++i) Put<uint32_t>(&soa, 0x01020304);
  for (const auto& p : pts) Put<double>(&soa, p.z());
  for (size_t i = 0; i < pts.size() * 3; ++i) Put<int16_t>(&soa, 7);
  for (const auto& p : pts) Put<float>(&soa, static_cast<float>(p.x()));
  for (const auto& p : pts) Put<int32_t>(&soa, static_cast<int32_t>(p.y()));
  const std::string packed = LzfCompress(soa);
  std::string body;
  Put<uint32_t>(&body, static_cast<uint32_t>(packed.size()));
  Put<uint32_t>(&body, static_cast<uint32_t>(soa.size()));
  return body + packed;
}

TEST(PcdReaderTest, BinaryCompressedStoresFieldsOneAfterAnother) {
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 500; ++i) pts.emplace_back(i * 0.5, i % 7, -0.25 * (i % 11));
  const std::string pcd =
      Header(kMixedFields, "4 8 2 4 4", "U F I F I", "1 1 3 1 1", 500, "binary_compressed") + CompressedMixed(pts);
  Result<SceneInput> r = ReadScene(pcd, "c.pcd");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->detail, "binary_compressed");
  ASSERT_EQ(r->points.size(), 500u);
  for (int i = 0; i < 500; ++i) {
    ASSERT_EQ(r->points[i], pts[i].cast<float>()) << "point " << i;
  }
}

TEST(PcdReaderTest, TruncatedBinaryBody) {
  std::string pcd = Header("x y z", "4 4 4", "F F F", "1 1 1", 100, "binary");
  for (int i = 0; i < 3 * 40 + 1; ++i) Put<float>(&pcd, 1.0f);
  Result<SceneInput> r = ReadScene(pcd, "cut.pcd");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(r.status().message(),
            "cut.pcd: PCD header declares 100 points but the body ends after 40; file truncated?");
}

TEST(PcdReaderTest, TruncatedAsciiBody) {
  const std::string pcd = Header("x y z", "4 4 4", "F F F", "1 1 1", 3, "ascii") + "1 2 3\n";
  Result<SceneInput> r = ReadScene(pcd, "cut.pcd");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("declares 3 points but the body ends after 1"));
}

TEST(PcdReaderTest, TruncatedCompressedBlock) {
  std::vector<Eigen::Vector3d> pts(10, Eigen::Vector3d(1, 2, 3));
  std::string pcd =
      Header(kMixedFields, "4 8 2 4 4", "U F I F I", "1 1 3 1 1", 10, "binary_compressed") + CompressedMixed(pts);
  pcd.pop_back();
  Result<SceneInput> r = ReadScene(pcd, "cut.pcd");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("file truncated?"));
}

TEST(PcdReaderTest, CompressedSizeDisagreesWithHeader) {
  std::vector<Eigen::Vector3d> pts(10, Eigen::Vector3d(1, 2, 3));
  const std::string pcd =
      Header(kMixedFields, "4 8 2 4 4", "U F I F I", "1 1 3 1 1", 11, "binary_compressed") + CompressedMixed(pts);
  Result<SceneInput> r = ReadScene(pcd, "m.pcd");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("declares 11 points of 26 bytes but the compressed block at byte"));
}

TEST(PcdReaderTest, CorruptLzfBackReference) {
  std::string pcd = Header("x y z", "4 4 4", "F F F", "1 1 1", 1, "binary_compressed");
  // A back-reference as the very first token points before the start of the output.
  const std::string packed = std::string("\x20\x05\x1f", 3) + std::string(9, 'a');
  Put<uint32_t>(&pcd, static_cast<uint32_t>(packed.size()));
  Put<uint32_t>(&pcd, 12);
  pcd += packed;
  Result<SceneInput> r = ReadScene(pcd, "lzf.pcd");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("back-reference before the start of output"));
}

TEST(PcdReaderTest, ImplausibleUncompressedSizeIsRejectedBeforeAllocating) {
  std::string pcd = Header("x y z", "4 4 4", "F F F", "1 1 1", 300'000'000, "binary_compressed");
  Put<uint32_t>(&pcd, 2);
  Put<uint32_t>(&pcd, 3'600'000'000u);
  pcd += std::string(2, '\0');
  ReadOptions options;  // above the default max_points: raise it to reach the size check
  options.max_points = uint64_t{1} << 40;
  Result<SceneInput> r = ReadScene(pcd, "bomb.pcd", options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("cannot decompress to the declared 3600000000 bytes"));
}

TEST(PcdReaderTest, HeaderErrors) {
  struct Case {
    std::string pcd;
    std::string expected;
  };
  const Case cases[] = {
      {Header("x y z", "4 4 4", "F F Q", "1 1 1", 1, "ascii") + "1 2 3\n",
       "line 5: unknown PCD TYPE \"Q\" for field \"z\""},
      {Header("x y z", "4 4 3", "F F F", "1 1 1", 1, "ascii") + "1 2 3\n", "invalid SIZE \"3\" for field \"z\""},
      {Header("x y z", "4 4", "F F F", "1 1 1", 1, "ascii") + "1 2 3\n", "SIZE lists 2 entries but FIELDS lists 3"},
      {Header("x y intensity", "4 4 4", "F F F", "1 1 1", 1, "ascii") + "1 2 3\n", "no field \"z\""},
      {Header("x y z", "4 4 4", "F F F", "1 1 1", 1, "binary_lzma") + "1 2 3\n",
       "unknown PCD DATA type \"binary_lzma\""},
      {Header("x y z", "4 4 4", "F F F", "1 1 1", 0, "ascii"), "declares 0 points"},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nPOINTS 2\n", "no \"DATA\" line"},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA "
       "ascii\n",
       "declares POINTS 3 but WIDTH * HEIGHT = 2 * 2 = 4"},
      {"VERSION 0.9\nFIELDS x y z\n", "unsupported PCD version"},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH -1\nDATA ascii\n",
       "expected \"WIDTH <non-negative integer>\""},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOLOR red\n", "unknown PCD header keyword \"COLOR\""},
      {Header("x y z", "4 4 4", "F F F", "1 1 1", 1, "ascii") + "1 2\n",
       "line 12: expected 3 values per point (FIELDS times COUNT), found 2"},
      {Header("x y z", "4 4 4", "F F F", "1 1 1", 1, "ascii") + "1 2 3\n4 5 6\n", "line 13: unexpected data"},
      {Header("x y z", "4 4 4", "F F F", "1 1 1", 1, "ascii") + "1 b 3\n",
       "expected a number for field \"y\", found \"b\""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.pcd);
    Result<SceneInput> r = ReadScene(c.pcd, "h.pcd");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr(c.expected));
  }
}

TEST(PcdReaderTest, PointLimitIsResourceExhausted) {
  std::string pcd = Header("x y z", "4 4 4", "F F F", "1 1 1", 5, "binary");
  for (int i = 0; i < 15; ++i) Put<float>(&pcd, 1.0f);
  ReadOptions options;
  options.max_points = 4;
  Result<SceneInput> r = ReadScene(pcd, "big.pcd", options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  options.max_points = 5;
  EXPECT_TRUE(ReadScene(pcd, "big.pcd", options).ok());
}

TEST(PcdReaderTest, EveryTruncationOfACompressedFileFailsCleanly) {
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 20; ++i) pts.emplace_back(i, 2 * i, 3 * i);
  const std::string pcd =
      Header(kMixedFields, "4 8 2 4 4", "U F I F I", "1 1 3 1 1", 20, "binary_compressed") + CompressedMixed(pts);
  ASSERT_TRUE(ReadScene(pcd, "full.pcd").ok());
  const size_t body = pcd.find("DATA binary_compressed\n") + 23;
  for (size_t n = body; n < pcd.size(); ++n) {
    EXPECT_FALSE(ReadScene(std::string_view(pcd).substr(0, n), "cut.pcd").ok()) << n;
  }
  // Corrupting any compressed byte never crashes (it may still decode to other values).
  for (size_t n = body + 8; n < pcd.size(); ++n) {
    std::string bad = pcd;
    bad[n] = static_cast<char>(bad[n] ^ 0x5a);
    (void)ReadScene(bad, "flip.pcd");
  }
}

// `points_m` as a PCD of F 8 fields x y z, binary or ascii.
std::string DoublePcd(const std::vector<Eigen::Vector3d>& points_m, const std::string& data) {
  std::string pcd = Header("x y z", "8 8 8", "F F F", "1 1 1", int(points_m.size()), data);
  for (const Eigen::Vector3d& p : points_m) {
    if (data == "binary") {
      for (int a = 0; a < 3; ++a) Put<double>(&pcd, p[a]);
    } else {
      char line[96];
      std::snprintf(line, sizeof line, "%.4f %.4f %.4f\n", p.x(), p.y(), p.z());
      pcd += line;
    }
  }
  return pcd;
}

TEST(PcdReaderTest, DoubleFieldsAtSurveyCoordinatesReadInALocalFrameToTheMillimetre) {
  for (const char* data : {"binary", "ascii"}) {
    Result<SceneInput> r = ReadScene(DoublePcd(SurveyPoints(), data), "utm.pcd");
    ASSERT_TRUE(r.ok()) << data << ": " << r.status().ToString();
    EXPECT_EQ(r->frame_origin_m, kSurveyOrigin) << data;
    EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3)) << data;
  }
}

TEST(PcdReaderTest, AWholeKilometreShiftReadsToTheSameLocalPoints) {
  const Eigen::Vector3d shift(1000, 1000, -1000);
  Result<SceneInput> survey = ReadScene(DoublePcd(SurveyPoints(), "binary"), "utm.pcd");
  Result<SceneInput> shifted = ReadScene(DoublePcd(Shifted(SurveyPoints(), shift), "binary"), "shifted.pcd");
  ASSERT_TRUE(survey.ok() && shifted.ok());
  EXPECT_EQ(shifted->frame_origin_m, kSurveyOrigin + shift);
  EXPECT_EQ(shifted->points, survey->points);
}

TEST(PcdReaderTest, UnitsScaleEveryField) {
  ReadOptions options;
  options.metres_per_unit = *MetresPerUnit("mm");
  std::vector<Eigen::Vector3d> in_mm = SurveyPoints();
  for (Eigen::Vector3d& p : in_mm) p *= 1000;
  Result<SceneInput> r = ReadScene(DoublePcd(in_mm, "binary"), "mm.pcd", options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));
}

}  // namespace
}  // namespace vc
