// Tests for vc/plan/unseen_causes.h: each cause on a scene built so that it alone applies, the
// order between causes, and that covered voxels are not counted.
#include "vc/plan/unseen_causes.h"

#include <gtest/gtest.h>

#include <vector>

#include "testing/scenes.h"

namespace vc {
namespace {

constexpr double kVoxelM = 1.0;

// A solid 3 x 3 x 3 block of 1 m voxels at indices 0..2 (centres 0.5 .. 2.5 m): one interior voxel.
VoxelScene Block() {
  testing::VoxelBuilder b;
  b.Box(0, 0, 0, 2, 2, 2);
  return b.Build(kVoxelM);
}

struct Site {
  VoxelScene scene = Block();
  VoxelSet coverable{scene.occupied.size()};
  std::vector<WorldPoint> candidates{WorldPoint(1.5, 1.5, 10.0)};  // straight above the block
  std::vector<double> floor_levels_m;
  std::vector<KeepOutZone> keep_out;
  ScannerModel scanner;

  UnseenCauses Count(int threads = 1) const {
    Result<UnseenCauses> r =
        CountUnseenCauses({scene, coverable, candidates, floor_levels_m, keep_out, scanner}, threads);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    return r.ok() ? *r : UnseenCauses{};
  }
};

TEST(UnseenCausesTest, InRangeAndViewTheTopIsHiddenTheRestFacesAwayAndTheCoreIsInterior) {
  const UnseenCauses c = Site{}.Count();
  EXPECT_EQ(c.interior, 1u);
  EXPECT_EQ(c.hidden, 9u);       // the top layer's upper faces face the candidate above
  EXPECT_EQ(c.faces_away, 17u);  // the sides and the bottom face away from it
  EXPECT_EQ(c.total(), 27u);
}

TEST(UnseenCausesTest, TheUndersideOfAFloorFacesAwayFromCandidatesAboveIt) {
  testing::VoxelBuilder b;
  b.Box(0, 0, 0, 9, 9, 1);  // a slab two voxels thick, top at z = 2
  Site s;
  s.scene = b.Build(kVoxelM);
  s.coverable = VoxelSet(s.scene.occupied.size());
  s.candidates = {WorldPoint(5, 5, 3.5), WorldPoint(20, 5, 3.5)};  // above it, and beside it outside
  const UnseenCauses c = s.Count();
  EXPECT_EQ(c.hidden, 100u + 10u);  // the top layer, and the lower layer's end facing +x (toward x = 20)
  EXPECT_EQ(c.faces_away, 90u);     // the rest of the lower layer: its open faces look down or away
  EXPECT_EQ(c.interior, 0u);
}

TEST(UnseenCausesTest, CoveredVoxelsAreNotCounted) {
  Site s;
  for (size_t id = 0; id < s.scene.occupied.size(); id += 2) s.coverable.set(id);
  EXPECT_EQ(s.Count().total(), s.scene.occupied.size() - s.coverable.count());
}

TEST(UnseenCausesTest, ACentreInAKeepOutZoneComesBeforeRangeAndView) {
  Site s;
  s.keep_out.push_back(KeepOutBox({0, 0, 0}, {1, 3, 3}));  // the x = 0 layer's centres (x = 0.5)
  s.scanner.max_range_m = 2.0;                             // and every candidate out of range
  const UnseenCauses c = s.Count();
  EXPECT_EQ(c.in_keep_out, 9u);
  EXPECT_EQ(c.out_of_range, 17u);
  EXPECT_EQ(c.interior, 1u);
}

TEST(UnseenCausesTest, BeyondMaxRangeAndWithinMinRangeAreOutOfRange) {
  Site far;
  far.scanner.max_range_m = 5.0;  // the nearest centre is 7.5 m below the candidate
  EXPECT_EQ(far.Count().out_of_range, 26u);
  Site near;
  near.candidates = {WorldPoint(1.5, 1.5, 1.5)};
  near.scanner.min_range_m = 3.0;  // every centre is within 1.8 m
  EXPECT_EQ(near.Count().out_of_range, 26u);
}

TEST(UnseenCausesTest, BelowTheLowestElevationOfEveryCandidateInRangeIsOutsideTheFieldOfView) {
  Site s;
  s.scanner.vfov_min_deg = -30.0;  // the block is at least 70 degrees below the candidate
  const UnseenCauses c = s.Count();
  EXPECT_EQ(c.outside_field_of_view, 26u);
  EXPECT_EQ(c.hidden + c.faces_away, 0u);
  s.candidates.push_back(WorldPoint(30.0, 1.5, 3.0));  // level with the block, 27.5 m away: in view
  const UnseenCauses in_view = s.Count();
  EXPECT_EQ(in_view.outside_field_of_view, 0u);
  EXPECT_EQ(in_view.hidden, 9u);  // the x = 2.5 layer faces it
  EXPECT_EQ(in_view.faces_away, 17u);
  s.scanner.max_range_m = 20.0;  // that one out of range again
  EXPECT_EQ(s.Count().outside_field_of_view, 26u);
}

TEST(UnseenCausesTest, AStoreyWithoutCandidatesIsNamedAndItsFloorVoxelsBelongToIt) {
  testing::VoxelBuilder b;
  b.Box(0, 0, 0, 9, 0, 0);  // ground floor slab, top at z = 1
  b.Box(0, 0, 5, 9, 0, 5);  // upper floor slab, top at z = 6
  b.Box(0, 0, 8, 0, 0, 8);  // a lamp on the upper storey
  Site s;
  s.scene = b.Build(kVoxelM);
  s.coverable = VoxelSet(s.scene.occupied.size());
  s.floor_levels_m = {1.0, 6.0};
  s.candidates = {WorldPoint(5.5, 0.5, 2.5)};  // on the ground floor only
  const UnseenCauses c = s.Count();
  EXPECT_EQ(c.no_candidate_on_floor, 11u);  // the upper slab (its top is that storey's floor) and the lamp
  EXPECT_EQ(c.hidden, 10u);                 // the ground slab's top faces the candidate
  s.candidates.push_back(WorldPoint(5.5, 0.5, 7.5));
  EXPECT_EQ(s.Count().no_candidate_on_floor, 0u);
  s.floor_levels_m.clear();  // user candidates: no floors known, no floor cause
  s.candidates.pop_back();
  EXPECT_EQ(s.Count().no_candidate_on_floor, 0u);
}

TEST(UnseenCausesTest, ThreadsGiveTheSameCounts) {
  testing::VoxelBuilder b;
  b.Box(0, 0, 0, 29, 29, 9);  // 9,000 voxels: three chunks
  Site s;
  s.scene = b.Build(kVoxelM);
  s.coverable = VoxelSet(s.scene.occupied.size());
  s.candidates = {WorldPoint(15, 15, 20), WorldPoint(-40, 15, 5)};
  s.scanner.max_range_m = 25.0;  // the far corners of the block are beyond both
  s.keep_out.push_back(KeepOutBox({0, 0, 0}, {1, 30, 10}));
  s.scanner.vfov_min_deg = -75.0;
  const UnseenCauses one = s.Count(1), four = s.Count(4);
  EXPECT_GT(one.out_of_range, 0u);
  EXPECT_GT(one.outside_field_of_view, 0u);
  EXPECT_EQ(one.interior, four.interior);
  EXPECT_EQ(one.out_of_range, four.out_of_range);
  EXPECT_EQ(one.in_keep_out, four.in_keep_out);
  EXPECT_EQ(one.outside_field_of_view, four.outside_field_of_view);
  EXPECT_EQ(one.faces_away, four.faces_away);
  EXPECT_EQ(one.hidden, four.hidden);
  EXPECT_EQ(one.total(), four.total());
}

TEST(UnseenCausesTest, ACancelledJobIsCancelled) {
  Site s;
  CancelToken token;
  token.Cancel();
  JobContext ctx;
  ctx.cancel = &token;
  const Result<UnseenCauses> r =
      CountUnseenCauses({s.scene, s.coverable, s.candidates, s.floor_levels_m, s.keep_out, s.scanner}, 1, ctx);
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled) << r.status().ToString();
}

}  // namespace
}  // namespace vc
