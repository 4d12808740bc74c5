// The stage runner: timings in the order the stages ran, cancellation before a stage, errors
// passed through, and progress relabelled to the running stage and mapped monotonically into
// [0, 1] (also through ProgressRange sub-ranges), and each stage's own peak resident memory.
#include "vc/plan/stage_runner.h"

#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "testing/test_paths.h"

namespace vc::planner {
namespace {

// Collects every progress event of a context.
struct Recorder {
  std::mutex mu;
  std::vector<ProgressEvent> events;
  JobContext Context(const CancelToken* cancel = nullptr) {
    JobContext ctx;
    ctx.cancel = cancel;
    ctx.progress = [this](const ProgressEvent& e) {
      std::lock_guard<std::mutex> lock(mu);
      events.push_back(e);
    };
    return ctx;
  }
};

Result<int> Ok(const JobContext&) { return 1; }

TEST(StageRunnerTest, RecordsTimingsInTheOrderTheStagesRan) {
  const JobContext ctx;
  StageRunner runner(ctx);
  ASSERT_TRUE(runner.Run(Stage::kVoxelize, Ok).ok());
  Result<int> slow = runner.Run(Stage::kCandidates, [](const JobContext&) -> Result<int> {
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    return 7;
  });
  ASSERT_TRUE(slow.ok());
  EXPECT_EQ(*slow, 7);
  ASSERT_TRUE(runner.Run(Stage::kVisibility, Ok).ok());
  const std::vector<StageTiming>& t = runner.timings();
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0].stage, Stage::kVoxelize);
  EXPECT_EQ(t[1].stage, Stage::kCandidates);
  EXPECT_EQ(t[2].stage, Stage::kVisibility);
  EXPECT_GE(t[1].seconds, 0.03);
  EXPECT_LT(t[0].seconds, t[1].seconds);
  EXPECT_GE(runner.elapsed_seconds(), t[0].seconds + t[1].seconds + t[2].seconds);
}

TEST(StageRunnerTest, RecordsEachStagesPeakResidentMemory) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << "ASan's quarantine keeps freed blocks resident";
  constexpr size_t kBlockBytes = size_t{96} << 20;
  const JobContext ctx;
  StageRunner runner(ctx);
  const auto hold_a_block = [&](const JobContext&) -> Result<int> {
    std::vector<char> block(kBlockBytes, 1);  // written, so resident, then freed
    asm volatile("" : : "r"(block.data()) : "memory");
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // sampled as well
    return block[kBlockBytes - 1];
  };
  ASSERT_TRUE(runner.Run(Stage::kVisibility, hold_a_block).ok());
  ASSERT_TRUE(runner.Run(Stage::kSelection, Ok).ok());
  const std::vector<StageTiming>& t = runner.timings();
  ASSERT_EQ(t.size(), 2u);
  ASSERT_GT(t[0].peak_rss_bytes, 0u);
  ASSERT_GT(t[1].peak_rss_bytes, 0u);
  // The second stage began after the first stage's block was freed.
  EXPECT_GE(t[0].peak_rss_bytes, t[1].peak_rss_bytes + kBlockBytes / 2);
}

TEST(StageRunnerTest, CancellationBeforeAStageStopsItWithCancelledNamingTheStage) {
  CancelToken token;
  Recorder rec;
  const JobContext ctx = rec.Context(&token);
  StageRunner runner(ctx);
  ASSERT_TRUE(runner.Run(Stage::kVoxelize, Ok).ok());
  token.Cancel();
  bool ran = false;
  Result<int> r = runner.Run(Stage::kCandidates, [&](const JobContext&) -> Result<int> {
    ran = true;
    return 1;
  });
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_NE(r.status().message().find("candidates"), std::string::npos) << r.status().ToString();
  EXPECT_FALSE(ran);
  ASSERT_EQ(runner.timings().size(), 1u);  // the cancelled stage is not timed
  EXPECT_EQ(runner.timings()[0].stage, Stage::kVoxelize);
  // The stage was begun (reported at 0) but never ended (no report at 1).
  ASSERT_FALSE(rec.events.empty());
  EXPECT_EQ(rec.events.back().stage, Stage::kCandidates);
  EXPECT_EQ(rec.events.back().fraction, 0.0);
}

