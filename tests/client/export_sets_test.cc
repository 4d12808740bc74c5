// vc/client/export_sets.h: evaluate --export-sets' directory checks and its station_<n>.xyz files.
#include "vc/client/export_sets.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "testing/test_paths.h"

namespace vc::client {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

void Touch(const fs::path& p) { std::ofstream(p) << "x\n"; }

TEST(PrepareExportDirTest, CreatesAMissingDirectoryWithItsParents) {
  const fs::path dir = fs::path(vc::testing::MakeTempDir()) / "a" / "b";
  ASSERT_TRUE(PrepareExportDir(dir.string(), false).ok());
  EXPECT_TRUE(fs::is_directory(dir));
  EXPECT_TRUE(fs::is_empty(dir));  // the write probe is gone
}

TEST(PrepareExportDirTest, RefusesANonEmptyDirectoryUnlessForced) {
  const fs::path dir = vc::testing::MakeTempDir();
  Touch(dir / "station_1.xyz");
  Touch(dir / "notes.txt");
  const Status refused = PrepareExportDir(dir.string(), false);
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.message(), HasSubstr(dir.string() + " is not empty (2 entries"));
  EXPECT_THAT(refused.message(), HasSubstr("--force"));
  EXPECT_TRUE(fs::exists(dir / "station_1.xyz"));
  ASSERT_TRUE(PrepareExportDir(dir.string(), true).ok());
  EXPECT_FALSE(fs::exists(dir / "station_1.xyz"));  // an older evaluation's sets go
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));       // anything else stays
}

TEST(PrepareExportDirTest, RefusesAFileAndADirectoryItCannotCreate) {
  const fs::path file = fs::path(vc::testing::MakeTempDir()) / "plan.json";
  Touch(file);
  const Status not_dir = PrepareExportDir(file.string(), true);
  EXPECT_EQ(not_dir.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(not_dir.message(), HasSubstr("exists and is not a directory"));
  const Status under_file = PrepareExportDir((file / "sets").string(), false);
  EXPECT_EQ(under_file.code(), StatusCode::kPermissionDenied);
  EXPECT_THAT(under_file.message(), HasSubstr("cannot create the directory"));
}

TEST(PrepareExportDirTest, RefusesADirectoryItCannotWriteInto) {
  if (geteuid() == 0) GTEST_SKIP() << "root writes into a read-only directory";
  const fs::path dir = fs::path(vc::testing::MakeTempDir()) / "ro";
  fs::create_directory(dir);
  ASSERT_EQ(chmod(dir.c_str(), 0555), 0);
  const Status s = PrepareExportDir(dir.string(), false);
  chmod(dir.c_str(), 0755);
  EXPECT_EQ(s.code(), StatusCode::kPermissionDenied);
  EXPECT_THAT(s.message(), HasSubstr("cannot write into the directory"));
}

TEST(SeenVoxelLineTest, ThreeDecimalsInTheInputsFrame) {
  EXPECT_EQ(SeenVoxelLine({0.05, -0.15, 1.25}, WorldPoint::Zero()), "0.050 -0.150 1.250");
  // Survey coordinates: the local centre plus the frame's origin, to the millimetre.
  EXPECT_EQ(SeenVoxelLine({-412.35, 37.05, 2.15}, {512000, 5612000, 100}), "511587.650 5612037.050 102.150");
  EXPECT_EQ(SeenVoxelLine({-0.0004, 0.0006, 0.0016}, WorldPoint::Zero()), "0.000 0.001 0.002");
}

TEST(WriteSeenSetsTest, OneFilePerViewpointWithItsVoxelCentresInIdOrder) {
  EvaluateJobResult r;
  r.voxel_centers = {{0.05, 0.05, 0.05}, {0.15, 0.05, 0.05}, {0.25, 0.05, 0.05}};
  r.frame_origin_m = {1000, 2000, 0};
  r.seen_sets.assign(2, VoxelSet(3));
  r.seen_sets[0].set(2);
  r.seen_sets[0].set(0);
  const std::string dir = vc::testing::MakeTempDir();
  const Result<std::vector<std::string>> files = WriteSeenSets(r, dir);
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  ASSERT_EQ(files->size(), 2u);
  EXPECT_EQ((*files)[0], dir + "/station_1.xyz");
  EXPECT_EQ(vc::testing::ReadFileBytes(dir + "/station_1.xyz"), "1000.050 2000.050 0.050\n1000.250 2000.050 0.050\n");
  EXPECT_TRUE(fs::exists(dir + "/station_2.xyz"));
  EXPECT_EQ(vc::testing::ReadFileBytes(dir + "/station_2.xyz"), "");  // sees nothing
}

TEST(WriteSeenSetsTest, AResultWithoutSetsIsRefused) {
  EXPECT_EQ(WriteSeenSets(EvaluateJobResult(), vc::testing::MakeTempDir()).status().code(),
            StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace vc::client
