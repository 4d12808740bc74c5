#include "vc/synth/synth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <unordered_map>
#include <vector>

#include "testing/test_paths.h"

namespace vc {
namespace {

const char* const kSmallScenes[] = {"box", "lroom",  "comb:3",   "rooms:3",  "hub:2",    "court:2",
                                    "tee", "star:4", "atrium:2", "twofloor", "tworooms", "stairs"};

// A dense voxel grid over a scene's bounds (plus a margin), filled from its points; keys are
// floor(p / resolution) as in OctoMap.
class VoxelGrid {
 public:
  VoxelGrid(const SceneInfo& info, double resolution) : r_(resolution) {
    for (int a = 0; a < 3; ++a) {
      origin_[a] = static_cast<int>(std::floor(info.bounds_min[a] / r_)) - 2;
      dims_[a] = static_cast<int>(std::floor(info.bounds_max[a] / r_)) + 3 - origin_[a];
    }
    cells_.assign(static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2], 0);
  }

  void Add(const Eigen::Vector3f& p) {
    std::array<int, 3> k;
    for (int a = 0; a < 3; ++a) k[a] = static_cast<int>(std::floor(static_cast<double>(p[a]) / r_)) - origin_[a];
    if (k[0] < 0 || k[1] < 0 || k[2] < 0 || k[0] >= dims_[0] || k[1] >= dims_[1] || k[2] >= dims_[2]) {
      ++outside_;
      return;
    }
    cells_[Index(k)] = 1;
  }

  uint64_t Occupied() const { return std::count(cells_.begin(), cells_.end(), 1); }
  uint64_t outside() const { return outside_; }

  std::array<int, 3> KeyOf(const WorldPoint& p) const {
    std::array<int, 3> k;
    for (int a = 0; a < 3; ++a) k[a] = static_cast<int>(std::floor(p[a] / r_)) - origin_[a];
    return k;
  }
  bool IsOccupied(const std::array<int, 3>& k) const { return cells_[Index(k)] == 1; }

  // 6-connected flood fill over free voxels from `seed`; marks reached voxels with 2. Returns
  // whether it reached the grid's border (i.e. escaped the scene's bounds).
  bool FloodEscapes(const std::array<int, 3>& seed) {
    std::vector<std::array<int, 3>> stack = {seed};
    cells_[Index(seed)] = 2;
    bool escaped = false;
    while (!stack.empty()) {
      const std::array<int, 3> k = stack.back();
      stack.pop_back();
      for (int a = 0; a < 3; ++a) {
        for (int d : {-1, 1}) {
          std::array<int, 3> n = k;
          n[a] += d;
          if (n[a] < 0 || n[a] >= dims_[a]) {
            escaped = true;
            continue;
          }
          uint8_t& c = cells_[Index(n)];
          if (c != 0) continue;
          c = 2;
          stack.push_back(n);
        }
      }
    }
    return escaped;
  }
  bool Reached(const std::array<int, 3>& k) const { return cells_[Index(k)] == 2; }

  // Occupied voxels per z layer, and the layer index of world height z.
  std::vector<uint64_t> LayerCounts() const {
    std::vector<uint64_t> counts(dims_[2], 0);
    for (size_t i = 0; i < cells_.size(); ++i) {
      if (cells_[i] == 1) ++counts[i / (static_cast<size_t>(dims_[0]) * dims_[1])];
    }
    return counts;
  }
  int LayerOf(double z) const { return static_cast<int>(std::floor(z / r_)) - origin_[2]; }

