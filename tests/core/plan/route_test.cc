// The walking route on hand-built voxel scenes (corridors, doors, storeys, stairs, holes), the
// open-path heuristic against exhaustive search, errors, and the real geb079 scan.
#include "vc/plan/route.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <numeric>
#include <random>
#include <set>
#include <tuple>

#include "testing/scenes.h"
#include "testing/test_paths.h"
#include "vc/plan/candidates.h"
#include "vc/scene/scene_input.h"
#include "vc/synth/synth.h"

namespace vc::planner {
namespace {

constexpr double kR = 0.1;

// Voxel boxes at kR.
struct Builder : testing::VoxelBuilder {
  VoxelScene Build() const { return VoxelBuilder::Build(kR); }
};

// Optical centre 1.5 m above the floor top 0.1 m (slab at z index 0) over voxel column (i, j).
WorldPoint At(int i, int j, double floor_top_m = 0.1) { return {(i + 0.5) * kR, (j + 0.5) * kR, floor_top_m + 1.5}; }

Route Plan(const VoxelScene& s, const std::vector<WorldPoint>& stations, const RouteOptions& o = {}) {
  Result<Route> r = PlanRoute(s, stations, {}, o);
  EXPECT_TRUE(r.ok()) << r.status().ToString();
  return r.ok() ? *r : Route{};
}

// Points along a polyline's segments, every 0.02 m or closer, vertices included.
std::vector<WorldPoint> Samples(const std::vector<WorldPoint>& line) {
  std::vector<WorldPoint> out;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const double len = (line[i + 1] - line[i]).norm();
    const int steps = std::max(1, static_cast<int>(std::ceil(len / 0.02)));
    for (int s = 0; s <= steps; ++s) out.push_back(line[i] + (line[i + 1] - line[i]) * (double(s) / steps));
  }
  return out;
}

// Every polyline point and every point along its segments satisfies walkable(p).
void ExpectOnWalkable(const Route& route, const std::function<bool(const WorldPoint&)>& walkable) {
  for (size_t k = 0; k < route.polylines.size(); ++k) {
    for (const WorldPoint& p : Samples(route.polylines[k])) {
      ASSERT_TRUE(walkable(p)) << "leg " << k << " passes (" << p.transpose() << ")";
    }
  }
}

bool In(double v, double lo, double hi) { return v >= lo - 1e-9 && v <= hi + 1e-9; }

void ExpectPermutation(const Route& r, int n) {
  std::vector<int> o = r.order;
  std::sort(o.begin(), o.end());
  std::vector<int> want(n);
  std::iota(want.begin(), want.end(), 0);
  EXPECT_EQ(o, want);
  EXPECT_EQ(r.legs_m.size(), size_t(n));
  EXPECT_EQ(r.polylines.size(), size_t(n));
}

// An L-shaped corridor: along x (free y 1..13) for x 1..58, then up along y (free x 45..58) to y 58;
// solid elsewhere up to z 25 over a floor slab at z 0. Walkable (0.2 m clearance): cells whose
// centre is 0.2 m or more from every wall voxel.
VoxelScene LCorridor() {
  Builder b;
  b.Box(0, 0, 0, 59, 59, 25);
  b.Erase(1, 1, 1, 58, 13, 25);
  b.Erase(45, 1, 1, 58, 58, 25);
  return b.Build();
}
// On the floor and 0.15 m or more inside the free space (a cell centre keeps 0.2 m from the walls).
bool OnLCorridorFloor(const WorldPoint& p) {
  const bool a = In(p.x(), 0.25, 5.75) && In(p.y(), 0.25, 1.25);
  const bool b = In(p.x(), 4.65, 5.75) && In(p.y(), 0.25, 5.75);
  return (a || b) && std::abs(p.z() - 0.1) < 1e-9;
}

TEST(RouteTest, LCorridorIsWalkedInOrderAlongTheCorridor) {
  const VoxelScene s = LCorridor();
  // Stations given out of walking order: the corner, the far end, the start of the corridor, its middle.
  const std::vector<WorldPoint> st{At(51, 7), At(51, 50), At(10, 7), At(30, 7)};
  const Route r = Plan(s, st);
  ExpectPermutation(r, 4);
  EXPECT_EQ(r.parts, 1);
  EXPECT_TRUE(r.warnings.empty());
  const std::vector<int> forward{2, 3, 0, 1}, backward{1, 0, 3, 2};
  EXPECT_TRUE(r.order == forward || r.order == backward);
  EXPECT_NEAR(r.length_m, 2.0 + 2.1 + 4.3, 1e-6);
  EXPECT_EQ(r.legs_m[0], 0.0);
  EXPECT_TRUE(r.polylines[0].empty());
  ExpectOnWalkable(r, OnLCorridorFloor);
  EXPECT_GT(r.walk_nodes, 0u);
}

TEST(RouteTest, LegAroundTheCornerIsTheCorridorDistanceNotTheStraightLine) {
  const VoxelScene s = LCorridor();
  const Route r = Plan(s, {At(10, 7), At(51, 50)});
  ASSERT_EQ(r.order.size(), 2u);
  // Octile distance via the cell by the inner corner, (46, 12), 0.21 m from the corner voxel (44, 14),
  // 3.1 + 5 sqrt(2) 0.1 + 3.3 + 5 sqrt(2) 0.1, plus 0.2 - 0.1 sqrt(2): no diagonal leaves that cell
  // upwards, as (46, 13) is too close to the wall.
  const double corridor = 6.6 + 0.9 * std::sqrt(2.0);
  EXPECT_NEAR(r.legs_m[1], corridor, 1e-6);
  EXPECT_GT(r.legs_m[1], (At(51, 50) - At(10, 7)).norm() + 1.5);
  ExpectOnWalkable(r, OnLCorridorFloor);
  // The polyline is simplified: far fewer points than cells walked.
  EXPECT_LT(r.polylines[1].size(), 10u);
}

// Two 3.9 x 3.9 m rooms side by side, a 0.2 m wall between them (x 40..41) with a 0.9 m door at y 25..33.
VoxelScene TwoRooms() {
  Builder b;
  b.Box(0, 0, 0, 81, 40, 25);
  b.Erase(1, 1, 1, 39, 39, 25);
  b.Erase(42, 1, 1, 80, 39, 25);
  b.Erase(40, 25, 1, 41, 33, 25);
  return b.Build();
}

TEST(RouteTest, PathBetweenTwoRoomsGoesThroughTheDoor) {
  const VoxelScene s = TwoRooms();
  const Route r = Plan(s, {At(10, 10), At(70, 10)});
  ASSERT_EQ(r.order.size(), 2u);
  EXPECT_EQ(r.parts, 1);
  // Walkable: 0.15 m or more inside the rooms' or the door's free space.
  ExpectOnWalkable(r, [](const WorldPoint& p) {
    const bool room_a = In(p.x(), 0.25, 3.85) && In(p.y(), 0.25, 3.85);
    const bool room_b = In(p.x(), 4.35, 7.95) && In(p.y(), 0.25, 3.85);
    const bool door = In(p.x(), 3.85, 4.35) && In(p.y(), 2.65, 3.25);
    return room_a || room_b || door;
  });
  bool through_door = false;
  for (const WorldPoint& p : Samples(r.polylines[1])) through_door |= In(p.x(), 4.0, 4.2) && In(p.y(), 2.65, 3.25);
  EXPECT_TRUE(through_door);
  EXPECT_GT(r.legs_m[1], 6.0 + 1.0);  // 6 m straight through the wall; the door is 1.5 m up from both
}

// Storey 1: slab at z 0 over x 0..99, y 0..39. Storey 2: slab at z 30 (top 3.1 m) over x 62..99. With
// stairs: 14 solid steps of 0.2 m rise and 0.3 m tread over y 20..31, from x 20 up to the slab's edge.
VoxelScene TwoStoreys(bool stairs) {
  Builder b;
  b.Box(0, 0, 0, 99, 39, 0);
  b.Box(62, 0, 30, 99, 39, 30);
  if (stairs) {
    for (int s = 1; s <= 14; ++s) b.Box(20 + 3 * (s - 1), 20, 1, 20 + 3 * s - 1, 31, 2 * s);
  }
  return b.Build();
}

TEST(RouteTest, StoreysWithoutStairsAreTwoPartsWithAWarning) {
  const VoxelScene s = TwoStoreys(false);
  const std::vector<WorldPoint> st{At(80, 10, 3.1), At(10, 10), At(90, 30, 3.1), At(50, 10)};
  const Route r = Plan(s, st);
  ExpectPermutation(r, 4);
  EXPECT_EQ(r.parts, 2);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("stations 0, 2 (floor z = 3.10 m) not linked"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("2 parts"), std::string::npos);
  EXPECT_NE(r.warnings[0].find("3.00 m lower: another storey, and no stairs or ramp in the data"), std::string::npos)
      << r.warnings[0];
  // The lowest storey first.
  EXPECT_TRUE(r.order[0] == 1 || r.order[0] == 3);
  EXPECT_EQ(r.legs_m[0], 0.0);
  EXPECT_NEAR(r.legs_m[1], 4.0, 1e-6);
  EXPECT_TRUE(std::isnan(r.legs_m[2]));
  EXPECT_TRUE(r.polylines[2].empty());
  EXPECT_NEAR(r.legs_m[3], 1.0 + std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(r.length_m, r.legs_m[1] + r.legs_m[3], 1e-9);
}

TEST(RouteTest, FloorBelowIsTheHighestSurfaceUnderTheOpticalCentre) {
  const VoxelScene s = TwoStoreys(false);
  EXPECT_NEAR(FloorBelow(s.grid, At(80, 10, 3.1)), 3.1, 1e-9);  // on the upper slab
  EXPECT_NEAR(FloorBelow(s.grid, At(80, 10)), 0.1, 1e-9);       // under it: the lower one
  EXPECT_NEAR(FloorBelow(s.grid, At(10, 10)), 0.1, 1e-9);
  EXPECT_TRUE(std::isnan(FloorBelow(s.grid, At(10, 10, -2.0))));  // below the lowest slab
}

TEST(RouteTest, StairsLinkTheStoreysAndThePathClimbsThem) {
  const VoxelScene s = TwoStoreys(true);
  const std::vector<WorldPoint> st{At(80, 10, 3.1), At(10, 10), At(90, 30, 3.1)};
  const Route r = Plan(s, st);
  ExpectPermutation(r, 3);
  EXPECT_EQ(r.parts, 1);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings[0];
  for (double leg : r.legs_m) EXPECT_TRUE(std::isfinite(leg));
  // The lone station downstairs is an end of the open path; the leg next to it climbs the stairs.
  ASSERT_TRUE(r.order[0] == 1 || r.order[2] == 1);
  const std::vector<WorldPoint>& climb = r.polylines[r.order[0] == 1 ? 1 : 2];
  bool on_stairs = false;
  for (const WorldPoint& p : climb) {
    on_stairs |= In(p.x(), 2.0, 6.2) && In(p.y(), 2.0, 3.2) && p.z() > 1.0 && p.z() < 2.5;
  }
  EXPECT_TRUE(on_stairs);
  EXPECT_NEAR(std::abs(climb.back().z() - climb.front().z()), 3.0, 1e-9);
  // Every point of the climb is near a floor, or over the stair (0.1 m margin) within a step of its tread.
  ExpectOnWalkable(r, [](const WorldPoint& p) {
    if (In(p.z(), 0.1, 0.3)) return true;
    if (In(p.z(), 2.9, 3.1)) return p.x() >= 5.8 - 1e-9;
    const int s = std::clamp(static_cast<int>(std::floor((p.x() - 2.0) / 0.3)) + 1, 0, 15);
    return In(p.y(), 1.9, 3.3) && std::abs(p.z() - (0.1 + 0.2 * s)) <= 0.2 + 1e-9;
  });
}

// Octile distance (m) between two cells' centres, the exact walking distance on an open floor.
double Octile(const WorldPoint& a, const WorldPoint& b) {
  const double dx = std::abs(a.x() - b.x()), dy = std::abs(a.y() - b.y());
  return std::max(dx, dy) - std::min(dx, dy) + std::min(dx, dy) * std::sqrt(2.0);
}

double BruteForce(const OpenPathProblem& p) {
  std::vector<int> perm(p.n);
  std::iota(perm.begin(), perm.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {
    best = std::min(best, OpenPathLength(p, perm));
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

OpenPathProblem Euclidean(const std::vector<Eigen::Vector2d>& pts, const std::optional<Eigen::Vector2d>& start) {
  OpenPathProblem p;
  p.n = int(pts.size());
  for (const auto& a : pts) {
    for (const auto& b : pts) p.distance_m.push_back((a - b).norm());
  }
  if (start) {
    for (const auto& a : pts) p.from_start_m.push_back((a - *start).norm());
  }
  return p;
}

TEST(OpenPathTest, OrOptFixesTheStationNearestNeighbourLeavesBehind) {
  // From the start at 0: NN walks 1, 3, 5 and then back to -1.1 (11.1 m); -1.1 first is 7.2 m.
  const OpenPathProblem p = Euclidean({{1, 0}, {3, 0}, {5, 0}, {-1.1, 0}}, Eigen::Vector2d(0, 0));
  const std::vector<int> nn = NearestNeighbourPath(p, -1);
  EXPECT_EQ(nn, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_NEAR(OpenPathLength(p, nn), 11.1, 1e-9);
  const std::vector<int> better = ImprovePath(p, nn);
  EXPECT_EQ(better, (std::vector<int>{3, 0, 1, 2}));
  EXPECT_NEAR(OpenPathLength(p, better), 7.2, 1e-9);
}

TEST(OpenPathTest, TwoOptUncrossesAPath) {
  // A 2 x 1 grid walked 0 -> 3 -> 1 -> 2 crosses itself; uncrossed it is 0 -> 1 -> 3 -> 2 ... length 3.
  const OpenPathProblem p = Euclidean({{0, 0}, {1, 0}, {0, 1}, {1, 1}}, std::nullopt);
  const std::vector<int> crossed{0, 3, 1, 2};
  const std::vector<int> fixed = ImprovePath(p, crossed);
  EXPECT_GT(OpenPathLength(p, crossed), 3.8);
  EXPECT_NEAR(OpenPathLength(p, fixed), 3.0, 1e-9);
}

TEST(OpenPathTest, HeuristicMatchesExhaustiveSearchOnSmallInstances) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 10);
  int exact = 0, total = 0;
  double worst = 1;
  for (int trial = 0; trial < 60; ++trial) {
    const int n = 3 + trial % 6;  // 3..8
    std::vector<Eigen::Vector2d> pts(n);
    for (auto& q : pts) q = {u(rng), u(rng)};
    std::optional<Eigen::Vector2d> start;
    if (trial % 2) {
      // Drawn in a fixed order (y first, as GCC evaluated the arguments Vector2d(u(rng), u(rng)),
      // whose order C++ leaves unspecified: under clang the instances were others).
      const double y = u(rng), x = u(rng);
      start = Eigen::Vector2d(x, y);
    }
    const OpenPathProblem p = Euclidean(pts, start);
    const Result<std::vector<int>> ordered = OrderOpenPath(p);
    ASSERT_TRUE(ordered.ok()) << ordered.status().ToString();
    const std::vector<int>& order = *ordered;
    std::vector<int> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < n; ++i) ASSERT_EQ(sorted[i], i);
    const double opt = BruteForce(p), got = OpenPathLength(p, order);
    EXPECT_LE(got, opt * 1.03 + 1e-9) << "trial " << trial;
    if (n <= 4) {
      EXPECT_NEAR(got, opt, 1e-9) << "trial " << trial;
    }
    worst = std::max(worst, got / opt);
    exact += got <= opt + 1e-9;
    ++total;
  }
  std::cout << "[ open path ] optimal in " << exact << " of " << total << ", worst ratio " << worst << "\n";
  EXPECT_GE(exact, total * 9 / 10);
}

TEST(OpenPathTest, NeighbourListMovesFixWhatTheFullMovesFix) {
  // The two cases above, with moves only among each point's 2 nearest.
  const OpenPathProblem behind = Euclidean({{1, 0}, {3, 0}, {5, 0}, {-1.1, 0}}, Eigen::Vector2d(0, 0));
  Result<std::vector<int>> better = ImprovePathNear(behind, NearestNeighbourPath(behind, -1), 2);
  ASSERT_TRUE(better.ok());
  EXPECT_EQ(*better, (std::vector<int>{3, 0, 1, 2}));
  const OpenPathProblem square = Euclidean({{0, 0}, {1, 0}, {0, 1}, {1, 1}}, std::nullopt);
  Result<std::vector<int>> fixed = ImprovePathNear(square, {0, 3, 1, 2}, 2);
  ASSERT_TRUE(fixed.ok());
  EXPECT_NEAR(OpenPathLength(square, *fixed), 3.0, 1e-9);
}

// Above kExhaustiveOrderMax points: kLargeOrderRestarts restarts with neighbour-list moves, within
// 3 % of the full moves from one start (600 random points in a 100 x 100 m square; the exhaustive
// rule, n restarts of the full moves, would take minutes), with and without a start.
TEST(OpenPathTest, LargeInstancesUseNeighbourListsAndStayClose) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 100);
  std::vector<Eigen::Vector2d> pts(600);
  for (auto& q : pts) {
    const double x = u(rng), y = u(rng);
    q = {x, y};
  }
  ASSERT_GT(int(pts.size()), kExhaustiveOrderMax);
  for (const std::optional<Eigen::Vector2d>& start : {std::optional<Eigen::Vector2d>(), std::optional(pts[0])}) {
    const OpenPathProblem p = Euclidean(pts, start);
    const auto t0 = std::chrono::steady_clock::now();
    const Result<std::vector<int>> order = OrderOpenPath(p);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(order.ok()) << order.status().ToString();
    std::vector<int> sorted = *order;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < p.n; ++i) ASSERT_EQ(sorted[i], i);
    const double full = OpenPathLength(p, ImprovePath(p, NearestNeighbourPath(p, start ? -1 : 0)));
    const double got = OpenPathLength(p, *order), nn = OpenPathLength(p, NearestNeighbourPath(p, start ? -1 : 0));
    std::cout << "[ open path, 600 points" << (start ? ", from a start" : "") << " ] " << got << " m in " << seconds
              << " s; full moves from one start " << full << " m; nearest neighbour " << nn << " m\n";
    EXPECT_LE(got, full * 1.03);
    EXPECT_LT(got, nn * 0.95);
  }
}

