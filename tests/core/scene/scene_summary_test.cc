// vc/scene/scene_summary.h: what Summarize reports for a cloud and for an octree (counts, bounding
// box, voxels at the working resolution), and the JSON and text forms of a summary.
#include "vc/scene/scene_summary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "testing/scenes.h"
#include "vc/scene/octomap_adapter.h"

namespace vc {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// Points at the centres of 0.1 m voxels: voxel (i, j, k) for i < 5, j < 3, k < 2, two points each.
SceneInput GridCloud() {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 2; ++k) {
        points.emplace_back(0.1f * i + 0.05f, 0.1f * j + 0.05f, 0.1f * k + 0.05f);
        points.emplace_back(0.1f * i + 0.04f, 0.1f * j + 0.06f, 0.1f * k + 0.05f);
      }
  SceneInput in = testing::Cloud(std::move(points));
  in.format = InputFormat::kPly;
  in.compression = Compression::kGzip;
  in.detail = "ascii 1.0";
  in.dropped_nonfinite = 2;
  return in;
}

TEST(SummarizeTest, ACloudsCountsBoundingBoxAndVoxels) {
  const SceneInput in = GridCloud();
  Result<SceneSummary> s = Summarize(in, 0, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->format, "ply");
  EXPECT_EQ(s->compression, "gzip");
  EXPECT_EQ(s->detail, "ascii 1.0");
  EXPECT_EQ(s->points, 60u);
  EXPECT_EQ(s->dropped_nonfinite, 2u);
  EXPECT_EQ(s->octree_leaves, 0u);
  EXPECT_EQ(s->resolution_m, kDefaultResolutionM);
  EXPECT_EQ(s->occupied_voxels, 5u * 3u * 2u);
  EXPECT_FLOAT_EQ(float(s->bbox_min.x()), 0.04f);
  EXPECT_FLOAT_EQ(float(s->bbox_min.y()), 0.05f);
  EXPECT_FLOAT_EQ(float(s->bbox_max.x()), 0.45f);
  EXPECT_FLOAT_EQ(float(s->bbox_max.y()), 0.26f);
  EXPECT_FLOAT_EQ(float(s->bbox_max.z()), 0.15f);
  // At 0.2 m, pairs of 0.1 m voxels share one: ceil(5/2) * ceil(3/2) * 1.
  s = Summarize(in, 0.2, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->resolution_m, 0.2);
  EXPECT_EQ(s->occupied_voxels, 3u * 2u * 1u);
}

TEST(SummarizeTest, AnOctreesLeavesResolutionAndBoundingBox) {
  SceneInput in;
  in.format = InputFormat::kOctomapBinary;
  // Eight keys of one aligned 2x2x2 block (pruned into one leaf) and one voxel on its own.
  std::vector<VoxelKey> keys;
  for (int d = 0; d < 8; ++d)
    keys.push_back({uint16_t(32768 + (d & 1)), uint16_t(32768 + (d >> 1 & 1)), uint16_t(32768 + (d >> 2))});
  keys.push_back({32768 + 10, 32768, 32768});
  in.octree = BuildOctree(0.2, keys);
  Result<SceneSummary> s = Summarize(in, 0, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->format, "octomap-bt");
  EXPECT_EQ(s->octree_leaves, 2u);
  EXPECT_EQ(s->octree_resolution_m, 0.2);
  EXPECT_EQ(s->resolution_m, 0.2);
  EXPECT_EQ(s->occupied_voxels, 9u);
  EXPECT_EQ(s->points, 0u);
  EXPECT_NEAR(s->bbox_min.x(), 0.0, 1e-9);
  EXPECT_NEAR(s->bbox_max.x(), 11 * 0.2, 1e-9);
  EXPECT_NEAR(s->bbox_max.z(), 2 * 0.2, 1e-9);
}

TEST(SummarizeTest, AVoxelCountOverTheBudgetIsResourceExhausted) {
  const Result<SceneSummary> s = Summarize(GridCloud(), 0.001, 64);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), StatusCode::kResourceExhausted) << s.status().ToString();
}

E57Scan Scan() {
  E57Scan e;
  e.name = "north";
  e.guid = "{1234}";
  e.point_count = 4242;
  e.translation_m = {1, 2, 3};
  e.rotation = Eigen::Quaterniond(0, 0, 0, 1);
  return e;
}