 private:
  size_t Index(const std::array<int, 3>& k) const {
    return (static_cast<size_t>(k[2]) * dims_[1] + k[1]) * dims_[0] + k[0];
  }
  double r_;
  std::array<int, 3> origin_{}, dims_{};
  std::vector<uint8_t> cells_;
  uint64_t outside_ = 0;
};

VoxelGrid Voxelize(std::string_view spec, double spacing, double resolution) {
  Result<SceneInfo> info = DescribeScene(spec);
  EXPECT_TRUE(info.ok()) << info.status().ToString();
  VoxelGrid grid(*info, resolution);
  SynthOptions options;
  options.spacing_m = spacing;
  EXPECT_TRUE(ForEachScenePoint(spec, options, [&grid](const Eigen::Vector3f& p) { grid.Add(p); }).ok());
  return grid;
}

// A point in free space inside a room: its centre in x and y, 1.7 m above its floor.
WorldPoint SeedPoint(const AxisBox& room) {
  return {(room.min.x() + room.max.x()) / 2, (room.min.y() + room.max.y()) / 2, room.min.z() + 1.7};
}

bool Disjoint(const AxisBox& a, const AxisBox& b) {
  for (int i = 0; i < 3; ++i) {
    if (a.max[i] <= b.min[i] || b.max[i] <= a.min[i]) return true;
  }
  return false;
}

TEST(SynthOptionsTest, ValidateRejectsSpacingOutsideRangeOrNotFinite) {
  for (double bad : {0.0, 0.004, 1.01, -0.1, std::nan(""), static_cast<double>(INFINITY)}) {
    SynthOptions o;
    o.spacing_m = bad;
    EXPECT_EQ(o.Validate().code(), StatusCode::kInvalidArgument) << bad;
  }
  for (double good : {0.005, 0.05, 1.0}) {
    SynthOptions o;
    o.spacing_m = good;
    EXPECT_TRUE(o.Validate().ok()) << good;
  }
}

TEST(DescribeSceneTest, BadSpecsAreInvalidArgumentListingValidNames) {
  for (const char* bad :
       {"",         "castle",    "Box",    "comb",   "comb:",  "comb:0",   "comb:51",  "comb:x", "comb:2x",
        "rooms:-1", "rooms:1.5", "box:2",  "hall:1", "hub",    "hub:0",    "hub:51",   "court",  "court:51",
        "tee:1",    "star",      "star:1", "star:5", "atrium", "atrium:1", "atrium:51"}) {
    Result<SceneInfo> info = DescribeScene(bad);
    ASSERT_FALSE(info.ok()) << bad;
    EXPECT_EQ(info.status().code(), StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(info.status().message().find("comb:K"), std::string::npos) << info.status().message();
  }
}

TEST(DescribeSceneTest, KnownScenesReportTheirOptimumRoomsAndFloors) {
  const std::vector<std::pair<std::string, int>> expected = {
      {"box", 1},      {"lroom", 1},    {"comb:1", 1}, {"comb:7", 7},   {"comb:50", 50},  {"rooms:1", 2},
      {"rooms:4", 5},  {"hub:1", 2},    {"hub:3", 6},  {"court:1", 4},  {"court:3", 8},   {"tee", 3},
      {"star:2", 2},   {"star:3", 3},   {"star:4", 4}, {"atrium:2", 8}, {"atrium:3", 12}, {"atrium:50", 200},
      {"twofloor", 2}, {"tworooms", 2}, {"stairs", 0}, {"hall", 0}};
  for (const auto& [spec, optimum] : expected) {
    Result<SceneInfo> info = DescribeScene(spec);
    ASSERT_TRUE(info.ok()) << spec << ": " << info.status().ToString();
    EXPECT_EQ(info->name, spec);
    EXPECT_FALSE(info->description.empty());
    EXPECT_EQ(info->optimum_stations, optimum) << spec;
    if (optimum > 0) {
      EXPECT_EQ(static_cast<int>(info->rooms.size()), optimum) << spec;
    }
    EXPECT_FALSE(info->rooms.empty()) << spec;
    ASSERT_FALSE(info->floor_heights_m.empty()) << spec;
    EXPECT_TRUE(std::is_sorted(info->floor_heights_m.begin(), info->floor_heights_m.end()));
    for (double f : info->floor_heights_m) {
      EXPECT_GT(f, info->bounds_min.z()) << spec;
      EXPECT_LT(f + 2.0, info->bounds_max.z()) << spec;
    }
    for (size_t i = 0; i < info->rooms.size(); ++i) {
      const AxisBox& room = info->rooms[i];
      EXPECT_TRUE((room.min.array() < room.max.array()).all()) << spec << " room " << i;
      EXPECT_TRUE((room.min.array() >= info->bounds_min.array()).all()) << spec << " room " << i;
      EXPECT_TRUE((room.max.array() <= info->bounds_max.array()).all()) << spec << " room " << i;
      for (size_t j = 0; j < i; ++j) {
        EXPECT_TRUE(Disjoint(room, info->rooms[j])) << spec << " " << i << "," << j;
      }
    }
  }
  EXPECT_EQ(DescribeScene("twofloor")->floor_heights_m.size(), 2u);
  EXPECT_EQ(DescribeScene("stairs")->rooms.size(), 2u);  // the lower bound of its unknown optimum
}

// Design coordinates (before kSceneOffsetM) of a world point.
Eigen::Vector3d Design(const Eigen::Vector3f& p) { return p.cast<double>() - kSceneOffsetM; }
Eigen::Vector3d Design(const WorldPoint& p) { return p - kSceneOffsetM; }

void ExpectBox(const AxisBox& box, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const std::string& what) {
  EXPECT_TRUE(Design(box.min).isApprox(lo, 1e-9)) << what << " min " << Design(box.min).transpose();
  EXPECT_TRUE(Design(box.max).isApprox(hi, 1e-9)) << what << " max " << Design(box.max).transpose();
}

TEST(DescribeSceneTest, TwoRoomsAndStairsRoomsFloorsAndBoundsInWorldCoordinates) {
  Result<SceneInfo> two = DescribeScene("tworooms");
  ASSERT_TRUE(two.ok());
  ASSERT_EQ(two->rooms.size(), 2u);
  ExpectBox(two->rooms[0], {0, 0, 0}, {5, 4, 3}, "room A");
  ExpectBox(two->rooms[1], {5.25, 0, 0}, {10.25, 4, 3}, "room B");
  ASSERT_EQ(two->floor_heights_m.size(), 1u);
  EXPECT_NEAR(two->floor_heights_m[0], kSceneOffsetM.z(), 1e-12);
  ExpectBox({two->bounds_min, two->bounds_max}, {-0.3, -0.3, -0.3}, {10.55, 4.3, 3.3}, "tworooms bounds");

  Result<SceneInfo> stairs = DescribeScene("stairs");
  ASSERT_TRUE(stairs.ok());
  ASSERT_EQ(stairs->rooms.size(), 2u);
  ExpectBox(stairs->rooms[0], {0, 0, 0}, {8, 6, 3}, "lower storey");
  ExpectBox(stairs->rooms[1], {0, 0, 3.3}, {8, 5, 6.3}, "upper storey");
  ASSERT_EQ(stairs->floor_heights_m.size(), 2u);
  EXPECT_NEAR(stairs->floor_heights_m[0], kSceneOffsetM.z(), 1e-12);
  EXPECT_NEAR(stairs->floor_heights_m[1], 3.3 + kSceneOffsetM.z(), 1e-12);
  ExpectBox({stairs->bounds_min, stairs->bounds_max}, {-0.3, -0.3, -0.3}, {8.3, 6.3, 6.6}, "stairs bounds");
}

// Whether design point q lies (within tol) on one of the planes x = xs, y = ys or z = zs.
bool OnAPlane(const Eigen::Vector3d& q, const std::vector<std::vector<double>>& planes, double tol = 1e-4) {
  for (int a = 0; a < 3; ++a) {
    for (double c : planes[a]) {
      if (std::abs(q[a] - c) <= tol) return true;
    }
  }
  return false;
}

TEST(GenerateSceneTest, TwoRoomsPointsLieOnWallsFloorCeilingCornicesAndTheDoor) {
  SynthOptions o;
  o.spacing_m = 0.05;
  Result<std::vector<Eigen::Vector3f>> points = GenerateScene("tworooms", o);
  ASSERT_TRUE(points.ok());
  // Walls, door jambs (y = 0.3, 1.2) and head (z = 2.1), cornice faces (0.2 m from the walls).
  const std::vector<std::vector<double>> planes = {
      {0, 0.2, 4.8, 5, 5.25, 5.45, 10.05, 10.25}, {0, 0.2, 0.3, 1.2, 3.8, 4}, {0, 2.1, 2.8, 3}};
  size_t off = 0, jamb_south = 0, jamb_north = 0, head = 0, in_wall = 0;
  for (const Eigen::Vector3f& p : *points) {
    const Eigen::Vector3d q = Design(p);
    off += !OnAPlane(q, planes);
    const bool through_wall = q.x() > 5.001 && q.x() < 5.249;  // strictly inside the shared wall
    if (!through_wall) continue;
    jamb_south += std::abs(q.y() - 0.3) < 1e-4 && q.z() < 2.1;
    jamb_north += std::abs(q.y() - 1.2) < 1e-4 && q.z() < 2.1;
    head += std::abs(q.z() - 2.1) < 1e-4 && q.y() > 0.3 && q.y() < 1.2;
    in_wall += q.y() < 0.299 || q.y() > 1.201 || q.z() > 2.101;  // only the doorway is open
  }
  EXPECT_EQ(off, 0u);
  EXPECT_GT(jamb_south, 40u);  // 0.25 x 2.1 m at 0.05 m: about 5 x 43 points
  EXPECT_GT(jamb_north, 40u);
  EXPECT_GT(head, 40u);
  EXPECT_EQ(in_wall, 0u);
}

TEST(SceneVoxelsTest, TwoRoomsAreJoinedOnlyThroughTheDoor) {
  Result<SceneInfo> info = DescribeScene("tworooms");
  ASSERT_TRUE(info.ok());
  VoxelGrid grid = Voxelize("tworooms", 0.05, 0.1);
  EXPECT_FALSE(grid.FloodEscapes(grid.KeyOf(SeedPoint(info->rooms[0]))));
  EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(info->rooms[1]))));
  // The door: 0.9 m wide (y in [0.3, 1.2]) and 2.1 m high in the wall x in [5, 5.25].
  const WorldPoint door = WorldPoint(5.125, 0.75, 1.0) + kSceneOffsetM;
  EXPECT_TRUE(grid.Reached(grid.KeyOf(door)));
  EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 0, 1.5))));  // above the head
  EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 1.0, 0))));  // wall north of the door
  EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 2.5, 0))));  // centre of the wall
}

