// E57 reader tests, through vc::ReadScene and vc::ReadE57Scans, on files from the test writer.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "testing/e57_writer.h"
#include "testing/survey.h"
#include "vc/scene/e57.h"
#include "vc/scene/scene_input.h"

namespace vc {
namespace {

using testing::E57Coordinates;
using testing::E57ScanSpec;
using testing::E57Spec;
using testing::E57ValueType;
using ::testing::HasSubstr;
using testing::HoldsInInputFrame;
using testing::kSurveyOrigin;
using testing::SurveyPoints;
using testing::WriteE57;

std::vector<Eigen::Vector3d> SomePoints() {
  return {{1.5, -2.25, 0.75}, {10, 20, 3}, {-4, 0.125, 1}, {0, 0, 0}, {7.5, 7.25, -1.5}};
}

E57Spec OneScan(E57ScanSpec scan) {
  E57Spec spec;
  spec.scans.push_back(std::move(scan));
  return spec;
}

E57ScanSpec Scan(E57ValueType type = E57ValueType::kFloatDouble) {
  E57ScanSpec s;
  s.type = type;
  s.points = SomePoints();
  return s;
}

void ExpectPoints(const SceneInput& in, const std::vector<Eigen::Vector3d>& expected, double tolerance) {
  ASSERT_EQ(in.points.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_LE((in.points[i].cast<double>() - expected[i]).norm(), tolerance)
        << i << ": " << in.points[i].transpose() << " vs " << expected[i].transpose();
  }
}

Status ReadStatus(const std::string& bytes) {
  Result<SceneInput> in = ReadScene(bytes, "t.e57");
  return in.ok() ? Status::Ok() : in.status();
}

TEST(E57Reader, DetectsFromContentAndReadsDoubles) {
  Result<SceneInput> in = ReadScene(WriteE57(OneScan(Scan())), "points.xyz");
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_EQ(in->format, InputFormat::kE57);
  EXPECT_EQ(InputFormatName(in->format), "e57");
  EXPECT_EQ(in->detail, "E57 1.0, 1 scan");
  ExpectPoints(*in, SomePoints(), 1e-6);
  ASSERT_EQ(in->scan_origins.size(), 1u);
  EXPECT_EQ(in->scan_origins[0], Eigen::Vector3d::Zero());
  EXPECT_EQ(in->dropped_nonfinite, 0u);
}

struct TypeCase {
  E57ValueType type;
  double tolerance;
};

class E57ValueTypes : public ::testing::TestWithParam<TypeCase> {};

TEST_P(E57ValueTypes, RoundTripCartesian) {
  E57ScanSpec scan = Scan(GetParam().type);
  if (GetParam().type == E57ValueType::kInteger) {
    scan.points = {{1, -2, 3}, {100, 200, -300}, {0, 0, 0}, {-7, 8, 9}};
  }
  const std::vector<Eigen::Vector3d> expected = scan.points;
  Result<SceneInput> in = ReadScene(WriteE57(OneScan(scan)), "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  ExpectPoints(*in, expected, GetParam().tolerance);
}

TEST_P(E57ValueTypes, RoundTripSphericalWithManyPackets) {
  E57ScanSpec scan = Scan(GetParam().type);
  scan.coordinates = E57Coordinates::kSpherical;
  scan.packets = 5;
  scan.points.clear();
  std::vector<Eigen::Vector3d> expected;
  for (int i = 0; i < 40; ++i) {
    const double range = 2 + i, azimuth = -3 + 0.15 * i, elevation = -1.2 + 0.06 * i;
    if (GetParam().type == E57ValueType::kInteger) continue;
    scan.points.emplace_back(range, azimuth, elevation);
    expected.emplace_back(range * std::cos(elevation) * std::cos(azimuth),
                          range * std::cos(elevation) * std::sin(azimuth), range * std::sin(elevation));
  }
  if (GetParam().type == E57ValueType::kInteger) {
    scan.points = {{5, 0, 0}, {3, 1, 1}};
    for (const auto& p : scan.points) {
      expected.emplace_back(p[0] * std::cos(p[2]) * std::cos(p[1]), p[0] * std::cos(p[2]) * std::sin(p[1]),
                            p[0] * std::sin(p[2]));
    }
  }
  Result<SceneInput> in = ReadScene(WriteE57(OneScan(scan)), "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  // Angles quantised by the scale (1 mm on a 1 rad scale) move points by up to range * scale.
  ExpectPoints(*in, expected, GetParam().type == E57ValueType::kScaledInteger ? 0.05 : 1e-4 * 50);
}

INSTANTIATE_TEST_SUITE_P(Types, E57ValueTypes,
                         ::testing::Values(TypeCase{E57ValueType::kInteger, 0},
                                           TypeCase{E57ValueType::kScaledInteger, 0.0009},
                                           TypeCase{E57ValueType::kFloatSingle, 1e-5},
                                           TypeCase{E57ValueType::kFloatDouble, 1e-9}));

TEST(E57Reader, AppliesEachScansPoseAndReportsOrigins) {
  E57Spec spec;
  std::vector<Eigen::Vector3d> expected;
  const Eigen::Quaterniond rotations[3] = {
      Eigen::Quaterniond::Identity(),
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ())),
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()))};
  const Eigen::Vector3d translations[3] = {{0, 0, 0}, {10, -5, 1.5}, {-3, 4, 0.5}};
  for (int s = 0; s < 3; ++s) {
    E57ScanSpec scan = Scan(s == 1 ? E57ValueType::kScaledInteger : E57ValueType::kFloatDouble);
    scan.name = "Station " + std::to_string(s);
    scan.rotation = rotations[s];
    scan.translation_m = translations[s];
    for (const auto& p : scan.points) expected.push_back(rotations[s] * p + translations[s]);
    spec.scans.push_back(scan);
  }
  Result<SceneInput> in = ReadScene(WriteE57(spec), "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_EQ(in->detail, "E57 1.0, 3 scans");
  ExpectPoints(*in, expected, 1e-3);
  ASSERT_EQ(in->scan_origins.size(), 3u);
  for (int s = 0; s < 3; ++s) EXPECT_LE((in->scan_origins[s] - translations[s]).norm(), 1e-12);
  // The 90-degree turn about z: scanner (1.5, -2.25, 0.75) -> world (2.25 + 10, 1.5 - 5, 0.75 + 1.5).
  EXPECT_LE((in->points[5].cast<double>() - Eigen::Vector3d(12.25, -3.5, 2.25)).norm(), 1e-3);
}

TEST(E57Reader, ListsScansWithoutReadingPoints) {
  E57Spec spec;
  E57ScanSpec a = Scan();
  a.name = "North";
  a.guid = "{A}";
  a.translation_m = {1, 2, 3};
  a.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()));
  E57ScanSpec b = Scan();
  b.name = "South";
  b.write_pose = false;
  b.points.resize(2);
  spec.scans = {a, b};
  Result<std::vector<E57Scan>> scans = ReadE57Scans(WriteE57(spec), "t.e57");
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  ASSERT_EQ(scans->size(), 2u);
  EXPECT_EQ((*scans)[0].name, "North");
  EXPECT_EQ((*scans)[0].guid, "{A}");
  EXPECT_EQ((*scans)[0].point_count, 5u);
  EXPECT_EQ((*scans)[0].translation_m, Eigen::Vector3d(1, 2, 3));
  EXPECT_LE((*scans)[0].rotation.angularDistance(a.rotation), 1e-12);
  EXPECT_EQ((*scans)[1].name, "South");
  EXPECT_EQ((*scans)[1].point_count, 2u);
  EXPECT_EQ((*scans)[1].translation_m, Eigen::Vector3d::Zero());
  EXPECT_EQ((*scans)[1].rotation.coeffs(), Eigen::Quaterniond::Identity().coeffs());
  EXPECT_TRUE(LooksLikeE57(WriteE57(spec)));
  EXPECT_FALSE(LooksLikeE57("ASTM-E5"));
}

