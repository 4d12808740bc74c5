// RefineLocally on a hand-built room with made-up visibility sets: a position between grid points
// that sees what two grid candidates see between them is found around the picks, and the loop
// stops when a solve no longer improves.
#include "vc/plan/local_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include "testing/scenes.h"
#include "vc/synth/synth.h"

namespace vc::planner {
namespace {

constexpr size_t kVoxels = 10;

// A closed 5 x 4 x 2.6 m room at 0.1 m.
VoxelScene Room() {
  testing::VoxelBuilder b;
  b.Box(0, 0, 0, 49, 39, 0);
  b.Box(0, 0, 0, 0, 39, 25);
  b.Box(49, 0, 0, 49, 39, 25);
  b.Box(0, 0, 0, 49, 0, 25);
  b.Box(0, 39, 0, 49, 39, 25);
  b.Box(0, 0, 25, 49, 39, 25);
  return b.Build(0.1);
}

// Made-up sets over kVoxels voxels: within 0.05 m (x, y) of `all` a position sees every voxel, at
// `left` voxels 0-4, at `right` voxels 5-9, elsewhere none.
struct FakeVisibility {
  WorldPoint all, left, right;
  int calls = 0;
  Result<std::vector<VoxelSet>> operator()(const std::vector<WorldPoint>& positions) {
    ++calls;
    std::vector<VoxelSet> sets(positions.size(), VoxelSet(kVoxels));
    auto near = [](const WorldPoint& a, const WorldPoint& b) { return (a - b).head<2>().norm() < 0.05; };
    for (size_t i = 0; i < positions.size(); ++i) {
      for (size_t v = 0; v < kVoxels; ++v) {
        if (near(positions[i], all) || (near(positions[i], left) && v < 5) || (near(positions[i], right) && v >= 5)) {
          sets[i].set(v);
        }
      }
    }
    return sets;
  }
};

// Any selector: greedy, counting its calls.
class CountingSelector final : public Selector {
 public:
  using Selector::Select;
  Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed, const JobContext& ctx) const override {
    ++calls;
    return GreedySelector(GreedyOptions{}).Select(sets, fixed, ctx);
  }
  mutable int calls = 0;
};

struct Fixture {
  VoxelScene scene = Room();
  CandidateGrid grid;
  FakeVisibility fake;
  CandidateSets in;
  Fixture() {
    Result<CandidateGrid> g = GenerateCandidates(scene, CandidateOptions{});
    EXPECT_TRUE(g.ok());
    grid = *g;
    fake.left = grid.positions[0];
    fake.right = grid.positions[1];
    fake.all = grid.positions[0] + WorldPoint(0.25, 0.25, 0);  // on the sub-grid around `left`
    in.positions = grid.positions;
    in.floor_z_m = grid.floor_z_m;
    in.sets = *fake(in.positions);
  }
};

TEST(LocalRefinementTest, FindsOneStationBetweenGridPointsWhereTwoWereNeeded) {
  Fixture s;
  CountingSelector selector;
  const VisibilityFn fn = [&](const std::vector<WorldPoint>& p) { return s.fake(p); };
  Result<LocalRefinementResult> r =
      RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, LocalRefinementOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->stations_per_solve, (std::vector<int>{2, 1, 1}));  // improved once, then no longer
  EXPECT_EQ(r->rounds, 2);
  EXPECT_EQ(selector.calls, 3);
  ASSERT_EQ(r->selection.picks.size(), 1u);
  const WorldPoint& p = r->candidates.positions[r->selection.picks[0]];
  EXPECT_LT((p - s.fake.all).head<2>().norm(), 1e-9);
  EXPECT_NEAR(p.z(), s.grid.positions[0].z(), 1e-9);  // same height above the same floor
  EXPECT_EQ(r->candidates.positions.size(), s.in.positions.size() + static_cast<size_t>(r->added));
  EXPECT_EQ(r->candidates.sets.size(), r->candidates.positions.size());
  // Round 1 adds the 5 x 5 sub-grids around both picks less the picks; none within a step of a
  // grid candidate or of each other, none without clearance.
  EXPECT_GT(r->added, 0);
  for (size_t i = s.in.positions.size(); i < r->candidates.positions.size(); ++i) {
    EXPECT_TRUE(HasClearance(s.scene.grid, r->candidates.positions[i], 0.2));
  }
}