TEST(DescribeSceneTest, HubRoomsAreTheSmallRoomsOnBothSidesOfTheHall) {
  Result<SceneInfo> hub = DescribeScene("hub:2");
  ASSERT_TRUE(hub.ok());
  ASSERT_EQ(hub->rooms.size(), 4u);  // per 5 m segment: the north room, then the south room
  ExpectBox(hub->rooms[0], {0.25, 4.75, 0}, {4.75, 7.75, 3}, "north room 0");
  ExpectBox(hub->rooms[1], {0.25, -3.25, 0}, {4.75, -0.25, 3}, "south room 0");
  ExpectBox(hub->rooms[2], {5.25, 4.75, 0}, {9.75, 7.75, 3}, "north room 1");
  ExpectBox(hub->rooms[3], {5.25, -3.25, 0}, {9.75, -0.25, 3}, "south room 1");
  ExpectBox({hub->bounds_min, hub->bounds_max}, {-0.3, -3.55, -0.3}, {10.3, 8.05, 3.3}, "hub:2 bounds");
}

TEST(SceneVoxelsTest, HubRoomsAreJoinedToTheHallOnlyThroughTheirDoors) {
  Result<SceneInfo> info = DescribeScene("hub:2");
  ASSERT_TRUE(info.ok());
  VoxelGrid grid = Voxelize("hub:2", 0.05, 0.1);
  const WorldPoint hall = WorldPoint(5, 2.25, 1.5) + kSceneOffsetM;
  EXPECT_FALSE(grid.FloodEscapes(grid.KeyOf(hall)));
  for (const AxisBox& room : info->rooms) EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(room))));
  // Door of north room 1: x in [7, 8], y in [4.5, 4.75], up to 2.1 m.
  const WorldPoint door = WorldPoint(7.5, 4.625, 1.0) + kSceneOffsetM;
  EXPECT_TRUE(grid.Reached(grid.KeyOf(door)));
  EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 0, 1.5))));         // above the head
  EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0.7, 0, 0))));         // wall beside the door
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(5, 6, 1) + kSceneOffsetM)));  // between two rooms
}

