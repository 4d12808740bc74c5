// ExactSelector: the integer program's optimum equals exhaustive search on small random instances
// (minimum stations, and maximum coverage with max_stations, including targets no plan of that
// size reaches), fixed stations stay first, never worse than greedy, comb:5's optimum on the 1 m
// grid, the model reduction, the time limit, cancellation and the memory-budget fallback; auto's
// shortcuts past CBC (the bound met by greedy, the swaps, the search or the Lagrangian heuristic).
#include "vc/plan/exact_selector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "vc/plan/greedy.h"
#include "vc/plan/scan_graph.h"
#include "vc/plan/stages.h"
#include "vc/synth/synth.h"

namespace vc::planner {
namespace {

std::vector<VoxelSet> RandomSets(std::mt19937& rng, int n, size_t voxels, double density) {
  std::bernoulli_distribution bit(density);
  std::vector<VoxelSet> sets(n, VoxelSet(voxels));
  for (VoxelSet& s : sets) {
    for (size_t v = 0; v < voxels; ++v) {
      if (bit(rng)) s.set(v);
    }
  }
  return sets;
}

uint64_t Union(const std::vector<VoxelSet>& sets, const std::vector<int>& picks) {
  VoxelSet u(sets[0].size());
  for (int p : picks) UnionInto(u, sets[p]);
  return CountBits(u);
}

uint64_t Target(double fraction, uint64_t coverable) {
  uint64_t k = 0;
  while (static_cast<double>(k) < fraction * static_cast<double>(coverable)) ++k;
  return k;
}

struct Best {
  int stations = 0;      // fewest stations (fixed included) of a plan with the best coverage
  uint64_t covered = 0;  // min(covered, target) of that plan
};

// Every subset containing the fixed sets: with max_stations > 0 (not counting the fixed ones) the
// most covered voxels (capped at target), then the fewest stations; else the fewest stations
// reaching the target.
Best Exhaustive(const std::vector<VoxelSet>& sets, int fixed, uint64_t target, int max_stations) {
  const int n = static_cast<int>(sets.size());
  Best best{n + 1, 0};
  for (uint32_t mask = 0; mask < (1u << n); ++mask) {
    if ((mask & ((1u << fixed) - 1)) != ((1u << fixed) - 1)) continue;
    std::vector<int> picks;
    for (int i = 0; i < n; ++i) {
      if (mask >> i & 1) picks.push_back(i);
    }
    const int free_picks = static_cast<int>(picks.size()) - fixed;
    if (max_stations > 0 && free_picks > max_stations) continue;
    const uint64_t covered = std::min(Union(sets, picks), target);
    if (max_stations == 0 && covered < target) continue;
    const int stations = static_cast<int>(picks.size());
    if (covered > best.covered || (covered == best.covered && stations < best.stations)) best = {stations, covered};
  }
  return best;
}

void ExpectFixedFirstAndGainOrder(const std::vector<VoxelSet>& sets, const Selection& s, int fixed) {
  ASSERT_GE(s.picks.size(), static_cast<size_t>(fixed));
  for (int i = 0; i < fixed; ++i) EXPECT_EQ(s.picks[i], i);
  VoxelSet so_far(sets[0].size());
  for (int i = 0; i < fixed; ++i) UnionInto(so_far, sets[i]);
  uint64_t last_gain = UINT64_MAX;
  for (size_t k = fixed; k < s.picks.size(); ++k) {
    EXPECT_GE(s.picks[k], fixed);
    const uint64_t gain = CountBits(sets[s.picks[k]]) - CountAnd(sets[s.picks[k]], so_far);
    EXPECT_LE(gain, last_gain) << "picks not in order of marginal gain at " << k;
    last_gain = gain;
    UnionInto(so_far, sets[s.picks[k]]);
  }
}

TEST(ExactSelectorTest, MinimumStationsEqualsExhaustiveSearch) {
  std::mt19937 rng(21);
  int beats_greedy = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const int n = 4 + static_cast<int>(rng() % 9);
    const size_t voxels = 20 + rng() % 120;
    std::vector<VoxelSet> sets = RandomSets(rng, n, voxels, 0.08 + 0.3 * (rng() % 100) / 100.0);
    const int fixed = static_cast<int>(rng() % 3);
    const double target = std::vector<double>{1.0, 0.95, 0.8, 0.5}[rng() % 4];
    ExactSelectorOptions o;
    o.greedy.target_coverage = target;
    o.greedy.consolidate = trial % 2 == 0;
    Result<Selection> got = ExactSelector(o).Select(sets, fixed, {});
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    const uint64_t t = Target(target, got->coverable);
    const Best want = Exhaustive(sets, fixed, t, 0);
    const std::string what = "trial " + std::to_string(trial);
    EXPECT_EQ(static_cast<int>(got->picks.size()), want.stations) << what;
    EXPECT_GE(got->covered, t) << what;
    EXPECT_EQ(got->covered, Union(sets, got->picks)) << what;
    EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal) << what;
    EXPECT_EQ(got->optimality.lower_bound, want.stations) << what;
    EXPECT_EQ(got->optimality.gap, 0.0) << what;
    EXPECT_EQ(got->optimality.solver, "exact");
    ExpectFixedFirstAndGainOrder(sets, *got, fixed);
    Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, fixed, {});
    ASSERT_TRUE(greedy.ok());
    EXPECT_LE(got->picks.size(), greedy->picks.size()) << what;
    beats_greedy += got->picks.size() < greedy->picks.size();
  }
  EXPECT_GT(beats_greedy, 0) << "no instance where greedy was short of the optimum: the test proves little";
}

