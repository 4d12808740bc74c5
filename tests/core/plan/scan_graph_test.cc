// The scan graph: overlap figures against a brute-force intersection, components, and the
// registration rules of greedy selection, consolidation and reduction (min_overlap).
#include "vc/plan/scan_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "vc/plan/greedy.h"
#include "vc/plan/reduction.h"
#include "vc/plan/selector.h"

namespace vc::planner {
namespace {

constexpr size_t kVoxels = 400;

// The voxels [begin, end).
VoxelSet Range(size_t begin, size_t end) {
  VoxelSet s(kVoxels);
  for (size_t v = begin; v < end; ++v) s.set(v);
  return s;
}

std::vector<int> Picks(const GreedyResult& r) {
  std::vector<int> out;
  for (const GreedyPick& p : r.picks) out.push_back(p.candidate);
  return out;
}

TEST(ScanGraph, OverlapIsTheSharedVoxelsOverTheSmallerSetAgainstBruteForce) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const size_t n = 1 + rng() % 700;  // not a multiple of 64, some sets empty
    VoxelSet a(n), b(n);
    const double pa = (rng() % 100) / 100.0, pb = (rng() % 100) / 100.0;
    uint64_t na = 0, nb = 0, common = 0;
    for (size_t v = 0; v < n; ++v) {
      const bool in_a = (rng() % 1000) < pa * 1000, in_b = (rng() % 1000) < pb * 1000;
      if (in_a) a.set(v);
      if (in_b) b.set(v);
      na += in_a;
      nb += in_b;
      common += in_a && in_b;
    }
    const double expected = std::min(na, nb) == 0 ? 0.0 : double(common) / double(std::min(na, nb));
    EXPECT_DOUBLE_EQ(Overlap(a, b), expected) << "trial " << trial;
    EXPECT_DOUBLE_EQ(Overlap(b, a), expected);
  }
  EXPECT_EQ(Overlap(Range(0, 0), Range(0, 10)), 0.0);
  EXPECT_EQ(Overlap(Range(0, 10), Range(0, 100)), 1.0);  // a set inside another overlaps it fully
}

TEST(ScanGraph, EdgesListEveryPositiveOverlapAndComponentsUseTheThreshold) {
  // 0 and 1 share 50 of 100; 1 and 2 share 10 of 100; 3 shares nothing.
  const std::vector<VoxelSet> sets{Range(0, 100), Range(50, 150), Range(140, 240), Range(300, 350)};
  const OverlapMatrix m(sets);
  const ScanGraph at30 = BuildScanGraph(m, 0.3);
  ASSERT_EQ(at30.edges.size(), 2u);
  EXPECT_EQ(at30.edges[0].i, 0);
  EXPECT_EQ(at30.edges[0].j, 1);
  EXPECT_DOUBLE_EQ(at30.edges[0].overlap, 0.5);
  EXPECT_EQ(at30.edges[1].i, 1);
  EXPECT_EQ(at30.edges[1].j, 2);
  EXPECT_DOUBLE_EQ(at30.edges[1].overlap, 0.1);
  EXPECT_FALSE(at30.connected);
  EXPECT_EQ(at30.components, (std::vector<std::vector<int>>{{0, 1}, {2}, {3}}));
  const ScanGraph off = BuildScanGraph(m, 0.0);  // any shared voxel links
  EXPECT_EQ(off.components, (std::vector<std::vector<int>>{{0, 1, 2}, {3}}));
  EXPECT_EQ(CountComponents(m, {0, 2}, 0.0), 2);
  EXPECT_EQ(CountComponents(m, {}, 0.3), 0);
  const ScanGraph single = BuildScanGraph(OverlapMatrix({Range(0, 5)}), 0.3);
  EXPECT_TRUE(single.connected);
  EXPECT_TRUE(single.edges.empty());
}