TEST(DescribeSceneTest, CourtRoomsAreTheSideRoomsThenTheEndRooms) {
  Result<SceneInfo> court = DescribeScene("court:2");
  ASSERT_TRUE(court.ok());
  ASSERT_EQ(court->rooms.size(), 6u);  // per 5 m segment north, south; then west and east
  ExpectBox(court->rooms[0], {0.25, 4.75, 0}, {4.75, 7.75, 3}, "north room 0");
  ExpectBox(court->rooms[1], {0.25, -3.25, 0}, {4.75, -0.25, 3}, "south room 0");
  ExpectBox(court->rooms[3], {5.25, -3.25, 0}, {9.75, -0.25, 3}, "south room 1");
  ExpectBox(court->rooms[4], {-3.25, 0.75, 0}, {-0.25, 3.75, 3}, "west room");
  ExpectBox(court->rooms[5], {10.25, 0.75, 0}, {13.25, 3.75, 3}, "east room");
  ExpectBox({court->bounds_min, court->bounds_max}, {-3.55, -3.55, -0.3}, {13.55, 8.05, 3.3}, "court:2 bounds");
}

TEST(SceneVoxelsTest, CourtRoomsAreJoinedToTheHallOnlyThroughTheirOffCentreDoors) {
  Result<SceneInfo> info = DescribeScene("court:2");
  ASSERT_TRUE(info.ok());
  VoxelGrid grid = Voxelize("court:2", 0.05, 0.1);
  EXPECT_FALSE(grid.FloodEscapes(grid.KeyOf(WorldPoint(5, 2.25, 1.5) + kSceneOffsetM)));
  for (const AxisBox& room : info->rooms) EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(room))));
  // North door 1: x in [6.25, 7.25] (0.75 m west of its room's centre); south door 1 x in
  // [7.75, 8.75]; the west door y in [1.75, 2.75] through the end wall x in [-0.25, 0].
  const WorldPoint north = WorldPoint(6.75, 4.625, 1.0) + kSceneOffsetM;
  const WorldPoint south = WorldPoint(8.25, -0.125, 1.0) + kSceneOffsetM;
  const WorldPoint west = WorldPoint(-0.125, 2.25, 1.0) + kSceneOffsetM;
  for (const WorldPoint& door : {north, south, west}) {
    EXPECT_TRUE(grid.Reached(grid.KeyOf(door))) << door.transpose();
    EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 0, 1.5)))) << "above the head " << door.transpose();
  }
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(7.5, 4.625, 1.0) + kSceneOffsetM)));   // the hub's door place
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(7.5, -0.125, 1.0) + kSceneOffsetM)));  // the same, south
  EXPECT_FALSE(grid.Reached(grid.KeyOf(west + WorldPoint(0, 0.8, 0))));                  // end wall beside the door
}

TEST(SceneVoxelsTest, TeeRoomsAreJoinedToTheHallOnlyThroughTheirCentredDoors) {
  Result<SceneInfo> info = DescribeScene("tee");
  ASSERT_TRUE(info.ok());
  ASSERT_EQ(info->rooms.size(), 3u);  // north, east, west
  ExpectBox(info->rooms[0], {1, 6.25, 0}, {5, 9.25, 3}, "north room");
  ExpectBox(info->rooms[1], {6.25, 1, 0}, {9.25, 5, 3}, "east room");
  ExpectBox(info->rooms[2], {-3.25, 1, 0}, {-0.25, 5, 3}, "west room");
  VoxelGrid grid = Voxelize("tee", 0.05, 0.1);
  EXPECT_FALSE(grid.FloodEscapes(grid.KeyOf(WorldPoint(3, 3, 1.5) + kSceneOffsetM)));
  for (const AxisBox& room : info->rooms) EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(room))));
  for (const WorldPoint& door : {WorldPoint(3, 6.125, 1.0), WorldPoint(6.125, 3, 1.0), WorldPoint(-0.125, 3, 1.0)}) {
    EXPECT_TRUE(grid.Reached(grid.KeyOf(door + kSceneOffsetM))) << door.transpose();
    EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 0, 1.5) + kSceneOffsetM))) << door.transpose();
  }
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(3, -0.125, 1.0) + kSceneOffsetM)));   // no south door
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(4.2, 6.125, 1.0) + kSceneOffsetM)));  // beside the north door
}

TEST(DescribeSceneTest, StarCountsOutsideTwoToFourNameTheirRange) {
  Result<SceneInfo> info = DescribeScene("star:5");
  ASSERT_FALSE(info.ok());
  EXPECT_NE(info.status().message().find("2..4"), std::string::npos) << info.status().message();
}

TEST(SceneVoxelsTest, StarArmsAreJoinedToTheHubOnlyThroughTheirDoors) {
  Result<SceneInfo> info = DescribeScene("star:4");
  ASSERT_TRUE(info.ok());
  ASSERT_EQ(info->rooms.size(), 4u);  // north, south, east, west
  ExpectBox(info->rooms[0], {1, 6.25, 0}, {3.5, 13.25, 3}, "north corridor");
  ExpectBox(info->rooms[1], {2, -4.25, 0}, {5.5, -0.25, 3}, "south room");
  ExpectBox(info->rooms[2], {6.25, 0.75, 0}, {12.25, 2.75, 3}, "east corridor");
  ExpectBox(info->rooms[3], {-4.25, 1.5, 0}, {-0.25, 5.5, 3}, "west room");
  EXPECT_EQ(DescribeScene("star:3")->rooms.size(), 3u);
  VoxelGrid grid = Voxelize("star:4", 0.05, 0.1);
  EXPECT_FALSE(grid.FloodEscapes(grid.KeyOf(WorldPoint(3, 3, 1.5) + kSceneOffsetM)));
  for (const AxisBox& room : info->rooms) EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(room))));
  // The doors: north x in [1.5, 2.5], south x in [3, 4], east y in [1, 2], west y in [3.5, 4.5].
  for (const WorldPoint& door : {WorldPoint(2, 6.125, 1.0), WorldPoint(3.5, -0.125, 1.0), WorldPoint(6.125, 1.5, 1.0),
                                 WorldPoint(-0.125, 4, 1.0)}) {
    EXPECT_TRUE(grid.Reached(grid.KeyOf(door + kSceneOffsetM))) << door.transpose();
    EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 0, 1.5) + kSceneOffsetM))) << door.transpose();
  }
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(3, 6.125, 1.0) + kSceneOffsetM)));   // beside the north door
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(-0.125, 3, 1.0) + kSceneOffsetM)));  // beside the west door
}