TEST(SummaryToJsonTest, EveryKeyWithItsValueAndE57ScansOnlyWhenThereAreAny) {
  SceneSummary s = *Summarize(GridCloud(), 0, kDefaultMemoryBudgetBytes);
  nlohmann::json j = nlohmann::json::parse(SummaryToJson(s));
  for (const char* key : {"format", "compression", "detail", "points", "dropped_nonfinite", "scans", "octree_leaves",
                          "octree_resolution_m", "bbox_min", "bbox_max", "resolution_m", "occupied_voxels"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["format"], "ply");
  EXPECT_EQ(j["points"], 60);
  EXPECT_EQ(j["occupied_voxels"], 30);
  EXPECT_EQ(j["bbox_max"].size(), 3u);
  EXPECT_EQ(j["bbox_max"][2].get<double>(), s.bbox_max.z());
  EXPECT_FALSE(j.contains("e57_scans"));

  s.e57_scans = {Scan()};
  j = nlohmann::json::parse(SummaryToJson(s));
  ASSERT_EQ(j["e57_scans"].size(), 1u);
  const nlohmann::json& scan = j["e57_scans"][0];
  EXPECT_EQ(scan["name"], "north");
  EXPECT_EQ(scan["guid"], "{1234}");
  EXPECT_EQ(scan["points"], 4242);
  EXPECT_EQ(scan["translation_m"], nlohmann::json({1.0, 2.0, 3.0}));
  EXPECT_EQ(scan["rotation_wxyz"], nlohmann::json({0.0, 0.0, 0.0, 1.0}));
}

TEST(SummarizeTest, ASurveySceneShowsItsFrameOriginAndItsBoundsInTheInputFrame) {
  SceneInput survey = testing::Cloud({{345.5f, 330.25f, 12}, {346.5f, 331.25f, 13}});
  survey.frame_origin_m = {512000, 5612000, 0};
  Result<SceneSummary> s = Summarize(survey, 0, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->frame_origin_m, WorldPoint(512000, 5612000, 0));
  EXPECT_EQ(s->bbox_min, WorldPoint(512345.5, 5612330.25, 12));
  EXPECT_EQ(s->bbox_max, WorldPoint(512346.5, 5612331.25, 13));
  const std::string text = SummaryToText(*s, "utm.xyz");
  EXPECT_THAT(text, HasSubstr("frame origin:      (512000.000, 5612000.000, 0.000) m"));
  EXPECT_THAT(text, HasSubstr("bounding box:      [512345.500, 5612330.250, 12.000] .. [512346.500, 5612331.250, "
                              "13.000] m\n"));
  EXPECT_THAT(text, HasSubstr("extent:            1.000 x 1.000 x 1.000 m\n"));
  const nlohmann::json j = nlohmann::json::parse(SummaryToJson(*s));
  EXPECT_EQ(j["frame_origin_m"], nlohmann::json({512000.0, 5612000.0, 0.0}));

  survey.frame_origin_m.setZero();
  s = Summarize(survey, 0, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(s.ok());
  EXPECT_THAT(SummaryToText(*s, "local.xyz"), Not(HasSubstr("frame origin")));
  EXPECT_EQ(nlohmann::json::parse(SummaryToJson(*s))["frame_origin_m"], nlohmann::json({0.0, 0.0, 0.0}));
}

TEST(SummaryToTextTest, ACloudsLinesAndAnOctreesLines) {
  SceneSummary s = *Summarize(GridCloud(), 0, kDefaultMemoryBudgetBytes);
  s.e57_scans = {Scan()};
  std::string text = SummaryToText(s, "room.ply.gz");
  EXPECT_THAT(text, HasSubstr("room.ply.gz\n"));
  EXPECT_THAT(text, HasSubstr("format:            ply (ascii 1.0), gzip-compressed\n"));
  EXPECT_THAT(text, HasSubstr("points:            60\n"));
  EXPECT_THAT(text, HasSubstr("dropped (NaN/inf): 2\n"));
  EXPECT_THAT(text, HasSubstr("0 \"north\": 4242 points, at (1.000, 2.000, 3.000) m, rotation (w, x, y, z) (0.0000, "
                              "0.0000, 0.0000, 1.0000)\n"));
  EXPECT_THAT(text, HasSubstr("occupied voxels:   30 at 0.100 m\n"));
  EXPECT_THAT(text, Not(HasSubstr("octree:")));

  s.octree_leaves = 7;
  s.octree_resolution_m = 0.05;
  s.compression = "none";
  text = SummaryToText(s, "tree.bt");
  EXPECT_THAT(text, HasSubstr("octree:            7 occupied leaves at 0.050 m\n"));
  EXPECT_THAT(text, Not(HasSubstr("points:")));
  EXPECT_THAT(text, Not(HasSubstr("-compressed")));
}

}  // namespace
}  // namespace vc