// A keep-out zone around the one position that sees everything: no position is added inside it,
// so the loop cannot find that station and the two grid picks stay.
TEST(LocalRefinementTest, NoPositionIsAddedInsideAKeepOutZone) {
  Fixture s;
  CountingSelector selector;
  const VisibilityFn fn = [&](const std::vector<WorldPoint>& p) { return s.fake(p); };
  LocalRefinementOptions o;
  const WorldPoint& a = s.fake.all;
  o.keep_out = {KeepOutBox(a - WorldPoint(0.1, 0.1, 5), a + WorldPoint(0.1, 0.1, 5))};
  Result<LocalRefinementResult> r = RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_GT(r->added, 0);
  for (size_t i = s.in.positions.size(); i < r->candidates.positions.size(); ++i) {
    EXPECT_LT(KeepOutZoneContaining(o.keep_out, r->candidates.positions[i]), 0) << "position " << i;
  }
  EXPECT_EQ(r->selection.picks.size(), 2u);
  EXPECT_EQ(r->stations_per_solve, (std::vector<int>{2, 2}));
}

// Returns the scripted selections in turn (then the last one again), whatever the sets.
class ScriptedSelector final : public Selector {
 public:
  explicit ScriptedSelector(std::vector<Selection> script) : script_(std::move(script)) {}
  using Selector::Select;
  Result<Selection> Select(const std::vector<VoxelSet>&, int, const JobContext&) const override {
    const size_t k = std::min(calls_++, script_.size() - 1);
    return script_[k];
  }

 private:
  std::vector<Selection> script_;
  mutable size_t calls_ = 0;
};

Selection Scripted(std::vector<int> picks, uint64_t covered, uint64_t coverable) {
  Selection s;
  s.picks = std::move(picks);
  s.covered = covered;
  s.coverable = coverable;
  return s;
}

// Fewer stations short of the target (a max_stations plan, a solve cut off at the deadline) do not
// replace a plan that reaches it; more coverage short of the target does replace less.
TEST(LocalRefinementTest, ASolveReachingTheTargetBeatsFewerStationsShortOfIt) {
  Fixture s;
  const VisibilityFn fn = [&](const std::vector<WorldPoint>& p) { return s.fake(p); };
  LocalRefinementOptions o;
  o.target_coverage = 0.9;
  {
    const ScriptedSelector selector({Scripted({0, 1}, 10, 10), Scripted({0}, 5, 10)});
    Result<LocalRefinementResult> r = RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, o);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->selection.picks, (std::vector<int>{0, 1}));
    EXPECT_EQ(r->stations_per_solve, (std::vector<int>{2, 1}));
  }
  {
    const ScriptedSelector selector({Scripted({0}, 5, 10), Scripted({0, 1}, 8, 10), Scripted({1}, 8, 10)});
    Result<LocalRefinementResult> r = RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, o);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->selection.picks, (std::vector<int>{1}));           // 5 -> 8 covered, then as much with one station
    EXPECT_EQ(r->stations_per_solve, (std::vector<int>{1, 2, 1}));  // then no new position around it: stop
  }
}

TEST(LocalRefinementTest, MaxAddedBoundsThePositionsAndSaysSo) {
  Fixture s;
  CountingSelector selector;
  const VisibilityFn fn = [&](const std::vector<WorldPoint>& p) { return s.fake(p); };
  LocalRefinementOptions o;
  o.max_added = 3;
  Result<LocalRefinementResult> r = RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->added, 3);
  EXPECT_TRUE(r->limited);
  EXPECT_EQ(r->candidates.positions.size(), s.in.positions.size() + 3);
  o.max_added = 0;
  r = RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->added, 0);
  EXPECT_EQ(r->rounds, 0);
}

TEST(LocalRefinementTest, NoRoundsKeepsTheFirstSolve) {
  Fixture s;
  CountingSelector selector;
  const VisibilityFn fn = [&](const std::vector<WorldPoint>& p) { return s.fake(p); };
  LocalRefinementOptions o;
  o.max_rounds = 0;
  Result<LocalRefinementResult> r = RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->selection.picks.size(), 2u);
  EXPECT_EQ(r->added, 0);
  EXPECT_EQ(selector.calls, 1);
}