TEST(SceneVoxelsTest, AtriumRoomsAreJoinedOnlyThroughTheirDoorsAndThePierIsSolid) {
  Result<SceneInfo> info = DescribeScene("atrium:2");
  ASSERT_TRUE(info.ok());
  ASSERT_EQ(info->rooms.size(), 8u);  // north 0, 1, south 0, 1, west 0, 1, east 0, 1
  ExpectBox(info->rooms[0], {0.25, 10.25, 0}, {4.75, 13.25, 3}, "north room 0");
  ExpectBox(info->rooms[3], {5.25, -3.25, 0}, {9.75, -0.25, 3}, "south room 1");
  ExpectBox(info->rooms[4], {-3.25, 0.25, 0}, {-0.25, 4.75, 3}, "west room 0");
  ExpectBox(info->rooms[7], {10.25, 5.25, 0}, {13.25, 9.75, 3}, "east room 1");
  VoxelGrid grid = Voxelize("atrium:2", 0.05, 0.1);
  EXPECT_FALSE(grid.FloodEscapes(grid.KeyOf(WorldPoint(2, 2, 3.5) + kSceneOffsetM)));
  for (const AxisBox& room : info->rooms) EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(room))));
  // Doors 0.75 m off their rooms' centres: north at x = 5i + 1.75, south at x = 5i + 3.25, west at
  // y = 5i + 1.75, east at y = 5i + 3.25 (the scene turned by 90 degrees is itself).
  for (const WorldPoint& door : {WorldPoint(1.75, 10.125, 1.0), WorldPoint(8.25, -0.125, 1.0),
                                 WorldPoint(-0.125, 6.75, 1.0), WorldPoint(10.125, 3.25, 1.0)}) {
    EXPECT_TRUE(grid.Reached(grid.KeyOf(door + kSceneOffsetM))) << door.transpose();
    EXPECT_FALSE(grid.Reached(grid.KeyOf(door + WorldPoint(0, 0, 1.5) + kSceneOffsetM))) << door.transpose();
  }
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(2.5, 10.125, 1.0) + kSceneOffsetM)));  // beside a north door
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(5, 5, 1.0) + kSceneOffsetM)));         // inside the pier
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(5, 5, 3.5) + kSceneOffsetM)));         // up to the ceiling
  EXPECT_TRUE(grid.Reached(grid.KeyOf(WorldPoint(5, 3.6, 3.5) + kSceneOffsetM)));        // beside it
}

// Stairs: 19 treads, step k spanning x in [1.3 + 0.3 (k - 1), 1.3 + 0.3 k], y in [0, 1], top at
// z = 0.165 k; the 20th riser, at x = 7, goes up to the upper floor at z = 3.3.
constexpr double kStairX0 = 1.3, kGoing = 0.3, kRise = 0.165;
constexpr int kTreads = 19;

TEST(GenerateSceneTest, StairsPointsLieOnTheStoreysAndTheSteps) {
  SynthOptions o;
  o.spacing_m = 0.05;
  Result<std::vector<Eigen::Vector3f>> points = GenerateScene("stairs", o);
  ASSERT_TRUE(points.ok());
  std::vector<std::vector<double>> planes = {{0, 0.2, 7.8, 8}, {0, 0.2, 1, 4.8, 5, 5.8, 6}, {0, 2.8, 3, 3.3, 6.1, 6.3}};
  for (int k = 0; k <= kTreads; ++k) {
    planes[0].push_back(kStairX0 + k * kGoing);  // risers
    planes[2].push_back(k * kRise);              // treads
  }
  size_t off = 0;
  for (const Eigen::Vector3f& p : *points) off += !OnAPlane(Design(p), planes);
  EXPECT_EQ(off, 0u);
}

