// vc::ReadScene / ReadSceneFile: detection, compression, OctoMap inputs and the real scans.
#include "vc/scene/scene_input.h"

#include <bzlib.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <octomap/ScanGraph.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "testing/survey.h"
#include "testing/test_paths.h"
#include "vc/scene/octomap_adapter.h"

namespace vc {
namespace {

using ::testing::HasSubstr;

std::string Gzip(const std::string& in) {
  z_stream zs{};
  EXPECT_EQ(deflateInit2(&zs, 9, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&zs, in.size()) + 32, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  zs.avail_in = static_cast<uInt>(in.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

std::string Bzip2(const std::string& in) {
  std::string out(in.size() + in.size() / 100 + 700, '\0');
  unsigned int size = static_cast<unsigned int>(out.size());
  EXPECT_EQ(BZ2_bzBuffToBuffCompress(out.data(), &size, const_cast<char*>(in.data()),
                                     static_cast<unsigned int>(in.size()), 9, 0, 0),
            BZ_OK);
  out.resize(size);
  return out;
}

const std::string kXyz = "1 2 3\n4 5 6\n7 8 9\n";
const std::string kPly =
    "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
    "property float z\nend_header\n1 2 3\n4 5 6\n";

TEST(SceneInputTest, Names) {
  EXPECT_EQ(InputFormatName(InputFormat::kPly), "ply");
  EXPECT_EQ(InputFormatName(InputFormat::kPcd), "pcd");
  EXPECT_EQ(InputFormatName(InputFormat::kXyz), "xyz");
  EXPECT_EQ(InputFormatName(InputFormat::kLas), "las");
  EXPECT_EQ(InputFormatName(InputFormat::kOctomapBinary), "octomap-bt");
  EXPECT_EQ(InputFormatName(InputFormat::kOctomapText), "octomap-ot");
  EXPECT_EQ(InputFormatName(InputFormat::kOctomapGraph), "octomap-graph");
  EXPECT_EQ(CompressionName(Compression::kNone), "none");
  EXPECT_EQ(CompressionName(Compression::kGzip), "gzip");
  EXPECT_EQ(CompressionName(Compression::kBzip2), "bzip2");
}

// The format comes from the content, whatever the name: DetectInputFormat is ReadScene's own
// dispatch, so what it says is what ReadScene reads.
TEST(SceneInputTest, DetectInputFormatIsWhatReadSceneReads) {
  EXPECT_EQ(DetectInputFormat(kPly), InputFormat::kPly);
  EXPECT_EQ(DetectInputFormat(kXyz), InputFormat::kXyz);
  EXPECT_EQ(DetectInputFormat("# Octomap OcTree binary file\n"), InputFormat::kOctomapBinary);
  EXPECT_EQ(DetectInputFormat("# Octomap OcTree file\n"), InputFormat::kOctomapText);
  EXPECT_EQ(DetectInputFormat(std::string("\x01\x00\x00\x00\xff", 5)), InputFormat::kOctomapGraph);
  Result<SceneInput> renamed = ReadScene(kXyz, "cloud.ply");
  ASSERT_TRUE(renamed.ok()) << renamed.status().ToString();
  EXPECT_EQ(renamed->format, DetectInputFormat(kXyz));
  EXPECT_EQ(DetectCompression(Gzip(kXyz)), Compression::kGzip);
  EXPECT_EQ(DetectCompression(Bzip2(kPly)), Compression::kBzip2);
  EXPECT_EQ(DetectCompression(kPly), Compression::kNone);
}

TEST(SceneInputTest, EmptyInput) {
  Result<SceneInput> r = ReadScene("", "upload");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(r.status().message(), "upload: input is empty (0 bytes)");
}

TEST(SceneInputTest, GzipCopyOfXyz) {
  Result<SceneInput> r = ReadScene(Gzip(kXyz), "p.xyz.gz");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kXyz);
  EXPECT_EQ(r->compression, Compression::kGzip);
  ASSERT_EQ(r->points.size(), 3u);
  EXPECT_EQ(r->points[2], Eigen::Vector3f(7, 8, 9));
}

TEST(SceneInputTest, Bzip2CopyOfPly) {
  Result<SceneInput> r = ReadScene(Bzip2(kPly), "p.ply.bz2");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kPly);
  EXPECT_EQ(r->compression, Compression::kBzip2);
  EXPECT_EQ(r->points.size(), 2u);
}

TEST(SceneInputTest, ConcatenatedMembersAndStreams) {
  Result<SceneInput> gz = ReadScene(Gzip("1 2 3\n") + Gzip("4 5 6\n"), "cat.gz");
  ASSERT_TRUE(gz.ok()) << gz.status().ToString();
  EXPECT_EQ(gz->points.size(), 2u);
  Result<SceneInput> bz = ReadScene(Bzip2("1 2 3\n") + Bzip2("4 5 6\n"), "cat.bz2");
  ASSERT_TRUE(bz.ok()) << bz.status().ToString();
  EXPECT_EQ(bz->points.size(), 2u);
}

TEST(SceneInputTest, ErrorsInsideCompressedInputNameTheSource) {
  Result<SceneInput> r = ReadScene(Gzip("1 2 3\n4 x 6\n"), "bad.xyz.gz");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("bad.xyz.gz (gzip-decompressed): line 2:"));
}

TEST(SceneInputTest, TruncatedGzip) {
  std::string big;
  for (int i = 0; i < 2000; ++i) big += std::to_string(i) + " 1 2\n";
  const std::string gz = Gzip(big);
  for (size_t n : {size_t{10}, gz.size() / 2, gz.size() - 4}) {
    Result<SceneInput> r = ReadScene(std::string_view(gz).substr(0, n), "cut.gz");
    ASSERT_FALSE(r.ok()) << n;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr("cut.gz: gzip stream truncated"));
  }
}

TEST(SceneInputTest, CorruptGzip) {
  std::string gz = Gzip(kXyz);
  gz[gz.size() - 6] = static_cast<char>(gz[gz.size() - 6] ^ 0xff);  // Inside the CRC32.
  Result<SceneInput> r = ReadScene(gz, "crc.gz");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("corrupt gzip stream"));
  Result<SceneInput> trailing = ReadScene(Gzip(kXyz) + "junk", "t.gz");
  ASSERT_FALSE(trailing.ok());
  EXPECT_THAT(trailing.status().message(), HasSubstr("4 bytes of non-gzip data follow"));
}