TEST(LocalRefinementTest, BadOptionsOrMismatchedInputsAreInvalidArgument) {
  Fixture s;
  CountingSelector selector;
  const VisibilityFn fn = [&](const std::vector<WorldPoint>& p) { return s.fake(p); };
  LocalRefinementOptions o;
  o.step_m = 0.75;  // more than the radius
  EXPECT_EQ(RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, o).status().code(),
            StatusCode::kInvalidArgument);
  CandidateSets short_floors = s.in;
  short_floors.floor_z_m.pop_back();
  LocalRefinementOptions bad_hood;
  bad_hood.neighbourhood_m = std::nan("");
  EXPECT_EQ(RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, bad_hood).status().code(),
            StatusCode::kInvalidArgument);
  bad_hood.neighbourhood_m = -1;
  EXPECT_EQ(RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, bad_hood).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(RefineLocally(selector, s.scene, short_floors, 0, CandidateOptions{}, fn, {}).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(selector.calls, 0);
}

TEST(LocalRefinementTest, VisibilityErrorsPassThrough) {
  Fixture s;
  CountingSelector selector;
  const VisibilityFn fn = [](const std::vector<WorldPoint>&) -> Result<std::vector<VoxelSet>> {
    return ResourceExhaustedError("no memory for the new sets");
  };
  Result<LocalRefinementResult> r = RefineLocally(selector, s.scene, s.in, 0, CandidateOptions{}, fn, {});
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
}

// The neighbourhood rule (coarse then fine), on made-up sets over 12 voxels: candidate `a` sees
// voxels 0-4, `b` (the candidate farthest from it) 5-9, and `c` (a grid neighbour of `a`) voxel 10
// alone, which a greedy needing gains of 2 leaves uncovered (voxel 11 no one sees). So only `a`'s
// neighbourhood can still gain.
struct NeighbourhoodFixture {
  static constexpr size_t kN = 12;
  Fixture s;
  int a = 0, b = 0, c = -1;
  GreedySelector selector{[] {
    GreedyOptions g;
    g.min_marginal_gain_voxels = 2;
    return g;
  }()};
  NeighbourhoodFixture() {
    const std::vector<WorldPoint>& p = s.in.positions;
    auto dist = [&](int i, int j) { return (p[i] - p[j]).head<2>().cwiseAbs().maxCoeff(); };
    for (int j = 1; j < static_cast<int>(p.size()); ++j) {
      if (dist(a, j) > dist(a, b)) b = j;
      if (j != b && dist(a, j) > 0.5 && dist(a, j) < 1.01 && (c < 0 || dist(a, j) < dist(a, c))) c = j;
    }
    for (size_t j = 0; j < p.size(); ++j)
      s.in.sets[j] = SetOf(j == size_t(a) ? 0 : j == size_t(b) ? 5 : 0, j == size_t(a) || j == size_t(b) ? 5 : 0);
    s.in.sets[c] = SetOf(10, 1);
  }
  static VoxelSet SetOf(size_t first, size_t count) {
    VoxelSet v(kN);
    for (size_t i = first; i < first + count; ++i) v.set(i);
    return v;
  }
  // The added positions see nothing (the rule decides before any is computed).
  VisibilityFn Fn() const {
    return [](const std::vector<WorldPoint>& q) -> Result<std::vector<VoxelSet>> {
      return std::vector<VoxelSet>(q.size(), VoxelSet(kN));
    };
  }
};

