// The Selector interface: GreedySelector picks exactly what SelectGreedy (lazy) followed by
// ConsolidatePicks picks, on the real visibility sets of comb:5 and on random sets, and reports
// the greedy pass's stop reason and coverage; the selection stage turns any selector's picks into
// stations.
#include "vc/plan/selector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "vc/plan/greedy.h"
#include "vc/plan/plan_options.h"
#include "vc/plan/stages.h"
#include "vc/synth/synth.h"

namespace vc::planner {
namespace {

// What the planner did before the Selector interface: lazy greedy, then consolidation.
Selection Reference(const std::vector<VoxelSet>& sets, const GreedyOptions& o) {
  Result<GreedyResult> greedy = SelectGreedy(sets, o);
  EXPECT_TRUE(greedy.ok()) << greedy.status().ToString();
  Selection s;
  if (!greedy.ok()) return s;
  for (const GreedyPick& p : greedy->picks) s.picks.push_back(p.candidate);
  s.stop = greedy->stop;
  s.coverable = greedy->coverable;
  s.covered = greedy->covered;
  s.first_pass_picks = static_cast<int>(s.picks.size());
  if (o.consolidate) {
    Result<ConsolidateResult> merged = ConsolidatePicks(sets, s.picks, o);
    EXPECT_TRUE(merged.ok()) << merged.status().ToString();
    if (!merged.ok()) return s;
    s.picks = merged->picks;
    s.saved_by_improvement = merged->dropped + merged->merged;
  }
  return s;
}

void ExpectSame(const Selection& got, const Selection& want, const std::string& what) {
  EXPECT_EQ(got.picks, want.picks) << what;
  EXPECT_EQ(got.stop, want.stop) << what;
  EXPECT_EQ(got.coverable, want.coverable) << what;
  EXPECT_EQ(got.covered, want.covered) << what;
  EXPECT_EQ(got.first_pass_picks, want.first_pass_picks) << what;
  EXPECT_EQ(got.saved_by_improvement, want.saved_by_improvement) << what;
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

TEST(GreedySelectorTest, PicksWhatGreedyThenConsolidationPickOnComb5) {
  const std::vector<VoxelSet> sets = SceneSets("comb:5");
  ASSERT_GT(sets.size(), 10u);
  for (double target : {1.0, 0.99, 0.9}) {
    for (bool consolidate : {true, false}) {
      GreedyOptions o;
      o.target_coverage = target;
      o.consolidate = consolidate;
      Result<Selection> got = GreedySelector(o).Select(sets, {});
      ASSERT_TRUE(got.ok()) << got.status().ToString();
      const Selection want = Reference(sets, o);
      ExpectSame(*got, want, "target " + std::to_string(target) + (consolidate ? " consolidated" : ""));
      EXPECT_FALSE(got->picks.empty());
      if (!consolidate) {
        EXPECT_EQ(got->saved_by_improvement, 0);
      }
    }
  }
  // At full coverage greedy needs more picks than the optimum 5 and consolidation repairs it.
  GreedyOptions full;
  full.target_coverage = 1.0;
  Result<Selection> got = GreedySelector(full).Select(sets, {});
  ASSERT_TRUE(got.ok());
  EXPECT_EQ(got->picks.size(), 5u);
  EXPECT_GT(got->first_pass_picks, 5);
  EXPECT_EQ(got->saved_by_improvement, got->first_pass_picks - 5);
}

TEST(GreedySelectorTest, PicksWhatGreedyThenConsolidationPickOnRandomSets) {
  std::mt19937 rng(2014);
  int saved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const size_t n = 20 + rng() % 300;
    std::vector<VoxelSet> sets;
    for (size_t i = 0; i < 3 + rng() % 40; ++i) {
      VoxelSet s(n);
      const size_t start = rng() % n, len = 1 + rng() % (n / 3);
      for (size_t v = 0; v < len; ++v) s.set((start + v) % n);
      sets.push_back(s);
    }
    GreedyOptions o;
    o.max_stations = static_cast<int>(rng() % 4);  // 0 = no limit
    o.min_marginal_gain_voxels = 1 + rng() % 3;
    o.target_coverage = (rng() % 2) ? 1.0 : 0.8;
    o.consolidate = rng() % 4 != 0;
    Result<Selection> got = GreedySelector(o).Select(sets, {});
    ASSERT_TRUE(got.ok()) << got.status().ToString();
    ExpectSame(*got, Reference(sets, o), "trial " + std::to_string(trial));
    saved += got->saved_by_improvement;
  }
  EXPECT_GT(saved, 0);  // the instances exercise consolidation, not only greedy
}

TEST(GreedySelectorTest, StopReasonComesFromTheGreedyPass) {
  std::vector<VoxelSet> sets(3, VoxelSet(30));
  for (int v = 0; v < 10; ++v) sets[0].set(v), sets[1].set(10 + v), sets[2].set(20 + v);
  GreedyOptions o;
  o.max_stations = 2;
  Result<Selection> got = GreedySelector(o).Select(sets, {});
  ASSERT_TRUE(got.ok());
  EXPECT_EQ(got->stop, StopReason::kMaxStations);
  EXPECT_EQ(got->picks, (std::vector<int>{0, 1}));
  EXPECT_EQ(got->covered, 20u);
  EXPECT_EQ(got->coverable, 30u);
}

TEST(GreedySelectorTest, RejectsSetsOfDifferentSizesAndStopsWhenCancelled) {
  const GreedySelector selector(GreedyOptions{});
  EXPECT_EQ(selector.Select({VoxelSet(10), VoxelSet(11)}, {}).status().code(), StatusCode::kInvalidArgument);
  CancelToken token;
  token.Cancel();
  JobContext ctx;
  ctx.cancel = &token;
  std::vector<VoxelSet> sets(2, VoxelSet(10));
  sets[0].set(1);
  EXPECT_EQ(selector.Select(sets, ctx).status().code(), StatusCode::kCancelled);
}

// Another selector (the way an ILP or a local search would plug in): always the last candidate.
class LastCandidateSelector final : public Selector {
 public:
  using Selector::Select;
  Result<Selection> Select(const std::vector<VoxelSet>& sets, int fixed, const JobContext&) const override {
    Selection s;
    for (int f = 0; f < fixed; ++f) s.picks.push_back(f);
    s.picks.push_back(static_cast<int>(sets.size()) - 1);
    s.first_pass_picks = 1;
    s.coverable = 4;
    return s;
  }
};

TEST(SelectionStageTest, TurnsAnySelectorsPicksIntoStationsAndReportsEach) {
  std::vector<VoxelSet> sets(3, VoxelSet(8));
  sets[0].set(0);
  sets[1].set(1);
  for (int v = 0; v < 4; ++v) sets[2].set(v);
  const std::vector<WorldPoint> candidates = {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}};
  const std::vector<double> floor_z = {0.0, 0.1, 0.2};
  const std::vector<uint64_t> visible = {1, 1, 4};
  std::vector<PlannedStation> reported;
  PlanCallbacks callbacks;
  callbacks.on_station = [&](const PlannedStation& s, int index) {
    EXPECT_EQ(index, static_cast<int>(reported.size()));
    reported.push_back(s);
  };
  const LastCandidateSelector selector;
  Result<SelectionOutput> out =
      RunSelectionStage({VoxelScene{}, selector, sets, {}, candidates, floor_z, visible, callbacks}, PlanOptions{}, {});
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  ASSERT_EQ(out->stations.size(), 1u);
  EXPECT_EQ(out->stations.candidate, (std::vector<int>{2}));
  EXPECT_EQ(out->stations.positions[0], candidates[2]);
  EXPECT_EQ(out->stations.floor_z_m[0], 0.2);
  EXPECT_EQ(out->stations.sets[0].count(), 4u);
  EXPECT_EQ(out->coverable.count(), 4u);  // the union of every candidate's set
  ASSERT_EQ(reported.size(), 1u);
  EXPECT_EQ(reported[0].marginal_gain, 4u);
  EXPECT_EQ(reported[0].cumulative_coverage, 1.0);
  EXPECT_EQ(reported[0].candidate_index, 2);
  EXPECT_FALSE(reported[0].fixed);
}

// The per-k bound over sets with a fixed station first: k = 1 is the fixed station alone (its 4
// voxels, proven), then the best candidates added to it; none where the classes would exceed the
// memory given.
TEST(SelectionStageTest, BestCoverageOfCountsTheFixedStationsAsGiven) {
  std::vector<VoxelSet> sets(4, VoxelSet(12));
  for (int v = 0; v < 4; ++v) sets[0].set(v);   // fixed
  for (int v = 2; v < 8; ++v) sets[1].set(v);   // adds 4
  for (int v = 8; v < 11; ++v) sets[2].set(v);  // adds 3
  for (int v = 0; v < 6; ++v) sets[3].set(v);   // adds 2
  Result<std::vector<std::optional<BestCoverage>>> b = BestCoverageOf(sets, 1, 3, 1.0, uint64_t{1} << 30, {});
  ASSERT_TRUE(b.ok()) << b.status().ToString();
  ASSERT_EQ(b->size(), 3u);
  const uint64_t expected[] = {4, 8, 11};
  for (size_t k = 0; k < 3; ++k) {
    ASSERT_TRUE((*b)[k]) << k;
    EXPECT_EQ((*b)[k]->upper_bound_voxels, expected[k]) << k;
    EXPECT_EQ((*b)[k]->best_voxels, expected[k]) << k;
  }
  Result<std::vector<std::optional<BestCoverage>>> small = BestCoverageOf(sets, 1, 3, 1.0, 100, {});
  ASSERT_TRUE(small.ok());
  EXPECT_TRUE(small->empty());
}

// The selector's proven bound at the target caps the per-k bound below it: 100 coverable voxels, the
// 0.95 target's need is 95; a bound of 3 stations means k = 1, 2 cover at most 94; k = 3 and points
// without a bound stay; nothing changes without a proven bound or with min_overlap, max_stations or
// local candidates (their bound is about another problem).
TEST(SelectionStageTest, CapBelowTheSelectorsBoundUsesTheBoundAtTheTarget) {
  const auto fresh = [] {
    return std::vector<std::optional<BestCoverage>>{BestCoverage{60, 50}, BestCoverage{100, 96}, std::nullopt,
                                                    BestCoverage{100, 100}};
  };
  Selection selection;
  selection.coverable = 100;
  selection.optimality.lower_bound = 3;
  PlanOptions o;
  o.target_coverage = 0.95;
  std::vector<std::optional<BestCoverage>> b = fresh();
  CapBelowTheSelectorsBound(b, selection, o);
  EXPECT_EQ(b[0]->upper_bound_voxels, 60u);
  EXPECT_EQ(b[0]->best_voxels, 50u);
  EXPECT_EQ(b[1]->upper_bound_voxels, 94u);
  EXPECT_EQ(b[1]->best_voxels, 94u);
  EXPECT_FALSE(b[2]);
  EXPECT_EQ(b[3]->upper_bound_voxels, 100u);

  const auto unchanged = [&](const Selection& sel, const PlanOptions& opt) {
    std::vector<std::optional<BestCoverage>> c = fresh();
    CapBelowTheSelectorsBound(c, sel, opt);
    return c[1]->upper_bound_voxels == 100 && c[1]->best_voxels == 96;
  };
  Selection no_bound = selection;
  no_bound.optimality.lower_bound = 0;
  EXPECT_TRUE(unchanged(no_bound, o));
  PlanOptions connected = o;
  connected.min_overlap = 0.3;
  EXPECT_TRUE(unchanged(selection, connected));
  PlanOptions capped = o;
  capped.max_stations = 3;
  EXPECT_TRUE(unchanged(selection, capped));
  PlanOptions local = o;
  local.local_candidates = true;
  EXPECT_TRUE(unchanged(selection, local));
}

// Sets over 12 voxels: the fixed station sees 0-3, candidates see 4-7, 8-11, 0-5 and 2-3.
std::vector<VoxelSet> FixedAndCandidates() {
  std::vector<VoxelSet> sets(5, VoxelSet(12));
  auto fill = [&](int s, int lo, int hi) {
    for (int v = lo; v <= hi; ++v) sets[s].set(v);
  };
  fill(0, 0, 3);  // fixed
  fill(1, 4, 7);
  fill(2, 8, 11);
  fill(3, 0, 5);
  fill(4, 2, 3);
  return sets;
}

TEST(GreedySelectorTest, FixedStationsArePickedFirstAndKeptThroughConsolidation) {
  GreedyOptions o;
  o.target_coverage = 1.0;
  Result<Selection> got = GreedySelector(o).Select(FixedAndCandidates(), 1, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  // Without the fixed station greedy would take 3 (0-5) first; with it, 1 and 2 cover the rest.
  EXPECT_EQ(got->picks, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(got->first_pass_picks, 2);
  EXPECT_EQ(got->covered, 12u);
  Result<Selection> free = GreedySelector(o).Select(FixedAndCandidates(), {});
  ASSERT_TRUE(free.ok());
  EXPECT_EQ(free->picks.front(), 3);
}

TEST(GreedySelectorTest, AFixedStationOthersCoverIsNotDropped) {
  std::vector<VoxelSet> sets = FixedAndCandidates();
  sets[0] = VoxelSet(12);
  sets[0].set(2);  // the fixed station sees only voxel 2, which candidate 3 sees too
  GreedyOptions o;
  o.target_coverage = 1.0;
  Result<Selection> got = GreedySelector(o).Select(sets, 1, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  ASSERT_FALSE(got->picks.empty());
  EXPECT_EQ(got->picks.front(), 0);
  EXPECT_EQ(got->saved_by_improvement, 0);
}

TEST(GreedySelectorTest, FixedStationsReachingTheTargetAddNone) {
  std::vector<VoxelSet> sets = FixedAndCandidates();
  GreedyOptions o;
  o.target_coverage = 0.3;  // 4 of 12 voxels
  Result<Selection> got = GreedySelector(o).Select(sets, 1, {});
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  EXPECT_EQ(got->picks, (std::vector<int>{0}));
  EXPECT_EQ(got->first_pass_picks, 0);
  EXPECT_EQ(got->stop, StopReason::kTargetReached);
}

TEST(GreedySelectorTest, RefusesMoreFixedStationsThanSets) {
  EXPECT_EQ(GreedySelector({}).Select(FixedAndCandidates(), 6, {}).status().code(), StatusCode::kInvalidArgument);
}

TEST(SelectionStageTest, FixedStationsComeFirstMarkedFixed) {
  std::vector<VoxelSet> sets = FixedAndCandidates();
  std::vector<VoxelSet> fixed_sets = {sets[0]};
  sets.erase(sets.begin());
  const std::vector<WorldPoint> candidates = {{1, 0, 1}, {2, 0, 1}, {3, 0, 1}, {4, 0, 1}};
  const std::vector<double> floor_z = {0, 0, 0, 0};
  const std::vector<uint64_t> visible = {4, 4, 6, 2};
  std::vector<PlannedStation> reported;
  PlanCallbacks callbacks;
  callbacks.on_station = [&](const PlannedStation& s, int) { reported.push_back(s); };
  PlanOptions options;
  options.fixed_stations = {{9, 9, 1}};
  GreedyOptions go;
  go.target_coverage = 1.0;
  const GreedySelector selector(go);
  Result<SelectionOutput> out = RunSelectionStage(
      {VoxelScene{}, selector, sets, fixed_sets, candidates, floor_z, visible, callbacks}, options, {});
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  ASSERT_EQ(out->stations.size(), 3u);
  EXPECT_EQ(out->stations.fixed, (std::vector<bool>{true, false, false}));
  EXPECT_EQ(out->stations.candidate, (std::vector<int>{-1, 0, 1}));
  EXPECT_EQ(out->stations.positions[0], options.fixed_stations[0]);
  EXPECT_TRUE(std::isnan(out->stations.floor_z_m[0]));
  EXPECT_EQ(out->coverable.count(), 12u);
  ASSERT_EQ(reported.size(), 3u);
  EXPECT_TRUE(reported[0].fixed);
  EXPECT_EQ(reported[0].marginal_gain, 4u);
  EXPECT_FALSE(reported[1].fixed);
}

// A value other than `v`, for each type of a VC_GREEDY_PARAMETERS row.
bool Changed(bool v) { return !v; }
int32_t Changed(int32_t v) { return v + 3; }
uint64_t Changed(uint64_t v) { return v + 5; }
double Changed(double v) { return v / 2; }

TEST(SelectionStageTest, SelectorOptionsForCarriesEveryGreedyRowAndMinOverlap) {
  PlanOptions plan;
#define VC_CHANGE_ROW(type, name, ...) plan.name = Changed(plan.name);
  VC_GREEDY_PARAMETERS(VC_CHANGE_ROW)
#undef VC_CHANGE_ROW
  plan.min_overlap = 0.3;
  const GreedyOptions o = SelectorOptionsFor(plan, 0.08);
#define VC_EXPECT_ROW(type, name, ...) EXPECT_EQ(o.name, plan.name) << #name;
  VC_GREEDY_PARAMETERS(VC_EXPECT_ROW)
#undef VC_EXPECT_ROW
  EXPECT_EQ(o.min_overlap, 0.3);
  EXPECT_DOUBLE_EQ(o.surface_voxels_per_m2, 156.25);  // 1 / 0.08^2
  EXPECT_EQ(SelectorOptionsFor(plan, 0).surface_voxels_per_m2, 0.0);
  EXPECT_TRUE(o.lazy);
  EXPECT_EQ(o.fixed, 0);
}

}  // namespace
}  // namespace vc::planner
