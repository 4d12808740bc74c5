// LAS reader tests, through vc::ReadScene, on files built in memory.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstring>
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
void PutAt(std::string* s, size_t offset, T v) {
  std::memcpy(s->data() + offset, &v, sizeof(T));
}

constexpr uint16_t kRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

struct LasSpec {
  int minor = 2;
  int format = 0;
  std::vector<std::array<int32_t, 3>> points = {{100, -200, 300}, {0, 0, 0}};
  double scale[3] = {0.01, 0.001, 0.5};
  double offset[3] = {1000.0, -50.0, 2.0};
  int extra_bytes = 0;        // Per record, beyond the format's minimum.
  std::string vlr_user = "";  // One VLR with this user id if non-empty.
  uint16_t vlr_record = 0;
  bool legacy_count = true;  // 1.4: also fill the 32-bit count.
};

std::string MakeLas(const LasSpec& s) {
  const uint16_t header_size = s.minor >= 4 ? 375 : s.minor == 3 ? 235 : 227;
  std::string las(header_size, '\0');
  std::memcpy(las.data(), "LASF", 4);
  PutAt<uint8_t>(&las, 24, 1);
  PutAt<uint8_t>(&las, 25, static_cast<uint8_t>(s.minor));
  PutAt<uint16_t>(&las, 94, header_size);
  if (!s.vlr_user.empty()) {
    std::string vlr(54 + 4, '\0');
    std::memcpy(vlr.data() + 2, s.vlr_user.data(), std::min<size_t>(16, s.vlr_user.size()));
    PutAt<uint16_t>(&vlr, 18, s.vlr_record);
    PutAt<uint16_t>(&vlr, 20, 4);
    las += vlr;
    PutAt<uint32_t>(&las, 100, 1);
  }
  PutAt<uint32_t>(&las, 96, static_cast<uint32_t>(las.size()));
  PutAt<uint8_t>(&las, 104, static_cast<uint8_t>(s.format));
  const uint16_t length = static_cast<uint16_t>(kRecordLength[s.format & 0x3f] + s.extra_bytes);
  PutAt<uint16_t>(&las, 105, length);
  if (s.minor < 4 || s.legacy_count) {
    PutAt<uint32_t>(&las, 107, static_cast<uint32_t>(s.points.size()));
  }
  for (int a = 0; a < 3; ++a) {
    PutAt<double>(&las, 131 + 8 * a, s.scale[a]);
    PutAt<double>(&las, 155 + 8 * a, s.offset[a]);
  }
  if (s.minor >= 4) PutAt<uint64_t>(&las, 247, s.points.size());
  for (const auto& p : s.points) {
    std::string rec(length, '\x5a');
    for (int a = 0; a < 3; ++a) PutAt<int32_t>(&rec, 4 * a, p[a]);
    las += rec;
  }
  return las;
}

TEST(LasReaderTest, EveryVersionAndPointFormatAppliesScaleAndOffset) {
  for (int minor = 0; minor <= 4; ++minor) {
    for (int format = 0; format <= 10; ++format) {
      if (format > 5 && minor < 4) continue;  // Formats 6-10 are LAS 1.4 only.
      if (format > 3 && minor < 3) continue;  // 4-5 (waveforms) are 1.3+.
      SCOPED_TRACE("LAS 1." + std::to_string(minor) + " PDRF " + std::to_string(format));
      LasSpec spec;
      spec.minor = minor;
      spec.format = format;
      spec.extra_bytes = format % 3;
      spec.legacy_count = format <= 5;
      Result<SceneInput> r = ReadScene(MakeLas(spec), "p.las");
      ASSERT_TRUE(r.ok()) << r.status().ToString();
      EXPECT_EQ(r->format, InputFormat::kLas);
      EXPECT_EQ(r->detail, "LAS 1." + std::to_string(minor) + " PDRF " + std::to_string(format));
      ASSERT_EQ(r->points.size(), 2u);
      // (1001, -50.2, 152) and (1000, -50, 2) in the file's frame; the local origin is at x = 1 km.
      EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d(1000, 0, 0));
      EXPECT_EQ(r->points[0], Eigen::Vector3f(1.0f, -50.2f, 152.0f));
      EXPECT_EQ(r->points[1], Eigen::Vector3f(0.0f, -50.0f, 2.0f));
    }
  }
}

TEST(LasReaderTest, Las14UsesThe64BitCount) {
  LasSpec spec;
  spec.minor = 4;
  spec.format = 6;
  spec.legacy_count = false;
  for (int i = 0; i < 5; ++i) spec.points.push_back({i, i, i});
  Result<SceneInput> r = ReadScene(MakeLas(spec), "p14.las");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->points.size(), 7u);
}

TEST(LasReaderTest, Las14InconsistentCounts) {
  LasSpec spec;
  spec.minor = 4;
  std::string las = MakeLas(spec);
  PutAt<uint32_t>(&las, 107, 1);
  Result<SceneInput> r = ReadScene(las, "p14.las");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("declares 2 points at byte 247 but a legacy count of 1"));
}

TEST(LasReaderTest, LazCompressedBitIsRefusedWithInstructions) {
  LasSpec spec;
  spec.format = 3 | 0x80;
  Result<SceneInput> r = ReadScene(MakeLas(spec), "in.laz");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(r.status().message(),
            "in.laz: compressed LAZ is not supported; decompress it first, e.g. `laszip -i in.laz "
            "-o out.las` or `pdal translate in.laz out.las`");
}