// Short of the target, only the positions whose neighbours see an uncovered voxel (c's) get a set:
// some around a, none around b; at neighbourhood_m 0 (the rule off) positions around both do.
TEST(LocalRefinementTest, TheNeighbourhoodRuleAddsOnlyPositionsWhoseNeighboursSeeUncoveredVoxels) {
  NeighbourhoodFixture f;
  ASSERT_GE(f.c, 0);
  const WorldPoint pa = f.s.in.positions[f.a], pb = f.s.in.positions[f.b], pc = f.s.in.positions[f.c];
  ASSERT_GT((pa - pb).head<2>().cwiseAbs().maxCoeff(), 2.5);  // b's positions are far from c
  auto within = [](const WorldPoint& p, const WorldPoint& q, double m) {
    return (p - q).head<2>().cwiseAbs().maxCoeff() <= m + 1e-9;
  };
  LocalRefinementOptions o;
  o.neighbourhood_m = 1.0;
  o.min_neighbourhood_gain_voxels = 1;
  Result<LocalRefinementResult> r = RefineLocally(f.selector, f.s.scene, f.s.in, 0, CandidateOptions{}, f.Fn(), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->stations_per_solve.front(), 2);  // a and b; c's one voxel is below the greedy's 2
  EXPECT_EQ(r->neighbourhood_rounds, 1);
  ASSERT_GT(r->added, 0);
  EXPECT_GT(r->passed_over, 0);  // b's, and a's on the side away from c
  for (size_t i = f.s.in.positions.size(); i < r->candidates.positions.size(); ++i) {
    const WorldPoint& q = r->candidates.positions[i];
    EXPECT_TRUE(within(q, pa, o.radius_m)) << "position " << i << " not around a";
    EXPECT_TRUE(within(q, pc, o.neighbourhood_m)) << "position " << i << " has no neighbour seeing voxel 10";
  }
  const int all_positions = r->added + r->passed_over;
  // A higher threshold than any neighbourhood offers (1 voxel): no position, no round.
  o.min_neighbourhood_gain_voxels = 2;
  r = RefineLocally(f.selector, f.s.scene, f.s.in, 0, CandidateOptions{}, f.Fn(), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->added, 0);
  EXPECT_EQ(r->passed_over, all_positions);
  EXPECT_EQ(r->rounds, 0);
  // The rule off: positions around both picks, as many as the rule passed over and kept.
  o.neighbourhood_m = 0;
  r = RefineLocally(f.selector, f.s.scene, f.s.in, 0, CandidateOptions{}, f.Fn(), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->neighbourhood_rounds, 0);
  EXPECT_EQ(r->passed_over, 0);
  EXPECT_EQ(r->added, all_positions);
  bool around_b = false;
  for (size_t i = f.s.in.positions.size(); i < r->candidates.positions.size(); ++i) {
    around_b |= within(r->candidates.positions[i], pb, o.radius_m);
  }
  EXPECT_TRUE(around_b);
}

// A solve that reaches the target leaves the round to save stations: every position gets a set
// whatever its neighbourhood, and the rule decides nothing.
TEST(LocalRefinementTest, TheNeighbourhoodRuleDoesNotApplyOnceTheTargetIsReached) {
  NeighbourhoodFixture f;
  LocalRefinementOptions o;
  o.neighbourhood_m = 1.0;
  o.min_neighbourhood_gain_voxels = 1000;
  o.target_coverage = 0.9;  // 10 of 11 coverable voxels
  Result<LocalRefinementResult> r = RefineLocally(f.selector, f.s.scene, f.s.in, 0, CandidateOptions{}, f.Fn(), o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->neighbourhood_rounds, 0);
  EXPECT_EQ(r->passed_over, 0);
  EXPECT_GT(r->added, 0);
  EXPECT_EQ(r->rounds, 1);
}

// An exact selector for tiny optima: the first single candidate or pair (in index order) whose
// union reaches `target` of all the sets' union; else greedy to the same target. No fixed stations.
class SmallExactSelector final : public Selector {
 public:
  explicit SmallExactSelector(double target) : target_(target) {}
  using Selector::Select;
  Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed, const JobContext& ctx) const override {
    if (fixed != 0 || sets.empty()) return InvalidArgumentError("SmallExactSelector: no fixed stations, some sets");
    VoxelSet all(sets[0].size());
    for (const VoxelSet& s : sets) all.Union(s);
    Selection out;
    out.coverable = all.count();
    const uint64_t need = static_cast<uint64_t>(std::ceil(target_ * static_cast<double>(out.coverable) - 1e-9));
    for (size_t a = 0; a < sets.size(); ++a) {
      if (sets[a].count() >= need) {
        out.picks = {static_cast<int>(a)};
        out.covered = sets[a].count();
        return out;
      }
    }
    for (size_t a = 0; a < sets.size(); ++a) {
      const uint64_t na = sets[a].count();
      for (size_t b = a + 1; b < sets.size(); ++b) {
        const uint64_t both = na + sets[b].count() - sets[a].CountAnd(sets[b]);
        if (both >= need && (out.picks.empty() || both > out.covered)) {
          out.picks = {static_cast<int>(a), static_cast<int>(b)};
          out.covered = both;
        }
      }
    }
    if (!out.picks.empty()) return out;
    GreedyOptions g;
    g.target_coverage = target_;
    return GreedySelector(g).Select(sets, 0, ctx);
  }

 private:
  double target_;
};

