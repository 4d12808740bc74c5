// The per-k bound and best coverage against exhaustive search: on random small instances the bound
// is never below the best k columns' coverage, the exact search finds it, both are monotone in k;
// without the exact search the bound still holds and greedy's prefix is never above it.
#include "vc/plan/k_coverage_bound.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

namespace vc::planner {
namespace {

// The most weight any k columns cover, for k = 0..columns, by enumerating every subset.
std::vector<uint64_t> ExhaustiveBest(const KCoverageProblem& p) {
  std::vector<uint64_t> best(static_cast<size_t>(p.columns) + 1, 0);
  for (uint32_t mask = 0; mask < (1u << p.columns); ++mask) {
    uint64_t covered = 0;
    for (size_t i = 0; i < p.weight.size(); ++i) {
      for (int j : p.seen_by[i]) {
        if (mask & (1u << j)) {
          covered += p.weight[i];
          break;
        }
      }
    }
    const int k = __builtin_popcount(mask);
    best[k] = std::max(best[k], covered);
  }
  return best;
}

KCoverageProblem RandomProblem(std::mt19937& rng) {
  KCoverageProblem p;
  p.columns = std::uniform_int_distribution<int>(1, 10)(rng);
  const int classes = std::uniform_int_distribution<int>(1, 25)(rng);
  std::uniform_int_distribution<int> weight(1, 30), coin(0, 3);
  for (int i = 0; i < classes; ++i) {
    std::vector<int> seen;
    for (int j = 0; j < p.columns; ++j) {
      if (coin(rng) == 0) seen.push_back(j);
    }
    if (seen.empty()) seen.push_back(std::uniform_int_distribution<int>(0, p.columns - 1)(rng));
    p.weight.push_back(static_cast<uint64_t>(weight(rng)));
    p.seen_by.push_back(seen);
  }
  return p;
}

void ExpectValidAgainstExhaustive(const KCoverageProblem& p, const std::vector<KCoverage>& got, bool exact) {
  const std::vector<uint64_t> truth = ExhaustiveBest(p);
  ASSERT_EQ(got.size(), static_cast<size_t>(p.columns));
  for (size_t k = 1; k <= got.size(); ++k) {
    const KCoverage& c = got[k - 1];
    EXPECT_GE(c.upper_bound, truth[k]) << "k=" << k;
    EXPECT_LE(c.best, truth[k]) << "k=" << k;
    EXPECT_EQ(c.optimal, c.best == c.upper_bound) << "k=" << k;
    if (exact) {
      EXPECT_TRUE(c.optimal) << "k=" << k;
      EXPECT_EQ(c.best, truth[k]) << "k=" << k;
    }
    if (k > 1) {
      EXPECT_GE(c.upper_bound, got[k - 2].upper_bound) << "k=" << k;
      EXPECT_GE(c.best, got[k - 2].best) << "k=" << k;
    }
  }
}

TEST(KCoverageBoundTest, BoundHoldsAndExactEqualsExhaustiveOnRandomInstances) {
  std::mt19937 rng(36);
  for (int t = 0; t < 300; ++t) {
    SCOPED_TRACE(t);
    const KCoverageProblem p = RandomProblem(rng);
    KCoverageOptions o;
    o.max_k = p.columns;
    ExpectValidAgainstExhaustive(p, KCoverageBounds(p, o), /*exact=*/true);
  }
}

TEST(KCoverageBoundTest, WithoutTheExactSearchTheLagrangianBoundStillHolds) {
  std::mt19937 rng(79);
  int tight = 0, total = 0;
  for (int t = 0; t < 300; ++t) {
    SCOPED_TRACE(t);
    const KCoverageProblem p = RandomProblem(rng);
    KCoverageOptions o;
    o.max_k = p.columns;
    o.exact_max_columns = 0;
    const std::vector<KCoverage> got = KCoverageBounds(p, o);
    ExpectValidAgainstExhaustive(p, got, /*exact=*/false);
    const std::vector<uint64_t> truth = ExhaustiveBest(p);
    for (size_t k = 1; k <= got.size(); ++k) tight += got[k - 1].upper_bound == truth[k], ++total;
  }
  // Not a proof of anything, but a bound that is never tight would be useless: most are.
  EXPECT_GT(tight, total / 2);
}

TEST(KCoverageBoundTest, SubgradientStepsOnlyTightenTheBound) {
  std::mt19937 rng(5);
  int improved = 0;
  for (int t = 0; t < 200; ++t) {
    const KCoverageProblem p = RandomProblem(rng);
    KCoverageOptions o;
    o.max_k = p.columns;
    o.exact_max_columns = 0;
    KCoverageOptions no_steps = o;
    no_steps.max_iterations_per_k = 0;
    const std::vector<KCoverage> with = KCoverageBounds(p, o), without = KCoverageBounds(p, no_steps);
    for (size_t k = 0; k < with.size(); ++k) {
      EXPECT_LE(with[k].upper_bound, without[k].upper_bound) << t;
      improved += with[k].upper_bound < without[k].upper_bound;
    }
  }
  EXPECT_GT(improved, 0);  // the steps run and do tighten some bounds
}

// Three columns of 10 disjoint voxels each and a fourth seeing half of each (15): greedy takes the
// fourth first, so its prefix of 3 covers 25; the best are 15, 20, 30, 30, proven.
TEST(KCoverageBoundTest, SmallKnownInstance) {
  KCoverageProblem p;
  p.columns = 4;
  for (int j = 0; j < 3; ++j) {
    p.weight.push_back(5), p.seen_by.push_back({j, 3});
    p.weight.push_back(5), p.seen_by.push_back({j});
  }
  KCoverageOptions o;
  o.max_k = 4;
  const std::vector<KCoverage> got = KCoverageBounds(p, o);
  ASSERT_EQ(got.size(), 4u);
  const uint64_t expected[] = {15, 20, 30, 30};
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(got[k].best, expected[k]) << k;
    EXPECT_EQ(got[k].upper_bound, expected[k]) << k;
    EXPECT_TRUE(got[k].optimal);
  }
}

TEST(KCoverageBoundTest, MaxKIsCappedByTheColumnsAndNothingAsked) {
  KCoverageProblem p;
  p.columns = 2;
  p.weight = {3, 4};
  p.seen_by = {{0}, {1}};
  KCoverageOptions o;
  o.max_k = 5;
  const std::vector<KCoverage> got = KCoverageBounds(p, o);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[1].upper_bound, 7u);
  o.max_k = 0;
  EXPECT_TRUE(KCoverageBounds(p, o).empty());
  o.max_k = 3;
  EXPECT_TRUE(KCoverageBounds(KCoverageProblem{}, o).empty());
}

}  // namespace
}  // namespace vc::planner
