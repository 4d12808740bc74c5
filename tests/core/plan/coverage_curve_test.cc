// The coverage curve: steps equal the gains, monotone, fractions of the coverable and of the whole
// scene, set-up and scan time per station; the milestones take the first point reaching a level.
#include "vc/plan/coverage_curve.h"

#include <gtest/gtest.h>

#include <vector>

namespace vc {
namespace {

TEST(CoverageCurveTest, StepsAreTheGainsAndTheFractionsOfCoverableAndScene) {
  const std::vector<CoveragePoint> c = CoverageCurve({60, 25, 10, 5}, 200, 100, 150);
  ASSERT_EQ(c.size(), 4u);
  const uint64_t expected_covered[] = {60, 85, 95, 100};
  for (size_t k = 0; k < c.size(); ++k) {
    EXPECT_EQ(c[k].stations, static_cast<int>(k) + 1);
    EXPECT_EQ(c[k].covered_voxels, expected_covered[k]);
    EXPECT_DOUBLE_EQ(c[k].coverable_fraction, expected_covered[k] / 100.0);
    EXPECT_DOUBLE_EQ(c[k].scene_fraction, expected_covered[k] / 200.0);
    EXPECT_DOUBLE_EQ(c[k].setup_scan_s, 150.0 * (k + 1));
  }
}

TEST(CoverageCurveTest, NoCoverableVoxelsGiveZeroFractionsAndNoStationsNoPoints) {
  const std::vector<CoveragePoint> c = CoverageCurve({0}, 0, 0, 60);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].coverable_fraction, 0.0);
  EXPECT_EQ(c[0].scene_fraction, 0.0);
  EXPECT_TRUE(CoverageCurve({}, 10, 10, 60).empty());
}

TEST(CoverageMilestonesTest, TheFewestLeadingStationsReachingEachLevel) {
  const std::vector<CoveragePoint> c = CoverageCurve({60, 25, 10, 3}, 200, 100, 60);
  const std::vector<CoverageMilestone> m = CoverageMilestones(c, 100, {0.80, 0.90, 0.95, 0.99, 0.6});
  ASSERT_EQ(m.size(), 5u);
  ASSERT_TRUE(m[0].reached && m[1].reached && m[2].reached && m[4].reached);
  EXPECT_EQ(m[0].reached->stations, 2);  // 85 >= 80
  EXPECT_EQ(m[1].reached->stations, 3);  // 95 >= 90
  EXPECT_EQ(m[2].reached->stations, 3);  // 95 >= 95: a level reached exactly counts
  EXPECT_FALSE(m[3].reached);            // the plan covers 98 of 100
  EXPECT_EQ(m[4].reached->stations, 1);
  EXPECT_DOUBLE_EQ(m[2].reached->scene_fraction, 0.475);
  EXPECT_DOUBLE_EQ(m[0].coverable_fraction, 0.80);
}

// The per-k bound: set where given (none past its end or where nullopt), best at least the plan's
// own prefix, optimal where the two meet; the milestones' fewest possible stations is the first k
// whose bound reaches the level.
TEST(CoverageCurveTest, BestCoverageAndTheFewestStationsAnyPlanNeeds) {
  std::vector<CoveragePoint> c = CoverageCurve({60, 25, 10, 3}, 200, 100, 60);
  AddBestCoverage(c, {BestCoverage{70, 65}, std::nullopt, BestCoverage{96, 96}});
  ASSERT_TRUE(c[0].best_voxels_upper_bound && c[0].best_voxels);
  EXPECT_EQ(*c[0].best_voxels_upper_bound, 70u);
  EXPECT_EQ(*c[0].best_voxels, 65u);
  EXPECT_FALSE(c[0].best_voxels_optimal);
  EXPECT_FALSE(c[1].best_voxels_upper_bound);
  EXPECT_FALSE(c[1].best_voxels);
  EXPECT_EQ(*c[2].best_voxels, 96u);  // above the plan's 95
  EXPECT_TRUE(c[2].best_voxels_optimal);
  EXPECT_FALSE(c[3].best_voxels_upper_bound);
  std::vector<CoveragePoint> prefix_best = CoverageCurve({60}, 200, 100, 60);
  AddBestCoverage(prefix_best, {BestCoverage{62, 55}});
  EXPECT_EQ(*prefix_best[0].best_voxels, 60u);  // the plan's own 60 beats the 55 found

  const std::vector<CoverageMilestone> m = CoverageMilestones(c, 100, {0.60, 0.90, 0.99});
  EXPECT_EQ(m[0].fewest_possible_stations, 1);  // 70 >= 60
  EXPECT_EQ(m[1].fewest_possible_stations, 3);  // k = 2 carries no bound; 96 >= 90
  EXPECT_FALSE(m[2].fewest_possible_stations);  // no bound reaches 99
  EXPECT_FALSE(CoverageMilestones(CoverageCurve({60}, 200, 100, 60), 100, {0.5})[0].fewest_possible_stations);
}

}  // namespace
}  // namespace vc