TEST(OpenPathTest, LargeOrderingIsCancellable) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 100);
  std::vector<Eigen::Vector2d> pts(kExhaustiveOrderMax + 50);
  for (auto& q : pts) {
    const double x = u(rng), y = u(rng);
    q = {x, y};
  }
  CancelToken cancel;
  cancel.Cancel();
  JobContext ctx;
  ctx.cancel = &cancel;
  EXPECT_EQ(OrderOpenPath(Euclidean(pts, std::nullopt), ctx).status().code(), StatusCode::kCancelled);
}

// A 10 x 10 m open floor (slab at z 0), nothing else.
VoxelScene OpenFloor() {
  Builder b;
  b.Box(0, 0, 0, 99, 99, 0);
  return b.Build();
}

TEST(RouteTest, OpenFloorRouteIsOptimalAndLegsAreOctileDistances) {
  const VoxelScene s = OpenFloor();
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> u(5, 94);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<WorldPoint> st(8);
    for (auto& p : st) {
      const int y = u(rng), x = u(rng);  // a fixed order, as in HeuristicMatchesExhaustiveSearch...
      p = At(x, y);
    }
    const Route r = Plan(s, st);
    ExpectPermutation(r, 8);
    EXPECT_EQ(r.parts, 1);
    for (int k = 1; k < 8; ++k) EXPECT_NEAR(r.legs_m[k], Octile(st[r.order[k - 1]], st[r.order[k]]), 1e-4);
    OpenPathProblem p;
    p.n = 8;
    for (const auto& a : st)
      for (const auto& b : st) p.distance_m.push_back(Octile(a, b));
    const double opt = BruteForce(p);
    EXPECT_LE(r.length_m, opt * 1.03 + 1e-4);
    EXPECT_GE(r.length_m, opt - 1e-4);
  }
}