TEST(StageRunnerTest, DeadlineBeforeAStageStopsItWithDeadlineExceededNamingTheStage) {
  CancelToken token;
  token.SetDeadline(std::chrono::steady_clock::now() - std::chrono::seconds(1));
  JobContext ctx;
  ctx.cancel = &token;
  StageRunner runner(ctx);
  Result<int> r = runner.Run(Stage::kReduction, Ok);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(r.status().message().find("reduction"), std::string::npos) << r.status().ToString();
  EXPECT_TRUE(runner.timings().empty());
}

TEST(StageRunnerTest, TheStageSeesTheCancelTokenAndItsErrorPassesThrough) {
  CancelToken token;
  Recorder rec;
  const JobContext ctx = rec.Context(&token);
  StageRunner runner(ctx);
  Result<int> r = runner.Run(Stage::kSelection, [&](const JobContext& c) -> Result<int> {
    token.Cancel();
    VC_RETURN_IF_ERROR(c.CheckCancelled("inner loop"));
    return 1;
  });
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_NE(r.status().message().find("inner loop"), std::string::npos) << r.status().ToString();
  EXPECT_TRUE(runner.timings().empty());
  for (const ProgressEvent& e : rec.events) EXPECT_LT(e.fraction, 1.0);  // no end report
}

TEST(StageRunnerTest, ProgressIsRelabelledToTheStageAndMonotoneInZeroOne) {
  Recorder rec;
  const JobContext ctx = rec.Context();
  StageRunner runner(ctx);
  ASSERT_TRUE(runner
                  .Run(Stage::kVisibility,
                       [](const JobContext& c) -> Result<int> {
                         // Work that reports under another stage's name and overshoots [0, 1].
                         c.Report(Stage::kEvaluation, -0.5);
                         c.Report(Stage::kEvaluation, 0.25, "a quarter");
                         c.Report(Stage::kUnspecified, 1.5);
                         return 1;
                       })
                  .ok());
  ASSERT_TRUE(runner
                  .Run(Stage::kRefine,
                       [](const JobContext& c) -> Result<int> {
                         // Two parts of the stage: [0, 0.9] and [0.9, 1].
                         const JobContext first = ProgressRange(c, 0.0, 0.9);
                         first.Report(Stage::kVisibility, 0.5);
                         first.Report(Stage::kVisibility, 1.0);
                         const JobContext second = ProgressRange(c, 0.9, 1.0);
                         second.Report(Stage::kReduction, 0.5);
                         return 1;
                       })
                  .ok());
  std::vector<double> visibility, refine;
  for (const ProgressEvent& e : rec.events) {
    ASSERT_TRUE(e.stage == Stage::kVisibility || e.stage == Stage::kRefine) << StageName(e.stage);
    EXPECT_GE(e.fraction, 0.0);
    EXPECT_LE(e.fraction, 1.0);
    (e.stage == Stage::kVisibility ? visibility : refine).push_back(e.fraction);
  }
  // Begin 0, the three clamped reports, end 1; the runner's stages arrive in order.
  EXPECT_EQ(visibility, (std::vector<double>{0.0, 0.0, 0.25, 1.0, 1.0}));
  ASSERT_EQ(refine.size(), 5u);
  EXPECT_EQ(refine[0], 0.0);
  EXPECT_DOUBLE_EQ(refine[1], 0.45);
  EXPECT_DOUBLE_EQ(refine[2], 0.9);
  EXPECT_DOUBLE_EQ(refine[3], 0.95);
  EXPECT_EQ(refine[4], 1.0);
  for (size_t i = 1; i < refine.size(); ++i) EXPECT_LE(refine[i - 1], refine[i]) << i;
  EXPECT_EQ(rec.events[2].message, "a quarter");  // messages pass through
  EXPECT_EQ(rec.events.front().stage, Stage::kVisibility);
  EXPECT_EQ(rec.events.back().stage, Stage::kRefine);
}

TEST(StageRunnerTest, WithoutAProgressCallbackStagesGetNone) {
  const JobContext ctx;
  StageRunner runner(ctx);
  Result<int> r = runner.Run(Stage::kVoxelize, [](const JobContext& c) -> Result<int> { return c.progress ? 1 : 0; });
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(*r, 0);
}

}  // namespace
}  // namespace vc::planner
