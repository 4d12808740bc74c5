// RefineLocally on a hand-built room with made-up visibility sets: a position between grid points
// that sees what two grid candidates see between them is found around the picks, and the loop
// stops when a solve no longer improves.
#include "vc/plan/local_refinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "testing/scenes.h"

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
    return GreedySelector(GreedySelectorOptions{}).Select(sets, fixed, ctx);
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

}  // namespace
}  // namespace vc::planner