TEST(SceneInputTest, TruncatedAndCorruptBzip2) {
  std::string big;
  for (int i = 0; i < 2000; ++i) big += std::to_string(i) + " 1 2\n";
  const std::string bz = Bzip2(big);
  Result<SceneInput> cut = ReadScene(std::string_view(bz).substr(0, bz.size() / 2), "cut.bz2");
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(cut.status().message(), HasSubstr("cut.bz2: bzip2 stream truncated"));
  std::string bad = bz;
  bad[bad.size() / 2] = static_cast<char>(bad[bad.size() / 2] ^ 0x55);
  Result<SceneInput> corrupt = ReadScene(bad, "bad.bz2");
  ASSERT_FALSE(corrupt.ok());
  EXPECT_THAT(corrupt.status().message(), HasSubstr("corrupt bzip2 stream"));
}

TEST(SceneInputTest, DecompressionLimitIsResourceExhausted) {
  const std::string zeros(1 << 20, '0');
  ReadOptions options;
  options.max_decompressed_bytes = 1000;
  for (const std::string& packed : {Gzip(zeros), Bzip2(zeros)}) {
    Result<SceneInput> r = ReadScene(packed, "bomb", options);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
    EXPECT_THAT(r.status().message(), HasSubstr("more than the limit of 1000 bytes"));
  }
  options.max_decompressed_bytes = kXyz.size();
  EXPECT_TRUE(ReadScene(Gzip(kXyz), "fits.gz", options).ok());
  options.max_decompressed_bytes = kXyz.size() - 1;
  EXPECT_FALSE(ReadScene(Gzip(kXyz), "fits.gz", options).ok());
  EXPECT_FALSE(ReadScene(kXyz, "plain", options).ok());
}