// prefer_greedy (--solver auto): greedy's plan exactly as GreedySelector returns it (picks, order,
// covered, stop) unless the integer program has strictly fewer stations (max_stations: strictly
// more coverage, or as much with fewer stations); the bounds are the solver's either way.
TEST(ExactSelectorTest, PreferGreedyKeepsGreedysPlanUnlessStrictlyBetter) {
  std::mt19937 rng(33);
  int kept_although_exact_differs = 0, replaced = 0, by_the_bound = 0, by_the_search = 0, by_the_heuristic = 0;
  for (int trial = 0; trial < 160; ++trial) {
    const int n = 4 + static_cast<int>(rng() % 9);
    const size_t voxels = 20 + rng() % 120;
    std::vector<VoxelSet> sets = RandomSets(rng, n, voxels, 0.08 + 0.3 * (rng() % 100) / 100.0);
    const int fixed = static_cast<int>(rng() % 3);
    ExactSelectorOptions o;
    o.greedy.target_coverage = std::vector<double>{1.0, 0.95, 0.8}[rng() % 3];
    o.greedy.consolidate = trial % 2 == 0;
    const bool max_mode = trial % 4 == 3;
    if (max_mode) o.greedy.max_stations = 1 + static_cast<int>(rng() % 3);
    Result<Selection> exact = ExactSelector(o).Select(sets, fixed, {});
    o.prefer_greedy = true;
    Result<Selection> got = ExactSelector(o).Select(sets, fixed, {});
    Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, fixed, {});
    ASSERT_TRUE(got.ok() && exact.ok() && greedy.ok()) << got.status().ToString();
    const std::string what = "trial " + std::to_string(trial);
    const uint64_t t = Target(o.greedy.target_coverage, got->coverable);
    const auto key = [&](const std::vector<int>& picks) {
      return std::make_pair(std::min(Union(sets, picks), t), -static_cast<int>(picks.size()));
    };
    const bool better = max_mode ? key(exact->picks) > key(greedy->picks) : exact->picks.size() < greedy->picks.size();
    if (better) {
      ++replaced;
      EXPECT_EQ(got->picks.size(), exact->picks.size()) << what;
      EXPECT_EQ(key(got->picks), key(exact->picks)) << what;
    } else {
      kept_although_exact_differs += exact->picks != greedy->picks;
      EXPECT_EQ(got->picks, greedy->picks) << what;
      EXPECT_EQ(got->covered, greedy->covered) << what;
      EXPECT_EQ(got->stop, greedy->stop) << what;
    }
    EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal) << what;
    EXPECT_EQ(got->optimality.stations, static_cast<int>(got->picks.size())) << what;
    if (!max_mode) EXPECT_EQ(got->optimality.lower_bound, exact->optimality.lower_bound) << what;
    // Auto's shortcut (the bound met by greedy's plan or by the swap search from it; no CBC): the
    // same station count as CBC's proven optimum, checked above.
    by_the_bound += got->optimality.note.find("no integer program solved") != std::string::npos;
    // ... and where a search over every plan one station smaller raised the bound to it.
    by_the_search += got->optimality.note.find("a search over every plan") != std::string::npos;
    // ... and where the Lagrangian heuristic's plan met the bound.
    by_the_heuristic += got->optimality.note.find("Lagrangian heuristic") != std::string::npos;
  }
  std::cout << "[ shortcuts ] " << by_the_bound << " by the bound, " << by_the_search << " by the search, "
            << by_the_heuristic << " by the Lagrangian heuristic's plan, of 160\n";
  EXPECT_GT(by_the_bound, 0) << "the bound never settled a selection: the shortcut is untested";
  EXPECT_GT(by_the_search, 0) << "the search never raised the bound: it is untested";
  EXPECT_GT(kept_although_exact_differs, 0) << "exact never reordered greedy's plan: the test proves little";
}

