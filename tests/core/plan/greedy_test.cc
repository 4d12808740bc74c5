// Greedy selection: against exhaustive search on tiny hand-made instances, lazy (CELF) against
// plain on random ones, the tie rule and every stopping rule.
#include "vc/plan/greedy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace vc::planner {
namespace {

VoxelSet MakeSet(size_t n, std::initializer_list<size_t> bits) {
  VoxelSet s(n);
  for (size_t b : bits) s.set(b);
  return s;
}

// Smallest number of sets whose union is the union of all (exhaustive, m <= 16).
int MinimumCover(const std::vector<VoxelSet>& sets) {
  const size_t n = sets[0].size();
  VoxelSet all(n);
  for (const auto& s : sets) UnionInto(all, s);
  const uint64_t target = CountBits(all);
  int best = static_cast<int>(sets.size());
  for (uint32_t mask = 0; mask < (1u << sets.size()); ++mask) {
    const int k = std::popcount(mask);
    if (k >= best) continue;
    VoxelSet u(n);
    for (size_t i = 0; i < sets.size(); ++i) {
      if (mask >> i & 1u) UnionInto(u, sets[i]);
    }
    if (CountBits(u) == target) best = k;
  }
  return best;
}

// Best coverage reachable with exactly k sets (exhaustive).
uint64_t BestCoverageWith(const std::vector<VoxelSet>& sets, int k) {
  uint64_t best = 0;
  for (uint32_t mask = 0; mask < (1u << sets.size()); ++mask) {
    if (std::popcount(mask) != k) continue;
    VoxelSet u(sets[0].size());
    for (size_t i = 0; i < sets.size(); ++i) {
      if (mask >> i & 1u) UnionInto(u, sets[i]);
    }
    best = std::max(best, CountBits(u));
  }
  return best;
}

// Chases every coverable voxel, as the exhaustive searches do (GreedyOptions' default target is the
// plan's 0.99).
GreedyOptions FullCoverage() {
  GreedyOptions o;
  o.target_coverage = 1.0;
  return o;
}

GreedyResult Greedy(const std::vector<VoxelSet>& sets, GreedyOptions o = FullCoverage()) {
  Result<GreedyResult> r = SelectGreedy(sets, o);
  EXPECT_TRUE(r.ok()) << r.status().ToString();
  return r.ok() ? *r : GreedyResult{};
}

std::vector<int> Picks(const GreedyResult& r) {
  std::vector<int> v;
  for (const auto& p : r.picks) v.push_back(p.candidate);
  return v;
}

// Three rooms (voxels 0-9, 10-19, 20-29) and a corridor (30-39). Candidates 0-2 stand in the
// rooms and see their room plus part of the corridor; candidates 3-5 stand in the corridor and see
// it plus a doorway's worth of each room.
std::vector<VoxelSet> ThreeRooms() {
  const size_t n = 40;
  std::vector<VoxelSet> sets;
  for (int room = 0; room < 3; ++room) {
    VoxelSet s(n);
    for (int v = 0; v < 10; ++v) s.set(room * 10 + v);
    for (int v = 0; v < 5; ++v) s.set(30 + room * 2 + v);
    sets.push_back(s);
  }
  for (int c = 0; c < 3; ++c) {
    VoxelSet s(n);
    for (int v = 30; v < 40; ++v) s.set(v);
    for (int room = 0; room < 3; ++room) s.set(room * 10 + c);
    sets.push_back(s);
  }
  return sets;
}

TEST(GreedyTest, ThreeRoomsMatchesExhaustiveMinimum) {
  const auto sets = ThreeRooms();
  const GreedyResult r = Greedy(sets);
  EXPECT_EQ(r.stop, StopReason::kExhausted);
  EXPECT_EQ(r.covered, r.coverable);
  EXPECT_EQ(r.coverable, 40u);
  ASSERT_EQ(static_cast<int>(r.picks.size()), MinimumCover(sets));
  EXPECT_EQ(MinimumCover(sets), 4);  // 3 rooms + a corridor remainder: (30..39) not all seen from rooms
  // Each room station is picked (their own voxels are seen by nothing else in full).
  std::vector<int> picks = Picks(r);
  std::sort(picks.begin(), picks.end());
  EXPECT_TRUE(std::binary_search(picks.begin(), picks.end(), 0));
  EXPECT_TRUE(std::binary_search(picks.begin(), picks.end(), 1));
  EXPECT_TRUE(std::binary_search(picks.begin(), picks.end(), 2));
}

TEST(GreedyTest, NestedAndDisjointSetsMatchExhaustive) {
  // Nested sets: the largest covers everything -> 1 pick.
  std::vector<VoxelSet> nested = {MakeSet(16, {0, 1}), MakeSet(16, {0, 1, 2, 3, 4}),
                                  MakeSet(16, {0, 1, 2, 3, 4, 5, 6, 7}), MakeSet(16, {3, 4})};
  EXPECT_EQ(Greedy(nested).picks.size(), static_cast<size_t>(MinimumCover(nested)));
  EXPECT_EQ(Picks(Greedy(nested)), std::vector<int>({2}));
  // Disjoint sets: all are needed, largest first.
  std::vector<VoxelSet> disjoint = {MakeSet(16, {0}), MakeSet(16, {1, 2, 3}), MakeSet(16, {4, 5})};
  EXPECT_EQ(Picks(Greedy(disjoint)), std::vector<int>({1, 2, 0}));
  EXPECT_EQ(MinimumCover(disjoint), 3);
}

TEST(GreedyTest, EveryPrefixIsOptimalOnLaminarInstances) {
  // Random laminar families (every two sets nested or disjoint): greedy is optimal for every k.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const size_t n = 48;
    std::vector<VoxelSet> sets;
    // Blocks of a random partition, plus unions of consecutive blocks.
    std::vector<size_t> cuts = {0};
    while (cuts.back() < n) cuts.push_back(std::min(n, cuts.back() + 1 + rng() % 8));
    for (size_t b = 0; b + 1 < cuts.size(); ++b) {
      VoxelSet s(n);
      for (size_t v = cuts[b]; v < cuts[b + 1]; ++v) s.set(v);
      sets.push_back(s);
      if (b % 2 == 1 && sets.size() < 12) {
        VoxelSet u = sets[sets.size() - 2];
        UnionInto(u, s);
        sets.push_back(u);
      }
      if (sets.size() >= 12) break;
    }
    const GreedyResult r = Greedy(sets);
    EXPECT_EQ(static_cast<int>(r.picks.size()), MinimumCover(sets)) << "trial " << trial;
    for (size_t k = 1; k <= r.picks.size(); ++k) {
      EXPECT_EQ(r.picks[k - 1].covered_after, BestCoverageWith(sets, static_cast<int>(k))) << "trial " << trial;
    }
  }
}

