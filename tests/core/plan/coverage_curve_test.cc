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

}  // namespace
}  // namespace vc