TEST(E57Reader, SkipsRecordsMarkedInvalidAndIgnoresIntensity) {
  E57ScanSpec scan = Scan();
  scan.intensity = true;
  scan.invalid_state = {0, 1, 0, 2, 0};
  Result<SceneInput> in = ReadScene(WriteE57(OneScan(scan)), "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  ExpectPoints(*in, {SomePoints()[0], SomePoints()[2], SomePoints()[4]}, 1e-9);
  EXPECT_EQ(in->detail, "E57 1.0, 1 scan, 2 records marked invalid");
}

TEST(E57Reader, RefusesAFileWithoutValidPoints) {
  E57ScanSpec scan = Scan();
  scan.invalid_state = {2, 2, 1, 2, 2};
  const Status s = ReadStatus(WriteE57(OneScan(scan)));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("E57 1.0, 1 scan, 5 records marked invalid: no valid, finite point"));
}

TEST(E57Reader, ReadsAnEmptyScanWithoutDataPackets) {
  E57Spec spec;
  E57ScanSpec empty = Scan();
  empty.points.clear();
  empty.translation_m = {5, 5, 1};
  spec.scans = {empty, Scan()};
  std::string file = WriteE57(spec);
  const uint64_t none = 0;
  std::memcpy(file.data() + 48 + 16, &none, 8);  // The empty scan's dataPhysicalOffset.
  testing::FixE57Checksums(&file);
  Result<SceneInput> in = ReadScene(file, "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  ExpectPoints(*in, SomePoints(), 1e-9);
  ASSERT_EQ(in->scan_origins.size(), 2u);
  EXPECT_EQ(in->scan_origins[0], Eigen::Vector3d(5, 5, 1));
}

TEST(E57Reader, SkipsEmptyAndIndexPackets) {
  E57ScanSpec scan = Scan(E57ValueType::kScaledInteger);
  scan.packets = 3;
  scan.extra_packets = true;
  Result<SceneInput> in = ReadScene(WriteE57(OneScan(scan)), "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  ExpectPoints(*in, SomePoints(), 0.0009);
}

TEST(E57Reader, DropsAndCountsNonFinitePoints) {
  E57ScanSpec scan = Scan();
  scan.points[1].x() = std::numeric_limits<double>::quiet_NaN();
  scan.points[3].z() = std::numeric_limits<double>::infinity();
  Result<SceneInput> in = ReadScene(WriteE57(OneScan(scan)), "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_EQ(in->points.size(), 3u);
  EXPECT_EQ(in->dropped_nonfinite, 2u);
}

// The root as libE57Format writes it (seen in a published sample's XML: indentation, an empty
// Integer element for 0, min/max attributes on Integer elements), plus the optional scan elements
// real scanners write (bounds, an extension namespace): all parsed past; empty Floats are 0.
TEST(E57Reader, ReadsTheLayoutOfLibE57FormatFiles) {
  E57ScanSpec scan = Scan();
  scan.translation_m = {0, 2, 0};
  E57Spec spec = OneScan(scan);
  spec.edit_xml = [](std::string& xml) {
    const auto replace = [&](const std::string& from, const std::string& to) {
      ASSERT_NE(xml.find(from), std::string::npos) << from;
      xml.replace(xml.find(from), from.size(), to);
    };
    replace("<e57Root type=\"Structure\" xmlns=",
            "<e57Root type=\"Structure\"\n         xmlns:nor=\"http://www.libe57.org/E57_NOR_surface_normals.txt\"\n"
            "         xmlns=");
    replace("<versionMajor type=\"Integer\">1</versionMajor>",
            "  <versionMajor type=\"Integer\" minimum=\"0\" maximum=\"255\">1</versionMajor>");
    replace("<versionMinor type=\"Integer\">0</versionMinor>",
            "  <versionMinor type=\"Integer\" minimum=\"0\" maximum=\"255\"/>");
    replace("<coordinateMetadata type=\"String\"></coordinateMetadata>", "  <coordinateMetadata type=\"String\"/>");
    replace("<x type=\"Float\">0</x><y type=\"Float\">2</y>", "<x type=\"Float\"/>\n    <y type=\"Float\">2</y>");
    replace("<points type=",
            "<cartesianBounds type=\"Structure\">\n      <xMinimum type=\"Float\">-4</xMinimum>\n"
            "      <xMaximum type=\"Float\">10</xMaximum>\n    </cartesianBounds>\n"
            "    <indexBounds type=\"Structure\">\n      <rowMaximum type=\"Integer\" minimum=\"0\"/>\n"
            "    </indexBounds>\n    <nor:normalsInfo type=\"String\"><![CDATA[none]]></nor:normalsInfo>\n"
            "    <points type=");
  };
  Result<SceneInput> in = ReadScene(WriteE57(spec), "t.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  std::vector<Eigen::Vector3d> expected;
  for (const auto& p : SomePoints()) expected.push_back(p + Eigen::Vector3d(0, 2, 0));
  ExpectPoints(*in, expected, 1e-9);
}

// --- Refusals: each names the section and the byte offset ---

TEST(E57Reader, RefusesAWrongChecksumNamingThePage) {
  std::string file = WriteE57(OneScan(Scan()));
  file[1024 + 100] ^= 0x20;
  const Status s = ReadStatus(file);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("t.e57: E57 page 1 (physical bytes 1024 to 2047)"));
  EXPECT_THAT(s.message(), HasSubstr("CRC-32C"));
  // The stored checksum is big-endian: a file written little-endian is refused.
  std::string swapped = WriteE57(OneScan(Scan()));
  std::swap(swapped[1020], swapped[1023]);
  std::swap(swapped[1021], swapped[1022]);
  EXPECT_THAT(ReadStatus(swapped).message(), HasSubstr("E57 page 0"));
}

TEST(E57Reader, RefusesTruncatedPages) {
  const std::string file = WriteE57(OneScan(Scan()));
  ASSERT_GE(file.size(), 2048u);
  std::string cut = file.substr(0, file.size() - 100);
  Status s = ReadStatus(cut);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("E57 header: file length at byte 16 is " + std::to_string(file.size())));
  // The header agrees with the cut, but the last page is partial.
  const uint64_t cut_size = cut.size();
  std::memcpy(cut.data() + 16, &cut_size, 8);
  testing::FixE57Checksums(&cut);
  s = ReadStatus(cut);
  EXPECT_THAT(s.message(), HasSubstr("not whole 1024-byte pages; the last page, at physical byte " +
                                     std::to_string(cut.size() / 1024 * 1024) + ", is truncated"));
  // Whole pages cut off: the XML section runs past the end.
  std::string short_file = file.substr(0, 1024);
  const uint64_t n = short_file.size();
  std::memcpy(short_file.data() + 16, &n, 8);
  testing::FixE57Checksums(&short_file);
  s = ReadStatus(short_file);
  EXPECT_THAT(s.message(), HasSubstr("E57 XML section"));
}

TEST(E57Reader, RefusesALyingRecordCount) {
  E57ScanSpec more = Scan();
  more.record_count_delta = 1;
  Status s = ReadStatus(WriteE57(OneScan(more)));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("E57 scan 0 binary section at physical byte 48"));
  EXPECT_THAT(s.message(), HasSubstr("holds 5 records"));
  EXPECT_THAT(s.message(), HasSubstr("the XML recordCount is 6"));
  E57ScanSpec fewer = Scan(E57ValueType::kScaledInteger);
  fewer.record_count_delta = -2;
  s = ReadStatus(WriteE57(OneScan(fewer)));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("holds more than 3 records"));
}