TEST(RouteTest, StartPicksTheWalkablyNearestStationFirst) {
  const VoxelScene s = TwoRooms();
  RouteOptions o;
  // Start in room A by the wall at eye height; station 0 is 0.9 m away behind the wall, station 1 2.5 m away in room A.
  o.start = WorldPoint(3.55, 1.05, 1.6);
  const Route r = Plan(s, {At(44, 10), At(10, 10)}, o);
  ASSERT_EQ(r.order.size(), 2u);
  EXPECT_EQ(r.order[0], 1);
  EXPECT_NEAR(r.legs_m[0], 2.5, 1e-6);
  ASSERT_FALSE(r.polylines[0].empty());
  EXPECT_NEAR(r.polylines[0].front().x(), 3.55, 1e-9);
  EXPECT_NEAR(r.polylines[0].front().z(), 0.1, 1e-9);
  EXPECT_NEAR(r.length_m, r.legs_m[0] + r.legs_m[1], 1e-9);
}

// A 6 x 2 m floor strip (x 0..59, y 0..19) cut across at x 30 .. 30 + gap - 1.
VoxelScene CutFloor(int gap_voxels, bool wall) {
  Builder b;
  b.Box(0, 0, 0, 59, 19, 0);
  b.Erase(30, 0, 0, 29 + gap_voxels, 19, 0);
  if (wall) b.Box(30, 0, 0, 30, 19, 25);
  return b.Build();
}