TEST(GreedyTest, IsGreedyNotOptimalOnTheClassicTrap) {
  // Optimum: {0, 1} (two halves). Greedy takes the bigger straddling set 2 first and then needs
  // both halves' remainders (3 then 2 voxels): 3 picks. Pins that this is the paper's greedy.
  std::vector<VoxelSet> sets = {MakeSet(12, {0, 1, 2, 3, 4, 5}), MakeSet(12, {6, 7, 8, 9, 10, 11}),
                                MakeSet(12, {0, 1, 2, 6, 7, 8, 3})};
  EXPECT_EQ(MinimumCover(sets), 2);
  EXPECT_EQ(Picks(Greedy(sets)), std::vector<int>({2, 1, 0}));
}

TEST(GreedyTest, TiesGoToTheLowestIndex) {
  std::vector<VoxelSet> sets = {MakeSet(8, {0, 1}), MakeSet(8, {2, 3, 4}), MakeSet(8, {5, 6, 7}),
                                MakeSet(8, {2, 3, 4})};
  for (bool lazy : {false, true}) {
    GreedyOptions o;
    o.lazy = lazy;
    EXPECT_EQ(Picks(Greedy(sets, o)), std::vector<int>({1, 2, 0})) << "lazy=" << lazy;
  }
}

TEST(GreedyTest, LazyAndPlainPickIdenticallyOnRandomInstances) {
  std::mt19937 rng(12345);
  uint64_t lazy_evals = 0, plain_evals = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const size_t n = 1 + rng() % 300;
    const size_t m = 1 + rng() % 60;
    const double density = 0.02 + (rng() % 100) / 400.0;
    std::bernoulli_distribution bit(density);
    std::vector<VoxelSet> sets;
    for (size_t i = 0; i < m; ++i) {
      if (i > 0 && rng() % 5 == 0) {
        sets.push_back(sets[rng() % i]);  // duplicates force ties
        continue;
      }
      VoxelSet s(n);
      for (size_t v = 0; v < n; ++v) {
        if (bit(rng)) s.set(v);
      }
      sets.push_back(s);
    }
    GreedyOptions o;
    o.max_stations = rng() % 3 == 0 ? static_cast<int>(1 + rng() % 5) : 0;
    o.min_marginal_gain_voxels = rng() % 3 == 0 ? 1 + rng() % 4 : 1;
    o.target_coverage = rng() % 3 == 0 ? 0.5 + (rng() % 50) / 100.0 : 1.0;
    o.lazy = false;
    const GreedyResult plain = Greedy(sets, o);
    o.lazy = true;
    const GreedyResult lazy = Greedy(sets, o);
    ASSERT_EQ(Picks(lazy), Picks(plain)) << "trial " << trial;
    ASSERT_EQ(lazy.stop, plain.stop) << "trial " << trial;
    ASSERT_EQ(lazy.covered, plain.covered);
    for (size_t k = 0; k < lazy.picks.size(); ++k) EXPECT_EQ(lazy.picks[k].marginal_gain, plain.picks[k].marginal_gain);
    lazy_evals += lazy.gain_evaluations;
    plain_evals += plain.gain_evaluations;
  }
  EXPECT_LT(lazy_evals, plain_evals);  // the point of CELF
}