TEST(E57Reader, RefusesBadXml) {
  E57Spec spec = OneScan(Scan());
  spec.edit_xml = [](std::string& xml) { xml.replace(xml.find("</data3D>"), 9, "</data3d>"); };
  Status s = ReadStatus(WriteE57(spec));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("E57 XML section (at physical byte"));
  EXPECT_THAT(s.message(), HasSubstr("does not parse: mismatched tag at line"));

  spec.edit_xml = [](std::string& xml) {
    xml.insert(xml.find("<e57Root"), "<!DOCTYPE e57Root [<!ENTITY a \"aa\">]>\n");
  };
  EXPECT_THAT(ReadStatus(WriteE57(spec)).message(), HasSubstr("DOCTYPE"));

  spec.edit_xml = [](std::string& xml) { xml.replace(xml.find("<points type"), 7, "<pointz"); };
  EXPECT_THAT(ReadStatus(WriteE57(spec)).message(), HasSubstr("does not parse"));

  spec.edit_xml = [](std::string& xml) {
    xml.replace(xml.find("<points type"), 7, "<pointz");
    xml.replace(xml.find("</points>"), 9, "</pointz>");
  };
  s = ReadStatus(WriteE57(spec));
  EXPECT_THAT(s.message(), HasSubstr("E57 XML section, line"));
  EXPECT_THAT(s.message(), HasSubstr("scan 0: <vectorChild> has no <points>"));

  spec.edit_xml = [](std::string& xml) { xml.replace(xml.find("type=\"Float\"/>"), 14, "type=\"String\"/>"); };
  EXPECT_THAT(ReadStatus(WriteE57(spec)).message(),
              HasSubstr("prototype field <cartesianX> has type \"String\"; only Integer, ScaledInteger, Float"));

  spec.edit_xml = [](std::string& xml) { xml.replace(xml.find("<w type=\"Float\">1"), 17, "<w type=\"Float\">2"); };
  EXPECT_THAT(ReadStatus(WriteE57(spec)).message(), HasSubstr("expected a unit quaternion"));

  spec.edit_xml = [](std::string& xml) {
    const std::string codec = "<vectorChild type=\"Structure\"><zipCodec type=\"Structure\"/></vectorChild>";
    xml.insert(xml.find("</codecs>"), codec);
  };
  EXPECT_THAT(ReadStatus(WriteE57(spec)).message(), HasSubstr("codec <zipCodec> is not supported"));

  spec.edit_xml = [](std::string& xml) { xml.replace(xml.find("cartesianZ"), 10, "cartesianQ"); };
  EXPECT_THAT(ReadStatus(WriteE57(spec)).message(), HasSubstr("neither cartesianX/Y/Z nor sphericalRange"));
}

