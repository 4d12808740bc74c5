#include "vc/visibility/validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "vc/synth/scanner_sim.h"

namespace vc {
namespace {

// A scan of `scene` from `position_m` with a 0.25 deg step all round (noise-free, no dropout).
CapturedScan Scan(const AnalyticScene& scene, const WorldPoint& position_m, const std::string& name) {
  SimulatedScanner scanner;
  scanner.position_m = position_m;
  scanner.horizontal_step_deg = 0.25;
  scanner.vertical_step_deg = 0.25;
  auto scan = SimulateScan(scene, scanner);
  EXPECT_TRUE(scan.ok()) << scan.status().ToString();
  return {name, position_m, scan.ok() ? scan->points_m : std::vector<Eigen::Vector3f>{}};
}

// Wall A (6 x 6 m, x = 2) hides wall B (4 x 4 m, x = 4) from the origin; from (6, 0, 0) B hides A.
AnalyticScene TwoWalls() {
  const Eigen::Vector3d y(0, 1, 0), z(0, 0, 1);
  return {{Rectangle({2, 0, 0}, 3 * y, 3 * z), Rectangle({4, 0, 0}, 2 * y, 2 * z)}};
}

TEST(ValidateAgainstScansTest, PlaneSeenHeadOnIsPredicted) {
  auto scene = TiltedPlaneScene(0.0);
  ASSERT_TRUE(scene.ok());
  auto report = ValidateAgainstScans({Scan(*scene, {0, 0, 0}, "plane")}, {});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->scans.size(), 1u);
  const ScanAgreement& a = report->scans[0];
  EXPECT_GT(a.captured, 1000u);
  // Measured: 1.000 (0.1 m voxels, a 4 x 4 m plane at 3 m, its points all in one voxel layer).
  EXPECT_GE(a.recall, 0.99);
  EXPECT_GE(a.recall_slack, a.recall);
  EXPECT_EQ(a.both, a.predicted);  // single scan: every model voxel is captured
}

TEST(ValidateAgainstScansTest, VoxelBehindAWallIsNeverPredicted) {
  const AnalyticScene scene = TwoWalls();
  ValidationOptions options;
  options.keep_sets = true;
  auto report = ValidateAgainstScans({Scan(scene, {0, 0, 0}, "front"), Scan(scene, {6, 0, 0}, "back")}, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->scans.size(), 2u);
  const ScanAgreement& front = report->scans[0];
  const ScanAgreement& back = report->scans[1];
  ASSERT_GT(back.captured, 1000u);
  EXPECT_FALSE(front.captured_set.Intersects(back.captured_set));  // the simulator agrees B is hidden
  EXPECT_FALSE(front.predicted_set.Intersects(back.captured_set));
  EXPECT_FALSE(back.predicted_set.Intersects(front.captured_set));
  EXPECT_GT(front.predicted, 0u);
  EXPECT_TRUE(report->precision_meaningful);
  EXPECT_TRUE(report->note.empty());
  EXPECT_EQ(report->model_voxels, report->model.occupied.size());
  EXPECT_EQ(front.captured + back.captured, report->model_voxels);
}

TEST(ValidateAgainstScansTest, SlackNeverLowersRecallOrPrecision) {
  const AnalyticScene scene = RoomWithClutterScene();
  const std::vector<CapturedScan> scans = {Scan(scene, kRoomWithClutterStationM, "a"),
                                           Scan(scene, {6.5, 3.0, 1.2}, "b")};
  for (const SelectionTest test : {SelectionTest::kSurfaceVisibility, SelectionTest::kCompatibility}) {
    ValidationOptions options;
    options.selection_test = test;
    auto report = ValidateAgainstScans(scans, options);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    for (const ScanAgreement& a : report->scans) {
      SCOPED_TRACE(std::string(SelectionTestName(test)) + " " + a.name);
      EXPECT_GT(a.captured, 0u);
      EXPECT_GT(a.predicted, 0u);
      EXPECT_LE(a.both, std::min(a.captured, a.predicted));
      EXPECT_GE(a.captured_near_predicted, a.both);
      EXPECT_GE(a.predicted_near_captured, a.both);
      EXPECT_GE(a.recall_slack, a.recall);
      EXPECT_GE(a.precision_slack, a.precision);
      EXPECT_FALSE(a.position_occupied);
    }
  }
}

// Counting faces too (ValidationOptions::count_faces) only adds voxels: the test's set is kept, the
// voxels of fully visible faces are a subset of those of faces at least partially visible, and
// nothing hidden behind a wall is added. On the noisy tilted plane (two voxel layers) the partial
// faces recover the surface test's misses (measured: recall 0.52 -> 1.00 at 30 deg, 1 cm noise).
TEST(ValidateAgainstScansTest, CountingFacesOnlyAddsVoxelsAndNotHiddenOnes) {
  const AnalyticScene walls = TwoWalls();
  const std::vector<CapturedScan> scans = {Scan(walls, {0, 0, 0}, "front"), Scan(walls, {6, 0, 0}, "back")};
  std::vector<ValidationReport> reports;
  for (const auto rule : {ValidationOptions::FaceRule::kNone, ValidationOptions::FaceRule::kFull,
                          ValidationOptions::FaceRule::kPartial}) {
    ValidationOptions options;
    options.keep_sets = true;
    options.count_faces = rule;
    auto report = ValidateAgainstScans(scans, options);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    reports.push_back(std::move(*report));
  }
  for (size_t i = 0; i < 2; ++i) {
    const VoxelSet& none = reports[0].scans[i].predicted_set;
    const VoxelSet& full = reports[1].scans[i].predicted_set;
    const VoxelSet& partial = reports[2].scans[i].predicted_set;
    EXPECT_TRUE(full.Contains(none));
    EXPECT_TRUE(partial.Contains(full));
    EXPECT_FALSE(partial.Intersects(reports[2].scans[1 - i].captured_set));  // the other wall stays hidden
  }

  auto plane = TiltedPlaneScene(30.0, 3.05);
  ASSERT_TRUE(plane.ok());
  SimulatedScanner scanner;
  scanner.hfov_deg = 100.0;
  scanner.vfov_min_deg = -45.0;
  scanner.vfov_max_deg = 45.0;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.25;
  scanner.range_noise_sigma_m = 0.01;
  auto scan = SimulateScan(*plane, scanner);
  ASSERT_TRUE(scan.ok());
  const std::vector<CapturedScan> noisy = {{"plane", {0, 0, 0}, scan->points_m}};
  ValidationOptions options;
  auto plain = ValidateAgainstScans(noisy, options);
  options.count_faces = ValidationOptions::FaceRule::kPartial;
  auto with_partial = ValidateAgainstScans(noisy, options);
  ASSERT_TRUE(plain.ok() && with_partial.ok());
  EXPECT_LT(plain->scans[0].recall, 0.7);
  EXPECT_GE(with_partial->scans[0].recall, 0.99);
}

// Two scans of the cluttered room that each cover 150 deg of azimuth: predicted all round, each
// scan's position is credited with the half of the room it never scanned; with hfov_deg 150 and
// each scan's heading the prediction keeps to its sector, so precision rises and recall stays.
TEST(ValidateAgainstScansTest, AHeadingKeepsThePredictionToTheScansSector) {
  const AnalyticScene scene = RoomWithClutterScene();
  std::vector<CapturedScan> scans;
  const std::pair<WorldPoint, double> stations[] = {{kRoomWithClutterStationM, 20.0}, {{6.5, 3.0, 1.2}, -160.0}};
  for (const auto& [position, heading_deg] : stations) {
    SimulatedScanner scanner;
    scanner.position_m = position;
    scanner.heading_rad = heading_deg * std::numbers::pi / 180;
    scanner.hfov_deg = 150;
    scanner.horizontal_step_deg = scanner.vertical_step_deg = 0.25;
    auto scan = SimulateScan(scene, scanner);
    ASSERT_TRUE(scan.ok()) << scan.status().ToString();
    scans.push_back({std::to_string(scans.size() + 1), position, scan->points_m, heading_deg});
  }
  auto all_round = ValidateAgainstScans(scans, {});
  ValidationOptions options;
  options.scanner.hfov_deg = 150;
  auto sector = ValidateAgainstScans(scans, options);
  ASSERT_TRUE(all_round.ok() && sector.ok()) << sector.status().ToString();
  for (size_t i = 0; i < scans.size(); ++i) {
    SCOPED_TRACE(i);
    const ScanAgreement& a = all_round->scans[i];
    const ScanAgreement& b = sector->scans[i];
    EXPECT_LT(b.predicted, a.predicted);
    EXPECT_GT(b.precision, a.precision + 0.1);
    EXPECT_GE(b.recall, a.recall - 0.01);
  }
  // Without a heading the sector has no centre: refused, naming the scan.
  scans[1].heading_deg.reset();
  auto refused = ValidateAgainstScans(scans, options);
  ASSERT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(refused.status().message().find("scan 2 (\"2\") has no heading"), std::string::npos)
      << refused.status().ToString();
  scans[1].heading_deg = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ValidateAgainstScans(scans, options).status().code(), StatusCode::kInvalidArgument);
}