TEST(LasReaderTest, LaszipVlrIsRefused) {
  LasSpec spec;
  spec.vlr_user = "laszip encoded";
  spec.vlr_record = 22204;
  Result<SceneInput> r = ReadScene(MakeLas(spec), "v.las");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("compressed LAZ is not supported"));
}

TEST(LasReaderTest, OtherVlrsAreSkipped) {
  LasSpec spec;
  spec.vlr_user = "LASF_Projection";
  spec.vlr_record = 34735;
  Result<SceneInput> r = ReadScene(MakeLas(spec), "v.las");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->points.size(), 2u);
}

TEST(LasReaderTest, TruncatedPointData) {
  LasSpec spec;
  spec.format = 1;
  for (int i = 0; i < 8; ++i) spec.points.push_back({i, i, i});
  std::string las = MakeLas(spec);
  las.resize(las.size() - 30);  // Cuts into the ninth record and removes the tenth.
  Result<SceneInput> r = ReadScene(las, "cut.las");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "cut.las: LAS header declares 10 points but the body ends after 8; file truncated?");
}

TEST(LasReaderTest, HugeDeclaredCountFailsWithoutAllocating) {
  std::string las = MakeLas(LasSpec{});
  PutAt<uint32_t>(&las, 107, 4'000'000'000u);
  ReadOptions options;
  options.max_points = uint64_t{1} << 40;
  Result<SceneInput> r = ReadScene(las, "huge.las", options);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("declares 4000000000 points but the body ends after 2"));
  Result<SceneInput> limited = ReadScene(las, "huge.las");
  ASSERT_FALSE(limited.ok());
  EXPECT_EQ(limited.status().code(), StatusCode::kResourceExhausted);
}

TEST(LasReaderTest, HeaderErrors) {
  struct Case {
    size_t offset;
    std::vector<uint8_t> bytes;
    std::string expected;
  };
  const Case cases[] = {
      {24, {2}, "unsupported LAS version 2.2 at byte 24"},
      {25, {5}, "unsupported LAS version 1.5"},
      {104, {11}, "unknown LAS point data record format 11"},
      {105, {10, 0}, "point record length at byte 105 is 10 but point format 0 needs at least 20"},
      {94, {100, 0}, "header size at byte 94 is 100, expected at least 227"},
      {96, {0xff, 0xff, 0, 0}, "offset to point data at byte 96 is 65535"},
      {107, {0, 0, 0, 0}, "declares 0 points"},
      {131, {0, 0, 0, 0, 0, 0, 0, 0}, "LAS x scale/offset"},
      {100, {3, 0, 0, 0}, "declares 3 variable length records"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    std::string las = MakeLas(LasSpec{});
    std::memcpy(las.data() + c.offset, c.bytes.data(), c.bytes.size());
    Result<SceneInput> r = ReadScene(las, "h.las");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr(c.expected));
  }
}

TEST(LasReaderTest, EveryTruncationFailsCleanly) {
  const std::string las = MakeLas(LasSpec{});
  for (size_t n = 4; n < las.size(); ++n) {
    EXPECT_FALSE(ReadScene(std::string_view(las).substr(0, n), "cut.las").ok()) << n;
  }
}

// `points_m` as LAS records of `scale` (file units) about `offset` (file units), in file units
// of `metres_per_unit` metres.
std::string SurveyLas(const std::vector<Eigen::Vector3d>& points_m, const Eigen::Vector3d& offset, double scale,
                      double metres_per_unit = 1.0) {
  LasSpec spec;
  spec.points.clear();
  for (int a = 0; a < 3; ++a) {
    spec.scale[a] = scale;
    spec.offset[a] = offset[a];
  }
  for (const Eigen::Vector3d& p : points_m) {
    std::array<int32_t, 3> record;
    for (int a = 0; a < 3; ++a) record[a] = int32_t(std::lround((p[a] / metres_per_unit - offset[a]) / scale));
    spec.points.push_back(record);
  }
  return MakeLas(spec);
}

TEST(LasReaderTest, SurveyCoordinatesFromScaleAndOffsetReadInALocalFrameToTheMillimetre) {
  const Eigen::Vector3d offset(512000, 5612000, 0);
  Result<SceneInput> r = ReadScene(SurveyLas(SurveyPoints(), offset, 0.001), "utm.las");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));

  const Eigen::Vector3d shift(4000, -3000, 0);
  Result<SceneInput> shifted = ReadScene(SurveyLas(Shifted(SurveyPoints(), shift), offset + shift, 0.001), "s.las");
  ASSERT_TRUE(shifted.ok()) << shifted.status().ToString();
  EXPECT_EQ(shifted->frame_origin_m, kSurveyOrigin + shift);
  EXPECT_EQ(shifted->points, r->points);
}

TEST(LasReaderTest, UnitsApplyAfterTheFilesScaleAndOffset) {
  const double us_foot = *MetresPerUnit("us-ft");
  const Eigen::Vector3d offset_ft(1680000, 18412000, 1000);
  ReadOptions options;
  options.metres_per_unit = us_foot;
  Result<SceneInput> r = ReadScene(SurveyLas(SurveyPoints(), offset_ft, 0.001, us_foot), "ft.las", options);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*r, SurveyPoints(), 1e-3));
}

}  // namespace
}  // namespace vc
