// Reduction: the top-3 matrix against brute-force G(P - T), the zero-loss rule (removes a
// duplicated station, never one whose removal loses visibility), pairs before singles, reduce_to.
#include "vc/plan/reduction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "vc/plan/stages.h"

namespace vc::planner {
namespace {

using Values = std::vector<std::vector<float>>;  // [station][face]

// G of the stations in `keep` (mask) over all faces, by definition.
double BruteG(const Values& v, const std::vector<bool>& keep) {
  double sum = 0;
  for (size_t f = 0; f < v[0].size(); ++f) {
    float best = 0;
    for (size_t s = 0; s < v.size(); ++s) {
      if (keep[s]) best = std::max(best, v[s][f]);
    }
    sum += best;
  }
  return sum / v[0].size();
}

std::vector<FaceTop3> Top3Of(const Values& v) {
  std::vector<FaceTop3> t(v[0].size());
  for (size_t s = 0; s < v.size(); ++s) {
    for (size_t f = 0; f < v[s].size(); ++f) InsertTop3(t[f], v[s][f], static_cast<int>(s));
  }
  return t;
}

// Random values on a coarse grid of levels (0, 0.3, 0.5..1.0) so that ties are common.
Values RandomValues(std::mt19937& rng, int stations, int faces, double seen) {
  const float levels[] = {0.3f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 1.0f};
  std::bernoulli_distribution visible(seen);
  Values v(stations, std::vector<float>(faces, 0.f));
  for (auto& row : v) {
    for (float& x : row) {
      if (visible(rng)) x = levels[rng() % 7];
    }
  }
  return v;
}

StationFaceValuesFn FromTable(const Values& v) {
  return [v](const std::vector<int>& stations, const JobContext&) -> Result<std::vector<SparseFaceValues>> {
    std::vector<SparseFaceValues> out(stations.size());
    for (size_t k = 0; k < stations.size(); ++k) {
      const std::vector<float>& row = v[stations[k]];
      for (size_t f = 0; f < row.size(); ++f) {
        if (row[f] > 0) out[k].faces.push_back(static_cast<uint32_t>(f)), out[k].values.push_back(row[f]);
      }
    }
    return out;
  };
}

TEST(ReductionTest, InsertTop3KeepsTheThreeLargestInOrder) {
  FaceTop3 t;
  InsertTop3(t, 0.5f, 0);
  InsertTop3(t, 0.f, 1);  // ignored
  InsertTop3(t, 0.9f, 2);
  InsertTop3(t, 0.7f, 3);
  InsertTop3(t, 0.6f, 4);
  InsertTop3(t, 0.95f, 5);
  EXPECT_EQ(t.v, (std::array<float, 3>{0.95f, 0.9f, 0.7f}));
  EXPECT_EQ(t.s, (std::array<int32_t, 3>{5, 2, 3}));
  FaceTop3 tie;
  InsertTop3(tie, 0.5f, 7);
  InsertTop3(tie, 0.5f, 8);
  EXPECT_EQ(tie.s[0], 7);
  EXPECT_EQ(tie.s[1], 8);
  EXPECT_EQ(tie.s[2], -1);
}

TEST(ReductionTest, MatrixMatchesBruteForceForEverySingleAndPair) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 60; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 7);
    const int faces = 1 + static_cast<int>(rng() % 200);
    const Values v = RandomValues(rng, n, faces, 0.1 + 0.8 * (rng() % 10) / 10.0);
    const ReductionMatrix m = ComputeReductionMatrix(Top3Of(v), n, faces, 1 + trial % 3);
    const std::vector<bool> all(n, true);
    const double g = BruteG(v, all);
    EXPECT_NEAR(m.global_visibility, g, 1e-12);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        std::vector<bool> keep = all;
        keep[i] = keep[j] = false;
        const double expected = g - BruteG(v, keep);
        EXPECT_NEAR(m.at(i, j), expected, 1e-12) << "trial " << trial << " i=" << i << " j=" << j;
        // Exactly zero when nothing is lost, so the zero-loss rule can trust it.
        EXPECT_EQ(m.at(i, j) == 0.0, expected == 0.0) << "trial " << trial << " i=" << i << " j=" << j;
      }
    }
  }
}

