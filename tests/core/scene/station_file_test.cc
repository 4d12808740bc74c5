// ReadStationFile / ParseStationFile: every source of existing stations (pose CSV with a header,
// header-less CSV, E57, OctoMap .graph, PCD VIEWPOINT) and every error, each naming where.
#include "vc/scene/station_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/ScanGraph.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "testing/e57_writer.h"
#include "testing/test_paths.h"

namespace vc {
namespace {

using ::testing::HasSubstr;

constexpr double kDeg = M_PI / 180.0;

TEST(StationFileTest, PoseCsvWithAHeaderAndExtraColumns) {
  const std::string text =
      "# 3DTK-style poses, angles in degrees\n"
      "Name,X,Y,Z,roll,pitch,yaw,quality\n"
      "s1,1.5,2,1.6,0,0,90,good\n"
      "\n"
      "s2,-3,0.25,1.2,0.5,-1,-45,fair  # a comment\n";
  Result<std::vector<KnownStation>> r = ParseStationFile(text, "poses.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[0].position_m, WorldPoint(1.5, 2, 1.6));
  EXPECT_EQ((*r)[0].name, "s1");
  ASSERT_TRUE((*r)[0].heading_rad.has_value());
  EXPECT_NEAR(*(*r)[0].heading_rad, 90 * kDeg, 1e-12);
  EXPECT_EQ((*r)[1].position_m, WorldPoint(-3, 0.25, 1.2));
  EXPECT_NEAR(*(*r)[1].heading_rad, -45 * kDeg, 1e-12);
  EXPECT_EQ((*r)[1].source, "poses.csv:5");
}

TEST(StationFileTest, HeaderColumnsInAnyOrderWithRadiansAndWhitespace) {
  Result<std::vector<KnownStation>> r = ParseStationFile("z_m\ty_m\tx_m\theading_rad\n1.5\t2\t3\t0.5\n", "p.txt");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 1u);
  EXPECT_EQ((*r)[0].position_m, WorldPoint(3, 2, 1.5));
  EXPECT_DOUBLE_EQ(*(*r)[0].heading_rad, 0.5);
}

TEST(StationFileTest, ASpreadsheetExportWithABomAndSemicolons) {
  Result<std::vector<KnownStation>> r = ParseStationFile("\xEF\xBB\xBFID;X;Y;Z\r\nA;1.5;2;1.6\r\n", "excel.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 1u);
  EXPECT_EQ((*r)[0].position_m, WorldPoint(1.5, 2, 1.6));
  EXPECT_EQ((*r)[0].name, "A");
  // A decimal comma is one field, refused as a number, not read as two.
  Result<std::vector<KnownStation>> comma = ParseStationFile("x;y;z\n1,5;2;1,6\n", "comma.csv");
  ASSERT_FALSE(comma.ok());
  EXPECT_THAT(comma.status().message(), HasSubstr("comma.csv:2: x (column 1) \"1,5\" is not a number"));
}

TEST(StationFileTest, HeaderlessRowsAreXyzAndMore) {
  // vc's own stations.csv has a header; a bare "x y z route_order" file works too.
  Result<std::vector<KnownStation>> r = ParseStationFile("1,2,3,1\n4 5 6 2 extra\n", "bare.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[1].position_m, WorldPoint(4, 5, 6));
  EXPECT_FALSE((*r)[0].heading_rad.has_value());
  r = ParseStationFile("x,y,z,route_order\n1,2,3,1\n", "stations.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ((*r)[0].position_m, WorldPoint(1, 2, 3));
}

TEST(StationFileTest, ANameColumnWinsOverStationAndIdColumns) {
  // A plan's stations.csv: a comment, "station" (its number) before "name", empty cells.
  Result<std::vector<KnownStation>> r = ParseStationFile(
      "# vc stations\nstation,name,x_m,y_m,z_m,floor,tripod_height_m\n1,S01,1,2,3,L0,1.5\n2,BM 7,4,5,6,,\n",
      "stations.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[1].name, "BM 7");
  EXPECT_EQ((*r)[1].position_m, WorldPoint(4, 5, 6));
  r = ParseStationFile("name,station,x,y,z\nA,1,1,2,3\n", "swapped.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ((*r)[0].name, "A");
  r = ParseStationFile("station,x,y,z\n7,1,2,3\n", "numbered.csv");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ((*r)[0].name, "7");
}

TEST(StationFileTest, E57ScansPosesWithHeadings) {
  testing::E57Spec spec;
  const double yaws[] = {0.7, -2.0, 3.0};
  for (int i = 0; i < 3; ++i) {
    testing::E57ScanSpec scan;
    scan.name = "scan" + std::to_string(i);
    scan.points = {{1, 0, 0}, {0, 1, 0}};
    scan.translation_m = Eigen::Vector3d(i, 2 * i, 1.5);
    scan.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(yaws[i], Eigen::Vector3d::UnitZ()));
    spec.scans.push_back(scan);
  }
  Result<std::vector<KnownStation>> r = ParseStationFile(testing::WriteE57(spec), "scanned.e57");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE((*r)[i].position_m.isApprox(WorldPoint(i, 2 * i, 1.5))) << i;
    EXPECT_NEAR(*(*r)[i].heading_rad, yaws[i], 1e-9) << i;
    EXPECT_EQ((*r)[i].name, "scan" + std::to_string(i));
    EXPECT_EQ((*r)[i].source, "scanned.e57, scan " + std::to_string(i));
  }
}

std::string TwoScanGraph() {
  octomap::ScanGraph graph;
  auto* scan1 = new octomap::Pointcloud();
  scan1->push_back(1, 0, 0);
  graph.addNode(scan1, octomap::pose6d(10, 0, 1.5, 0, 0, 0));
  auto* scan2 = new octomap::Pointcloud();
  scan2->push_back(0, 1, 0);
  graph.addNode(scan2, octomap::pose6d(0, 3, 1.2, 0, 0, M_PI / 2));
  std::stringstream s;
  graph.writeBinary(s);
  return s.str();
}

TEST(StationFileTest, ScanGraphOrigins) {
  // Named .graph, or sniffed as binary under any name.
  for (const char* name : {"site.graph", "site.bin"}) {
    Result<std::vector<KnownStation>> r = ParseStationFile(TwoScanGraph(), name);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_EQ(r->size(), 2u);
    // OctoMap keeps poses as float.
    EXPECT_TRUE((*r)[0].position_m.isApprox(WorldPoint(10, 0, 1.5), 1e-6)) << (*r)[0].position_m.transpose();
    EXPECT_TRUE((*r)[1].position_m.isApprox(WorldPoint(0, 3, 1.2), 1e-6)) << (*r)[1].position_m.transpose();
    EXPECT_NEAR(*(*r)[0].heading_rad, 0, 1e-9);
    EXPECT_NEAR(*(*r)[1].heading_rad, M_PI / 2, 1e-9);
    EXPECT_EQ((*r)[1].source, std::string(name) + ", scan 1");
  }
}

TEST(StationFileTest, PcdViewpoint) {
  const double c = std::cos(M_PI / 8), s = std::sin(M_PI / 8);  // yaw 45 degrees
  const std::string pcd =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
      "WIDTH 1\nHEIGHT 1\nVIEWPOINT 4 5 1.6 " +
      std::to_string(c) + " 0 0 " + std::to_string(s) + "\nPOINTS 1\nDATA ascii\n1 2 3\n";
  Result<std::vector<KnownStation>> r = ParseStationFile(pcd, "scan.pcd");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 1u);
  EXPECT_EQ((*r)[0].position_m, WorldPoint(4, 5, 1.6));
  EXPECT_NEAR(*(*r)[0].heading_rad, M_PI / 4, 1e-5);  // the quaternion written to 6 decimals
  EXPECT_EQ((*r)[0].source, "scan.pcd:9");
}

TEST(StationFileTest, ARealBinaryCompressedPcdGivesItsViewpoint) {
  // room_scan1.pcd (shared data) keeps PCL's default VIEWPOINT 0 0 0 1 0 0 0 on line 9.
  Result<std::vector<KnownStation>> r = ReadStationFile(testing::SharedDataPath("room-2scans/room_scan1.pcd"));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->size(), 1u);
  EXPECT_EQ((*r)[0].position_m, WorldPoint(0, 0, 0));
  EXPECT_DOUBLE_EQ(*(*r)[0].heading_rad, 0);
  EXPECT_THAT((*r)[0].source, ::testing::EndsWith("room_scan1.pcd:9"));
}

// The error's code and that its message holds `where`.
void ExpectError(const std::string& bytes, const std::string& source, const std::string& where) {
  Result<std::vector<KnownStation>> r = ParseStationFile(bytes, source);
  ASSERT_FALSE(r.ok()) << source;
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument) << source;
  EXPECT_THAT(r.status().message(), HasSubstr(where)) << source;
}

TEST(StationFileTest, ABadTokenNamesFileLineAndToken) {
  ExpectError("x,y,z\n1,2,3\n1,2x,3\n", "bad.csv", "bad.csv:3: y (column 2) \"2x\" is not a number");
  ExpectError("1,2,3\n1,2\n", "short.csv", "short.csv:2: expected at least 3 columns, found 2");
  ExpectError("x,y,z,yaw\n1,2,3,east\n", "yaw.csv", "yaw.csv:2: yaw (column 4) \"east\" is not a number");
  ExpectError("a,b,c\n1,2,3\n", "nohead.csv", "nohead.csv:1: the header \"a,b,c\" names no x, y and z columns");
}

TEST(StationFileTest, NanAndInfinityAreRefused) {
  ExpectError("1,2,3\nnan,2,3\n", "nan.csv", "nan.csv:2: x (column 1) is \"nan\"; values must be finite");
  ExpectError("x,y,z,roll\n1,2,inf,0\n", "inf.csv", "inf.csv:2: z (column 3) is \"inf\"");
  ExpectError("VERSION 0.7\nFIELDS x y z\nVIEWPOINT 0 nan 0 1 0 0 0\nDATA ascii\n", "v.pcd", "v.pcd:3: ty");
}

TEST(StationFileTest, AnEmptyFileHasNoStation) {
  for (const char* text : {"", "# nothing\n\n", "x,y,z\n"}) {
    ExpectError(text, "empty.csv", "empty.csv: no station found");
  }
  ExpectError("VERSION 0.7\nFIELDS x y z\nDATA ascii\n", "noview.pcd", "noview.pcd: the PCD header has no VIEWPOINT");
}

TEST(StationFileTest, BinaryGarbageIsNamedWithoutItsBytes) {
  std::string garbage = "\x89\x01\x02\x03\xff\xfe garbage \x00\x11";
  garbage.resize(64, '\x07');
  Result<std::vector<KnownStation>> r = ParseStationFile(garbage, "junk.dat");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("junk.dat: binary content (byte 1)"));
  const std::string message(r.status().message());
  for (char c : message) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << int(c);
  // A damaged .graph names the scan graph and a byte offset, not its bytes.
  std::string graph = TwoScanGraph();
  graph.resize(graph.size() / 2);
  ExpectError(graph, "cut.graph", "cut.graph: scan graph, byte");
}

TEST(StationFileTest, ReadStationFileReadsAPathOrSaysNotFound) {
  const std::string path = ::testing::TempDir() + "/stations_file_test.csv";
  std::ofstream(path) << "x;y;z\n1;2;3\n";
  Result<std::vector<KnownStation>> r = ReadStationFile(path);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ((*r)[0].source, path + ":2");
  EXPECT_EQ(ReadStationFile(path + ".missing").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace vc