// The gain rule (min_gain_voxels_per_minute): greedy stops where a station is worth less than its
// minutes; the integer program then seeks the fewest stations covering what greedy covered there,
// not the target coverage, and the plan says the gain rule stopped it.
TEST(ExactSelectorTest, GainRuleMinimisesStationsForWhatGreedyCoveredWhenItStopped) {
  std::mt19937 rng(47);
  int stopped_by_rule = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const int n = 4 + static_cast<int>(rng() % 9);
    const size_t voxels = 40 + rng() % 120;
    std::vector<VoxelSet> sets = RandomSets(rng, n, voxels, 0.08 + 0.3 * (rng() % 100) / 100.0);
    const int fixed = static_cast<int>(rng() % 2);
    ExactSelectorOptions o;
    o.greedy.target_coverage = 1.0;
    o.greedy.station_seconds = 60;
    o.greedy.min_gain_voxels_per_minute = 2 + static_cast<double>(rng() % 8);
    o.prefer_greedy = trial % 2 == 0;
    Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, fixed, {});
    Result<Selection> got = ExactSelector(o).Select(sets, fixed, {});
    ASSERT_TRUE(greedy.ok() && got.ok()) << got.status().ToString();
    if (greedy->stop != StopReason::kGainRule) continue;
    ++stopped_by_rule;
    const std::string what = "trial " + std::to_string(trial);
    const Best want = Exhaustive(sets, fixed, greedy->covered, 0);
    EXPECT_EQ(static_cast<int>(got->picks.size()), want.stations) << what;
    EXPECT_GE(got->covered, greedy->covered) << what;
    // Fewer stations may happen to cover every coverable voxel: then that is why it stopped.
    const StopReason want_stop = got->covered == got->coverable ? StopReason::kExhausted : StopReason::kGainRule;
    EXPECT_EQ(got->stop, want_stop) << what;
  }
  EXPECT_GT(stopped_by_rule, 10) << "the gain rule rarely stopped greedy: the test proves little";
}

// With max_stations the covered voxels are maximised (capped at the target); when no plan of that
// size reaches the target, the plan covers the most any can and stops on kMaxStations.
TEST(ExactSelectorTest, MaximumCoverageEqualsExhaustiveSearchIncludingUnreachableTargets) {
  std::mt19937 rng(2021);
  int unreachable = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const int n = 4 + static_cast<int>(rng() % 9);
    const size_t voxels = 20 + rng() % 120;
    std::vector<VoxelSet> sets = RandomSets(rng, n, voxels, 0.05 + 0.25 * (rng() % 100) / 100.0);
    const int fixed = static_cast<int>(rng() % 2);
    ExactSelectorOptions o;
    o.greedy.max_stations = 1 + static_cast<int>(rng() % 3);
    o.greedy.target_coverage = std::vector<double>{1.0, 0.9, 0.6}[rng() % 3];
    Result<Selection> got = ExactSelector(o).Select(sets, fixed, {});
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    const uint64_t t = Target(o.greedy.target_coverage, got->coverable);
    const Best want = Exhaustive(sets, fixed, t, o.greedy.max_stations);
    const std::string what = "trial " + std::to_string(trial);
    EXPECT_EQ(std::min(got->covered, t), want.covered) << what;
    EXPECT_EQ(static_cast<int>(got->picks.size()), want.stations) << what;
    EXPECT_LE(static_cast<int>(got->picks.size()) - fixed, o.greedy.max_stations) << what;
    EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal) << what;
    EXPECT_EQ(got->optimality.covered_bound, want.covered) << what;
    if (want.covered < t) {
      ++unreachable;
      EXPECT_EQ(got->stop, StopReason::kMaxStations) << what;
    } else {
      EXPECT_NE(got->stop, StopReason::kMaxStations) << what;
    }
    ExpectFixedFirstAndGainOrder(sets, *got, fixed);
  }
  EXPECT_GT(unreachable, 10);
  EXPECT_LT(unreachable, 110);
}

// Whether `picks` form one component of the scan graph at min_overlap (scan_graph.h).
bool Connected(const std::vector<VoxelSet>& sets, const std::vector<int>& picks, double min_overlap) {
  if (picks.empty()) return true;
  std::vector<int> reached{picks[0]};
  std::vector<char> seen(sets.size(), 0);
  seen[picks[0]] = 1;
  for (size_t q = 0; q < reached.size(); ++q) {
    for (int p : picks) {
      if (!seen[p] && IsEdge(Overlap(sets[reached[q]], sets[p]), min_overlap)) {
        seen[p] = 1;
        reached.push_back(p);
      }
    }
  }
  return reached.size() == picks.size();
}