// hub:1 (docs/SCENES.md, optimum 2: a station just inside each door). Prints the figures
// docs/PLANNING.md ("Doorway candidates") records.
struct Hub {
  VoxelScene scene;
  CandidateGrid grid;
  std::vector<VoxelSet> sets;
  explicit Hub(bool doorways) {
    Result<VoxelScene> s = Voxelize(testing::Synthetic("hub:1"), VoxelizeOptions{0.1});
    EXPECT_TRUE(s.ok());
    scene = std::move(*s);
    CandidateOptions o;
    o.doorway_candidates = doorways;
    grid = *GenerateCandidates(scene, o);
    sets = *ComputeVisibilitySets(scene, grid.positions, Options());
  }
  static VisibilitySetsOptions Options() {
    VisibilitySetsOptions o;
    o.scanner = ScannerModel{};
    return o;
  }
  VisibilityFn Fn() const {
    return [this](const std::vector<WorldPoint>& p) { return ComputeVisibilitySets(scene, p, Options()); };
  }
  CandidateSets Candidates() const { return {grid.positions, grid.floor_z_m, sets}; }
  // Whether every room of hub:1 has a picked station inside it.
  bool StationInEveryRoom(const LocalRefinementResult& r) const {
    const SceneInfo info = *DescribeScene("hub:1");
    return std::all_of(info.rooms.begin(), info.rooms.end(), [&](const AxisBox& room) {
      return std::any_of(r.selection.picks.begin(), r.selection.picks.end(), [&](int k) {
        const WorldPoint& p = r.candidates.positions[k];
        return (p.array() >= room.min.array()).all() && (p.array() <= room.max.array()).all();
      });
    });
  }
};

void Print(const char* what, const LocalRefinementResult& r) {
  std::cout << "[ hub:1, " << what << " ] stations per solve:";
  for (size_t i = 0; i < r.stations_per_solve.size(); ++i) {
    std::cout << " " << r.stations_per_solve[i] << " (" << r.covered_per_solve[i] << " voxels)";
  }
  std::cout << ", " << r.candidates.positions.size() - r.added << " candidates + " << r.added << " added\n";
}

TEST(LocalRefinementHubTest, AnExactSelectorReachesTheOptimumWithDoorwayCandidates) {
  const Hub hub(true);
  Result<LocalRefinementResult> r = RefineLocally(SmallExactSelector(0.99), hub.scene, hub.Candidates(), 0,
                                                  CandidateOptions{}, hub.Fn(), {0.5, 0.25, 0});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  Print("doorway candidates, exact, no rounds", *r);
  EXPECT_EQ(r->selection.picks.size(), 2u);
  EXPECT_TRUE(hub.StationInEveryRoom(*r));
}

TEST(LocalRefinementHubTest, OnTheGridAloneGreedyAndExactNeedThreeEvenWithTheLoop) {
  const Hub hub(false);
  for (const bool exact : {false, true}) {
    GreedyOptions g;
    g.target_coverage = 0.99;
    const GreedySelector greedy(g);
    const SmallExactSelector small(0.99);
    const Selector& selector = exact ? static_cast<const Selector&>(small) : greedy;
    Result<LocalRefinementResult> r =
        RefineLocally(selector, hub.scene, hub.Candidates(), 0, CandidateOptions{}, hub.Fn(), {});
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    Print(exact ? "grid, exact, local refinement" : "grid, greedy, local refinement", *r);
    EXPECT_EQ(r->stations_per_solve.front(), 3);  // no pair of grid candidates reaches 0.99
    EXPECT_LE(r->selection.picks.size(), 3u);     // never worse than the first solve
  }
}