TEST(GreedyTest, MarginalGainsAreNonIncreasingAndSumToCovered) {
  const auto sets = ThreeRooms();
  const GreedyResult r = Greedy(sets);
  uint64_t sum = 0;
  for (size_t k = 0; k < r.picks.size(); ++k) {
    if (k > 0) {
      EXPECT_LE(r.picks[k].marginal_gain, r.picks[k - 1].marginal_gain);
    }
    sum += r.picks[k].marginal_gain;
    EXPECT_EQ(r.picks[k].covered_after, sum);
  }
  EXPECT_EQ(sum, r.covered);
}

TEST(GreedyTest, StopsAtMaxStations) {
  GreedyOptions o;
  o.max_stations = 2;
  const GreedyResult r = Greedy(ThreeRooms(), o);
  EXPECT_EQ(r.picks.size(), 2u);
  EXPECT_EQ(r.stop, StopReason::kMaxStations);
  EXPECT_LT(r.covered, r.coverable);
}

TEST(GreedyTest, StopsAtMinimumMarginalGain) {
  // Gains 6, 3, 1: a threshold of 2 keeps the first two.
  std::vector<VoxelSet> sets = {MakeSet(10, {0, 1, 2, 3, 4, 5}), MakeSet(10, {6, 7, 8}), MakeSet(10, {9})};
  GreedyOptions o;
  o.min_marginal_gain_voxels = 2;
  const GreedyResult r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0, 1}));
  EXPECT_EQ(r.stop, StopReason::kMinGain);
}

TEST(GreedyTest, GainRuleStopsWhereAStationIsWorthLessThanItsMinutes) {
  // Gains 6, 3, 1 at 2 minutes a station.
  std::vector<VoxelSet> sets = {MakeSet(10, {0, 1, 2, 3, 4, 5}), MakeSet(10, {6, 7, 8}), MakeSet(10, {9})};
  GreedyOptions o = FullCoverage();
  o.station_seconds = 120;
  o.min_gain_voxels_per_minute = 2;  // a station must add 4 voxels
  GreedyResult r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0}));
  EXPECT_EQ(r.stop, StopReason::kGainRule);
  o.min_gain_voxels_per_minute = 1.5;  // 3 voxels: a gain of exactly 3 is worth its time
  r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0, 1}));
  EXPECT_EQ(r.stop, StopReason::kGainRule);
  EXPECT_EQ(r.covered, 9u);
  o.min_gain_voxels_per_minute = 0;  // off
  r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0, 1, 2}));
  EXPECT_EQ(r.stop, StopReason::kExhausted);
  o.min_gain_voxels_per_minute = 1000;
  o.station_seconds = 0;  // a station that costs nothing is always worth it
  EXPECT_EQ(Greedy(sets, o).picks.size(), 3u);
}