// With min_overlap the optimum is over connected plans (the single-commodity flow); when no
// connected plan reaches the target the greedy plan comes back, heuristic, with a note.
TEST(ExactSelectorTest, ConnectedOptimumEqualsExhaustiveSearch) {
  std::mt19937 rng(2022);
  int infeasible = 0, dearer = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 4 + static_cast<int>(rng() % 8);
    const size_t voxels = 30 + rng() % 90;
    std::vector<VoxelSet> sets = RandomSets(rng, n, voxels, 0.1 + 0.3 * (rng() % 100) / 100.0);
    const int fixed = static_cast<int>(rng() % 2);
    ExactSelectorOptions o;
    o.greedy.target_coverage = std::vector<double>{1.0, 0.9, 0.7}[rng() % 3];
    o.greedy.min_overlap = std::vector<double>{0.2, 0.3, 0.4}[rng() % 3];
    Result<Selection> got = ExactSelector(o).Select(sets, fixed, {});
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    const uint64_t t = Target(o.greedy.target_coverage, got->coverable);
    // Exhaustive: the fewest stations of a connected plan (fixed included) reaching the target.
    int best = n + 1;
    for (uint32_t mask = 0; mask < (1u << n); ++mask) {
      if (fixed && !(mask & 1u)) continue;
      std::vector<int> picks;
      for (int i = 0; i < n; ++i) {
        if (mask >> i & 1) picks.push_back(i);
      }
      if (static_cast<int>(picks.size()) >= best || Union(sets, picks) < t) continue;
      if (Connected(sets, picks, o.greedy.min_overlap)) best = static_cast<int>(picks.size());
    }
    const std::string what = "trial " + std::to_string(trial);
    if (best > n) {
      ++infeasible;
      EXPECT_EQ(got->optimality.status, OptimalityStatus::kHeuristic) << what;
      EXPECT_NE(got->optimality.note.find("no connected plan"), std::string::npos) << what;
      continue;
    }
    EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal) << what;
    EXPECT_EQ(static_cast<int>(got->picks.size()), best) << what;
    EXPECT_GE(got->covered, t) << what;
    EXPECT_TRUE(Connected(sets, got->picks, o.greedy.min_overlap)) << what;
    ExpectFixedFirstAndGainOrder(sets, *got, fixed);
    const Best unconnected = Exhaustive(sets, fixed, t, 0);
    dearer += best > unconnected.stations;
  }
  EXPECT_GT(infeasible, 0);
  EXPECT_LT(infeasible, 60);
  EXPECT_GT(dearer, 0) << "connectivity never cost a station: the test proves little";
}

// prefer_greedy with min_overlap: the plan is connected whenever a connected one exists, in both
// modes; greedy's plan is kept only when it is connected and no worse.
TEST(ExactSelectorTest, PreferGreedyNeverKeepsADisconnectedPlan) {
  std::mt19937 rng(2023);
  int replaced_disconnected = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const int n = 4 + static_cast<int>(rng() % 8);
    const size_t voxels = 30 + rng() % 90;
    std::vector<VoxelSet> sets = RandomSets(rng, n, voxels, 0.1 + 0.3 * (rng() % 100) / 100.0);
    ExactSelectorOptions o;
    o.greedy.target_coverage = std::vector<double>{1.0, 0.9, 0.7}[rng() % 3];
    o.greedy.min_overlap = std::vector<double>{0.2, 0.3, 0.4}[rng() % 3];
    if (trial % 2) o.greedy.max_stations = 1 + static_cast<int>(rng() % 3);
    Result<Selection> exact = ExactSelector(o).Select(sets, 0, {});
    o.prefer_greedy = true;
    Result<Selection> got = ExactSelector(o).Select(sets, 0, {});
    Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, 0, {});
    ASSERT_TRUE(exact.ok() && got.ok() && greedy.ok());
    const std::string what = "trial " + std::to_string(trial);
    if (exact->optimality.status == OptimalityStatus::kHeuristic) continue;  // no connected plan found
    EXPECT_TRUE(Connected(sets, got->picks, o.greedy.min_overlap)) << what;
    if (!Connected(sets, greedy->picks, o.greedy.min_overlap)) {
      ++replaced_disconnected;
      EXPECT_NE(got->picks, greedy->picks) << what;
    }
  }
  EXPECT_GT(replaced_disconnected, 0) << "greedy's plan was always connected: the test proves little";
}

TEST(ExactSelectorTest, FixedStationsStayFirstEvenWhenUseless) {
  std::vector<VoxelSet> sets(4, VoxelSet(10));
  for (size_t v = 0; v < 10; ++v) sets[3].set(v);  // one candidate sees everything
  sets[0].set(0);                                  // fixed, covered by candidate 3
  // sets[1] is a fixed station that sees nothing.
  sets[2].set(1);
  Result<Selection> got = ExactSelector({}).Select(sets, 2, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_EQ(got->picks, (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal);
  EXPECT_EQ(got->optimality.lower_bound, 3);
}

TEST(ExactSelectorTest, ReductionMergesClassesDropsDominatedAndFixesSoleViews) {
  // Voxels 0-3 seen by {0, 1}; 4-5 by {1} only; 6-9 by {2, 3}; candidate 4 = candidate 3.
  std::vector<VoxelSet> sets(5, VoxelSet(10));
  for (int v : {0, 1, 2, 3}) sets[0].set(v);
  for (int v : {0, 1, 2, 3, 4, 5}) sets[1].set(v);
  for (int v : {6, 7}) sets[2].set(v);
  for (int v : {6, 7, 8, 9}) sets[3].set(v), sets[4].set(v);
  Result<Selection> got = ExactSelector({}).Select(sets, 0, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_EQ(got->optimality.before.candidates, 5);
  EXPECT_EQ(got->optimality.before.voxel_classes, 10);
  // 1 is the only view of 4-5: fixed, it covers all 0 sees; 2 and 4 are dominated by 3, which is
  // then the only view of 6-9: nothing is left to solve.
  EXPECT_EQ(got->optimality.forced, 2);
  EXPECT_EQ(got->optimality.dominated, 2);
  EXPECT_EQ(got->optimality.model.candidates, 0);
  EXPECT_EQ(got->optimality.model.voxel_classes, 0);
  std::vector<int> picks = got->picks;
  std::sort(picks.begin(), picks.end());
  EXPECT_EQ(picks, (std::vector<int>{1, 3}));
  EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal);
}

TEST(ExactSelectorTest, NeverWorseThanGreedyOnLargerInstances) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<VoxelSet> sets = RandomSets(rng, 60, 800, 0.04);
    ExactSelectorOptions o;
    o.greedy.target_coverage = trial % 2 ? 1.0 : 0.97;
    o.time_limit_s = trial % 3 == 0 ? 0.05 : 2.0;
    Result<Selection> got = ExactSelector(o).Select(sets, 0, {});
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, 0, {});
    ASSERT_TRUE(greedy.ok());
    EXPECT_LE(got->picks.size(), greedy->picks.size()) << "trial " << trial;
    EXPECT_GE(got->covered, Target(o.greedy.target_coverage, got->coverable));
    EXPECT_LE(got->optimality.lower_bound, got->picks.size());
    EXPECT_NE(got->optimality.status, OptimalityStatus::kHeuristic);
  }
}