// A ramp rising one voxel every 4 columns (1:4, terrain's ground) along x, 6 x 4 m at 0.1 m:
// column x's top is at ((x / 4) + 1) * 0.1 m. The positions added around two picks 1 m apart, on a
// 0.5 m sub-grid within 1.5 m, for `ground`.
struct Ramp {
  VoxelScene scene;
  CandidateSets in;
  FakeVisibility fake;
  Ramp() {
    testing::VoxelBuilder b;
    for (int x = 0; x < 60; ++x) b.Box(x, 0, 0, x, 39, x / 4);
    scene = b.Build(0.1);
    CandidateOptions o;
    o.ground = GroundModel::kTerrain;
    Result<CandidateGrid> g = GenerateCandidates(scene, o);
    EXPECT_TRUE(g.ok());
    // The candidates nearest to (3, 2) m and (4, 2) m: both see part, nothing sees all.
    auto nearest = [&](const WorldPoint& q) {
      size_t best = 0;
      for (size_t i = 0; i < g->positions.size(); ++i) {
        if ((g->positions[i] - q).head<2>().norm() < (g->positions[best] - q).head<2>().norm()) best = i;
      }
      return g->positions[best];
    };
    fake.left = nearest(WorldPoint(3, 2, 0));
    fake.right = nearest(WorldPoint(4, 2, 0));
    fake.all = WorldPoint(-100, -100, 0);
    in.positions = g->positions;
    in.floor_z_m = g->floor_z_m;
    in.sets = *fake(in.positions);
  }
  static double TopZ(double x_m) { return (static_cast<int>(std::floor(x_m / 0.1)) / 4 + 1) * 0.1; }
  std::vector<WorldPoint> Added(GroundModel ground) {
    CountingSelector selector;
    const VisibilityFn fn = [&](const std::vector<WorldPoint>& p) { return fake(p); };
    CandidateOptions o;
    o.ground = ground;
    LocalRefinementOptions lo;
    lo.radius_m = 1.5;
    lo.step_m = 0.5;
    lo.max_rounds = 1;
    Result<LocalRefinementResult> r = RefineLocally(selector, scene, in, 0, o, fn, lo);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    if (!r.ok()) return {};
    EXPECT_EQ(r->stations_per_solve.front(), 2);
    std::vector<WorldPoint> added(r->candidates.positions.begin() + static_cast<std::ptrdiff_t>(in.positions.size()),
                                  r->candidates.positions.end());
    for (size_t i = in.positions.size(); i < r->candidates.positions.size(); ++i) {
      EXPECT_NEAR(r->candidates.positions[i].z() - r->candidates.floor_z_m[i], 1.5, 1e-9);
    }
    return added;
  }
};

TEST(LocalRefinementTest, OnTerrainAddedPositionsStandAtTheirHeightOverTheGroundUnderThem) {
  Ramp ramp;
  const std::vector<WorldPoint> terrain = ramp.Added(GroundModel::kTerrain);
  ASSERT_FALSE(terrain.empty());
  bool uphill = false, downhill = false;
  for (const WorldPoint& p : terrain) {
    EXPECT_NEAR(p.z(), Ramp::TopZ(p.x()) + 1.5, 1e-9) << p.transpose();
    uphill = uphill || p.x() > ramp.fake.right.x() + 1.4;
    downhill = downhill || p.x() < ramp.fake.left.x() - 1.4;
  }
  EXPECT_TRUE(uphill);
  EXPECT_TRUE(downhill);
  // The floor level's band (+-0.2 m) loses the positions 1.5 m up and down the ramp (0.3-0.4 m away).
  const std::vector<WorldPoint> floors = ramp.Added(GroundModel::kFloors);
  EXPECT_LT(floors.size(), terrain.size());
  for (const WorldPoint& p : floors) {
    EXPECT_FALSE(p.x() > ramp.fake.right.x() + 1.4 || p.x() < ramp.fake.left.x() - 1.4) << p.transpose();
  }
}

}  // namespace
}  // namespace vc::planner