TEST(E57Reader, RefusesFieldsWiderThan64Bits) {
  E57Spec spec = OneScan(Scan(E57ValueType::kScaledInteger));
  spec.edit_xml = [](std::string& xml) { xml.insert(xml.find("maximum=\"") + 9, "99999999999999999999"); };
  const Status s = ReadStatus(WriteE57(spec));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("scan 0: prototype field <cartesianX> maximum="));
  EXPECT_THAT(s.message(), HasSubstr("is not a 64-bit integer"));
}

TEST(E57Reader, RefusesAWrongHeader) {
  const std::string good = WriteE57(OneScan(Scan()));
  std::string page = good;
  const uint64_t half = 512;
  std::memcpy(page.data() + 40, &half, 8);
  testing::FixE57Checksums(&page);
  Status s = ReadStatus(page);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("E57 header: page size at byte 40 is 512, expected 1024"));

  std::string version = good;
  version[8] = 2;
  testing::FixE57Checksums(&version);
  EXPECT_THAT(ReadStatus(version).message(), HasSubstr("E57 header: version 2.0 at byte 8 is not supported"));

  Result<std::vector<E57Scan>> scans = ReadE57Scans("ASTM-E5x" + good.substr(8), "t.e57");
  ASSERT_FALSE(scans.ok());
  EXPECT_THAT(scans.status().message(), HasSubstr("E57 header"));

  std::string xml_in_checksum = good;
  const uint64_t into_checksum = 1021;
  std::memcpy(xml_in_checksum.data() + 24, &into_checksum, 8);
  testing::FixE57Checksums(&xml_in_checksum);
  EXPECT_THAT(ReadStatus(xml_in_checksum).message(),
              HasSubstr("XML section (header byte 24) at physical byte 1021 points into a page checksum"));
}