// With the time limit too short for CBC to improve anything, auto's plan is the better of greedy's
// and the Lagrangian heuristic's (CBC's warm start, ExactRun::WarmPicks): never more stations than
// greedy's, always at the target, and fewer where the heuristic's plan is (geb079: 49 against 51).
TEST(ExactSelectorTest, AutoStartsFromTheLagrangianPlanWhereItBeatsGreedy) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<VoxelSet> sets = RandomSets(rng, 60, 800, 0.04);
    ExactSelectorOptions o;
    o.prefer_greedy = true;
    o.greedy.target_coverage = trial % 2 ? 1.0 : 0.97;
    o.time_limit_s = 1e-3;
    Result<Selection> got = ExactSelector(o).Select(sets, 0, {});
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, 0, {});
    ASSERT_TRUE(greedy.ok());
    EXPECT_LE(got->picks.size(), greedy->picks.size()) << "trial " << trial;
    EXPECT_GE(Union(sets, got->picks), Target(o.greedy.target_coverage, got->coverable)) << "trial " << trial;
    EXPECT_LE(got->optimality.lower_bound, got->picks.size()) << "trial " << trial;
    // Trial 6: greedy 46, the swaps from it stall, the Lagrangian heuristic's plan 45 (not at the
    // bound); before CBC started from it, auto returned greedy's 46 here.
    if (trial == 6) {
      EXPECT_EQ(greedy->picks.size(), 46u);
      EXPECT_LE(got->picks.size(), 45u);
    }
  }
}

// Rooms around a hall (hub:K in miniature): per room a deep station that sees only the room and
// one just inside its door that sees the room and a share of the hall, the shares tiling it; one
// hall station sees all of the hall. Greedy takes the hall first, then a deep station per room
// (the lower index among equal gains): K + 1. No drop, 2-for-1 or 1-for-1 exchange gets below that
// (every door station must come in at once), so the swap search stalls; the Lagrangian heuristic's
// plan is the K door stations, which the bound proves: optimal, no integer program.
TEST(ExactSelectorTest, LagrangianPlanProvesRoomsAroundAHallWhereTheSwapsStall) {
  const int rooms = 6;
  const size_t room_voxels = 60, share_voxels = 400, per_room = room_voxels + share_voxels;
  std::vector<VoxelSet> sets(2 * rooms + 1, VoxelSet(rooms * per_room));
  for (int r = 0; r < rooms; ++r) {
    for (size_t v = r * per_room; v < r * per_room + room_voxels; ++v) {
      sets[r].set(v);          // deep station r
      sets[rooms + r].set(v);  // door station r
    }
    for (size_t v = r * per_room + room_voxels; v < (r + 1) * per_room; ++v) {
      sets[rooms + r].set(v);
      sets[2 * rooms].set(v);  // the hall station
    }
  }
  ExactSelectorOptions o;
  o.greedy.target_coverage = 0.99;  // below 1: no sole view is fixed, the model keeps its choice
  Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, 0, {});
  ASSERT_TRUE(greedy.ok());
  EXPECT_EQ(static_cast<int>(greedy->picks.size()), rooms + 1);
  o.prefer_greedy = true;
  Result<Selection> got = ExactSelector(o).Select(sets, 0, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  ASSERT_EQ(static_cast<int>(got->picks.size()), rooms);
  for (int p : got->picks) EXPECT_GE(p, rooms) << "not a door station";
  EXPECT_LT(*std::max_element(got->picks.begin(), got->picks.end()), 2 * rooms) << "the hall station";
  EXPECT_GE(got->covered, Target(0.99, got->coverable));
  EXPECT_EQ(got->covered, Union(sets, got->picks));
  EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal);
  EXPECT_EQ(got->optimality.lower_bound, rooms);
  EXPECT_NE(got->optimality.note.find("Lagrangian heuristic"), std::string::npos) << got->optimality.note;
  EXPECT_NE(got->optimality.note.find("no integer program solved"), std::string::npos) << got->optimality.note;
  // CBC agrees.
  o.prefer_greedy = false;
  Result<Selection> exact = ExactSelector(o).Select(sets, 0, {});
  ASSERT_TRUE(exact.ok());
  EXPECT_EQ(exact->picks.size(), got->picks.size());
  EXPECT_EQ(exact->optimality.status, OptimalityStatus::kOptimal);
}