// SmallestGainPickedVoxels is where greedy's rules stop: a gain of exactly it is picked, one less
// is not (the coarse-then-fine round gates its fine positions with it).
TEST(GreedyTest, SmallestGainPickedIsWhereTheRulesStop) {
  std::vector<VoxelSet> sets = {MakeSet(10, {0, 1, 2, 3, 4, 5}), MakeSet(10, {6, 7, 8}), MakeSet(10, {9})};
  GreedyOptions o = FullCoverage();
  EXPECT_EQ(SmallestGainPickedVoxels(o), 1u);  // no rule: any gain
  o.station_seconds = 120;
  o.min_gain_voxels_per_minute = 1.5;  // 3 voxels a station
  EXPECT_EQ(SmallestGainPickedVoxels(o), 3u);
  EXPECT_EQ(Picks(Greedy(sets, o)), std::vector<int>({0, 1}));  // the gain of 3 picked, of 1 not
  o.min_gain_voxels_per_minute = 1.6;                           // 3.2 voxels: at least 4
  EXPECT_EQ(SmallestGainPickedVoxels(o), 4u);
  EXPECT_EQ(Picks(Greedy(sets, o)), std::vector<int>({0}));
  o.min_gain_voxels_per_minute = 0;
  o.surface_voxels_per_m2 = 4;
  o.min_gain_m2_per_minute = 0.625;  // 2.5 m^2 / 2 min x 4 voxels = 5 voxels
  EXPECT_EQ(SmallestGainPickedVoxels(o), 5u);
  o.min_marginal_gain_voxels = 7;  // the larger rule
  EXPECT_EQ(SmallestGainPickedVoxels(o), 7u);
}

TEST(GreedyTest, AreaGainRuleConvertsSquareMetresToVoxels) {
  // Gains 6, 3, 1 at 2 minutes a station and 4 surface voxels per m^2 (0.5 m voxels).
  std::vector<VoxelSet> sets = {MakeSet(10, {0, 1, 2, 3, 4, 5}), MakeSet(10, {6, 7, 8}), MakeSet(10, {9})};
  GreedyOptions o = FullCoverage();
  o.station_seconds = 120;
  o.surface_voxels_per_m2 = 4;
  o.min_gain_m2_per_minute = 0.5;  // 1 m^2 = 4 voxels a station: the gain of 3 stops it
  GreedyResult r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0}));
  EXPECT_EQ(r.stop, StopReason::kGainRule);
  o.min_gain_m2_per_minute = 0.375;  // 3 voxels: the gain of 3 is worth its time
  r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0, 1}));
  EXPECT_EQ(r.stop, StopReason::kGainRule);
  o.min_gain_voxels_per_minute = 0.25;  // the voxel rule takes the area rule's place: 0.5 voxels
  EXPECT_EQ(Greedy(sets, o).picks.size(), 3u);
  o.min_gain_voxels_per_minute = 0;
  o.surface_voxels_per_m2 = 0;  // no conversion: the area rule never stops
  EXPECT_EQ(Greedy(sets, o).picks.size(), 3u);
}

TEST(GreedyTest, GainRuleAlwaysPlacesTheFirstStation) {
  std::vector<VoxelSet> sets = {MakeSet(10, {0, 1, 2, 3, 4, 5}), MakeSet(10, {6, 7, 8})};
  GreedyOptions o = FullCoverage();
  o.station_seconds = 60;
  o.min_gain_voxels_per_minute = 1e6;
  const GreedyResult r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0}));
  EXPECT_EQ(r.stop, StopReason::kGainRule);
}

