// vc/client/compact_upload.h: a point cloud goes up as its voxels (and those are the voxels the
// server would make of the file), everything PrepareUpload must not shrink goes up as it is with
// the reason, content the server would refuse is refused here (named by what the file's name
// claims when that differs), a renamed file is read as what it holds, and DescribeUpload's line
// for each.
#include "vc/client/compact_upload.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "testing/e57_writer.h"
#include "vc/scene/octomap_adapter.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"

namespace vc::client {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// A 2 m x 2 m floor sampled every centimetre, as ASCII XYZ: 40,000 points, 400 voxels of 0.1 m.
std::string FloorXyz() {
  std::string xyz;
  char line[64];
  for (int i = 0; i < 200; ++i) {
    for (int j = 0; j < 200; ++j) {
      std::snprintf(line, sizeof line, "%.3f %.3f 0.005\n", 0.01 * i + 0.005, 0.01 * j + 0.005);
      xyz += line;
    }
  }
  return xyz;
}

std::vector<VoxelKey> Keys(const std::string& bytes, const std::string& name, double r) {
  Result<SceneInput> in = ReadScene(bytes, name);
  EXPECT_TRUE(in.ok()) << in.status().ToString();
  if (!in.ok()) return {};
  Result<std::vector<VoxelKey>> keys = OccupiedKeys(*in, r, kDefaultMemoryBudgetBytes);
  EXPECT_TRUE(keys.ok()) << keys.status().ToString();
  return keys.ok() ? *keys : std::vector<VoxelKey>{};
}

// PrepareUpload's upload for a file it accepts.
PreparedUpload Prepared(const Upload& file, double resolution_m, bool raw) {
  Result<PreparedUpload> p = PrepareUpload(file, resolution_m, raw);
  EXPECT_TRUE(p.ok()) << p.status().ToString();
  return p.ok() ? *p : PreparedUpload{};
}

TEST(PrepareUploadTest, ACloudGoesUpAsTheVoxelsTheServerWouldMakeOfIt) {
  const std::string xyz = FloorXyz();
  for (const double r : {0.0, 0.2}) {
    const PreparedUpload p = Prepared({xyz, "floor.xyz", ""}, r, false);
    const double used = r > 0 ? r : kDefaultResolutionM;
    EXPECT_EQ(p.summary.format, "vc-voxels");
    EXPECT_EQ(p.summary.resolution_m, used);
    EXPECT_EQ(p.summary.file_bytes, xyz.size());
    EXPECT_EQ(p.summary.bytes_sent, p.upload.bytes.size());
    EXPECT_LT(p.summary.bytes_sent, xyz.size() / 10);
    EXPECT_TRUE(p.summary.why_raw.empty());
    EXPECT_EQ(p.upload.source_name, "floor.xyz");
    const std::vector<VoxelKey> sent = Keys(p.upload.bytes, "floor.xyz", used);
    EXPECT_EQ(sent, Keys(xyz, "floor.xyz", used));
    EXPECT_EQ(p.summary.voxels, sent.size());
    EXPECT_EQ(sent.size(), r > 0 ? 100u : 400u);
  }
}

void ExpectRaw(const Upload& file, bool raw, const std::string& why) {
  const PreparedUpload p = Prepared(file, 0, raw);
  EXPECT_EQ(p.summary.format, "raw") << why;
  EXPECT_THAT(p.summary.why_raw, StartsWith(why));
  EXPECT_EQ(p.upload.bytes, file.bytes) << why;
  EXPECT_EQ(p.upload.source_name, file.source_name);
  EXPECT_EQ(p.summary.bytes_sent, file.bytes.size());
  EXPECT_EQ(p.summary.file_bytes, file.bytes.size());
  EXPECT_EQ(p.summary.voxels, 0u);
}

TEST(PrepareUploadTest, WhatMustNotShrinkGoesUpAsItIsWithTheReason) {
  const std::string xyz = FloorXyz();
  ExpectRaw({xyz, "floor.xyz", ""}, true, "--raw-upload");
  ExpectRaw({"ply\nformat nonsense\n", "bad.ply", ""}, true, "--raw-upload");
  ExpectRaw({"1 2 3\n", "one.xyz", ""}, false, "the vc-voxels stream is not smaller");

  std::stringstream bt;
  ASSERT_TRUE(BuildOctree(0.1, {VoxelKey{32768, 32768, 32768}})->writeBinary(bt));
  ExpectRaw({bt.str(), "tree.bt", ""}, false, "an octree is uploaded as it is");

  testing::E57Spec spec;
  spec.scans.resize(1);
  for (int i = 0; i < 50; ++i) spec.scans[0].points.emplace_back(1 + 0.01 * i, 2, 0.5);
  ExpectRaw({testing::WriteE57(spec), "scan.e57", ""}, false, "the scan origins it carries are kept");

  const PreparedUpload compact = Prepared({xyz, "floor.xyz", ""}, 0, false);
  ExpectRaw(compact.upload, false, "already a vc-voxels stream");
}

TEST(PrepareUploadTest, TheUnitsGoWithARawUploadAndIntoTheSummary) {
  const std::string xyz = FloorXyz();
  // Compact: read here in the file's units, sent as voxels in metres (no units on the wire).
  const PreparedUpload compact = Prepared({xyz, "floor.xyz", "mm"}, 0.0, false);
  EXPECT_EQ(compact.summary.format, "vc-voxels");
  EXPECT_EQ(compact.summary.units, "mm");
  EXPECT_EQ(compact.upload.units, "");
  // Raw: the server reads the file, so it needs the units.
  const PreparedUpload raw = Prepared({xyz, "floor.xyz", "us-ft"}, 0.0, true);
  EXPECT_EQ(raw.summary.format, "raw");
  EXPECT_EQ(raw.summary.units, "us-ft");
  EXPECT_EQ(raw.upload.units, "us-ft");
  // Units the client does not know: the server is left to say so.
  const PreparedUpload unknown = Prepared({xyz, "floor.xyz", "yd"}, 0.0, false);
  EXPECT_EQ(unknown.summary.format, "raw");
  EXPECT_THAT(unknown.summary.why_raw, HasSubstr("unknown length unit \"yd\""));
  EXPECT_EQ(unknown.upload.units, "yd");
}

// What the server's reader would refuse is refused here, before anything is sent, in the words
// of the file's name when that names another format than the content.
TEST(PrepareUploadTest, ContentTheServerWouldRefuseIsRefusedHere) {
  Result<PreparedUpload> bad = PrepareUpload({"ply\nformat nonsense\n", "bad.ply", ""}, 0, false);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), StartsWith("bad.ply"));
  // XYZ text named .ply that is no good as XYZ either: said to be no PLY file, then why.
  Result<PreparedUpload> renamed = PrepareUpload({"1 2 3\n4 five 6\n", "scan.ply", ""}, 0, false);
  ASSERT_FALSE(renamed.ok());
  EXPECT_THAT(renamed.status().message(),
              StartsWith("scan.ply is not a PLY file (it looks like XYZ text; rename it .xyz, or export it again as "
                         "PLY): scan.ply"));
  // Binary data in no format, named .las.
  Result<PreparedUpload> binary = PrepareUpload({std::string("\x01\x02\x00\xff\xfe", 5), "site.las", ""}, 0, false);
  ASSERT_FALSE(binary.ok());
  EXPECT_THAT(
      binary.status().message(),
      StartsWith("site.las is not a LAS file (it is binary data in no format vc reads; export it again as LAS): "));
  // Beyond what the name says, the reader's own message stands.
  Result<PreparedUpload> named_right = PrepareUpload({"1 2 3\n4 five 6\n", "scan.xyz", ""}, 0, false);
  ASSERT_FALSE(named_right.ok());
  EXPECT_THAT(named_right.status().message(), Not(HasSubstr("not an XYZ")));
}