TEST(GenerateSceneTest, StairsHaveARealFlightRiseAtMost18cmGoingAtLeast28cm) {
  SynthOptions o;
  o.spacing_m = 0.05;
  Result<std::vector<Eigen::Vector3f>> points = GenerateScene("stairs", o);
  ASSERT_TRUE(points.ok());
  // Horizontal surfaces over the flight's footprint, below the upper floor: exactly the treads.
  std::vector<double> tread_lo(kTreads + 1, 1e9), tread_hi(kTreads + 1, -1e9);
  size_t other = 0, risers = 0, top_riser = 0;
  for (const Eigen::Vector3f& p : *points) {
    const Eigen::Vector3d q = Design(p);
    if (q.y() < 0.001 || q.y() > 0.999 || q.x() < kStairX0 - 0.001 || q.x() > 7.001 || q.z() > 3.299) continue;
    const double kx = (q.x() - kStairX0) / kGoing;
    const double kz = q.z() / kRise;
    const int kt = static_cast<int>(std::round(kz));
    const bool on_tread = std::abs(kz - kt) < 1e-3 && kt >= 1 && kt <= kTreads;
    if (on_tread) {  // including the nosing lines, which lie on riser planes too
      tread_lo[kt] = std::min(tread_lo[kt], q.x());
      tread_hi[kt] = std::max(tread_hi[kt], q.x());
    }
    if (std::abs(kx - std::round(kx)) < 1e-4) {            // on a riser plane
      const int k = static_cast<int>(std::round(kx)) + 1;  // riser k, from (k - 1) * rise up to k * rise
      // Above the first riser: the end of the foot bay's cornice (y <= 0.2, z in [2.8, 3]) and the
      // end of the slab opening (z in [3, 3.3]).
      if (k == 1 && (q.z() >= 3.0 - 1e-4 || (q.z() >= 2.8 - 1e-4 && q.y() <= 0.2 + 1e-4))) continue;
      const bool ok = q.z() >= (k - 1) * kRise - 1e-4 && q.z() <= k * kRise + 1e-4;
      risers += ok;
      top_riser += ok && k == kTreads + 1;
      other += !ok;
    } else {
      other += !on_tread;
    }
  }
  EXPECT_EQ(other, 0u);
  EXPECT_GT(risers, 20u * 3 * 20);  // 20 risers 1 m wide, >= 3 rows each at 0.05 m
  EXPECT_GT(top_riser, 3u * 20);    // the last one, up to the upper floor
  for (int k = 1; k <= kTreads; ++k) {
    EXPECT_NEAR(tread_lo[k], kStairX0 + (k - 1) * kGoing, 1e-4) << "tread " << k;
    EXPECT_NEAR(tread_hi[k], kStairX0 + k * kGoing, 1e-4) << "tread " << k;
    EXPECT_GE(tread_hi[k] - tread_lo[k], 0.28 - 1e-4) << "going of tread " << k;
  }
  // Rises: floor -> tread 1 -> ... -> tread 19 -> upper floor, all equal and <= 0.18 m.
  Result<SceneInfo> info = DescribeScene("stairs");
  ASSERT_TRUE(info.ok());
  const double total = info->floor_heights_m[1] - info->floor_heights_m[0];
  EXPECT_NEAR(total, (kTreads + 1) * kRise, 1e-9);
  EXPECT_LE(kRise, 0.18);
}

TEST(SceneVoxelsTest, StairsFlightIsSolidWithHeadroomAndJoinsTheStoreys) {
  Result<SceneInfo> info = DescribeScene("stairs");
  ASSERT_TRUE(info.ok());
  VoxelGrid grid = Voxelize("stairs", 0.05, 0.1);
  EXPECT_FALSE(grid.FloodEscapes(grid.KeyOf(SeedPoint(info->rooms[0]))));
  EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(info->rooms[1]))));
  for (int k = 1; k <= kTreads; ++k) {
    const double x = kStairX0 + (k - 0.5) * kGoing, z = k * kRise;
    const auto at = [&](double dz) { return grid.KeyOf(WorldPoint(x, 0.5, z + dz) + kSceneOffsetM); };
    EXPECT_TRUE(grid.IsOccupied(at(0))) << "tread " << k;
    // 2 m of headroom above every tread, reached from the lower storey.
    for (double dz = 0.15; dz < 2.0; dz += 0.1) EXPECT_TRUE(grid.Reached(at(dz))) << "tread " << k << " +" << dz;
    // Solid under the tread: enclosed, never reached.
    if (k >= 3) {
      EXPECT_FALSE(grid.Reached(at(-0.25))) << "tread " << k;
    }
  }
  // The slab is closed beside and beyond the opening.
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(4, 2, 3.15) + kSceneOffsetM)));
  EXPECT_FALSE(grid.Reached(grid.KeyOf(WorldPoint(7.5, 0.5, 3.15) + kSceneOffsetM)));
  EXPECT_TRUE(grid.Reached(grid.KeyOf(WorldPoint(4, 0.5, 3.15) + kSceneOffsetM)));
}

TEST(DescribeSceneTest, ListNamesEveryScene) {
  const std::string list = ListScenes();
  for (const char* name : {"box", "lroom", "comb", "rooms", "hub", "court", "tee", "star", "atrium", "twofloor",
                           "tworooms", "stairs", "hall", "slope", "hillside"}) {
    EXPECT_NE(list.find(name), std::string::npos) << name;
  }
}

TEST(GenerateSceneTest, SameSeedGivesIdenticalPointsOtherSeedDiffers) {
  SynthOptions a;
  a.spacing_m = 0.1;
  a.seed = 7;
  Result<std::vector<Eigen::Vector3f>> first = GenerateScene("rooms:2", a);
  Result<std::vector<Eigen::Vector3f>> second = GenerateScene("rooms:2", a);
  ASSERT_TRUE(first.ok() && second.ok());
  ASSERT_GT(first->size(), 1000u);
  EXPECT_TRUE(*first == *second);
  SynthOptions b = a;
  b.seed = 8;
  Result<std::vector<Eigen::Vector3f>> third = GenerateScene("rooms:2", b);
  ASSERT_TRUE(third.ok());
  ASSERT_EQ(third->size(), first->size());  // jitter moves points, never adds or drops them
  size_t moved = 0;
  for (size_t i = 0; i < first->size(); ++i) moved += (*first)[i] != (*third)[i];
  EXPECT_GT(moved, first->size() / 2);
}