TEST(GreedyTest, StopsAtTargetCoverage) {
  std::vector<VoxelSet> sets = {MakeSet(10, {0, 1, 2, 3, 4, 5}), MakeSet(10, {6, 7, 8}), MakeSet(10, {9})};
  GreedyOptions o;
  o.target_coverage = 0.6;  // 6 of 10 after the first pick
  GreedyResult r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0}));
  EXPECT_EQ(r.stop, StopReason::kTargetReached);
  o.target_coverage = 0.61;
  r = Greedy(sets, o);
  EXPECT_EQ(Picks(r), std::vector<int>({0, 1}));
}

TEST(GreedyTest, NothingCoverableMeansNoPick) {
  std::vector<VoxelSet> sets = {VoxelSet(10), VoxelSet(10)};
  const GreedyResult r = Greedy(sets);
  EXPECT_TRUE(r.picks.empty());
  EXPECT_EQ(r.coverable, 0u);
  EXPECT_EQ(r.stop, StopReason::kExhausted);
}

std::vector<int> Consolidated(const std::vector<VoxelSet>& sets, std::vector<int> picks) {
  Result<ConsolidateResult> r = ConsolidatePicks(sets, std::move(picks));
  EXPECT_TRUE(r.ok());
  return r.ok() ? r->picks : std::vector<int>{};
}

uint64_t Covered(const std::vector<VoxelSet>& sets, const std::vector<int>& picks) {
  VoxelSet u(sets[0].size());
  for (int p : picks) UnionInto(u, sets[p]);
  return CountBits(u);
}

TEST(ConsolidateTest, RepairsTheClassicTrapToTheOptimum) {
  std::vector<VoxelSet> sets = {MakeSet(12, {0, 1, 2, 3, 4, 5}), MakeSet(12, {6, 7, 8, 9, 10, 11}),
                                MakeSet(12, {0, 1, 2, 6, 7, 8, 3})};
  const std::vector<int> greedy = Picks(Greedy(sets));
  ASSERT_EQ(greedy, std::vector<int>({2, 1, 0}));
  EXPECT_EQ(Consolidated(sets, greedy), std::vector<int>({1, 0}));  // pick 2 is covered by 0 and 1
}

TEST(ConsolidateTest, MergesTwoPicksIntoOneCandidate) {
  // Two half-rooms (0, 1) picked, while candidate 2 sees both halves; 3 covers the rest.
  std::vector<VoxelSet> sets = {MakeSet(10, {0, 1, 2, 8}), MakeSet(10, {3, 4, 5, 9}), MakeSet(10, {0, 1, 2, 3, 4, 5}),
                                MakeSet(10, {6, 7, 8, 9})};
  Result<ConsolidateResult> r = ConsolidatePicks(sets, {0, 1, 3});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->picks, std::vector<int>({2, 3}));
  EXPECT_EQ(r->merged, 1);
  EXPECT_EQ(r->dropped, 0);
}

TEST(ConsolidateTest, NeverLosesCoverageNorAddsPicks) {
  std::mt19937 rng(77);
  int saved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const size_t n = 20 + rng() % 200;
    std::vector<VoxelSet> sets;
    for (size_t i = 0; i < 5 + rng() % 30; ++i) {
      VoxelSet s(n);
      const size_t start = rng() % n, len = 1 + rng() % (n / 3);
      for (size_t v = 0; v < len; ++v) s.set((start + v) % n);
      sets.push_back(s);
    }
    const std::vector<int> greedy = Picks(Greedy(sets));
    const std::vector<int> merged = Consolidated(sets, greedy);
    EXPECT_EQ(Covered(sets, merged), Covered(sets, greedy)) << "trial " << trial;
    EXPECT_LE(merged.size(), greedy.size());
    if (sets.size() <= 16) {
      EXPECT_GE(static_cast<int>(merged.size()), MinimumCover(sets));
    }
    saved += static_cast<int>(greedy.size() - merged.size());
  }
  EXPECT_GT(saved, 0);  // the instances exercised it
}