TEST(ReductionTest, FacesOutsideTheTableCountInTheDenominator) {
  const Values v = {{1.f, 0.5f}};
  const ReductionMatrix m = ComputeReductionMatrix(Top3Of(v), 1, /*faces_total=*/6);
  EXPECT_NEAR(m.global_visibility, 1.5 / 6, 1e-12);
  EXPECT_NEAR(m.at(0, 0), 1.5 / 6, 1e-12);
}

TEST(ReductionTest, RemovesADeliberatelyDuplicatedStation) {
  std::mt19937 rng(3);
  Values v = RandomValues(rng, 3, 300, 0.5);
  // Make each of the 3 stations the unique best somewhere, so none is obsolete alone.
  for (int s = 0; s < 3; ++s) {
    for (auto& row : v) row[s] = 0.f;
    v[s][s] = 1.f;
  }
  v.push_back(v[1]);  // station 3 duplicates station 1
  Result<ReductionRun> run = RunReduction(4, 300, FromTable(v), {});
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_EQ(run->removed, std::vector<int>({3}));  // the later copy
  EXPECT_EQ(run->initial.at(1, 1), 0.0);
  EXPECT_EQ(run->initial.at(3, 3), 0.0);
  EXPECT_GT(run->initial.at(1, 3), 0.0);  // removing both copies loses what they saw
  EXPECT_DOUBLE_EQ(run->global_visibility_after, run->global_visibility_before);
  EXPECT_NEAR(run->global_visibility_after, BruteG(v, {true, true, true, false}), 1e-12);
}

TEST(ReductionTest, AFixedStationIsNeverRemovedEvenWhenObsolete) {
  Values v(3, std::vector<float>(6, 0.f));
  for (int f = 0; f < 3; ++f) v[0][f] = v[1][f] = 1.f;  // 0 and 1 see the same faces
  for (int f = 3; f < 6; ++f) v[2][f] = 1.f;
  ReductionRunOptions o;
  Result<ReductionRun> run = RunReduction(3, 6, FromTable(v), o);
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->removed, std::vector<int>({1}));  // the later copy
  o.fixed = {false, true, false};                  // ... unless it is fixed: then the other copy goes
  run = RunReduction(3, 6, FromTable(v), o);
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->removed, std::vector<int>({0}));
  o.fixed = {true, true, false};  // both fixed: nothing goes
  run = RunReduction(3, 6, FromTable(v), o);
  ASSERT_TRUE(run.ok());
  EXPECT_TRUE(run->removed.empty());
  // reduce_to removes only the stations that are not fixed.
  o.fixed = {true, false, true};
  o.reduce_to = 1;
  run = RunReduction(3, 6, FromTable(v), o);
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->removed, std::vector<int>({1}));
}

TEST(ReductionTest, DefaultRuleNeverRemovesAStationThatLosesVisibility) {
  std::mt19937 rng(2024);
  int removed_total = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const int n = 2 + static_cast<int>(rng() % 7);
    const int faces = 20 + static_cast<int>(rng() % 100);
    Values v = RandomValues(rng, n, faces, 0.05 + 0.3 * (rng() % 4) / 3.0);
    // Sometimes copy or dominate a station to create obsolete ones.
    if (rng() % 2) v[rng() % n] = v[rng() % n];
    if (rng() % 3 == 0) {
      const int a = rng() % n, b = rng() % n;
      for (int f = 0; f < faces; ++f) v[a][f] = std::min(v[a][f], v[b][f]);
    }
    Result<ReductionRun> run = RunReduction(n, faces, FromTable(v), {});
    ASSERT_TRUE(run.ok());
    std::vector<bool> keep(n, true);
    for (int s : run->removed) keep[s] = false;
    removed_total += static_cast<int>(run->removed.size());
    // Nothing was lost, by brute force.
    EXPECT_DOUBLE_EQ(BruteG(v, keep), BruteG(v, std::vector<bool>(n, true))) << "trial " << trial;
    for (const auto& step : run->steps) EXPECT_EQ(step.loss, 0.0);
    // And no remaining station is obsolete (unless it is the last one).
    const int left = static_cast<int>(std::count(keep.begin(), keep.end(), true));
    ASSERT_GE(left, 1);
    if (left > 1) {
      for (int s = 0; s < n; ++s) {
        if (!keep[s]) continue;
        std::vector<bool> without = keep;
        without[s] = false;
        EXPECT_LT(BruteG(v, without), BruteG(v, keep)) << "trial " << trial << " station " << s;
      }
    }
  }
  EXPECT_GT(removed_total, 0);  // the instances did exercise removal
}

