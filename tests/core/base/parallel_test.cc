// vc/base/parallel.h: every chunk runs once with its own range, on as many threads as asked,
// partial sums combined in chunk order do not depend on the thread count, and a cancelled job
// stops early with the token's status naming the work.
#include "vc/base/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

namespace vc {
namespace {

TEST(ParallelChunksTest, CallsEveryChunkOnceWithItsRange) {
  constexpr uint64_t kN = 1003, kChunk = 10, kChunks = 101;
  for (const int threads : {1, 3, 8, 0}) {
    std::vector<std::atomic<int>> calls(kChunks);
    std::vector<uint64_t> begin(kChunks), end(kChunks);
    const Status s = ParallelChunks(kN, kChunk, threads, {}, [&](uint64_t c, uint64_t b, uint64_t e) {
      ASSERT_LT(c, kChunks);
      calls[c].fetch_add(1);
      begin[c] = b;
      end[c] = e;
    });
    ASSERT_TRUE(s.ok()) << s.ToString();
    for (uint64_t c = 0; c < kChunks; ++c) {
      EXPECT_EQ(calls[c].load(), 1) << "chunk " << c << ", threads " << threads;
      EXPECT_EQ(begin[c], c * kChunk);
      EXPECT_EQ(end[c], std::min(kN, (c + 1) * kChunk));
    }
  }
}

TEST(ParallelChunksTest, NothingToDoCallsNothing) {
  int calls = 0;
  EXPECT_TRUE(ParallelChunks(0, 16, 4, {}, [&](uint64_t, uint64_t, uint64_t) { ++calls; }).ok());
  EXPECT_EQ(calls, 0);
}

TEST(ParallelChunksTest, RunsOnSeveralThreads) {
  std::mutex mu;
  std::set<std::thread::id> seen;
  const Status s = ParallelChunks(64, 1, 4, {}, [&](uint64_t, uint64_t, uint64_t) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    std::lock_guard lock(mu);
    seen.insert(std::this_thread::get_id());
  });
  ASSERT_TRUE(s.ok());
  EXPECT_GE(seen.size(), 2u);
  EXPECT_LE(seen.size(), 4u);
}

TEST(ParallelChunksTest, PartialSumsInChunkOrderDoNotDependOnTheThreadCount) {
  constexpr uint64_t kN = 100000, kChunk = 1000;
  auto sum = [&](int threads) {
    std::vector<double> partial(kN / kChunk, 0.0);
    EXPECT_TRUE(ParallelChunks(kN, kChunk, threads, {}, [&](uint64_t c, uint64_t b, uint64_t e) {
                  for (uint64_t i = b; i < e; ++i) partial[c] += 1.0 / double(i + 1);
                }).ok());
    double total = 0;
    for (double p : partial) total += p;
    return total;
  };
  const double one = sum(1);
  EXPECT_NEAR(one, std::log(double(kN)) + 0.5772156649, 1e-4);  // the harmonic number H(n)
  for (const int threads : {2, 5, 16}) EXPECT_EQ(sum(threads), one) << threads << " threads";
}

TEST(ParallelChunksTest, ACancelledJobStopsEarlyAndNamesTheWork) {
  for (const int threads : {1, 4}) {
    CancelToken token;
    JobContext ctx;
    ctx.cancel = &token;
    std::atomic<int> calls{0};
    const Status s = ParallelChunks(
        10000, 1, threads, ctx,
        [&](uint64_t, uint64_t, uint64_t) {
          if (calls.fetch_add(1) == 0) token.Cancel();
        },
        "the sweep");
    EXPECT_EQ(s.code(), StatusCode::kCancelled) << s.ToString();
    EXPECT_EQ(s.message(), "the sweep was cancelled");
    if (threads == 1) {
      EXPECT_EQ(calls.load(), 1);  // the next chunk checks the token first
    } else {
      EXPECT_LT(calls.load(), 100);
    }
  }
}

TEST(ParallelChunksTest, APassedDeadlineRunsNothing) {
  CancelToken token;
  token.SetDeadline(std::chrono::steady_clock::now() - std::chrono::seconds(1));
  JobContext ctx;
  ctx.cancel = &token;
  int calls = 0;
  const Status s = ParallelChunks(100, 10, 1, ctx, [&](uint64_t, uint64_t, uint64_t) { ++calls; });
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_EQ(s.message(), "the computation ran past the deadline");
  EXPECT_EQ(calls, 0);
}

TEST(ResolveThreadsTest, AtLeastOneAndAtMostOnePerChunk) {
  const int cores = std::max(1, int(std::thread::hardware_concurrency()));
  EXPECT_EQ(ResolveThreads(0, 100000), std::min(cores, 100000));
  EXPECT_EQ(ResolveThreads(-3, 100000), std::min(cores, 100000));
  EXPECT_EQ(ResolveThreads(6, 100), 6);
  EXPECT_EQ(ResolveThreads(6, 4), 4);
  EXPECT_EQ(ResolveThreads(6, 0), 1);
  EXPECT_EQ(ResolveThreads(0, 1), 1);
}

}  // namespace
}  // namespace vc