// A random instance hard enough that CBC does not prove the optimum within a fraction of a second.
std::vector<VoxelSet> HardSets() {
  std::mt19937 rng(99);
  return RandomSets(rng, 250, 3000, 0.02);
}

TEST(ExactSelectorTest, TimeLimitReturnsAFeasiblePlanWithItsBound) {
  const std::vector<VoxelSet> sets = HardSets();
  ExactSelectorOptions o;
  o.greedy.target_coverage = 1.0;
  o.time_limit_s = 0.3;
  const auto t0 = std::chrono::steady_clock::now();
  Result<Selection> got = ExactSelector(o).Select(sets, 0, {});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_LT(seconds, o.time_limit_s + 3.0);
  EXPECT_EQ(got->optimality.status, OptimalityStatus::kFeasible);
  EXPECT_GT(got->optimality.lower_bound, 0);
  EXPECT_LT(got->optimality.lower_bound, got->picks.size());
  EXPECT_GT(got->optimality.gap, 0);
  EXPECT_EQ(got->covered, got->coverable);
}

// CBC checks its time limit only between nodes: the LP relaxation of a large partial-coverage model
// is cut off at the deadline too, and the Lagrangian bound over the reduced classes stands in for the LP's.
TEST(ExactSelectorTest, TimeLimitCutsOffALongRootLp) {
  std::mt19937 rng(3);
  const std::vector<VoxelSet> sets = RandomSets(rng, 120, 40000, 0.03);
  ExactSelectorOptions o;
  o.greedy.target_coverage = 0.99;
  o.time_limit_s = 0.2;
  const auto t0 = std::chrono::steady_clock::now();
  Result<Selection> got = ExactSelector(o).Select(sets, 0, {});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_LT(seconds, o.time_limit_s + 3.0);
  EXPECT_EQ(got->optimality.status, OptimalityStatus::kFeasible);
  EXPECT_GE(got->optimality.lower_bound, 1);
  EXPECT_LE(got->optimality.lower_bound, got->picks.size());
  EXPECT_GE(got->covered, Target(0.99, got->coverable));
}

TEST(ExactSelectorTest, CancellationStopsTheSolver) {
  const std::vector<VoxelSet> sets = HardSets();
  ExactSelectorOptions o;
  o.greedy.target_coverage = 1.0;
  o.time_limit_s = 60;
  CancelToken token;
  JobContext ctx;
  ctx.cancel = &token;
  std::thread canceller([&token] {
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    token.Cancel();
  });
  const auto t0 = std::chrono::steady_clock::now();
  Result<Selection> got = ExactSelector(o).Select(sets, 0, ctx);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  canceller.join();
  ASSERT_FALSE(got.ok());
  EXPECT_EQ(got.status().code(), StatusCode::kCancelled);
  EXPECT_LT(seconds, 10.0);
}

TEST(ExactSelectorTest, ReportsIncumbentAndBoundAsSelectionProgress) {
  const std::vector<VoxelSet> sets = HardSets();
  ExactSelectorOptions o;
  o.greedy.target_coverage = 1.0;
  o.time_limit_s = 1.5;
  std::vector<ProgressEvent> events;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { events.push_back(e); };
  Result<Selection> got = ExactSelector(o).Select(sets, 0, ctx);
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  bool seen = false;
  for (const ProgressEvent& e : events) {
    EXPECT_EQ(e.stage, Stage::kSelection);
    seen = seen || (e.message.find("incumbent") != std::string::npos && e.message.find("bound") != std::string::npos);
  }
  EXPECT_TRUE(seen);
}

TEST(ExactSelectorTest, ReportsClassesAndReductionWithCountsAndNeverFallingFractions) {
  const std::vector<VoxelSet> sets = HardSets();
  ExactSelectorOptions o;
  o.greedy.target_coverage = 1.0;
  o.greedy.consolidate = true;
  o.time_limit_s = 1.0;
  std::vector<ProgressEvent> events;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { events.push_back(e); };
  Result<Selection> got = ExactSelector(o).Select(sets, 0, ctx);
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  bool consolidation = false, classes = false, reduction = false;
  for (size_t i = 0; i < events.size(); ++i) {
    const ProgressEvent& e = events[i];
    if (i > 0) EXPECT_GE(e.fraction, events[i - 1].fraction) << "event " << i << ": " << e.message;
    consolidation = consolidation || e.message.rfind("consolidation pass 1", 0) == 0;
    if (e.message.rfind("exact: voxel classes", 0) == 0) {
      classes = true;
      EXPECT_EQ(e.unit, "candidate passes");
      EXPECT_EQ(e.total, 2 * sets.size());
    }
    if (e.message.rfind("exact: model reduction round ", 0) == 0) {
      reduction = true;
      EXPECT_EQ(e.unit, "candidates");
      EXPECT_GT(e.total, 0u);
      EXPECT_LE(e.done, e.total);
    }
  }
  EXPECT_TRUE(consolidation);
  EXPECT_TRUE(classes);
  EXPECT_TRUE(reduction);
}