TEST(SceneInputTest, UnsupportedCompressionIsNamed) {
  Result<SceneInput> r = ReadScene(std::string("\xFD"
                                               "7zXZ\0\0\x04",
                                               8),
                                   "p.xz");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("xz-compressed input is not supported"));
}

TEST(SceneInputTest, DetectsByContentNotName) {
  Result<SceneInput> r = ReadScene(kPly, "cloud.xyz");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kPly);
}

TEST(SceneInputTest, UnrecognisedBinaryListsSupportedFormats) {
  const std::string junk("\x01\x00\x00\x00\xde\xad\xbe\xef\x00\x13", 10);
  Result<SceneInput> r = ReadScene(junk, "mystery.bin");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("mystery.bin: unrecognised format"));
  EXPECT_THAT(r.status().message(), HasSubstr("PLY, PCD v0.7, ASCII XYZ/CSV, LAS"));
}

std::shared_ptr<octomap::OcTree> SmallTree() {
  auto tree = std::make_shared<octomap::OcTree>(0.1);
  for (int i = 0; i < 10; ++i) tree->updateNode(octomap::point3d(0.05f + 0.1f * i, 0.05f, 0.05f), true);
  tree->updateNode(octomap::point3d(-1, -1, -1), false);
  return tree;
}

TEST(SceneInputTest, OctomapBinary) {
  const auto tree = SmallTree();
  std::stringstream bt;
  ASSERT_TRUE(tree->writeBinary(bt));
  Result<SceneInput> r = ReadScene(bt.str(), "t.bt");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kOctomapBinary);
  ASSERT_TRUE(r->is_octree());
  EXPECT_TRUE(r->points.empty());
  EXPECT_DOUBLE_EQ(r->octree->getResolution(), 0.1);
  EXPECT_EQ(r->detail, "resolution 0.1 m");
  EXPECT_EQ(CountOccupiedLeaves(*r->octree), 10u);
}

TEST(SceneInputTest, OctomapText) {
  const auto tree = SmallTree();
  std::stringstream ot;
  ASSERT_TRUE(tree->write(ot));
  Result<SceneInput> r = ReadScene(ot.str(), "t.ot");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kOctomapText);
  ASSERT_TRUE(r->is_octree());
  EXPECT_EQ(CountOccupiedLeaves(*r->octree), 10u);
}

TEST(SceneInputTest, GzipCopyOfOctomapBinary) {
  std::stringstream bt;
  ASSERT_TRUE(SmallTree()->writeBinary(bt));
  Result<SceneInput> r = ReadScene(Gzip(bt.str()), "t.bt.gz");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->compression, Compression::kGzip);
  ASSERT_TRUE(r->is_octree());
}

TEST(SceneInputTest, BrokenOctomapBinaryIsAnError) {
  std::stringstream bt;
  ASSERT_TRUE(SmallTree()->writeBinary(bt));
  const std::string full = bt.str();
  Result<SceneInput> r = ReadScene(std::string_view(full).substr(0, full.size() - 3), "cut.bt");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("cut.bt"));
}

