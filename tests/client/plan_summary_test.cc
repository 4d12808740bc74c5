// vc-client's plan summary: the optimality line for each status, and none for the default greedy.
#include "vc/client/plan_summary.h"

#include <gtest/gtest.h>

namespace vc::client {
namespace {

TEST(OptimalityLineTest, SaysProvenOptimalOrHowFarFromTheBound) {
  PlanResult r;
  EXPECT_EQ(OptimalityLine(r), "") << "the default greedy plan prints no line";
  r.optimality.solver = "exact";
  r.optimality.status = planner::OptimalityStatus::kOptimal;
  r.optimality.stations = 37;
  r.optimality.lower_bound = 37;
  EXPECT_EQ(OptimalityLine(r), "optimal: 37 stations, proven\n");
  r.optimality.status = planner::OptimalityStatus::kFeasible;
  r.optimality.lower_bound = 32.2;  // a fractional bound rounds up: 33 stations at least
  EXPECT_EQ(OptimalityLine(r), "37 stations, at most 4 more than the optimum (bound 33)\n");
  r.optimality.solver = "greedy+swap";
  r.optimality.status = planner::OptimalityStatus::kHeuristic;
  EXPECT_EQ(OptimalityLine(r), "37 stations (greedy+swap), no bound on the optimum\n");
  EXPECT_NE(PlanSummary(r).find("37 stations (greedy+swap)"), std::string::npos);
}

}  // namespace
}  // namespace vc::client