TEST(RouteTest, SmallFloorHolesAreBridged) {
  const std::vector<WorldPoint> st{At(10, 10), At(50, 10)};
  Route r = Plan(CutFloor(4, false), st);  // 0.4 m
  EXPECT_EQ(r.parts, 1);
  EXPECT_NEAR(r.legs_m[1], 4.0, 1e-6);
  EXPECT_GT(r.bridged_nodes, 0u);
  // A 2D shadow inside the floor too.
  Builder b;
  b.Box(0, 0, 0, 59, 19, 0);
  b.Erase(20, 5, 0, 24, 15, 0);
  r = Plan(b.Build(), {At(10, 10), At(40, 10)});
  EXPECT_EQ(r.parts, 1);
  EXPECT_NEAR(r.legs_m[1], 3.0, 1e-6);  // straight across the hole
}

// A 6 x 2 m floor slab (z index 0) closed by walls 2.5 m high.
Builder ClosedFloor() {
  Builder b;
  b.Box(0, 0, 0, 59, 19, 0);
  b.Box(0, 0, 0, 59, 0, 25);
  b.Box(0, 19, 0, 59, 19, 25);
  b.Box(0, 0, 0, 0, 19, 25);
  b.Box(59, 0, 0, 59, 19, 25);
  return b;
}