TEST(E57Reader, RefusesABadBinarySection) {
  std::string file = WriteE57(OneScan(Scan()));
  file[48] = 0;  // Section id.
  testing::FixE57Checksums(&file);
  EXPECT_THAT(ReadStatus(file).message(),
              HasSubstr("E57 scan 0 binary section at physical byte 48: section id is 0, expected 1"));

  file = WriteE57(OneScan(Scan()));
  file[48 + 32] = 7;  // First packet's type.
  testing::FixE57Checksums(&file);
  EXPECT_THAT(ReadStatus(file).message(), HasSubstr("at physical byte 80: unknown packet type 7"));

  file = WriteE57(OneScan(Scan()));
  file[48 + 32 + 4] = 9;  // Bytestream count.
  testing::FixE57Checksums(&file);
  EXPECT_THAT(ReadStatus(file).message(), HasSubstr("data packet has 9 bytestreams but the prototype has 3 fields"));

  file = WriteE57(OneScan(Scan()));
  file[48 + 32 + 2] = 2;  // Packet length - 1, low byte.
  file[48 + 32 + 3] = 0;
  testing::FixE57Checksums(&file);
  EXPECT_THAT(ReadStatus(file).message(), HasSubstr("data packet of 3 bytes is shorter than its 6-byte header"));

  file = WriteE57(OneScan(Scan()));
  const uint64_t past_end = file.size() + 8;
  std::memcpy(file.data() + 48 + 16, &past_end, 8);  // dataPhysicalOffset.
  testing::FixE57Checksums(&file);
  EXPECT_THAT(ReadStatus(file).message(),
              HasSubstr("scan 0 binary section data (section header byte 16) at physical byte"));
}