TEST(ReductionTest, AZeroLossPairBeatsASingle) {
  // Four identical stations: first a pair goes (the latest two), then one more single.
  const Values v(4, std::vector<float>{0.5f, 0.9f, 0.3f});
  Result<ReductionRun> run = RunReduction(4, 3, FromTable(v), {});
  ASSERT_TRUE(run.ok());
  ASSERT_EQ(run->steps.size(), 2u);
  EXPECT_EQ(run->steps[0].stations, std::vector<int>({2, 3}));
  EXPECT_EQ(run->steps[1].stations, std::vector<int>({1}));
  EXPECT_EQ(run->removed, std::vector<int>({2, 3, 1}));
}

TEST(ReductionTest, NothingObsoleteNothingRemoved) {
  const Values v = {{1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}};
  Result<ReductionRun> run = RunReduction(3, 3, FromTable(v), {});
  ASSERT_TRUE(run.ok());
  EXPECT_TRUE(run->removed.empty());
  EXPECT_NEAR(run->initial.at(0, 0), 1.0 / 3, 1e-12);
  EXPECT_NEAR(run->initial.at(0, 2), 2.0 / 3, 1e-12);
}

TEST(ReductionTest, ReduceToRemovesTheCheapestUntilTheCountIsMet) {
  // Station losses: 0 -> 3 faces, 1 -> 1 face, 2 -> 2 faces, 3 -> 4 faces (each unique).
  Values v(4, std::vector<float>(10, 0.f));
  int f = 0;
  for (int s : {0, 0, 0, 1, 2, 2, 3, 3, 3, 3}) v[s][f++] = 1.f;
  ReductionRunOptions o;
  o.reduce_to = 3;
  Result<ReductionRun> run = RunReduction(4, 10, FromTable(v), o);
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->removed, std::vector<int>({1}));
  EXPECT_NEAR(run->global_visibility_after, 0.9, 1e-12);
  // Two must go: the pair {1, 2} loses 0.3 (0.15 per station), single 1 loses 0.1: single 1 first,
  // then single 2.
  o.reduce_to = 2;
  run = RunReduction(4, 10, FromTable(v), o);
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->removed, std::vector<int>({1, 2}));
  EXPECT_NEAR(run->global_visibility_after, 0.7, 1e-12);
}

TEST(ReductionTest, ReduceToTakesAPairWhenItIsCheaperPerStation) {
  // 3 stations seeing disjoint faces: 0 -> 2 faces, 1 -> 2 faces, 2 -> 5 faces. Two must go: the
  // pair {0, 1} loses 4 faces = 2 per station, the same as single 0; ties prefer the pair.
  Values v(3, std::vector<float>(9, 0.f));
  int f = 0;
  for (int s : {0, 0, 1, 1, 2, 2, 2, 2, 2}) v[s][f++] = 1.f;
  ReductionRunOptions o;
  o.reduce_to = 1;
  Result<ReductionRun> run = RunReduction(3, 9, FromTable(v), o);
  ASSERT_TRUE(run.ok());
  ASSERT_EQ(run->steps.size(), 1u);
  EXPECT_EQ(run->steps[0].stations, std::vector<int>({0, 1}));
  EXPECT_NEAR(run->steps[0].loss, 4.0 / 9, 1e-12);
}