TEST(ScanGraph, MatrixOnSeveralThreadsHoldsEveryPairsOverlap) {
  std::mt19937_64 rng(11);
  std::vector<VoxelSet> sets;
  for (int k = 0; k < 37; ++k) {  // rows of unequal length, more rows than threads
    VoxelSet s(kVoxels);
    const size_t begin = rng() % kVoxels, end = std::min<size_t>(kVoxels, begin + rng() % 120);
    for (size_t v = begin; v < end; ++v)
      if (rng() % 3) s.set(v);
    sets.push_back(std::move(s));
  }
  for (int threads : {1, 2, 4}) {
    const OverlapMatrix m(sets, threads);
    ASSERT_EQ(m.size(), 37);
    for (int i = 0; i < 37; ++i)
      for (int j = 0; j < 37; ++j) {
        EXPECT_EQ(m.at(i, j), i == j ? 1.0 : Overlap(sets[i], sets[j])) << i << " " << j << " threads " << threads;
      }
  }
}

TEST(ScanGraph, ReplaceRecomputesOneStationsRowAndColumn) {
  std::vector<VoxelSet> sets{Range(0, 100), Range(50, 150), Range(300, 350)};
  OverlapMatrix m(sets);
  const VoxelSet moved = Range(320, 400);
  m.Replace(0, moved, sets);
  EXPECT_DOUBLE_EQ(m.at(0, 2), 30.0 / 50.0);
  EXPECT_DOUBLE_EQ(m.at(2, 0), 30.0 / 50.0);
  EXPECT_DOUBLE_EQ(m.at(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(m.at(1, 2), 0.0);
}

TEST(GreedyRegistration, OffPicksTheFewestAndOnLinksThemThroughASharedView) {
  // Two rooms (0 and 1) no view shares; candidate 2 sees half of each.
  const std::vector<VoxelSet> sets{Range(0, 100), Range(100, 200), Range(50, 150)};
  GreedyOptions plain;
  Result<GreedyResult> off = SelectGreedy(sets, plain);
  ASSERT_TRUE(off.ok());
  EXPECT_EQ(Picks(*off), (std::vector<int>{0, 1}));
  GreedyOptions linked;
  linked.min_overlap = 0.3;
  Result<GreedyResult> on = SelectGreedy(sets, linked);
  ASSERT_TRUE(on.ok());
  EXPECT_EQ(Picks(*on), (std::vector<int>{0, 2, 1}));
  EXPECT_EQ(on->covered, 200u);
  EXPECT_EQ(on->connectors, 0);  // 2 was picked for its gain: it was the best linked candidate
  linked.lazy = false;           // the plain recount picks the same
  Result<GreedyResult> plain_on = SelectGreedy(sets, linked);
  ASSERT_TRUE(plain_on.ok());
  EXPECT_EQ(Picks(*plain_on), Picks(*on));
}

TEST(GreedyRegistration, AChainOfConnectingStationsReachesAGainBeyondTheLinkedOnes) {
  // 0 = [0,100); 2 = [80,130) links 0 (20/50) and 1 (20/50) but gains only 30 < min gain 40;
  // 1 = [110,210) shares nothing with 0.
  const std::vector<VoxelSet> sets{Range(0, 100), Range(110, 210), Range(80, 130)};
  for (bool lazy : {true, false}) {
    GreedyOptions o;
    o.min_overlap = 0.3;
    o.min_marginal_gain_voxels = 40;
    o.lazy = lazy;
    Result<GreedyResult> r = SelectGreedy(sets, o);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(Picks(*r), (std::vector<int>{0, 2, 1})) << "lazy " << lazy;
    EXPECT_TRUE(r->picks[1].connector);
    EXPECT_FALSE(r->picks[2].connector);
    EXPECT_EQ(r->connectors, 1);
    EXPECT_EQ(r->new_groups, 0);
    EXPECT_EQ(r->stop, StopReason::kExhausted);
  }
}

TEST(GreedyRegistration, WithoutAnyChainANewGroupStartsAndIsCounted) {
  const std::vector<VoxelSet> sets{Range(0, 100), Range(200, 290), Range(0, 40)};
  GreedyOptions o;
  o.min_overlap = 0.3;
  Result<GreedyResult> r = SelectGreedy(sets, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(Picks(*r), (std::vector<int>{0, 1}));
  EXPECT_EQ(r->new_groups, 1);
  EXPECT_EQ(r->covered, r->coverable);
}

TEST(GreedyRegistration, FixedStationsInTwoGroupsAreJoinedWhenAChainExists) {
  // Fixed 0 and 1 cover the target alone; candidate 2 links them.
  const std::vector<VoxelSet> sets{Range(0, 100), Range(200, 300), Range(60, 240), Range(300, 310)};
  GreedyOptions o;
  o.fixed = 2;
  o.target_coverage = 0.5;
  o.min_overlap = 0.3;
  Result<GreedyResult> r = SelectGreedy(sets, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(Picks(*r), (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(r->picks[2].connector);
  o.min_overlap = 0;  // off: the fixed stations alone
  r = SelectGreedy(sets, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(Picks(*r), (std::vector<int>{0, 1}));
}

TEST(GreedyRegistration, MaxStationsBoundsTheChainsToo) {
  const std::vector<VoxelSet> sets{Range(0, 100), Range(110, 210), Range(80, 130)};
  GreedyOptions o;
  o.min_overlap = 0.3;
  o.min_marginal_gain_voxels = 40;
  o.max_stations = 2;  // the chain 2 -> 1 needs two more
  Result<GreedyResult> r = SelectGreedy(sets, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(Picks(*r), (std::vector<int>{0}));
  EXPECT_EQ(r->stop, StopReason::kMaxStations);
}

TEST(GreedyRegistration, BadMinOverlapIsRefused) {
  GreedyOptions o;
  o.min_overlap = 1.5;
  EXPECT_EQ(SelectGreedy({Range(0, 1)}, o).status().code(), StatusCode::kInvalidArgument);
}

TEST(ConsolidateRegistration, APickOthersCoverStaysWhenItIsTheOnlyLink) {
  const std::vector<VoxelSet> sets{Range(0, 100), Range(100, 200), Range(50, 150)};
  Result<ConsolidateResult> off = ConsolidatePicks(sets, {0, 2, 1});
  ASSERT_TRUE(off.ok());
  EXPECT_EQ(off->picks, (std::vector<int>{0, 1}));  // 2 is covered twice over: dropped
  GreedyOptions linked;
  linked.min_overlap = 0.3;
  Result<ConsolidateResult> on = ConsolidatePicks(sets, {0, 2, 1}, linked);
  ASSERT_TRUE(on.ok());
  EXPECT_EQ(on->picks, (std::vector<int>{0, 2, 1}));
  EXPECT_EQ(on->dropped, 0);
}

TEST(ConsolidateRegistration, AReplacementThatKeepsTheGraphLinkedIsStillMade) {
  // 1 and 2 are covered by 3 alone, which also links to 0 (a pair merge keeps one group).
  const std::vector<VoxelSet> sets{Range(0, 100), Range(60, 120), Range(120, 180), Range(60, 180)};
  GreedyOptions linked;
  linked.min_overlap = 0.3;
  Result<ConsolidateResult> on = ConsolidatePicks(sets, {0, 1, 2}, linked);
  ASSERT_TRUE(on.ok());
  EXPECT_EQ(on->picks, (std::vector<int>{0, 3}));
  EXPECT_EQ(on->merged, 1);
}

TEST(ReductionRegistration, AZeroLossStationThatLinksTheOthersIsKept) {
  ReductionMatrix m;
  m.size = 3;
  m.loss = {0.1, 0.2, 0.2,  //
            0.2, 0.0, 0.2,  //
            0.2, 0.2, 0.1};
  EXPECT_EQ(ChooseRemoval(m, {0, 1, 2}, 0), (std::vector<int>{1}));
  // Station 1 is the only link between 0 and 2.
  auto keeps = [](const std::vector<int>& remaining) {
    return std::find(remaining.begin(), remaining.end(), 1) != remaining.end();
  };
  EXPECT_TRUE(ChooseRemoval(m, {0, 1, 2}, 0, {}, keeps).empty());
  // With reduce_to the cheapest allowed subset goes instead.
  EXPECT_EQ(ChooseRemoval(m, {0, 1, 2}, 2, {}, keeps), (std::vector<int>{2}));
}

}  // namespace
}  // namespace vc::planner