TEST(GenerateSceneTest, CountMatchesTheStream) {
  for (const char* spec : {"box", "lroom", "comb:2", "rooms:2", "hub:1", "court:1", "tee", "star:3", "atrium:2",
                           "twofloor", "tworooms", "stairs", "hillside"}) {
    for (double spacing : {0.07, 0.2}) {
      SynthOptions o;
      o.spacing_m = spacing;
      Result<uint64_t> count = CountScenePoints(spec, o);
      Result<std::vector<Eigen::Vector3f>> points = GenerateScene(spec, o);
      ASSERT_TRUE(count.ok() && points.ok()) << spec;
      EXPECT_EQ(*count, points->size()) << spec << " " << spacing;
    }
  }
}

TEST(GenerateSceneTest, EveryPointIsFiniteAndInsideTheBounds) {
  for (const char* spec : {"box", "lroom", "comb:3", "rooms:3", "hub:2", "court:2", "tee", "twofloor", "tworooms",
                           "stairs", "hall", "hillside"}) {
    SynthOptions o;
    o.spacing_m = 0.2;
    Result<SceneInfo> info = DescribeScene(spec);
    Result<std::vector<Eigen::Vector3f>> points = GenerateScene(spec, o);
    ASSERT_TRUE(info.ok() && points.ok()) << spec;
    ASSERT_FALSE(points->empty());
    size_t bad = 0;
    for (const Eigen::Vector3f& p : *points) {
      const Eigen::Vector3d q = p.cast<double>();
      bad += !q.allFinite() || (q.array() < info->bounds_min.array()).any() ||
             (q.array() > info->bounds_max.array()).any();
    }
    EXPECT_EQ(bad, 0u) << spec;
  }
}

// Nearest-neighbour distances (brute force within a hash grid of cell `spacing`).
std::vector<double> NearestNeighbourDistances(const std::vector<Eigen::Vector3f>& points, double cell) {
  auto key = [cell](const Eigen::Vector3f& p) {
    return std::array<int64_t, 3>{static_cast<int64_t>(std::floor(p.x() / cell)),
                                  static_cast<int64_t>(std::floor(p.y() / cell)),
                                  static_cast<int64_t>(std::floor(p.z() / cell))};
  };
  auto hash = [](const std::array<int64_t, 3>& k) { return (k[0] * 73856093) ^ (k[1] * 19349663) ^ (k[2] * 83492791); };
  std::unordered_map<int64_t, std::vector<int>> buckets;
  std::vector<std::array<int64_t, 3>> keys(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    keys[i] = key(points[i]);
    buckets[hash(keys[i])].push_back(static_cast<int>(i));
  }
  std::vector<double> nn;
  nn.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    double best = 1e9;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = buckets.find(hash({keys[i][0] + dx, keys[i][1] + dy, keys[i][2] + dz}));
          if (it == buckets.end()) continue;
          for (int j : it->second) {
            if (j != static_cast<int>(i)) best = std::min(best, static_cast<double>((points[j] - points[i]).norm()));
          }
        }
      }
    }
    nn.push_back(best);
  }
  std::sort(nn.begin(), nn.end());
  return nn;
}

TEST(GenerateSceneTest, NearestNeighbourDistancesFollowTheSpacing) {
  for (const auto& [spec, spacing] : std::vector<std::pair<const char*, double>>{{"box", 0.1}, {"lroom", 0.13}}) {
    SynthOptions o;
    o.spacing_m = spacing;
    Result<std::vector<Eigen::Vector3f>> points = GenerateScene(spec, o);
    ASSERT_TRUE(points.ok());
    const std::vector<double> nn = NearestNeighbourDistances(*points, 1.5 * spacing);
    const double median = nn[nn.size() / 2], p99 = nn[nn.size() * 99 / 100];
    const double close = std::lower_bound(nn.begin(), nn.end(), 0.5 * spacing) - nn.begin();
    EXPECT_GT(median, 0.8 * spacing) << spec;
    EXPECT_LE(median, 1.0 * spacing) << spec;
    EXPECT_LE(p99, 1.2 * spacing) << spec;
    EXPECT_LT(close / nn.size(), 0.03) << spec << ": too many points closer than half the spacing";
  }
}

TEST(GenerateSceneTest, TooManyPointsIsResourceExhausted) {
  SynthOptions o;
  o.spacing_m = 0.005;
  Result<uint64_t> count = CountScenePoints("hall", o);
  ASSERT_TRUE(count.ok());
  EXPECT_GT(*count, kMaxGeneratedPoints);
  Result<std::vector<Eigen::Vector3f>> points = GenerateScene("hall", o);
  ASSERT_FALSE(points.ok());
  EXPECT_EQ(points.status().code(), StatusCode::kResourceExhausted);
}