TEST(ReductionTest, CachedAndRecomputedRefillsAgree) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 3 + static_cast<int>(rng() % 5);
    Values v = RandomValues(rng, n, 150, 0.3);
    v.push_back(v[0]);
    v.push_back(v[1]);
    ReductionRunOptions cached, recomputed;
    cached.reduce_to = recomputed.reduce_to = 2;
    recomputed.cache_budget_bytes = 0;
    Result<ReductionRun> a = RunReduction(n + 2, 150, FromTable(v), cached);
    Result<ReductionRun> b = RunReduction(n + 2, 150, FromTable(v), recomputed);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->removed, b->removed);
    EXPECT_EQ(a->global_visibility_after, b->global_visibility_after);
    EXPECT_EQ(a->initial.loss, b->initial.loss);
  }
}

TEST(ReductionTest, MatrixIsTheSameForAnyThreadCount) {
  std::mt19937 rng(8);
  const Values v = RandomValues(rng, 6, 200000, 0.4);
  const auto t = Top3Of(v);
  const ReductionMatrix one = ComputeReductionMatrix(t, 6, 200000, 1);
  const ReductionMatrix four = ComputeReductionMatrix(t, 6, 200000, 4);
  EXPECT_EQ(one.loss, four.loss);
  EXPECT_EQ(one.global_visibility, four.global_visibility);
}

TEST(ReductionTest, ErrorsFromTheValueSourcePropagate) {
  StationFaceValuesFn failing = [](const std::vector<int>& stations,
                                   const JobContext&) -> Result<std::vector<SparseFaceValues>> {
    if (stations[0] == 1) return CancelledError("evaluation was cancelled");
    return std::vector<SparseFaceValues>(stations.size(), SparseFaceValues{{0, 1, 2, 3}, {0.5f, 0.5f, 0.5f, 0.5f}});
  };
  ReductionRunOptions one_at_a_time;
  one_at_a_time.batch_stations = 1;
  Result<ReductionRun> run = RunReduction(2, 4, failing, one_at_a_time);
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().code(), StatusCode::kCancelled);
  // A source that answers for fewer stations than asked, or with faces out of order or range.
  StationFaceValuesFn too_few = [](const std::vector<int>&,
                                   const JobContext&) -> Result<std::vector<SparseFaceValues>> {
    return std::vector<SparseFaceValues>{};
  };
  EXPECT_EQ(RunReduction(1, 4, too_few, {}).status().code(), StatusCode::kInternal);
  for (const SparseFaceValues& bad : {SparseFaceValues{{2, 1}, {0.5f, 0.5f}}, SparseFaceValues{{1, 4}, {0.5f, 0.5f}},
                                      SparseFaceValues{{1, 1}, {0.5f, 0.5f}}, SparseFaceValues{{1}, {}}}) {
    StationFaceValuesFn source = [bad](const std::vector<int>&,
                                       const JobContext&) -> Result<std::vector<SparseFaceValues>> {
      return std::vector<SparseFaceValues>{bad};
    };
    EXPECT_EQ(RunReduction(1, 4, source, {}).status().code(), StatusCode::kInternal);
  }
}

TEST(ReductionTest, BatchesAndAPartlyFilledCacheGiveTheSameRun) {
  // The cache budget running out part-way through the first build (then every removal asks for
  // the values again), and any batch size, must not change a removal.
  std::mt19937 rng(21);
  for (int trial = 0; trial < 10; ++trial) {
    const int n = 6 + static_cast<int>(rng() % 5);
    Values v = RandomValues(rng, n, 400, 0.2);
    v.push_back(v[2]);
    v.push_back(v[4]);
    ReductionRunOptions reference;
    reference.reduce_to = 3;
    const Result<ReductionRun> a = RunReduction(n + 2, 400, FromTable(v), reference);
    ReductionRunOptions other = reference;
    other.batch_stations = 1 + trial % 3;
    other.cache_budget_bytes = 400 * 8 * 2;  // about two stations' values
    int calls = 0;
    const StationFaceValuesFn counted = [&](const std::vector<int>& stations, const JobContext& ctx) {
      ++calls;
      return FromTable(v)(stations, ctx);
    };
    const Result<ReductionRun> b = RunReduction(n + 2, 400, counted, other);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->removed, b->removed);
    EXPECT_EQ(a->global_visibility_after, b->global_visibility_after);
    EXPECT_EQ(a->initial.loss, b->initial.loss);
    // Without the cache, each removal step rebuilt from fresh values: more calls than one build.
    const int one_build = (n + 2 + other.batch_stations - 1) / other.batch_stations;
    EXPECT_GT(calls, one_build) << "trial " << trial;
  }
}