TEST(RouteTest, WideGapsAndWallsAreNotBridged) {
  // Unseen floor is walked on within max_gap_m (0.5 m) of a seen one: a cut up to about 1 m is
  // crossed (0.8 m here), a 1.2 m one is not (its middle is 0.6 m from either edge).
  const std::vector<WorldPoint> st{At(10, 10), At(50, 10)};
  Route r = Plan(CutFloor(8, false), st);
  EXPECT_EQ(r.parts, 1);
  r = Plan(CutFloor(12, false), st);
  EXPECT_EQ(r.parts, 2);
  EXPECT_TRUE(std::isnan(r.legs_m[1]));
  RouteOptions narrow;
  narrow.max_gap_m = 0.3;
  r = Plan(CutFloor(8, false), st, narrow);
  EXPECT_EQ(r.parts, 2);
  // A wall across an intact floor, in a closed room (open sides would let the walk go round the
  // wall's ends over the unseen floor beyond the scan).
  Builder walled = ClosedFloor();
  walled.Box(30, 0, 0, 30, 19, 25);
  r = Plan(walled.Build(), st);
  EXPECT_EQ(r.parts, 2);
}

// ClosedFloor split by a wall at x 30 with a doorway (y 6..13) whose sill rises `sill_voxels`.
VoxelScene DoorWithSill(int sill_voxels) {
  Builder b = ClosedFloor();
  b.Box(30, 0, 0, 30, 19, 25);
  b.Erase(30, 6, 1, 30, 13, 25);
  if (sill_voxels > 0) b.Box(30, 6, 1, 30, 13, sill_voxels);
  return b.Build();
}