TEST(ValidateAgainstScansTest, SingleScanSaysOnlyRecallIsMeaningful) {
  auto report = ValidateAgainstScans({Scan(TwoWalls(), {0, 0, 0}, "only")}, {});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_FALSE(report->precision_meaningful);
  EXPECT_NE(report->note.find("only recall"), std::string::npos) << report->note;
  EXPECT_EQ(report->scans[0].captured, report->model_voxels);
  EXPECT_TRUE(report->model.occupied.empty());  // keep_sets off
}

TEST(ValidateAgainstScansTest, ScanWithNoPointsIsRefusedByName) {
  const AnalyticScene scene = TwoWalls();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const auto& points : {std::vector<Eigen::Vector3f>{}, std::vector<Eigen::Vector3f>{{nan, 0, 0}}}) {
    auto report = ValidateAgainstScans({Scan(scene, {0, 0, 0}, "front"), {"empty.xyz", {6, 0, 0}, points}}, {});
    ASSERT_FALSE(report.ok());
    EXPECT_EQ(report.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(report.status().message().find("scan 2 (\"empty.xyz\")"), std::string::npos)
        << report.status().ToString();
  }
}

TEST(ValidateAgainstScansTest, NonFinitePositionIsRefusedByName) {
  CapturedScan scan = Scan(TwoWalls(), {0, 0, 0}, "station-7");
  scan.position_m.y() = std::numeric_limits<double>::quiet_NaN();
  auto report = ValidateAgainstScans({scan}, {});
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(report.status().message().find("station-7"), std::string::npos) << report.status().ToString();
}