// A renamed file that reads as what it holds goes up as that, with a note (vc goes by the content,
// on the server too); a name that agrees, or says nothing, gets none.
TEST(PrepareUploadTest, ARenamedFileIsReadAsWhatItHoldsWithANote) {
  const std::string xyz = FloorXyz();
  const PreparedUpload renamed = Prepared({xyz, "floor.ply", ""}, 0, false);
  EXPECT_EQ(renamed.summary.format, "vc-voxels");
  EXPECT_EQ(renamed.format_note,
            "floor.ply holds XYZ text, not PLY: read as XYZ text (vc goes by the content, not the name)");
  EXPECT_EQ(Prepared({xyz, "floor.xyz", ""}, 0, false).format_note, "");
  EXPECT_EQ(Prepared({xyz, "floor.xyz.gz", ""}, 0, false).format_note, "");
  EXPECT_EQ(Prepared({xyz, "floor", ""}, 0, false).format_note, "");
  EXPECT_EQ(Prepared({"1 2 3\n", "one.pcd", ""}, 0, false).format_note,
            "one.pcd holds XYZ text, not PCD: read as XYZ text (vc goes by the content, not the name)");
}

TEST(DescribeUploadTest, OneLineForEachKind) {
  UploadSummary s;
  s.format = "vc-voxels";
  s.voxels = 131705;
  s.resolution_m = 0.1;
  s.bytes_sent = 212000;
  s.file_bytes = 4600000;
  EXPECT_EQ(DescribeUpload(s), "compact upload: 131705 voxels of 0.1 m, 212000 bytes instead of the file's 4600000");
  UploadSummary raw;
  raw.format = "raw";
  raw.bytes_sent = 1200;
  raw.why_raw = "an octree is uploaded as it is";
  EXPECT_EQ(DescribeUpload(raw), "raw upload of 1200 bytes (an octree is uploaded as it is)");
}

}  // namespace
}  // namespace vc::client
