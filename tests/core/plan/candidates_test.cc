// Candidate generation on hand-built voxel scenes: floor levels, roofs, desks, holes, clearance.
#include "vc/plan/candidates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "testing/scenes.h"
#include "vc/synth/synth.h"

namespace vc::planner {
namespace {

constexpr double kR = 0.1;

struct Builder : testing::VoxelBuilder {
  // A 5 x 4 m room: floor slab at z index 0, walls up to `top`, and a ceiling at `top` if asked.
  void Room(int top, bool ceiling) {
    Box(0, 0, 0, 49, 39, 0);
    Box(0, 0, 0, 0, 39, top);
    Box(49, 0, 0, 49, 39, top);
    Box(0, 0, 0, 49, 0, top);
    Box(0, 39, 0, 49, 39, top);
    if (ceiling) Box(0, 0, top, 49, 39, top);
  }
  // At kR, moved by (-20, -17, shift_z) voxels.
  VoxelScene Build(int shift_z = 0) const { return VoxelBuilder::Build(kR, {-20, -17, shift_z}); }
};

CandidateGrid Generate(const VoxelScene& s, CandidateOptions o = {}) {
  Result<CandidateGrid> r = GenerateCandidates(s, o);
  EXPECT_TRUE(r.ok()) << r.status().ToString();
  return r.ok() ? *r : CandidateGrid{};
}

TEST(CandidatesTest, ClosedRoomHasOneLevelAndCandidatesAtTripodHeight) {
  Builder b;
  b.Room(25, true);
  const CandidateGrid c = Generate(b.Build());
  ASSERT_EQ(c.levels.size(), 1u);  // the ceiling's outside is a roof
  EXPECT_NEAR(c.levels[0].z_m, 0.1, 1e-9);
  ASSERT_EQ(c.positions.size(), 20u);  // 5 x 4 cells of 1 m, all 0.4 m from the walls
  for (size_t i = 0; i < c.positions.size(); ++i) {
    EXPECT_NEAR(c.positions[i].z(), 1.6, 1e-9);
    EXPECT_NEAR(c.floor_z_m[i], 0.1, 1e-9);
    EXPECT_GT(c.positions[i].x(), -1.9);
    EXPECT_LT(c.positions[i].x(), 2.9);
    EXPECT_GT(c.positions[i].y(), -1.6);
    EXPECT_LT(c.positions[i].y(), 2.2);
  }
  EXPECT_EQ(c.rejected_no_floor + c.rejected_clearance + c.positions.size(), c.cells);
}

TEST(CandidatesTest, SeveralHeightsGiveACandidatePerHeightWhereItFitsUnderWhatIsAbove) {
  Builder b;
  b.Room(25, true);             // ceiling at 2.5 m: 2.4 m free above the floor's top at 0.1 m
  b.Box(0, 0, 20, 20, 39, 20);  // a soffit at 2.0-2.1 m over x -2.0 .. 0.1 m: 1.9 m free below it
  CandidateOptions o;
  o.tripod_heights_m = {1.2, 1.6, 2.0};
  const CandidateGrid c = Generate(b.Build(), o);
  ASSERT_EQ(c.levels.size(), 1u);
  // 20 cells x 3 heights, but 2.0 m + 0.2 m clearance does not fit under the soffit (8 cells).
  EXPECT_EQ(c.cells, 60u);
  EXPECT_EQ(c.positions.size(), 52u);
  EXPECT_EQ(c.rejected_clearance, 8u);
  ASSERT_EQ(c.height_m.size(), c.positions.size());
  std::map<double, int> per_height;
  for (size_t i = 0; i < c.positions.size(); ++i) {
    EXPECT_NEAR(c.positions[i].z() - c.floor_z_m[i], c.height_m[i], 1e-9);
    ++per_height[c.height_m[i]];
    if (c.height_m[i] == 2.0) {
      EXPECT_GT(c.positions[i].x(), 0.1) << "2.0 m under the soffit";
    }
  }
  EXPECT_EQ(per_height[1.2], 20);
  EXPECT_EQ(per_height[1.6], 20);
  EXPECT_EQ(per_height[2.0], 12);
  // A cell's heights are adjacent, in the order given.
  EXPECT_EQ(c.height_m[0], 1.2);
  EXPECT_EQ(c.height_m[1], 1.6);
  EXPECT_EQ(c.positions[0].x(), c.positions[1].x());
}

TEST(CandidatesTest, FloorBelowZeroWorksToo) {
  Builder b;
  b.Room(25, true);
  const CandidateGrid c = Generate(b.Build(/*shift_z=*/-4));  // floor top at -0.3 m
  ASSERT_EQ(c.levels.size(), 1u);
  EXPECT_NEAR(c.levels[0].z_m, -0.3, 1e-9);
  ASSERT_EQ(c.positions.size(), 20u);
  EXPECT_NEAR(c.positions[0].z(), 1.2, 1e-9);
}

TEST(CandidatesTest, OpenRoomKeepsItsFloorButNotTheWallTops) {
  Builder b;
  b.Room(25, false);
  const CandidateGrid c = Generate(b.Build());
  ASSERT_EQ(c.levels.size(), 1u);
  EXPECT_NEAR(c.levels[0].z_m, 0.1, 1e-9);
  EXPECT_EQ(c.positions.size(), 20u);
}

TEST(CandidatesTest, LargerClearanceDropsCellsNearWalls) {
  Builder b;
  b.Room(25, true);
  CandidateOptions o;
  o.clearance_m = 0.45;  // cells 0.4 m from a wall fail
  const CandidateGrid c = Generate(b.Build(), o);
  EXPECT_EQ(c.positions.size(), 6u);
  EXPECT_EQ(c.rejected_clearance, 14u);
  o.clearance_m = 1.2;  // wider than half the room: nothing survives
  EXPECT_TRUE(Generate(b.Build(), o).positions.empty());
}

TEST(CandidatesTest, TwoStoreysGetCandidatesOnBothFloors) {
  Builder b;
  b.Room(55, true);
  b.Box(0, 0, 27, 49, 39, 28);  // slab: ceiling below, floor above (top at 2.9 m)
  const CandidateGrid c = Generate(b.Build());
  ASSERT_EQ(c.levels.size(), 2u);
  EXPECT_NEAR(c.levels[0].z_m, 0.1, 1e-9);
  EXPECT_NEAR(c.levels[1].z_m, 2.9, 1e-9);
  int lower = 0, upper = 0;
  for (const WorldPoint& p : c.positions) {
    if (std::fabs(p.z() - 1.6) < 1e-9) ++lower;
    if (std::fabs(p.z() - 4.4) < 1e-9) ++upper;
  }
  EXPECT_EQ(lower, 20);
  EXPECT_EQ(upper, 20);
  EXPECT_EQ(c.positions.size(), 40u);
}

TEST(CandidatesTest, NoStationOnOrUnderALowDesk) {
  Builder b;
  b.Room(25, true);
  b.Box(10, 10, 4, 25, 20, 4);  // a desk top at 0.4-0.5 m over x 1.0-2.6 m, y 1.0-2.1 m
  const CandidateGrid c = Generate(b.Build());
  ASSERT_EQ(c.levels.size(), 1u);
  EXPECT_NEAR(c.levels[0].z_m, 0.1, 1e-9);
  for (const WorldPoint& p : c.positions) {
    EXPECT_NEAR(p.z(), 1.6, 1e-9);
    EXPECT_FALSE(std::fabs(p.x() - -0.5) < 1e-9 && std::fabs(p.y() - -0.2) < 1e-9) << "candidate above the desk";
  }
  EXPECT_EQ(c.positions.size(), 19u);
}

TEST(CandidatesTest, NoStationOverAHoleInTheFloor) {
  Builder b;
  b.Room(25, true);
  b.Erase(20, 10, 0, 29, 19, 0);  // a 1 x 1 m hole under the cell centred at (2.5, 1.5)
  const CandidateGrid c = Generate(b.Build());
  for (const WorldPoint& p : c.positions) {
    EXPECT_FALSE(std::fabs(p.x() - 0.5) < 1e-9 && std::fabs(p.y() - -0.2) < 1e-9) << "candidate over the hole";
  }
  EXPECT_EQ(c.positions.size(), 19u);
  EXPECT_EQ(c.rejected_no_floor, 1u);
}

TEST(CandidatesTest, HasClearanceMeasuresToTheNearestVoxelCube) {
  Builder b;
  b.Room(25, true);
  const VoxelScene s = b.Build();
  // Builder coordinates are shifted by (-2.0, -1.7) m: the west wall's cube ends at x = -1.9.
  EXPECT_FALSE(HasClearance(s.grid, WorldPoint(-1.75, 0.3, 1.6), 0.2));
  EXPECT_TRUE(HasClearance(s.grid, WorldPoint(-1.65, 0.3, 1.6), 0.2));
  EXPECT_FALSE(HasClearance(s.grid, WorldPoint(0.0, 0.3, 0.05), 0.0));  // inside the floor
  EXPECT_TRUE(HasClearance(s.grid, WorldPoint(0.0, 0.3, 0.15), 0.0));
  EXPECT_FALSE(HasClearance(s.grid, WorldPoint(0.0, 0.3, 0.15), 0.1));
}

TEST(CandidatesTest, FloorTopNearFindsTheLevelUnderAPoint) {
  Builder b;
  b.Room(55, true);
  b.Box(0, 0, 27, 49, 39, 28);
  b.Erase(20, 10, 0, 29, 19, 0);
  const VoxelScene s = b.Build();
  const CandidateOptions o;
  ASSERT_TRUE(FloorTopNear(s.grid, -1.0, -0.7, 0.1, o).has_value());
  EXPECT_NEAR(*FloorTopNear(s.grid, -1.0, -0.7, 0.1, o), 0.1, 1e-9);
  EXPECT_NEAR(*FloorTopNear(s.grid, -1.0, -0.7, 2.9, o), 2.9, 1e-9);
  EXPECT_FALSE(FloorTopNear(s.grid, 0.5, -0.2, 0.1, o).has_value());   // the hole
  EXPECT_FALSE(FloorTopNear(s.grid, -1.0, -0.7, 1.5, o).has_value());  // no floor near 1.5 m
}

// Doorway candidates. Kept passage candidates are appended after the grid's, which they leave
// unchanged.
CandidateGrid WithPassages(const VoxelScene& s) {
  const CandidateGrid off = Generate(s);
  CandidateOptions o;
  o.doorway_candidates = true;
  const CandidateGrid on = Generate(s, o);
  EXPECT_EQ(on.positions.size(), off.positions.size() + on.passage_candidates);
  for (size_t i = 0; i < off.positions.size() && i < on.positions.size(); ++i) {
    EXPECT_EQ(on.positions[i], off.positions[i]) << i;
  }
  EXPECT_EQ(off.passage_candidates, 0u);
  return on;
}

TEST(CandidatesTest, ADoorInAWallGetsCandidatesInTheDoorwayOnItsCentreLine) {
  Builder b;
  b.Room(25, true);
  b.Box(24, 1, 1, 26, 38, 24);     // a wall across the room at x 0.4-0.7 m
  b.Erase(24, 15, 1, 26, 23, 20);  // its door: y -0.2-0.7 m (0.9 m wide), 2 m high
  const CandidateGrid c = WithPassages(b.Build());
  EXPECT_GT(c.passage_candidates, 0u);
  bool in_doorway = false;
  for (size_t i = c.positions.size() - c.passage_candidates; i < c.positions.size(); ++i) {
    const WorldPoint& p = c.positions[i];
    EXPECT_NEAR(p.y(), 0.25, 1e-9) << "off the door's centre line: " << p.transpose();
    EXPECT_NEAR(p.x(), 0.55, 0.5 + 0.15 + 1e-9) << "too far from the door: " << p.transpose();
    EXPECT_NEAR(p.z(), 1.6, 1e-9);
    in_doorway = in_doorway || (p.x() > 0.4 && p.x() < 0.7);
  }
  EXPECT_TRUE(in_doorway);
}

TEST(CandidatesTest, AnOpenRoomGetsNoPassageCandidates) {
  Builder b;
  b.Room(25, true);
  EXPECT_EQ(WithPassages(b.Build()).passage_candidates, 0u);
}

TEST(CandidatesTest, APinchInA2mCorridorGetsCandidatesThereOnly) {
  testing::VoxelBuilder b;
  b.Box(0, 0, 0, 99, 21, 0);  // floor of a corridor 10 m long
  b.Box(0, 0, 0, 99, 0, 25);  // its walls: 2 m of free space between them (y 0.1-2.1 m)
  b.Box(0, 21, 0, 99, 21, 25);
  b.Box(0, 0, 0, 0, 21, 25);  // closed ends
  b.Box(99, 0, 0, 99, 21, 25);
  b.Box(0, 0, 25, 99, 21, 25);  // ceiling
  b.Box(45, 1, 1, 54, 4, 24);   // the pinch: 0.4 m from each wall over x 4.5-5.5 m, 1.2 m left
  b.Box(45, 17, 1, 54, 20, 24);
  const CandidateGrid c = WithPassages(b.Build(kR));
  EXPECT_GT(c.passage_candidates, 0u);
  for (size_t i = c.positions.size() - c.passage_candidates; i < c.positions.size(); ++i) {
    const WorldPoint& p = c.positions[i];
    EXPECT_NEAR(p.y(), 1.1, 1e-9) << p.transpose();              // the pinch's centre line
    EXPECT_NEAR(p.x(), 5.0, 0.5 + 0.5 + 1e-9) << p.transpose();  // within half a cell of it
  }
}

// hub:1 (docs/SCENES.md): the optimum's stations stand 0.125 m inside each room's door, on its
// centre line x = 2.5 (design). The grid's nearest are 0.375 m away; passage candidates are there.
TEST(CandidatesTest, HubDoorsGetCandidatesWhereTheOptimumStands) {
  Result<VoxelScene> scene = Voxelize(testing::Synthetic("hub:1"), VoxelizeOptions{0.1});
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const CandidateGrid c = WithPassages(*scene);
  const WorldPoint offset(0.0137, 0.0213, 0);  // kSceneOffsetM in x, y
  const std::vector<WorldPoint> optima = {WorldPoint(2.5, 4.875, 0) + offset, WorldPoint(2.5, -0.375, 0) + offset};
  for (const WorldPoint& optimum : optima) {
    double grid_d = 1e9, passage_d = 1e9;
    for (size_t i = 0; i < c.positions.size(); ++i) {
      const double d = (c.positions[i] - optimum).head<2>().norm();
      double& best = i + c.passage_candidates < c.positions.size() ? grid_d : passage_d;
      best = std::min(best, d);
    }
    EXPECT_GT(grid_d, 0.3) << optimum.transpose();
    EXPECT_LT(passage_d, 0.1) << optimum.transpose();
  }
}

// The synthetic scene `spec` at 0.1 m.
VoxelScene SyntheticAt10cm(const std::string& spec) {
  Result<VoxelScene> scene = Voxelize(testing::Synthetic(spec), VoxelizeOptions{0.1});
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return scene.ok() ? std::move(*scene) : VoxelScene{};
}

TEST(CandidatesTest, AutoPicksFloorsInBuildingsAndTerrainOnTheSlopingSite) {
  for (const char* spec : {"twofloor", "stairs", "hub:1", "tworooms"}) {
    const CandidateGrid c = Generate(SyntheticAt10cm(spec));
    EXPECT_EQ(c.ground.model, GroundModel::kFloors) << spec << ": " << c.ground.reason;
    EXPECT_GE(c.ground.floor_share, kFloorShare) << spec;
    EXPECT_FALSE(c.levels.empty()) << spec;
    std::cout << "[ " << spec << " ] " << c.ground.reason << "\n";
  }
  const CandidateGrid slope = Generate(SyntheticAt10cm("slope"));
  EXPECT_EQ(slope.ground.model, GroundModel::kTerrain) << slope.ground.reason;
  EXPECT_LT(slope.ground.floor_share, kFloorShare);
  EXPECT_NE(slope.ground.reason.find("terrain: only"), std::string::npos) << slope.ground.reason;
  std::cout << "[ slope ] " << slope.ground.reason << "\n";
}

// The slope scene's design (docs/SCENES.md): terraces 1 m deep rising 0.1 m along x from x = 0,
// and the footprints of its two buildings and its van, shifted by kSceneOffsetM.
double SlopeGroundZ(double x) { return 0.1 * std::floor(x - kSceneOffsetM.x()) + kSceneOffsetM.z(); }
bool OnARoof(const WorldPoint& p) {
  const double x = p.x() - kSceneOffsetM.x(), y = p.y() - kSceneOffsetM.y();
  return (x > 8 && x < 16 && y > 6 && y < 14) || (x > 24 && x < 32 && y > 16 && y < 24) ||
         (x > 34 && x < 38.5 && y > 5 && y < 7);
}

TEST(CandidatesTest, TerrainCandidatesStandOnTheGroundOnlyNeverOnRoofsOrTheVan) {
  const CandidateGrid c = Generate(SyntheticAt10cm("slope"));
  ASSERT_EQ(c.ground.model, GroundModel::kTerrain);
  EXPECT_TRUE(c.levels.empty());
  // 40 x 30 cells, less the buildings' and the van's footprints and the cells by their walls.
  EXPECT_GT(c.positions.size(), 900u);
  EXPECT_LT(c.positions.size(), 1200u);
  for (size_t i = 0; i < c.positions.size(); ++i) {
    const WorldPoint& p = c.positions[i];
    EXPECT_FALSE(OnARoof(p)) << p.transpose();
    // The floor is the terrace under the candidate, or the next one within the 3 x 3 columns.
    EXPECT_NEAR(c.floor_z_m[i], SlopeGroundZ(p.x()), 0.11) << p.transpose();
    EXPECT_NEAR(p.z() - c.floor_z_m[i], 1.5, 1e-9);
    EXPECT_EQ(c.level[i], -1);
  }
  EXPECT_EQ(c.rejected_no_floor + c.rejected_clearance + c.positions.size(), c.cells);
}

// At 0.4 m the slope's 0.5 m base is one voxel, so a slope rising a voxel at a time measured 0.5 at
// every rise: the ground broke into strips, the largest one a terrace, and auto picked floors.
TEST(CandidatesTest, TerrainAtCoarseVoxelsKeepsTheSlopeWhole) {
  Result<VoxelScene> scene = Voxelize(testing::Synthetic("slope"), VoxelizeOptions{0.4});
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const CandidateGrid c = Generate(*scene);
  ASSERT_EQ(c.ground.model, GroundModel::kTerrain) << c.ground.reason;
  // Most of the 40 x 30 cells (at 0.1 m: 900-1200), not one terrace's 4 x 30.
  EXPECT_GT(c.positions.size(), 800u);
  for (size_t i = 0; i < c.positions.size(); ++i) {
    const WorldPoint& p = c.positions[i];
    EXPECT_FALSE(OnARoof(p)) << p.transpose();
    // On the ground: within a voxel and a half of the terrace under it (the voxels are 0.4 m).
    EXPECT_NEAR(c.floor_z_m[i], SlopeGroundZ(p.x()), 0.6) << p.transpose();
  }
  std::cout << "[ slope at 0.4 m ] " << c.positions.size() << " candidates, " << c.ground.reason << "\n";
}

TEST(CandidatesTest, EitherModelCanBeForced) {
  const VoxelScene slope = SyntheticAt10cm("slope");
  CandidateOptions o;
  o.ground = GroundModel::kFloors;
  const CandidateGrid floors = Generate(slope, o);
  EXPECT_EQ(floors.ground.model, GroundModel::kFloors);
  EXPECT_NE(floors.ground.reason.find("floors, as requested"), std::string::npos) << floors.ground.reason;
  EXPECT_FALSE(floors.levels.empty());
  // A few levels of a 4 m slope: far fewer candidates than the terrain's.
  EXPECT_LT(floors.positions.size(), Generate(slope).positions.size() / 2);

  Builder b;
  b.Room(25, true);
  o.ground = GroundModel::kTerrain;
  const CandidateGrid terrain = Generate(b.Build(), o);
  EXPECT_EQ(terrain.ground.model, GroundModel::kTerrain);
  EXPECT_NE(terrain.ground.reason.find("terrain, as requested"), std::string::npos) << terrain.ground.reason;
  ASSERT_EQ(terrain.positions.size(), 20u);  // the same cells as the floor level's, never on the ceiling's top
  for (size_t i = 0; i < terrain.positions.size(); ++i) EXPECT_NEAR(terrain.floor_z_m[i], 0.1, 1e-9);
}

TEST(CandidatesTest, TerrainGroundIsTheLargestWalkableComponentNotADeskOrAPlatform) {
  // A 5 x 4 m open ramp rising one voxel every 0.5 m along x, a desk 0.8 m high on it and a
  // 1 m high platform in a corner: neither is linked to the ramp by a step of at most 0.25 m.
  Builder b;
  for (int x = 0; x < 50; ++x) b.Box(x, 0, 0, x, 39, x / 5);
  b.Box(20, 15, 12, 29, 24, 12);  // the desk's top, 0.8 m above the ramp at x 2.0 .. 2.9 m
  b.Box(40, 30, 0, 49, 39, 19);   // the platform: top 1 m above the ramp's end
  CandidateOptions o;
  o.ground = GroundModel::kTerrain;
  const CandidateGrid c = Generate(b.Build(), o);
  ASSERT_GT(c.positions.size(), 10u);
  for (size_t i = 0; i < c.positions.size(); ++i) {
    const WorldPoint& p = c.positions[i];
    const int ix = static_cast<int>(std::floor(p.x() / kR)) + 20;  // Builder::Build moves x by -20 voxels
    EXPECT_NEAR(c.floor_z_m[i], (ix / 5 + 1) * kR, 2 * kR + 1e-9) << p.transpose();
  }
}

// On a flat floor the terrain's obstacle slice is the floor level's: the same door gets the same
// passage candidates under either model.
TEST(CandidatesTest, ADoorGetsTheSamePassageCandidatesOnTerrainAsOnItsFloorLevel) {
  Builder b;
  b.Room(25, true);
  b.Box(24, 1, 1, 26, 38, 24);
  b.Erase(24, 15, 1, 26, 23, 20);
  CandidateOptions o;
  o.doorway_candidates = true;
  o.ground = GroundModel::kFloors;
  const CandidateGrid floors = Generate(b.Build(), o);
  o.ground = GroundModel::kTerrain;
  const CandidateGrid terrain = Generate(b.Build(), o);
  ASSERT_GT(floors.passage_candidates, 0u);
  ASSERT_EQ(terrain.passage_candidates, floors.passage_candidates);
  ASSERT_EQ(terrain.positions.size(), floors.positions.size());
  for (size_t i = 0; i < floors.positions.size(); ++i) {
    EXPECT_EQ(terrain.positions[i], floors.positions[i]) << i;
    EXPECT_EQ(terrain.floor_z_m[i], floors.floor_z_m[i]) << i;
  }
}

// hillside (docs/SCENES.md): terraces 0.5 m deep rising 0.1 m along x; a house over design
// x 8-14.6, y 4-10 whose room's floor, z 1.5, is the ground outside its door (x 8-8.3, y 6.5-7.5).
double HillsideGroundZ(double x_design, double y_design) {
  if (x_design > 8 && x_design < 14.3 && y_design > 4.3 && y_design < 9.7) return 1.5;  // the room, the door
  return 0.1 * std::floor(x_design / 0.5);
}

TEST(CandidatesTest, ADoorOntoSlopingGroundGetsCandidatesOnTheGroundInTheDoorway) {
  const CandidateGrid c = WithPassages(SyntheticAt10cm("hillside"));
  ASSERT_EQ(c.ground.model, GroundModel::kTerrain) << c.ground.reason;
  ASSERT_GT(c.passage_candidates, 0u);
  bool in_doorway = false, outside = false, inside = false;
  for (size_t i = c.positions.size() - c.passage_candidates; i < c.positions.size(); ++i) {
    const WorldPoint& p = c.positions[i];
    const double x = p.x() - kSceneOffsetM.x(), y = p.y() - kSceneOffsetM.y();
    std::cout << "[ hillside passage ] " << x << ", " << y << ", floor " << c.floor_z_m[i] - kSceneOffsetM.z() << "\n";
    EXPECT_EQ(c.level[i], -1);
    EXPECT_NEAR(p.z() - c.floor_z_m[i], 1.5, 1e-9) << p.transpose();
    // On the ground under it: the terrace or the room's floor, within a voxel.
    EXPECT_NEAR(c.floor_z_m[i] - kSceneOffsetM.z(), HillsideGroundZ(x, y), 0.11) << x << ", " << y;
    // On the door's centre line, at most half a cell beyond the wall.
    EXPECT_NEAR(y, 7.0, 0.05 + 1e-9) << x << ", " << y;
    EXPECT_NEAR(x, 8.15, 0.15 + 0.5 + 1e-9) << x << ", " << y;
    in_doorway = in_doorway || (x > 8 && x < 8.3);
    outside = outside || x < 8;
    inside = inside || x > 8.3;
  }
  EXPECT_TRUE(in_doorway);
  EXPECT_TRUE(outside);
  EXPECT_TRUE(inside);
}

// A ramp rising one voxel every 3 columns (a slope of 1:3, within the terrain's 0.36) across a
// 6 x 4 m grid at 0.1 m, column x's top at ((x / 3) + 1) * 0.1 m (Builder::Build moves x by -20).
double RampTopZ(double x_m) {
  const int ix = static_cast<int>(std::floor(x_m / kR)) + 20;
  return (ix / 3 + 1) * kR;
}

TEST(CandidatesTest, AStationMovedOnTerrainStandsOnTheGroundUnderItsNewPlace) {
  Builder b;
  for (int x = 0; x < 60; ++x) b.Box(x, 0, 0, x, 39, x / 3);
  const VoxelScene s = b.Build();
  CandidateOptions o;
  o.ground = GroundModel::kTerrain;
  const WorldPoint from(1.05, 0.25, 0);  // column 30, top 1.1 m
  const double floor = RampTopZ(from.x());
  ASSERT_NEAR(floor, 1.1, 1e-9);
  for (double dx : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
    for (double dy : {-1.0, 0.0, 1.0}) {
      if (dx == 0 && dy == 0) continue;
      const double x = from.x() + dx, y = from.y() + dy;
      const std::optional<double> top = MovedStationFloor(s.grid, from, floor, x, y, o);
      ASSERT_TRUE(top.has_value()) << dx << ", " << dy;
      EXPECT_NEAR(*top, RampTopZ(x), 1e-9) << dx << ", " << dy;
    }
  }
  // The floor level's band (+-0.2 m here) loses the ground 1 m up or down the ramp (0.3 m away).
  o.ground = GroundModel::kFloors;
  EXPECT_FALSE(MovedStationFloor(s.grid, from, floor, from.x() + 1.0, from.y(), o).has_value());
  EXPECT_FALSE(MovedStationFloor(s.grid, from, floor, from.x() - 1.0, from.y(), o).has_value());
}

TEST(CandidatesTest, AStationMovedOnTerrainDoesNotCrossAWallAStepOrASteepRise) {
  Builder b;
  b.Box(0, 0, 0, 59, 39, 0);      // flat ground, top 0.1 m
  b.Box(30, 0, 1, 30, 19, 20);    // a wall 2 m high along y at x 1.0 m, over y -1.7 .. 0.2 m
  b.Box(40, 20, 1, 59, 39, 5);    // a platform 0.5 m high (2 steps of 0.25 m)
  b.Box(10, 25, 1, 14, 39, 1);    // a strip raised one voxel: a sill
  b.Erase(20, 25, 0, 20, 39, 0);  // a one-voxel gap in the map
  const VoxelScene s = b.Build();
  CandidateOptions o;
  o.ground = GroundModel::kTerrain;
  const WorldPoint from(0.55, -1.0, 0);                                           // column 25, row 7
  EXPECT_FALSE(MovedStationFloor(s.grid, from, 0.1, 1.55, -1.0, o).has_value());  // the wall
  const std::optional<double> beside = MovedStationFloor(s.grid, from, 0.1, 0.55, -0.5, o);
  ASSERT_TRUE(beside.has_value());
  EXPECT_NEAR(*beside, 0.1, 1e-9);
  const WorldPoint open(0.55, 1.0, 0);  // column 25, row 27: past the wall's end
  EXPECT_FALSE(MovedStationFloor(s.grid, open, 0.1, 2.55, 1.0, o).has_value());  // onto the platform
  const std::optional<double> over_sill = MovedStationFloor(s.grid, open, 0.1, -1.45, 1.0, o);
  ASSERT_TRUE(over_sill.has_value());  // across the sill (one voxel up and down) and the gap
  EXPECT_NEAR(*over_sill, 0.1, 1e-9);
  const std::optional<double> on_sill = MovedStationFloor(s.grid, open, 0.1, -0.75, 1.0, o);
  ASSERT_TRUE(on_sill.has_value());
  EXPECT_NEAR(*on_sill, 0.2, 1e-9);
  // A 1 m move may rise 0.36 m and a voxel: a 0.5 m step up a steeper ramp is too much.
  Builder steep;
  for (int x = 0; x < 60; ++x) steep.Box(x, 0, 0, x, 39, x / 2);  // 1:2
  const VoxelScene st = steep.Build();
  EXPECT_FALSE(MovedStationFloor(st.grid, WorldPoint(1.05, 0.25, 0), 1.6, 2.05, 0.25, o).has_value());
}

TEST(CandidatesTest, Cancelled) {
  Builder b;
  b.Room(25, true);
  CancelToken token;
  token.Cancel();
  JobContext ctx;
  ctx.cancel = &token;
  EXPECT_EQ(GenerateCandidates(b.Build(), {}, ctx).status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace vc::planner