TEST(ValidateAgainstScansTest, PositionBeyondRangeOfTheModelIsRefusedByName) {
  CapturedScan scan = Scan(TwoWalls(), {0, 0, 0}, "far");
  ValidationOptions options;
  options.scanner.max_range_m = 20.0;
  scan.position_m = {4.0, 0.0, 2.0 + 19.0};  // 19 m above the top of the walls: in range
  EXPECT_TRUE(ValidateAgainstScans({scan}, options).ok());
  scan.position_m = {4.0, 0.0, 2.0 + 21.0};  // 21 m above: beyond it
  auto report = ValidateAgainstScans({scan}, options);
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(report.status().message().find("scan 1 (\"far\")"), std::string::npos) << report.status().ToString();
}

TEST(ValidateAgainstScansTest, PointOutsideTheKeyRangeIsRefusedByName) {
  CapturedScan scan = Scan(TwoWalls(), {0, 0, 0}, "wild");
  scan.points_m.push_back({1e6f, 0, 0});  // beyond OctoMap's 16-bit keys at 0.1 m (+-3276.8 m)
  auto report = ValidateAgainstScans({scan}, {});
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(report.status().message().find("scan 1 (\"wild\")"), std::string::npos) << report.status().ToString();
}

TEST(ValidateAgainstScansTest, PositionInAnOccupiedVoxelIsReportedAndPredictsNothing) {
  CapturedScan scan = Scan(TwoWalls(), {0, 0, 0}, "in-wall");
  scan.position_m = {2.0, 0.05, 0.05};  // on wall A
  auto report = ValidateAgainstScans({scan}, {});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_TRUE(report->scans[0].position_occupied);
  EXPECT_EQ(report->scans[0].predicted, 0u);
  EXPECT_EQ(report->scans[0].recall, 0.0);
  EXPECT_EQ(report->scans[0].precision, 0.0);  // 0 / 0 is reported as 0
}

TEST(ValidateAgainstScansTest, NoScansOrBadOptionsAreRefused) {
  EXPECT_EQ(ValidateAgainstScans({}, {}).status().code(), StatusCode::kInvalidArgument);
  const CapturedScan scan = Scan(TwoWalls(), {0, 0, 0}, "s");
  ValidationOptions options;
  options.resolution_m = 0.0;
  EXPECT_EQ(ValidateAgainstScans({scan}, options).status().code(), StatusCode::kInvalidArgument);
  options = {};
  options.scanner.min_range_m = 100.0;
  EXPECT_EQ(ValidateAgainstScans({scan}, options).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace vc