TEST(ForEachScenePointTest, BadSpecOrOptionsAreInvalidArgument) {
  int calls = 0;
  auto fn = [&calls](const Eigen::Vector3f&) { ++calls; };
  EXPECT_EQ(ForEachScenePoint("nope", SynthOptions{}, fn).code(), StatusCode::kInvalidArgument);
  SynthOptions o;
  o.spacing_m = 0.001;
  EXPECT_EQ(ForEachScenePoint("box", o, fn).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(CountScenePoints("box", o).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(GenerateScene("rooms:0", SynthOptions{}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(calls, 0);
}

// Checks a scene voxelised at 0.1 m (spacing 0.05 m): closed (a flood fill from a room never
// leaves the bounds), connected (it reaches every room, through doors and openings), and its ground
// floor is the largest horizontal layer of occupied voxels. Returns the occupied voxel count.
uint64_t CheckClosedConnectedFloorDominant(const char* spec) {
  Result<SceneInfo> info = DescribeScene(spec);
  EXPECT_TRUE(info.ok());
  if (!info.ok()) return 0;
  VoxelGrid grid = Voxelize(spec, 0.05, 0.1);
  const uint64_t occupied = grid.Occupied();
  std::cout << spec << ": " << occupied << " occupied voxels at 0.1 m\n";
  EXPECT_EQ(grid.outside(), 0u) << spec;
  const std::vector<uint64_t> layers = grid.LayerCounts();
  const int floor_layer = grid.LayerOf(info->floor_heights_m[0]);
  for (int z = 0; z < static_cast<int>(layers.size()); ++z) {
    if (z != floor_layer) {
      EXPECT_LT(layers[z], layers[floor_layer]) << spec << " layer " << z;
    }
  }
  const auto seed = grid.KeyOf(SeedPoint(info->rooms[0]));
  EXPECT_FALSE(grid.IsOccupied(seed)) << spec;
  EXPECT_FALSE(grid.FloodEscapes(seed)) << spec << " leaks";
  for (size_t i = 0; i < info->rooms.size(); ++i) {
    EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(info->rooms[i])))) << spec << " room " << i;
  }
  return occupied;
}

TEST(SceneVoxelsTest, HallHasAbout400kVoxelsIsClosedConnectedAndFloorDominant) {
  const uint64_t occupied = CheckClosedConnectedFloorDominant("hall");
  EXPECT_GE(occupied, 300000u);
  EXPECT_LE(occupied, 500000u);
}

TEST(SceneVoxelsTest, SmallScenesAreClosedConnectedAndFloorDominant) {
  for (const char* spec : kSmallScenes) CheckClosedConnectedFloorDominant(spec);
}

TEST(SceneVoxelsTest, BoxIsWatertightAtTwiceTheSpacing) {
  for (const auto& [spacing, resolution] :
       std::vector<std::pair<double, double>>{{0.02, 0.04}, {0.04, 0.08}, {0.1, 0.2}}) {
    Result<SceneInfo> info = DescribeScene("box");
    ASSERT_TRUE(info.ok());
    VoxelGrid grid = Voxelize("box", spacing, resolution);
    const auto seed = grid.KeyOf(SeedPoint(info->rooms[0]));
    ASSERT_FALSE(grid.IsOccupied(seed));
    EXPECT_FALSE(grid.FloodEscapes(seed)) << "box leaks at " << resolution << " m";
  }
}

TEST(SceneVoxelsTest, RoomsAreJoinedOnlyThroughTheirDoors) {
  Result<SceneInfo> info = DescribeScene("rooms:4");
  ASSERT_TRUE(info.ok());
  ASSERT_EQ(info->rooms.size(), 5u);  // four rooms, then the corridor
  VoxelGrid grid = Voxelize("rooms:4", 0.05, 0.1);
  const auto seed = grid.KeyOf(SeedPoint(info->rooms[0]));
  EXPECT_FALSE(grid.FloodEscapes(seed));
  for (const AxisBox& room : info->rooms) {
    EXPECT_TRUE(grid.Reached(grid.KeyOf(SeedPoint(room))));
  }
  // The door of room 0 is 1 m wide and 2.1 m high: above it, the wall is solid.
  const AxisBox& r0 = info->rooms[0];
  const WorldPoint door_centre((r0.min.x() + r0.max.x()) / 2, r0.min.y() - 0.125, r0.min.z() + 1.0);
  EXPECT_TRUE(grid.Reached(grid.KeyOf(door_centre)));
  EXPECT_FALSE(grid.Reached(grid.KeyOf(door_centre + WorldPoint(0, 0, 1.5))));
  EXPECT_FALSE(grid.Reached(grid.KeyOf(door_centre + WorldPoint(1.0, 0, 0))));
}

TEST(WritePlyBinaryTest, HeaderAndBodyMatchGenerateScene) {
  SynthOptions o;
  o.spacing_m = 0.25;
  o.seed = 3;
  Result<std::vector<Eigen::Vector3f>> points = GenerateScene("rooms:1", o);
  ASSERT_TRUE(points.ok());
  const std::string path = testing::MakeTempDir() + "/rooms.ply";
  ASSERT_TRUE(WritePlyBinary(path, "rooms:1", o).ok());
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in);
  std::string line, header;
  uint64_t vertices = 0;
  while (std::getline(in, line) && line != "end_header") {
    header += line + "\n";
    if (line.rfind("element vertex ", 0) == 0) vertices = std::stoull(line.substr(15));
  }
  EXPECT_EQ(header.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u) << header;
  EXPECT_NE(header.find("property float x\nproperty float y\nproperty float z\n"), std::string::npos);
  ASSERT_EQ(vertices, points->size());
  std::vector<float> body(3 * vertices + 1);
  in.read(reinterpret_cast<char*>(body.data()), static_cast<std::streamsize>(body.size() * sizeof(float)));
  ASSERT_EQ(static_cast<uint64_t>(in.gcount()), 3 * vertices * sizeof(float)) << "body size";
  for (size_t i = 0; i < vertices; ++i) {
    ASSERT_EQ(Eigen::Vector3f(body[3 * i], body[3 * i + 1], body[3 * i + 2]), (*points)[i]) << i;
  }
}

TEST(WritePlyBinaryTest, UnwritablePathIsFailedPrecondition) {
  const Status s = WritePlyBinary(testing::MakeTempDir() + "/no/such/dir/x.ply", "box", SynthOptions{});
  EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace vc