TEST(SceneInputTest, ScanGraphIsTriedLastForBinaryContent) {
  octomap::ScanGraph graph;
  auto* scan1 = new octomap::Pointcloud();
  scan1->push_back(1, 0, 0);
  scan1->push_back(2, 0, 0);
  graph.addNode(scan1, octomap::pose6d(10, 0, 0, 0, 0, 0));
  auto* scan2 = new octomap::Pointcloud();
  scan2->push_back(0, 1, 0);
  // Yaw +90 degrees: the local x axis becomes the world y axis.
  graph.addNode(scan2, octomap::pose6d(0, 0, 5, 0, 0, M_PI / 2));
  std::stringstream s;
  graph.writeBinary(s);
  Result<SceneInput> r = ReadScene(s.str(), "g.graph");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kOctomapGraph);
  EXPECT_EQ(r->points.size(), 3u);
  ASSERT_EQ(r->scan_origins.size(), 2u);
  EXPECT_EQ(r->scan_origins[1], Eigen::Vector3d(0, 0, 5));
  EXPECT_EQ(r->scan_origins[0], Eigen::Vector3d(10, 0, 0));
  // Points are transformed into the world frame by their scan's pose.
  EXPECT_TRUE(r->points[0].isApprox(Eigen::Vector3f(11, 0, 0))) << r->points[0].transpose();
  EXPECT_TRUE(r->points[1].isApprox(Eigen::Vector3f(12, 0, 0))) << r->points[1].transpose();
  EXPECT_TRUE(r->points[2].isApprox(Eigen::Vector3f(-1, 0, 5), 1e-5f)) << r->points[2].transpose();
}

// A ScanGraph of two scans posed at survey coordinates (exact in OctoMap's float poses).
std::string SurveyGraph() {
  octomap::ScanGraph graph;
  auto* scan1 = new octomap::Pointcloud();
  scan1->push_back(1.5f, 0, 0);
  scan1->push_back(0, 2.25f, -1);
  graph.addNode(scan1, octomap::pose6d(512340.25, 5612328.5, 311, 0, 0, 0));
  auto* scan2 = new octomap::Pointcloud();
  scan2->push_back(0, 1, 0);
  graph.addNode(scan2, octomap::pose6d(512344.125, 5612336, 310.5, 0, 0, M_PI / 2));
  std::stringstream s;
  graph.writeBinary(s);
  return s.str();
}

TEST(SceneInputTest, ScanGraphAtSurveyCoordinatesReadsInALocalFrameWithLocalScanOrigins) {
  Result<SceneInput> r = ReadScene(SurveyGraph(), "utm.graph");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, vc::testing::kSurveyOrigin);
  EXPECT_TRUE(vc::testing::HoldsInInputFrame(
      *r, {{512341.75, 5612328.5, 311}, {512340.25, 5612330.75, 310}, {512343.125, 5612336, 310.5}}, 1e-3));
  ASSERT_EQ(r->scan_origins.size(), 2u);
  EXPECT_EQ(r->scan_origins[0], Eigen::Vector3d(340.25, 328.5, 311));
  EXPECT_EQ(r->scan_origins[1], Eigen::Vector3d(344.125, 336, 310.5));

  ReadOptions in_feet;
  in_feet.metres_per_unit = 0.3048;
  r = ReadScene(SurveyGraph(), "ft.graph", in_feet);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d(156000, 1711000, 0));
  ASSERT_EQ(r->scan_origins.size(), 2u);
  EXPECT_NEAR((r->scan_origins[0] + r->frame_origin_m).x(), 512340.25 * 0.3048, 1e-6);
}

TEST(SceneInputTest, OctreesAreReadInMetresOnly) {
  std::stringstream bt, ot;
  ASSERT_TRUE(SmallTree()->writeBinary(bt));
  ASSERT_TRUE(SmallTree()->write(ot));
  ReadOptions in_mm;
  in_mm.metres_per_unit = 0.001;
  for (const std::string& tree : {bt.str(), ot.str()}) {
    Result<SceneInput> r = ReadScene(tree, "t.tree", in_mm);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr("t.tree: OctoMap octrees are read in metres"));
    r = ReadScene(tree, "t.tree");
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d::Zero());
  }
}