TEST(E57Reader, ChecksLimitsBeforeReadingPoints) {
  ReadOptions options;
  options.max_points = 4;
  Result<SceneInput> in = ReadScene(WriteE57(OneScan(Scan())), "t.e57", options);
  ASSERT_FALSE(in.ok());
  EXPECT_EQ(in.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(in.status().message(), HasSubstr("E57 XML section declares 5 points"));
  options = ReadOptions();
  options.max_result_bytes = 4 * kBytesPerPoint;
  in = ReadScene(WriteE57(OneScan(Scan())), "t.e57", options);
  ASSERT_FALSE(in.ok());
  EXPECT_EQ(in.status().code(), StatusCode::kResourceExhausted);
}

// Two scans posed at survey coordinates, their points (scanner frame) turned and moved onto
// SurveyPoints(): the first scan holds the first two points, the second the other three.
E57Spec SurveyScans(double metres_per_unit = 1.0) {
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d stations[2] = {{512340.25, 5612328.5, 311.0}, {512344.125, 5612336.75, 310.5}};
  const std::vector<Eigen::Vector3d> world = SurveyPoints();
  E57Spec spec;
  for (int s = 0; s < 2; ++s) {
    E57ScanSpec scan = Scan();
    scan.rotation = turn;
    scan.translation_m = stations[s] / metres_per_unit;
    scan.points.clear();
    for (size_t i = s == 0 ? 0 : 2; i < (s == 0 ? 2u : world.size()); ++i) {
      scan.points.push_back(turn.inverse() * (world[i] / metres_per_unit - scan.translation_m));
    }
    spec.scans.push_back(scan);
  }
  return spec;
}

TEST(E57Reader, ScansPosedAtSurveyCoordinatesReadInALocalFrameToTheMillimetre) {
  Result<SceneInput> in = ReadScene(WriteE57(SurveyScans()), "utm.e57");
  ASSERT_TRUE(in.ok()) << in.status().message();
  EXPECT_EQ(in->frame_origin_m, kSurveyOrigin);
  EXPECT_TRUE(HoldsInInputFrame(*in, SurveyPoints(), 1e-3));
  ASSERT_EQ(in->scan_origins.size(), 2u);
  // The scan origins are local too, in double.
  EXPECT_LE((in->scan_origins[0] - Eigen::Vector3d(340.25, 328.5, 311.0)).norm(), 1e-9);
  EXPECT_LE((in->scan_origins[1] - Eigen::Vector3d(344.125, 336.75, 310.5)).norm(), 1e-9);
}

// E57 coordinates are metres by the standard (ASTM E2807): other units are refused, not applied,
// and the file reads in metres as before.
TEST(E57Reader, UnitsOtherThanMetresAreRefusedSinceE57HoldsMetres) {
  ReadOptions options;
  options.metres_per_unit = *MetresPerUnit("us-ft");
  const Result<SceneInput> in = ReadScene(WriteE57(SurveyScans()), "site.e57", options);
  ASSERT_FALSE(in.ok());
  EXPECT_EQ(in.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(in.status().message().rfind("site.e57: E57 files hold metres by the standard (ASTM E2807), but units of "
                                        "0.304801 m were given; read the E57 without units",
                                        0),
            0u)
      << in.status().message();
  options.metres_per_unit = 1.0;
  const Result<SceneInput> metres = ReadScene(WriteE57(SurveyScans()), "site.e57", options);
  ASSERT_TRUE(metres.ok()) << metres.status().message();
  EXPECT_TRUE(HoldsInInputFrame(*metres, SurveyPoints(), 1e-3));
}

}  // namespace
}  // namespace vc
