// RunCandidatesStage's checks of fixed stations against the scene: outside the scene's bounds and
// inside an occupied voxel are INVALID_ARGUMENT naming the station and the bounds; a station with no
// floor straight below gets a warning saying how far the floor is.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "testing/scenes.h"
#include "vc/plan/stages.h"

namespace vc::planner {
namespace {

using ::testing::HasSubstr;

constexpr double kR = 0.1;

// A 5 x 4 m closed room at kR, moved by (-20, -17, 0) voxels (x -2..3 m, y -1.7..2.3 m), with a hole
// in the floor around (-0.75, -0.45) and a pit around (1.25, -0.45) whose floor lies 5 m lower.
VoxelScene RoomWithAHoleAndAPit() {
  testing::VoxelBuilder b;
  b.Box(0, 0, 0, 49, 39, 0);
  b.Box(0, 0, 0, 0, 39, 25);
  b.Box(49, 0, 0, 49, 39, 25);
  b.Box(0, 0, 0, 49, 0, 25);
  b.Box(0, 39, 0, 49, 39, 25);
  b.Box(0, 0, 25, 49, 39, 25);
  b.Erase(10, 10, 0, 14, 14, 0);
  b.Erase(30, 10, 0, 34, 14, 0);
  b.Box(30, 10, -50, 34, 14, -50);
  return b.Build(kR, {-20, -17, 0});
}

Result<CandidatesOutput> Candidates(const VoxelScene& scene, const std::vector<WorldPoint>& fixed) {
  PlanOptions options;
  options.resolution_m = kR;
  options.fixed_stations = fixed;
  return RunCandidatesStage({scene}, options, {});
}

bool HasWarning(const CandidatesOutput& out, const std::string& text) {
  return std::any_of(out.warnings.begin(), out.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// The grid's options carry every candidate row of the plan's options (refinement and local
// candidates start from them, so a row missing here would be missing there too).
TEST(CandidatesStageTest, CandidateOptionsForCarriesEveryCandidateRow) {
  PlanOptions plan;
  plan.grid_spacing_m = 0.7;
  plan.tripod_height_m = 1.3;
  plan.clearance_m = 0.35;
  plan.tripod_heights_m = {1.2, 1.8};
  plan.doorway_candidates = false;
  plan.ground = GroundModel::kTerrain;
  plan.walk_max_step_m = 0.4;
  const CandidateOptions o = CandidateOptionsFor(plan);
  EXPECT_EQ(o.grid_spacing_m, 0.7);
  EXPECT_EQ(o.tripod_height_m, 1.3);
  EXPECT_EQ(o.clearance_m, 0.35);
  EXPECT_EQ(o.tripod_heights_m, (std::vector<double>{1.2, 1.8}));
  EXPECT_FALSE(o.doorway_candidates);
  EXPECT_EQ(o.ground, GroundModel::kTerrain);
  EXPECT_EQ(o.walk_max_step_m, 0.4);
  plan.doorway_candidates = true;
  EXPECT_TRUE(CandidateOptionsFor(plan).doorway_candidates);
}

TEST(CandidatesStageTest, AFixedStationOverTheFloorPassesWithoutWarning) {
  const VoxelScene scene = RoomWithAHoleAndAPit();
  Result<CandidatesOutput> free = Candidates(scene, {});
  ASSERT_TRUE(free.ok()) << free.status().ToString();
  Result<CandidatesOutput> r = Candidates(scene, {WorldPoint(2.05, 0.35, 1.6)});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->warnings, free->warnings);
  EXPECT_EQ(r->positions, free->positions);
}

TEST(CandidatesStageTest, AFixedStationOutsideTheBoundsIsRefusedNamingThem) {
  const VoxelScene scene = RoomWithAHoleAndAPit();
  Result<CandidatesOutput> r = Candidates(scene, {WorldPoint(2.05, 0.35, 1.6), WorldPoint(102.05, 0.35, 1.6)});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("fixed_stations[1] (station 2 of the file"));
  EXPECT_THAT(r.status().message(), HasSubstr("outside the scene's bounds (x -2"));
  EXPECT_THAT(r.status().message(), HasSubstr("widened by 2 m"));
  // Below the pit's floor too.
  r = Candidates(scene, {WorldPoint(2.05, 0.35, -7.5)});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("fixed_stations[0]"));
}

TEST(CandidatesStageTest, MessagesNameAGeoreferencedScenesPositionsInTheInputsFrame) {
  VoxelScene scene = RoomWithAHoleAndAPit();
  scene.frame_origin_m = WorldPoint(512000, 5612000, 0);
  Result<CandidatesOutput> r = Candidates(scene, {WorldPoint(102.05, 0.35, 1.6)});  // local, as the stages see it
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("at 512102.050, 5612000.350, 1.6)"));
  EXPECT_THAT(r.status().message(), HasSubstr("(x 511998.000.."));
  r = Candidates(scene, {WorldPoint(-1.95, 0.35, 1.0)});
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.status().message(), HasSubstr("511998.050, 5612000.350, 1"));
}

TEST(CandidatesStageTest, AFixedStationInsideAWallIsRefused) {
  Result<CandidatesOutput> r = Candidates(RoomWithAHoleAndAPit(), {WorldPoint(-1.95, 0.35, 1.0)});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("fixed_stations[0]"));
  EXPECT_THAT(r.status().message(), HasSubstr("lies inside an occupied voxel (x -2"));  // the voxel's bounds
  EXPECT_THAT(r.status().message(), HasSubstr("z 1"));
}

TEST(CandidatesStageTest, AFixedStationWithoutAFloorBelowIsWarnedAboutWithTheDistance) {
  const VoxelScene scene = RoomWithAHoleAndAPit();
  // Over the hole; over the pit (its floor's top at z = -4.9 m); outside the walls within the
  // 2 m margin (nothing below).
  Result<CandidatesOutput> r =
      Candidates(scene, {WorldPoint(-0.75, -0.45, 1.6), WorldPoint(1.25, -0.45, 1.6), WorldPoint(4.5, 0.35, 1.6)});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(HasWarning(*r, "fixed_stations[0] (station 1 of the file, at -0.75, -0.45, 1.6) has no floor below it"))
      << ::testing::PrintToString(r->warnings);
  EXPECT_TRUE(HasWarning(*r, "down to the scene's bottom at z = -5")) << ::testing::PrintToString(r->warnings);
  EXPECT_TRUE(HasWarning(*r, "6.6 m below it")) << ::testing::PrintToString(r->warnings);
  EXPECT_TRUE(HasWarning(*r, "fixed_stations[1]")) << ::testing::PrintToString(r->warnings);
  EXPECT_TRUE(HasWarning(*r, "straight below is 6.5 m down")) << ::testing::PrintToString(r->warnings);
  EXPECT_TRUE(HasWarning(*r, "fixed_stations[2]")) << ::testing::PrintToString(r->warnings);
}

}  // namespace
}  // namespace vc::planner