// Consolidation as its header states it, written plainly (no neighbour filters, no coverage
// counts): drop the latest pick the others cover, else replace the first pair (in pick order) by
// the first candidate (by decreasing |set|, then index) that sees what only those two cover.
std::vector<int> ReferenceConsolidation(const std::vector<VoxelSet>& sets, std::vector<int> picks) {
  std::vector<int> order(sets.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return CountBits(sets[a]) > CountBits(sets[b]); });
  auto others = [&](size_t a, size_t b) {
    VoxelSet u(sets[0].size());
    for (size_t k = 0; k < picks.size(); ++k) {
      if (k != a && k != b) UnionInto(u, sets[picks[k]]);
    }
    return u;
  };
  auto covers = [](const VoxelSet& big, const VoxelSet& small) { return CountAnd(big, small) == CountBits(small); };
  while (true) {
    bool changed = false;
    for (size_t i = picks.size(); picks.size() > 1 && i-- > 0 && !changed;) {
      if (covers(others(i, i), sets[picks[i]])) {
        picks.erase(picks.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
      }
    }
    for (size_t a = 0; a < picks.size() && !changed; ++a) {
      for (size_t b = a + 1; b < picks.size() && !changed; ++b) {
        const VoxelSet rest_of = others(a, b);
        VoxelSet rest(sets[0].size());
        for (size_t v = 0; v < rest.size(); ++v) {
          if ((sets[picks[a]].test(v) || sets[picks[b]].test(v)) && !rest_of.test(v)) rest.set(v);
        }
        for (int c : order) {
          if (!covers(sets[c], rest)) continue;
          picks[a] = c;
          picks.erase(picks.begin() + static_cast<std::ptrdiff_t>(b));
          changed = true;
          break;
        }
      }
    }
    if (!changed) return picks;
  }
}

TEST(ConsolidateTest, SameAsThePlainReferenceOnSitesWithFarApartPicks) {
  std::mt19937 rng(2026);
  int changed = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const size_t n = 200 + rng() % 800;
    std::vector<VoxelSet> sets;
    for (size_t i = 0; i < 20 + rng() % 60; ++i) {
      VoxelSet s(n);
      const size_t start = rng() % n, len = 5 + rng() % 40;
      for (size_t v = 0; v < len; ++v) {
        if (rng() % 5 != 0) s.set((start + v) % n);
      }
      sets.push_back(s);
    }
    const std::vector<int> greedy = Picks(Greedy(sets));
    const std::vector<int> want = ReferenceConsolidation(sets, greedy);
    EXPECT_EQ(Consolidated(sets, greedy), want) << "trial " << trial;
    changed += want != greedy;
  }
  EXPECT_GT(changed, 10);  // the instances exercised drops and merges
}

// Picks drawn at random (not greedy's), so that many of them are redundant and one change makes
// another possible: the pairs found unmergeable before a change are rechecked where it touched them.
TEST(ConsolidateTest, SameAsThePlainReferenceWhenEachChangeEnablesTheNext) {
  std::mt19937 rng(37);
  int long_runs = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const size_t n = 150 + rng() % 300;
    std::vector<VoxelSet> sets;
    for (size_t i = 0; i < 30 + rng() % 40; ++i) {
      VoxelSet s(n);
      const size_t start = rng() % n, len = 10 + rng() % 60;
      for (size_t v = 0; v < len; ++v) {
        if (rng() % 4 != 0) s.set((start + v) % n);
      }
      sets.push_back(s);
    }
    std::vector<int> picks(sets.size());
    std::iota(picks.begin(), picks.end(), 0);
    std::shuffle(picks.begin(), picks.end(), rng);
    picks.resize(8 + rng() % 16);
    const std::vector<int> want = ReferenceConsolidation(sets, picks);
    EXPECT_EQ(Consolidated(sets, picks), want) << "trial " << trial;
    long_runs += picks.size() - want.size() >= 4;
  }
  EXPECT_GT(long_runs, 30);  // most instances took several passes
}