TEST(ExactSelectorTest, SelectionFractionsNeverFallOnAnyPath) {
  std::mt19937 rng(37);
  const std::vector<VoxelSet> sets = RandomSets(rng, 60, 800, 0.04);
  struct Path {
    std::string name;
    double target;
    double min_overlap;
    uint64_t budget_bytes;
  };
  const std::vector<Path> paths = {{"full cover", 1.0, 0.0, uint64_t{1} << 30},
                                   {"below full cover (size probe)", 0.9, 0.0, uint64_t{1} << 30},
                                   {"connected (scan graph)", 0.95, 0.02, uint64_t{1} << 30},
                                   {"over the memory budget", 0.95, 0.0, 1}};
  for (const Path& path : paths) {
    ExactSelectorOptions o;
    o.greedy.target_coverage = path.target;
    o.greedy.min_overlap = path.min_overlap;
    o.memory_budget_bytes = path.budget_bytes;
    o.time_limit_s = 1.0;
    std::vector<ProgressEvent> events;
    JobContext ctx;
    ctx.progress = [&](const ProgressEvent& e) { events.push_back(e); };
    Result<Selection> got = ExactSelector(o).Select(sets, 0, ctx);
    ASSERT_TRUE(got.ok()) << path.name << ": " << got.status().ToString();
    ASSERT_FALSE(events.empty()) << path.name;
    for (size_t i = 1; i < events.size(); ++i) {
      EXPECT_GE(events[i].fraction, events[i - 1].fraction)
          << path.name << ", event " << i << ": " << events[i].message << " after " << events[i - 1].message;
    }
  }
}

TEST(ExactSelectorTest, OverTheMemoryBudgetFallsBackToSwapLocalSearch) {
  std::mt19937 rng(5);
  int fallbacks = 0, improved = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<VoxelSet> sets = RandomSets(rng, 30, 300, 0.15);
    ExactSelectorOptions o;
    o.greedy.consolidate = false;
    o.greedy.target_coverage = trial % 2 ? 1.0 : 0.9;
    o.memory_budget_bytes = 1;
    Result<Selection> got = ExactSelector(o).Select(sets, trial % 3, {});
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, trial % 3, {});
    ASSERT_TRUE(greedy.ok());
    if (got->optimality.model.candidates == 0) {
      EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal);  // the reduction solved it: no model
    } else {
      ++fallbacks;
      EXPECT_EQ(got->optimality.solver, "greedy+swap");
      EXPECT_NE(got->optimality.note.find("memory budget"), std::string::npos);
      EXPECT_EQ(got->optimality.status, OptimalityStatus::kFeasible);
      EXPECT_GT(got->optimality.lower_bound, 0);
      EXPECT_LE(got->optimality.lower_bound, static_cast<double>(got->picks.size()));
      // No integer program, but the Lagrangian bound: valid (at most the optimum the ILP proves; on a
      // few instances, the ILP being slow under the sanitizers).
      if (fallbacks <= 4) {
        ExactSelectorOptions within = o;
        within.memory_budget_bytes = ExactSelectorOptions{}.memory_budget_bytes;
        // The proof must not depend on the machine's speed: the default 20 s ran out under ASan on a
        // loaded machine (status feasible, not optimal). These instances are solved well within it
        // in release; the limit is only a backstop.
        within.time_limit_s = 600;
        Result<Selection> optimum = ExactSelector(within).Select(sets, trial % 3, {});
        ASSERT_TRUE(optimum.ok());
        ASSERT_EQ(optimum->optimality.status, OptimalityStatus::kOptimal);
        EXPECT_LE(got->optimality.lower_bound, static_cast<double>(optimum->picks.size()));
      }
    }
    EXPECT_LE(got->picks.size(), greedy->picks.size());
    improved += got->picks.size() < greedy->picks.size();
    EXPECT_GE(got->covered, Target(o.greedy.target_coverage, got->coverable));
    ExpectFixedFirstAndGainOrder(sets, *got, trial % 3);
  }
  EXPECT_GT(fallbacks, 10);
  EXPECT_GT(improved, 0) << "the swaps never saved a station over unconsolidated greedy";
}