TEST(RouteTest, SillsUpToTheStepAreWalkedOverHigherOnesSplit) {
  const std::vector<WorldPoint> st{At(10, 10), At(50, 10)};
  Route r = Plan(DoorWithSill(2), st);  // 0.2 m, below max_step_m (0.25 m)
  EXPECT_EQ(r.parts, 1);
  EXPECT_GT(r.legs_m[1], 4.0);
  EXPECT_LT(r.legs_m[1], 4.5);
  double top = 0;
  for (const WorldPoint& p : r.polylines[1]) top = std::max(top, p.z());
  EXPECT_NEAR(top, 0.3, 1e-9);    // over the sill
  r = Plan(DoorWithSill(3), st);  // 0.3 m
  EXPECT_EQ(r.parts, 2);
  // One message for the split, saying where the walk stops and why.
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("station 1 (floor z = 0.10 m) not linked"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("0.60 m from the others'"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("something 0.30 m high between"), std::string::npos) << r.warnings[0];
  RouteOptions higher;
  higher.max_step_m = 0.35;
  r = Plan(DoorWithSill(3), st, higher);
  EXPECT_EQ(r.parts, 1);
}

// A 6 x 2 m strip: floor (slab z 0) for x < 20, a solid ramp over x 20..39 whose top rises
// `rise_voxels` every `run` columns, and a landing at its top height for x >= 40.
VoxelScene Ramp(int rise_voxels, int run) {
  Builder b;
  b.Box(0, 0, 0, 59, 19, 0);
  int top = 0;
  for (int x = 20; x < 40; ++x) {
    top = (x - 19) / run * rise_voxels;
    b.Box(x, 0, 0, x, 19, top);
  }
  b.Box(40, 0, 0, 59, 19, top);
  return b.Build();
}

TEST(RouteTest, RampsAreWalkedUpAndStepsHigherThanTheStepAreNot) {
  RouteOptions seen_only;  // no walk round the strip's ends over the unseen ground beside it
  seen_only.max_gap_m = 0;
  // 1 m up over 2 m (0.1 m every 0.2 m): one walk, up the ramp.
  Route r = Plan(Ramp(1, 2), {At(10, 10), At(50, 10, 1.1)}, seen_only);
  EXPECT_EQ(r.parts, 1);
  EXPECT_GT(r.legs_m[1], std::hypot(4.0, 1.0) - 1e-9);
  EXPECT_LT(r.legs_m[1], 4.5);
  // 0.3 m every 0.4 m: a flight of steps each higher than max_step_m.
  r = Plan(Ramp(3, 4), {At(10, 10), At(50, 10, 1.6)}, seen_only);
  EXPECT_EQ(r.parts, 2);
}

// A 6 x 2 m floor (slab at z 5, top 0.6 m) with a trench across it at x 30 .. 29 + width whose
// bottom (z 0) the scan saw: a drain, a duct, a gap between two slabs.
VoxelScene Trench(int width_voxels) {
  Builder b;
  b.Box(0, 0, 5, 59, 19, 5);
  b.Erase(30, 0, 5, 29 + width_voxels, 19, 5);
  b.Box(30, 0, 0, 29 + width_voxels, 19, 0);
  return b.Build();
}

TEST(RouteTest, GapsOfAVoxelOrTwoAreNotWalls) {
  const std::vector<WorldPoint> st{At(10, 10, 0.6), At(50, 10, 0.6)};
  for (int width : {1, 2}) {
    const Route r = Plan(Trench(width), st);
    EXPECT_EQ(r.parts, 1) << width;
    EXPECT_NEAR(r.legs_m[1], 4.0, 1e-6) << width;  // straight across, at the floor's height
    ExpectOnWalkable(r, [](const WorldPoint& p) { return std::abs(p.z() - 0.6) < 1e-9; });
  }
  EXPECT_EQ(Plan(Trench(3), st).parts, 2);
  // A wall one voxel thick is not a gap, and the message says so.
  Builder walled = ClosedFloor();
  walled.Box(30, 0, 0, 30, 19, 25);
  const Route r = Plan(walled.Build(), {At(10, 10), At(50, 10)});
  EXPECT_EQ(r.parts, 2);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("at about the same height, with a wall"), std::string::npos) << r.warnings[0];
}

TEST(RouteTest, StationOnClutterOverUnseenFloorJoinsTheFloorAroundIt) {
  // geb079's lone station: a room whose floor the scan never saw (x >= 30), the station over a
  // low box (0.2 m, top 0.3 m) in it, and the seen floor's lowest voxel a voxel below the rest (a
  // noise voxel), so the unseen floor is bridged at 0.0 m, 0.3 m below the box's top.
  Builder b;
  b.Box(0, 0, 0, 29, 19, 0);
  b.Box(25, 10, -1, 25, 10, -1);
  b.Erase(25, 10, 0, 25, 10, 0);
  b.Box(33, 9, 1, 35, 11, 2);
  RouteOptions o;
  o.max_gap_m = 1.5;  // the planner's settings (docs/PLANNING.md, "The walking route")
  o.max_blocked_fraction = 0.35;
  const Route r = Plan(b.Build(), {At(10, 10), At(34, 10, 0.3)}, o);
  EXPECT_EQ(r.parts, 1);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings[0];
  EXPECT_TRUE(std::isfinite(r.legs_m[1]));
}

TEST(RouteTest, UnseenFloorIsNeverBridgedAboveASeenOne) {
  // A closed room with a platform 0.5 m high in one half: the air over the floor next to the
  // platform is within max_gap_m of the platform's top, but the floor below it was seen.
  Builder b = ClosedFloor();
  b.Box(30, 0, 1, 59, 19, 5);
  const Route r = Plan(b.Build(), {At(10, 10), At(50, 10, 0.6)});
  EXPECT_EQ(r.parts, 2);  // no walk up through the air beside the platform
}