// E57 and octrees fix metres (so --units and a CRS's unit do not apply to them); DetectSceneFormat
// sees through compression, as ReadScene does.
TEST(SceneInputTest, FormatsThatHoldMetresAndTheFormatUnderCompression) {
  EXPECT_TRUE(FormatHoldsMetres(InputFormat::kE57));
  EXPECT_TRUE(FormatHoldsMetres(InputFormat::kOctomapBinary));
  EXPECT_TRUE(FormatHoldsMetres(InputFormat::kOctomapText));
  for (InputFormat f : {InputFormat::kPly, InputFormat::kPcd, InputFormat::kXyz, InputFormat::kLas,
                        InputFormat::kOctomapGraph, InputFormat::kVoxelStream}) {
    EXPECT_FALSE(FormatHoldsMetres(f)) << InputFormatName(f);
  }
  EXPECT_EQ(*DetectSceneFormat(kPly, "p.ply"), InputFormat::kPly);
  EXPECT_EQ(*DetectSceneFormat(Gzip(kPly), "p.ply.gz"), InputFormat::kPly);
  std::stringstream bt;
  ASSERT_TRUE(SmallTree()->writeBinary(bt));
  EXPECT_EQ(*DetectSceneFormat(Bzip2(bt.str()), "t.bt.bz2"), InputFormat::kOctomapBinary);
  const Result<InputFormat> truncated = DetectSceneFormat(Gzip(kXyz).substr(0, 12), "cut.gz");
  ASSERT_FALSE(truncated.ok());
  EXPECT_EQ(truncated.status().code(), StatusCode::kInvalidArgument);
}

TEST(SceneInputTest, ReadSceneFileNotFound) {
  Result<SceneInput> r = ReadSceneFile("/nonexistent/dir/cloud.ply");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(r.status().message(), HasSubstr("/nonexistent/dir/cloud.ply"));
}

TEST(SceneInputTest, ReadSceneFileUsesThePathAsSource) {
  const std::string path = vc::testing::MakeTempDir() + "/cloud.dat";
  {
    std::ofstream out(path, std::ios::binary);
    out << "1 2 3\n4 5\n";
  }
  Result<SceneInput> r = ReadSceneFile(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), path + ": line 2: expected at least 3 columns (x y z), found 2 in \"4 5\"");
}

// Flips random bytes of valid inputs of every format: every result is a value or a clean error.
TEST(SceneInputTest, RandomCorruptionGivesOnlyCleanErrors) {
  std::string ply_bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
      "property double y\nproperty short z\nelement face 2\nproperty list uchar int v\n"
      "end_header\n";
  for (int i = 0; i < 4; ++i) ply_bin += std::string("\0\0\x80?\0\0\0\0\0\0\xf0?\x05\0", 14);
  for (int i = 0; i < 2; ++i) ply_bin += std::string("\x03\0\0\0\0\x01\0\0\0\x02\0\0\0", 13);
  ASSERT_TRUE(ReadScene(ply_bin, "seed.ply").ok());
  std::string pcd =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
      "POINTS 2\nDATA binary_compressed\n";
  // LZF: a 12-byte literal (x0 x1 y0) then a back-reference repeating the last 12 bytes.
  const std::string literal("\0\0\x80?\0\0\0@\0\0@@", 12);
  pcd += std::string("\x10\0\0\0\x18\0\0\0", 8) + "\x0b" + literal + std::string("\xe0\x03\x0b", 3);
  ASSERT_TRUE(ReadScene(pcd, "seed.pcd").ok()) << ReadScene(pcd, "seed.pcd").status().ToString();
  std::stringstream bt;
  ASSERT_TRUE(SmallTree()->writeBinary(bt));
  const std::string seeds[] = {ply_bin, pcd, kPly, kXyz, Gzip(kXyz), Bzip2(kPly), bt.str()};
  uint32_t rng = 12345;
  auto next = [&] { return rng = rng * 1664525u + 1013904223u; };
  for (const std::string& seed : seeds) {
    for (int round = 0; round < 300; ++round) {
      std::string bad = seed;
      const int flips = 1 + static_cast<int>(next() % 4);
      for (int f = 0; f < flips; ++f) bad[next() % bad.size()] = static_cast<char>(next() >> 24);
      Result<SceneInput> r = ReadScene(bad, "fuzz");
      if (r.ok()) continue;
      const StatusCode code = r.status().code();
      EXPECT_TRUE(code == StatusCode::kInvalidArgument || code == StatusCode::kResourceExhausted)
          << r.status().ToString();
      EXPECT_THAT(r.status().message(), HasSubstr("fuzz"));
    }
  }
}