// Rooms around a hall: one wide candidate sees the hall and every room's doorway side, each room's
// own candidate its doorway and far side. Over the budget the model is refused before any class is
// built, and the bound is the Lagrangian one (the LP's: the wide one and 5 rooms), not the counting
// bound (2: the wide candidate's weight into the target).
TEST(ExactSelectorTest, OverTheMemoryBudgetTheBoundIsLagrangian) {
  const int rooms = 10;
  const size_t hall = 5000, doorway = 40, far = 60;
  std::vector<VoxelSet> sets(rooms + 1, VoxelSet(hall + rooms * (doorway + far)));
  for (size_t v = 0; v < hall; ++v) sets[rooms].set(v);
  for (int r = 0; r < rooms; ++r) {
    const size_t first = hall + r * (doorway + far);
    for (size_t v = first; v < first + doorway; ++v) {
      sets[r].set(v);
      sets[rooms].set(v);
    }
    for (size_t v = first + doorway; v < first + doorway + far; ++v) sets[r].set(v);
  }
  ExactSelectorOptions o;
  o.greedy.target_coverage = 0.95;  // 5700 of 6000 voxels: the wide one (5400) and 5 far sides (300)
  o.memory_budget_bytes = 1;
  o.swap_search = false;
  o.prefer_greedy = true;
  Result<Selection> got = ExactSelector(o).Select(sets, 0, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_EQ(got->optimality.solver, "greedy");
  EXPECT_NE(got->optimality.note.find("Lagrangian"), std::string::npos) << got->optimality.note;
  // Refused on the size probed before the reduction: 10 room-side classes and the hall, at least.
  EXPECT_NE(got->optimality.note.find("at least"), std::string::npos) << got->optimality.note;
  EXPECT_EQ(got->optimality.model.candidates, rooms + 1);
  EXPECT_EQ(got->optimality.model.voxel_classes, 2 * rooms + 1);
  EXPECT_EQ(got->optimality.status, OptimalityStatus::kFeasible);
  const Best want = Exhaustive(sets, 0, Target(0.95, got->coverable), 0);
  EXPECT_EQ(want.stations, 6);
  EXPECT_EQ(got->optimality.lower_bound, want.stations);
}

TEST(ExactSelectorTest, RejectsBadArguments) {
  std::vector<VoxelSet> sets(2, VoxelSet(8));
  ExactSelectorOptions o;
  o.time_limit_s = 0;
  EXPECT_EQ(ExactSelector(o).Select(sets, 0, {}).status().code(), StatusCode::kInvalidArgument);
  sets.emplace_back(9);
  EXPECT_EQ(ExactSelector({}).Select(sets, 0, {}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ExactSelector({}).Select(std::vector<VoxelSet>(2, VoxelSet(8)), 3, {}).status().code(),
            StatusCode::kInvalidArgument);
}

// The candidates' visibility sets of a synthetic scene, as the planner computes them.
std::vector<VoxelSet> SceneSets(const std::string& spec) {
  SynthOptions so;
  so.spacing_m = 0.05;
  Result<std::vector<Eigen::Vector3f>> points = GenerateScene(spec, so);
  EXPECT_TRUE(points.ok()) << points.status().ToString();
  if (!points.ok()) return {};
  SceneInput input;
  input.points = std::move(*points);
  PlanOptions options;
  options.resolution_m = 0.1;
  Result<VoxelizeOutput> voxels = RunVoxelizeStage({input}, options, {});
  EXPECT_TRUE(voxels.ok()) << voxels.status().ToString();
  if (!voxels.ok()) return {};
  Result<CandidatesOutput> candidates = RunCandidatesStage({voxels->scene}, options, {});
  EXPECT_TRUE(candidates.ok()) << candidates.status().ToString();
  if (!candidates.ok()) return {};
  const PlanCallbacks callbacks;
  Result<VisibilityOutput> visibility =
      RunVisibilityStage({voxels->scene, candidates->positions, candidates->floor_z_m, {}, callbacks}, options, {});
  EXPECT_TRUE(visibility.ok()) << visibility.status().ToString();
  return visibility.ok() ? std::move(visibility->sets) : std::vector<VoxelSet>{};
}

// docs/PLANNING.md: on comb:5's 1 m grid greedy picks 7 where 5 suffice; the ILP proves 5 from the
// unconsolidated greedy warm start.
TEST(ExactSelectorTest, Comb5IsFiveStationsProvenOptimal) {
  const std::vector<VoxelSet> sets = SceneSets("comb:5");
  ASSERT_GT(sets.size(), 10u);
  ExactSelectorOptions o;
  o.greedy.target_coverage = 1.0;
  o.greedy.consolidate = false;
  Result<Selection> greedy = GreedySelector(o.greedy).Select(sets, {});
  ASSERT_TRUE(greedy.ok());
  EXPECT_EQ(greedy->picks.size(), 7u);
  Result<Selection> got = ExactSelector(o).Select(sets, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_EQ(got->picks.size(), 5u);
  EXPECT_EQ(got->covered, got->coverable);
  EXPECT_EQ(got->optimality.status, OptimalityStatus::kOptimal);
  EXPECT_EQ(got->optimality.lower_bound, 5);
  EXPECT_LT(got->optimality.model.candidates, got->optimality.before.candidates);
  EXPECT_LT(got->optimality.model.voxel_classes, got->optimality.before.voxel_classes);
}

}  // namespace
}  // namespace vc::planner