TEST(RouteTest, SpaceTheScanNeverObservedIsWalkedOnlyWhereNothingElseLinks) {
  // One open floor 6 x 2 m; a band across it (x 2.5 to 3.5 m) is space the scan never observed
  // (a wall it may have missed), except a 0.4 m gap near y = 1.8 m.
  Builder b;
  b.Box(0, 0, 0, 59, 19, 0);
  const VoxelScene s = b.Build();
  const std::vector<WorldPoint> st{At(10, 3), At(50, 3)};
  const Route plain = Plan(s, st);
  EXPECT_NEAR(plain.legs_m[1], 4.0, 1e-6);  // straight across
  RouteOptions o;
  o.known_free = [](const WorldPoint& p) { return p.x() < 2.5 || p.x() > 3.5 || p.y() > 1.6; };
  const Route careful = Plan(s, st, o);
  EXPECT_EQ(careful.parts, 1);
  // Through the gap: up to y ~1.6 m and back, longer than 4 m, and a true length.
  EXPECT_GT(careful.legs_m[1], 4.5);
  double top = 0;
  for (const WorldPoint& p : careful.polylines[1]) top = std::max(top, p.y());
  EXPECT_GT(top, 1.6);
  double length = 0;
  for (size_t k = 1; k < careful.polylines[1].size(); ++k) {
    length += (careful.polylines[1][k] - careful.polylines[1][k - 1]).norm();
  }
  EXPECT_NEAR(careful.legs_m[1], length, 1e-9);
  // With no gap at all, the unknown band is crossed (nothing else links), straight.
  o.known_free = [](const WorldPoint& p) { return p.x() < 2.5 || p.x() > 3.5; };
  const Route forced = Plan(s, st, o);
  EXPECT_EQ(forced.parts, 1);
  EXPECT_NEAR(forced.legs_m[1], 4.0, 1e-6);
}

TEST(RouteTest, SameInputSameRoute) {
  const VoxelScene s = TwoRooms();
  const std::vector<WorldPoint> st{At(10, 10), At(70, 10), At(30, 30), At(60, 35), At(20, 20), At(75, 30)};
  const Route a = Plan(s, st), b = Plan(s, st);
  EXPECT_EQ(a.order, b.order);
  EXPECT_EQ(a.legs_m, b.legs_m);
  EXPECT_EQ(a.polylines, b.polylines);
}

TEST(RouteTest, StationWithoutAWalkableCellIsItsOwnPart) {
  const VoxelScene s = TwoRooms();
  // Station 1 stands inside the solid block outside the rooms, on nothing walkable.
  const Route r = Plan(s, {At(10, 10), WorldPoint(8.5, 2, 1.6), At(20, 10)});
  ExpectPermutation(r, 3);
  EXPECT_EQ(r.parts, 2);
  ASSERT_EQ(r.warnings.size(), 1u);  // once, for the station, not again for its part
  EXPECT_NE(r.warnings[0].find("station 1 has no floor below it"), std::string::npos) << r.warnings[0];
}

TEST(RouteTest, NoStationsIsAnEmptyRoute) {
  const Route r = Plan(OpenFloor(), {});
  EXPECT_TRUE(r.order.empty());
  EXPECT_EQ(r.parts, 0);
}