// --- Real scans (../shared/data, see its README) ---

TEST(SceneInputRealDataTest, HallScanBzip2Xyz) {
  Result<SceneInput> r = ReadSceneFile(vc::testing::SharedDataPath("hall-scan/scan.dat.bz2"));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kXyz);
  EXPECT_EQ(r->compression, Compression::kBzip2);
  EXPECT_EQ(r->points.size(), 88'206u);
  EXPECT_EQ(r->dropped_nonfinite, 0u);
  // Within 500 m of its frame's origin: the local frame is the file's, so plans do not change.
  EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d::Zero());
}

TEST(SceneInputRealDataTest, RoomScansBinaryCompressedPcd) {
  const std::pair<const char*, size_t> scans[] = {{"room-2scans/room_scan1.pcd", 112'586},
                                                  {"room-2scans/room_scan2.pcd", 112'624}};
  for (const auto& [name, count] : scans) {
    SCOPED_TRACE(name);
    Result<SceneInput> r = ReadSceneFile(vc::testing::SharedDataPath(name));
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->format, InputFormat::kPcd);
    EXPECT_EQ(r->detail, "binary_compressed");
    EXPECT_EQ(r->points.size() + r->dropped_nonfinite, count);
    EXPECT_EQ(r->points.size(), count);
    EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d::Zero());
    // Scanner frame, z up: the floor is about 1.3 m below the scanner and the ceiling 1.7 m above.
    Eigen::Vector3f lo = r->points[0], hi = r->points[0];
    for (const auto& p : r->points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    EXPECT_LT(lo.z(), -1.0f);
    EXPECT_GT(hi.z(), 1.4f);
  }
}

TEST(SceneInputRealDataTest, Geb079Octree) {
  Result<SceneInput> r = ReadSceneFile(vc::testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->format, InputFormat::kOctomapBinary);
  ASSERT_TRUE(r->is_octree());
  EXPECT_DOUBLE_EQ(OctreeResolution(*r->octree), 0.08);
  EXPECT_EQ(CountOccupiedLeaves(*r->octree), 143'729u);
}

TEST(FrameOriginNearTest, EachAxisToItsNearestWholeKilometre) {
  EXPECT_EQ(FrameOriginNear({512345.678, 5612330.123, 312.5}), Eigen::Vector3d(512000, 5612000, 0));
  EXPECT_EQ(FrameOriginNear({-0.04, 499.9, -1500.1}), Eigen::Vector3d(0, 0, -2000));
}

TEST(MetresPerUnitTest, EachNamedUnitAndARefusal) {
  EXPECT_EQ(*MetresPerUnit("m"), 1.0);
  EXPECT_EQ(*MetresPerUnit("cm"), 0.01);
  EXPECT_EQ(*MetresPerUnit("mm"), 0.001);
  EXPECT_EQ(*MetresPerUnit("ft"), 0.3048);
  EXPECT_NEAR(*MetresPerUnit("us-ft"), 0.3048006096, 1e-10);
  Result<double> bad = MetresPerUnit("inch");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), ::testing::HasSubstr("\"inch\"; use one of m, cm, mm, ft"));
}

}  // namespace
}  // namespace vc