// The build reports the stations evaluated at every batch's end, up to all of them, and the
// removals report their count against the most there can be; fractions never fall.
TEST(ReductionTest, ReportsStationsEvaluatedAndRemovalsWithCounts) {
  std::mt19937 rng(8);
  Values v = RandomValues(rng, 6, 400, 0.2);
  v.push_back(v[1]);
  v.push_back(v[3]);
  ReductionRunOptions o;
  o.reduce_to = 3;
  o.batch_stations = 2;
  std::vector<ProgressEvent> events;
  JobContext ctx;
  ctx.progress = [&](const ProgressEvent& e) { events.push_back(e); };
  const Result<ReductionRun> r = RunReduction(8, 400, FromTable(v), o, ctx);
  ASSERT_TRUE(r.ok());
  std::vector<uint64_t> evaluated;
  bool removals_seen = false;
  for (size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].stage, Stage::kReduction);
    if (i > 0) EXPECT_GE(events[i].fraction, events[i - 1].fraction) << "event " << i;
    if (events[i].unit == "stations evaluated") {
      EXPECT_EQ(events[i].total, 8u);
      evaluated.push_back(events[i].done);
    }
    if (events[i].unit == "stations removed (at most)") {
      removals_seen = true;
      EXPECT_EQ(events[i].total, 5u);  // 8 stations down to reduce_to 3
    }
  }
  EXPECT_EQ(evaluated, (std::vector<uint64_t>{2, 4, 6, 8}));  // one batch of 2 at a time
  EXPECT_TRUE(removals_seen);
  EXPECT_EQ(events.back().fraction, 1.0);
}

// The batch in flight stays within the cache budget: the first is sized for the worst case (every
// face seen, 8 bytes a face: one station here), the next ones for what the stations saw.
TEST(ReductionTest, BatchesGrowFromTheWorstCaseToWhatStationsSee) {
  std::mt19937 rng(33);
  const int n = 12, faces = 1000;
  const Values v = RandomValues(rng, n, faces, 0.05);  // ~50 faces a station: ~400 bytes
  ReductionRunOptions o;
  o.cache_budget_bytes = faces * 8;  // one station in the worst case
  std::vector<size_t> sizes;
  const StationFaceValuesFn counted = [&](const std::vector<int>& stations, const JobContext& ctx) {
    sizes.push_back(stations.size());
    return FromTable(v)(stations, ctx);
  };
  const Result<ReductionRun> run = RunReduction(n, faces, counted, o);
  const Result<ReductionRun> reference = RunReduction(n, faces, FromTable(v), {});
  ASSERT_TRUE(run.ok() && reference.ok());
  ASSERT_GE(sizes.size(), 2u);
  EXPECT_EQ(sizes[0], 1u);
  EXPECT_GT(*std::max_element(sizes.begin(), sizes.end()), 1u);
  EXPECT_EQ(run->initial.loss, reference->initial.loss);
  EXPECT_EQ(run->removed, reference->removed);
}

// The reduction's evaluation, here and on a peer computing a shard of it: the plan's scanner and
// threads over all faces, each station's sparse values kept and not the face values.
TEST(ReductionTest, StationsAreEvaluatedWithThePlansScannerKeepingTheirSparseValues) {
  PlanOptions options;
  options.threads = 3;
  options.scanner.max_range_m = 12;
  const EvaluateOptions e = ReductionEvaluateOptions(options);
  EXPECT_EQ(e.threads, 3);
  EXPECT_EQ(e.scanner.max_range_m, 12);
  EXPECT_EQ(e.faces, FaceSet::kAll);
  EXPECT_EQ(e.sample_faces, 0u);
  EXPECT_TRUE(e.keep_sparse_per_viewpoint_values);
  EXPECT_FALSE(e.keep_face_values);
}

}  // namespace
}  // namespace vc::planner