TEST(RouteTest, NonFiniteInputIsInvalidArgument) {
  const VoxelScene s = OpenFloor();
  EXPECT_EQ(PlanRoute(s, {WorldPoint(NAN, 0, 1)}, {}, {}).status().code(), StatusCode::kInvalidArgument);
  RouteOptions o;
  o.max_step_m = INFINITY;
  EXPECT_EQ(PlanRoute(s, {At(5, 5)}, {}, o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.start = WorldPoint(0, NAN, 0);
  EXPECT_EQ(PlanRoute(s, {At(5, 5)}, {}, o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.cell_m = 1.0;  // coarser than twice the clearance
  EXPECT_EQ(PlanRoute(s, {At(5, 5)}, {}, o).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(PlanRoute(s, {At(5, 5)}, {0.1, 0.1}, {}).status().code(), StatusCode::kInvalidArgument);
}

TEST(RouteTest, CoarserCellsStillFollowTheCorridor) {
  RouteOptions o;
  o.cell_m = 0.4;
  const Route r = Plan(LCorridor(), {At(10, 7), At(51, 50)}, o);
  EXPECT_EQ(r.parts, 1);
  EXPECT_NEAR(r.cell_m, 0.4, 1e-9);
  EXPECT_GT(r.legs_m[1], 7.0);
}

TEST(RouteTest, OverTheMemoryBudgetIsResourceExhausted) {
  RouteOptions o;
  o.memory_budget_bytes = 20000;
  const Result<Route> r = PlanRoute(OpenFloor(), {At(5, 5)}, {}, o);
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_NE(r.status().message().find("cell_m"), std::string::npos);
}

// The sloping site (vc-synth slope: 0.1 m terraces every 1 m, a 1:10 slope) at 0.4 m voxels,
// coarser than the 0.25 m step: the ground rises a voxel (0.4 m) every 4 m, which is still a
// walkable slope, so the route climbs it in one walk along the site's free edge (y = 27.5 m);
// the roof of building B (5 m above the ground) stays a part of its own. Before, the step in
// voxels was 0 at this resolution and every voxel of rise split the route (3 parts here without
// bridging; fr_campus at 0.4 m).
TEST(RouteTest, SlopeAtVoxelsCoarserThanTheStepIsOneWalk) {
  VoxelizeOptions vo;
  vo.resolution_m = 0.4;
  Result<VoxelScene> scene = Voxelize(testing::Synthetic("slope"), vo);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  auto station = [](double x, double y, double ground_m) -> WorldPoint {
    return kSceneOffsetM + WorldPoint(x, y, ground_m + 1.5);
  };
  const std::vector<WorldPoint> slope{station(1.5, 27.5, 0.1), station(20.5, 27.5, 2.0), station(38.5, 27.5, 3.8)};
  RouteOptions seen_only;  // no bridging, whose extra voxel of step would hide the defect
  seen_only.max_gap_m = 0;
  const Route up = Plan(*scene, slope, seen_only);
  EXPECT_EQ(up.parts, 1);
  EXPECT_EQ(up.order, (std::vector<int>{0, 1, 2}));
  EXPECT_GT(up.length_m, 37.0);
  EXPECT_LT(up.length_m, 40.0);
  EXPECT_TRUE(up.warnings.empty()) << up.warnings.front();
  std::vector<WorldPoint> with_roof = slope;
  with_roof.push_back(station(28, 20, 8.0));
  const Route roof = Plan(*scene, with_roof, seen_only);
  EXPECT_EQ(roof.parts, 2);
  ASSERT_EQ(roof.warnings.size(), 1u);
  EXPECT_NE(roof.warnings[0].find("station 3 "), std::string::npos) << roof.warnings[0];
  EXPECT_NE(roof.warnings[0].find("lower"), std::string::npos) << roof.warnings[0];
}

// The distances between stations count against the budget too (16 bytes a pair): 400 stations
// on the open floor need 2.4 MiB, its walk graph under 1 MiB.
TEST(RouteTest, DistancesOverTheMemoryBudgetAreResourceExhausted) {
  std::vector<WorldPoint> stations;
  for (int i = 0; i < 400; ++i) stations.push_back(At(5 + (i % 20) * 4, 5 + (i / 20) * 4));
  RouteOptions o;
  o.memory_budget_bytes = 2 << 20;
  const Result<Route> r = PlanRoute(OpenFloor(), stations, {}, o);
  ASSERT_EQ(r.status().code(), StatusCode::kResourceExhausted) << r.status().ToString();
  EXPECT_NE(r.status().message().find("distances between 400 stations"), std::string::npos) << r.status().message();
  o.memory_budget_bytes = 4 << 20;
  EXPECT_TRUE(PlanRoute(OpenFloor(), stations, {}, o).ok());
}

TEST(RouteTest, CancelledIsCancelled) {
  CancelToken cancel;
  cancel.Cancel();
  JobContext ctx;
  ctx.cancel = &cancel;
  EXPECT_EQ(PlanRoute(OpenFloor(), {At(5, 5), At(50, 50)}, {}, {}, ctx).status().code(), StatusCode::kCancelled);
}

// Real data: a route through 15 spread-out candidates of geb079's lowest level (a smoke test).
TEST(RouteTest, Geb079CandidatesSmoke) {
  Result<SceneInput> in = ReadSceneFile(testing::SharedDataPath("geb079/geb079.bt"));
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  Result<VoxelScene> scene = Voxelize(*in, {});
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  Result<CandidateGrid> c = GenerateCandidates(*scene, {});
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  EXPECT_EQ(c->ground.model, GroundModel::kFloors) << c->ground.reason;
  // Farthest-point sampling over the level-0 candidates, from the first.
  std::vector<int> pool;
  for (size_t i = 0; i < c->positions.size(); ++i)
    if (c->level[i] == 0) pool.push_back(int(i));
  ASSERT_GE(pool.size(), 15u);
  std::vector<int> pick{pool[0]};
  std::vector<double> near(c->positions.size(), std::numeric_limits<double>::infinity());
  while (pick.size() < 15) {
    int best = -1;
    for (int i : pool) {
      near[i] = std::min(near[i], (c->positions[i] - c->positions[pick.back()]).norm());
      if (best < 0 || near[i] > near[best]) best = i;
    }
    pick.push_back(best);
  }
  std::vector<WorldPoint> st;
  std::vector<double> floor;
  for (int i : pick) {
    st.push_back(c->positions[i]);
    floor.push_back(c->floor_z_m[i]);
  }
  const auto t0 = std::chrono::steady_clock::now();
  RouteOptions ro;
  ro.max_gap_m = 1.5;  // what the planner passes (docs/PLANNING.md, "The walking route")
  ro.max_blocked_fraction = 0.35;
  Result<Route> r = PlanRoute(*scene, st, floor, ro);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  std::cout << "[ geb079 ] " << c->positions.size() << " candidates; walk grid " << r->walk_cells << " cells of "
            << r->cell_m << " m, " << r->walk_nodes << " walk nodes (" << r->bridged_nodes << " bridged); route "
            << r->length_m << " m in " << r->parts << " part(s); " << ms << " ms\n";
  for (const std::string& w : r->warnings) std::cout << "  warning: " << w << "\n";
  ExpectPermutation(*r, 15);
  // One walk with the planner's settings. geb079's office floors were mostly not seen (the scanner
  // looked in from the corridor) and hold clutter: with the strict defaults (all of the walking
  // cylinder free, 0.5 m of unseen floor) the route fell into 10 parts.
  EXPECT_EQ(r->parts, 1);
  EXPECT_EQ(std::count_if(r->legs_m.begin(), r->legs_m.end(), [](double l) { return std::isnan(l); }), r->parts - 1);
  // The station the default plan left apart before #35 (number 23 of 69): in an office whose
  // floor was never seen, over a box top 0.16 m high among clutter.
  st.push_back(WorldPoint(23.98, -4.54, 1.66));
  floor.push_back(0.16);
  r = PlanRoute(*scene, st, floor, ro);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->parts, 1) << (r->warnings.empty() ? "" : r->warnings[0]);
}

}  // namespace
}  // namespace vc::planner