// A large universe (2^16 voxels, 128 blocks of 512) with clusters of candidates far apart,
// some of them sparse: the blocks each candidate touches rule most pairs out before any voxel is
// compared, and the picks stay those of the plain reference.
TEST(ConsolidateTest, SameAsThePlainReferenceOnALargeSiteOfFarApartClusters) {
  std::mt19937 rng(35);
  const size_t n = size_t{1} << 16;
  int changed = 0;
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<VoxelSet> sets;
    for (int cluster = 0; cluster < 6; ++cluster) {
      const size_t base = rng() % (n - 3000);
      for (int i = 0; i < 8; ++i) {
        VoxelSet s(n);
        const size_t start = base + rng() % 800, len = 300 + rng() % 1200;
        for (size_t v = 0; v < len; ++v) {
          if (rng() % 4 != 0) s.set(start + v);
        }
        if (i % 3 == 0) s.Compact(0.0001);  // sparse when the bitmap is smaller at all
        sets.push_back(s);
      }
    }
    std::vector<int> picks(sets.size());
    std::iota(picks.begin(), picks.end(), 0);
    std::shuffle(picks.begin(), picks.end(), rng);
    picks.resize(30 + rng() % 18);
    const std::vector<int> want = ReferenceConsolidation(sets, picks);
    EXPECT_EQ(Consolidated(sets, picks), want) << "trial " << trial;
    changed += want != picks;
  }
  EXPECT_GE(changed, 6);  // most trials dropped or merged (7 of 8 with this seed)
}

// `pairs` pairs of half-rooms, each pair seen whole by one more candidate: consolidation merges one
// pair per pass, so it takes pairs + 1 passes. The picks are the half-rooms (0 .. 2 pairs - 1).
std::vector<VoxelSet> HalfRoomPairs(int pairs) {
  const size_t n = size_t(pairs) * 8;
  std::vector<VoxelSet> sets;
  for (int p = 0; p < pairs; ++p) {
    VoxelSet left(n), right(n);
    for (size_t v = 0; v < 4; ++v) left.set(size_t(p) * 8 + v);
    for (size_t v = 4; v < 8; ++v) right.set(size_t(p) * 8 + v);
    sets.push_back(left);
    sets.push_back(right);
  }
  for (int p = 0; p < pairs; ++p) {
    VoxelSet whole(n);
    for (size_t v = 0; v < 8; ++v) whole.set(size_t(p) * 8 + v);
    sets.push_back(whole);
  }
  return sets;
}

std::vector<int> FirstPicks(int count) {
  std::vector<int> picks(size_t(count), 0);
  std::iota(picks.begin(), picks.end(), 0);
  return picks;
}

TEST(ConsolidateTest, ReportsEveryPassWithCountsAndRisingFractions) {
  const std::vector<VoxelSet> sets = HalfRoomPairs(6);
  std::vector<ProgressEvent> events;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { events.push_back(e); };
  Result<ConsolidateResult> r = ConsolidatePicks(sets, FirstPicks(12), {}, ctx);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->merged, 6);
  std::vector<std::string> passes_seen;
  for (size_t i = 0; i < events.size(); ++i) {
    const ProgressEvent& e = events[i];
    EXPECT_EQ(e.stage, Stage::kSelection);
    EXPECT_NE(e.message.find("consolidation pass "), std::string::npos) << e.message;
    if (i > 0) {
      EXPECT_GE(e.fraction, events[i - 1].fraction) << "event " << i << ": " << e.message;
    }
    if (e.unit.empty() || e.unit == "picks checked") continue;  // the latter only in a slow pass
    EXPECT_EQ(e.unit, "pairs of picks");
    EXPECT_LE(e.done, e.total);
    if (e.done == 0) passes_seen.push_back(e.message.substr(0, e.message.find(" (")));
  }
  // 12 picks (66 pairs) in the first pass, one fewer per merge, and a last pass that changes nothing.
  EXPECT_EQ(events.front().total, 66u);
  ASSERT_FALSE(passes_seen.empty());
  EXPECT_EQ(passes_seen.back(), "consolidation pass 7");
  EXPECT_EQ(events.back().fraction, 1.0);
  EXPECT_NE(events.back().message.find("6 merged"), std::string::npos) << events.back().message;
}

