// vc/base/progress.h: stage names, the cancellation token (cancel and deadline) and what
// JobContext passes to the progress callback.
#include "vc/base/progress.h"

#include <gtest/gtest.h>

#include <chrono>
#include <iterator>
#include <set>
#include <string>
#include <vector>

namespace vc {
namespace {

TEST(StageNameTest, EveryStageHasItsOwnNameInPlanOrder) {
  const std::vector<std::string> want = {"read",   "voxelize",  "candidates", "visibility", "selection",
                                         "refine", "reduction", "evaluation", "route"};
  std::vector<std::string> got;
  for (const Stage s : kAllStages) got.emplace_back(StageName(s));
  EXPECT_EQ(got, want);
  for (size_t i = 1; i < std::size(kAllStages); ++i) EXPECT_LT(kAllStages[i - 1], kAllStages[i]);
  EXPECT_EQ(StageName(Stage::kUnspecified), "unspecified");
  EXPECT_EQ(StageName(static_cast<Stage>(200)), "unspecified");
}

TEST(CancelTokenTest, CancelAndDeadlineGiveTheirOwnCodesNamingTheWork) {
  CancelToken token;
  EXPECT_FALSE(token.cancelled());
  EXPECT_TRUE(token.Check("the plan").ok());

  token.SetDeadline(std::chrono::steady_clock::now() + std::chrono::hours(1));
  EXPECT_FALSE(token.cancelled());
  EXPECT_TRUE(token.Check("the plan").ok());

  token.SetDeadline(std::chrono::steady_clock::now() - std::chrono::milliseconds(1));
  EXPECT_TRUE(token.cancelled());
  Status s = token.Check("the plan");
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_EQ(s.message(), "the plan ran past the deadline");

  token.Cancel();  // an explicit cancel wins over the passed deadline
  s = token.Check("the evaluation");
  EXPECT_EQ(s.code(), StatusCode::kCancelled);
  EXPECT_EQ(s.message(), "the evaluation was cancelled");
}

TEST(JobContextTest, WithoutTokenOrCallbackNothingIsCancelledOrReported) {
  const JobContext ctx;
  EXPECT_TRUE(ctx.CheckCancelled("x").ok());
  ctx.Report(Stage::kRead, 0.5, "half");  // no callback: must not crash
  ctx.ReportCount(Stage::kRead, 1, 2, "files");
}

TEST(JobContextTest, ReportsPassStageFractionCountsAndUnit) {
  std::vector<ProgressEvent> events;
  CancelToken token;
  JobContext ctx;
  ctx.cancel = &token;
  ctx.progress = [&](const ProgressEvent& e) { events.push_back(e); };
  ctx.Report(Stage::kVisibility, 0.25, "a quarter");
  ctx.ReportCount(Stage::kCandidates, 412, 858, "candidates", "counting");
  ctx.ReportCount(Stage::kSelection, 7, 0, "stations");  // total unknown: fraction 0
  ctx.ReportCount(Stage::kReduction, 12, 10, "pairs");   // over the total: fraction capped at 1
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[0].stage, Stage::kVisibility);
  EXPECT_EQ(events[0].fraction, 0.25);
  EXPECT_EQ(events[0].message, "a quarter");
  EXPECT_EQ(events[0].total, 0u);
  EXPECT_TRUE(events[0].unit.empty());
  EXPECT_EQ(events[1].stage, Stage::kCandidates);
  EXPECT_DOUBLE_EQ(events[1].fraction, 412.0 / 858.0);
  EXPECT_EQ(events[1].done, 412u);
  EXPECT_EQ(events[1].total, 858u);
  EXPECT_EQ(events[1].unit, "candidates");
  EXPECT_EQ(events[1].message, "counting");
  EXPECT_EQ(events[2].fraction, 0.0);
  EXPECT_EQ(events[2].done, 7u);
  EXPECT_EQ(events[3].fraction, 1.0);
  EXPECT_EQ(events[3].done, 12u);

  token.Cancel();
  EXPECT_EQ(ctx.CheckCancelled("the route").code(), StatusCode::kCancelled);
}

}  // namespace
}  // namespace vc