// A long consolidation (every candidate of a strip picked, most of them redundant) reports each of
// its many passes with the pairs of picks it has, the count falling by a pick per pass.
TEST(ConsolidateTest, ALongConsolidationReportsEveryPassWithItsPairsOfPicks) {
  std::vector<VoxelSet> sets;
  for (size_t start = 0; start < 400; start += 4) {
    VoxelSet s(420);
    for (size_t v = start; v < start + 20; ++v) s.set(v);
    sets.push_back(s);
  }
  std::vector<uint64_t> pass_totals;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) {
    if (e.unit == "pairs of picks" && e.done == 0) pass_totals.push_back(e.total);
  };
  Result<ConsolidateResult> r = ConsolidatePicks(sets, FirstPicks(static_cast<int>(sets.size())), {}, ctx);
  ASSERT_TRUE(r.ok());
  const int changes = r->dropped + r->merged;
  EXPECT_GE(changes, 50);  // 100 picks of 20 voxels each, 4 apart: about one in five is needed
  ASSERT_EQ(pass_totals.size(), size_t(changes) + 1);  // one report at each pass's start
  for (size_t k = 0; k < pass_totals.size(); ++k) {
    const uint64_t picks = sets.size() - k;
    EXPECT_EQ(pass_totals[k], picks * (picks - 1) / 2) << "pass " << k + 1;
  }
}

// The time budget: spent at once, nothing is changed and the result says so; none (0), the picks
// are the reference's.
TEST(ConsolidateTest, StopsAtItsTimeBudgetKeepingThePicksSoFar) {
  const std::vector<VoxelSet> sets = HalfRoomPairs(6);
  GreedyOptions o;
  o.consolidate_budget_s = 1e-12;
  std::string last;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { last = e.message; };
  Result<ConsolidateResult> r = ConsolidatePicks(sets, FirstPicks(12), o, ctx);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->budget_reached);
  EXPECT_EQ(r->picks, FirstPicks(12));
  EXPECT_EQ(r->merged + r->dropped, 0);
  EXPECT_NE(last.find("stopped at its time budget"), std::string::npos) << last;
  o.consolidate_budget_s = 0;
  r = ConsolidatePicks(sets, FirstPicks(12), o, ctx);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->budget_reached);
  EXPECT_EQ(r->merged, 6);
  EXPECT_EQ(r->picks, ReferenceConsolidation(sets, FirstPicks(12)));
  EXPECT_NE(last.find(", done"), std::string::npos) << last;
}

TEST(ConsolidateTest, CancelledDuringAPassReturnsCancelledAtOnce) {
  const std::vector<VoxelSet> sets = HalfRoomPairs(6);
  CancelToken cancel;
  int events_after_cancel = 0;
  JobContext ctx;
  ctx.cancel = &cancel;
  ctx.progress = [&](const ProgressEvent& e) {
    if (cancel.cancelled()) ++events_after_cancel;
    if (e.message.rfind("consolidation pass 2", 0) == 0) cancel.Cancel();
  };
  Result<ConsolidateResult> r = ConsolidatePicks(sets, FirstPicks(12), {}, ctx);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_EQ(events_after_cancel, 0);  // stopped before the next report, let alone the next pass
}

TEST(GreedyTest, RejectsSetsOfDifferentSizes) {
  std::vector<VoxelSet> sets = {VoxelSet(10), VoxelSet(11)};
  const auto r = SelectGreedy(sets, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
}

TEST(GreedyTest, RejectsBadOptions) {
  GreedyOptions o;
  o.target_coverage = 0;
  EXPECT_EQ(SelectGreedy(ThreeRooms(), o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.max_stations = -1;
  EXPECT_EQ(SelectGreedy(ThreeRooms(), o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.min_gain_voxels_per_minute = -1;
  EXPECT_EQ(SelectGreedy(ThreeRooms(), o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.min_gain_m2_per_minute = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(SelectGreedy(ThreeRooms(), o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.surface_voxels_per_m2 = -1;
  EXPECT_EQ(SelectGreedy(ThreeRooms(), o).status().code(), StatusCode::kInvalidArgument);
  o = {};
  o.station_seconds = std::numeric_limits<double>::infinity();
  EXPECT_EQ(SelectGreedy(ThreeRooms(), o).status().code(), StatusCode::kInvalidArgument);
}

TEST(GreedyTest, Cancelled) {
  CancelToken token;
  token.Cancel();
  JobContext ctx;
  ctx.cancel = &token;
  const auto r = SelectGreedy(ThreeRooms(), {}, ctx);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace vc::planner
