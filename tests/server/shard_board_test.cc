// ShardBoard and LaneRetryPolicy: the fan-out's rules, on a fake clock (no sleeps, no sockets);
// then lanes waiting in Take on other threads, woken by what the board's other calls do.
#include "vc/server/shard_board.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <latch>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace vc::server {
namespace {

using Attempt = ShardBoard::Attempt;
using std::chrono::milliseconds;
using std::chrono::seconds;

// How long a test waits for another thread before it reports a failure (real time).
constexpr auto kTestWait = seconds(30);
// A poll interval no test outlives: a lane that misses its wake-up stays asleep.
constexpr auto kNoPoll = std::chrono::hours(24);

// A clock that moves only when told; several threads may read and advance it. It counts its
// reads: the board reads its clock only under its lock.
class FakeClock {
 public:
  ShardBoard::NowFn fn() {
    return [this] { return Read(); };
  }
  void Advance(ShardBoard::Clock::duration d) {
    std::lock_guard lock(mu_);
    now_ += d;
  }
  // Times the clock was read.
  size_t reads() const {
    std::lock_guard lock(mu_);
    return reads_;
  }
  // Waits up to kTestWait until the clock has been read more than `n` times; false if it was not.
  bool AwaitReadsOver(size_t n) {
    std::unique_lock lock(mu_);
    return read_.wait_for(lock, kTestWait, [&] { return reads_ > n; });
  }

 private:
  ShardBoard::Clock::time_point Read() {
    std::lock_guard lock(mu_);
    ++reads_;
    read_.notify_all();
    return now_;
  }

  mutable std::mutex mu_;
  std::condition_variable read_;
  ShardBoard::Clock::time_point now_{seconds(1000)};
  size_t reads_ = 0;
};

// A lane on its own thread, in Take(wait, defer) on a board that has nothing for it yet. Once it
// has read the board's clock it holds the board's lock until it waits, so whatever the test does
// to the board next happens while the lane waits and must wake it. Joined on destruction (after
// stopping the board, if the lane is still waiting then).
class WaitingLane {
 public:
  WaitingLane(ShardBoard& board, FakeClock& clock, ShardBoard::Clock::duration wait, bool defer = false)
      : board_(board) {
    const size_t reads = clock.reads();
    std::packaged_task<std::optional<Attempt>()> take([&board, wait, defer] { return board.Take(wait, defer); });
    answer_ = take.get_future().share();
    thread_ = std::thread(std::move(take));
    in_take_ = clock.AwaitReadsOver(reads);
  }
  WaitingLane(const WaitingLane&) = delete;
  WaitingLane& operator=(const WaitingLane&) = delete;
  ~WaitingLane() {
    if (!Returned(milliseconds(0))) board_.Stop();
    thread_.join();
  }

  // The lane is in Take (it read the board's clock).
  bool in_take() const { return in_take_; }
  // Take returned within `wait` (real time).
  bool Returned(std::chrono::milliseconds wait = kTestWait) const {
    return answer_.wait_for(wait) == std::future_status::ready;
  }
  // What Take returned (once Returned()).
  std::optional<Attempt> answer() const { return answer_.get(); }

 private:
  ShardBoard& board_;
  std::shared_future<std::optional<Attempt>> answer_;
  std::thread thread_;
  bool in_take_ = false;
};

// The shards TryTake hands out until it hands out none.
std::vector<size_t> TakeAll(ShardBoard& board) {
  std::vector<size_t> shards;
  while (std::optional<Attempt> a = board.TryTake()) shards.push_back(a->shard);
  return shards;
}

TEST(ShardBoard, CutsTheViewpointsIntoShardsInOrderTheLastSmaller) {
  FakeClock clock;
  ShardBoard board(10, 4, clock.fn());
  ASSERT_EQ(board.size(), 3u);
  std::vector<std::pair<size_t, size_t>> ranges;
  while (std::optional<Attempt> a = board.TryTake()) ranges.emplace_back(a->begin, a->end);
  EXPECT_EQ(ranges, (std::vector<std::pair<size_t, size_t>>{{0, 4}, {4, 8}, {8, 10}}));
}

TEST(ShardBoard, NoViewpointsMeansNoShardAndFinished) {
  FakeClock clock;
  ShardBoard board(0, 4, clock.fn());
  EXPECT_EQ(board.size(), 0u);
  EXPECT_TRUE(board.Finished());
  EXPECT_FALSE(board.TryTake().has_value());
}

TEST(ShardBoard, HandsOutEachShardOnceWhileNoneIsSlow) {
  FakeClock clock;
  ShardBoard board(12, 4, clock.fn());
  EXPECT_EQ(TakeAll(board), (std::vector<size_t>{0, 1, 2}));
  clock.Advance(seconds(29));  // under kSlowShardBeforeAnyFinished
  EXPECT_FALSE(board.TryTake().has_value());
  EXPECT_FALSE(board.Finished());
}

TEST(ShardBoard, FinishesWhenEveryShardIsDeliveredAndCountsWhoAnswered) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn());
  const std::optional<Attempt> a = board.TryTake();
  const std::optional<Attempt> b = board.TryTake();
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(board.Deliver(*a, "peer-1"));
  EXPECT_EQ(board.done(), 1u);
  EXPECT_FALSE(board.Finished());
  EXPECT_TRUE(board.Deliver(*b, "this replica"));
  EXPECT_EQ(board.done(), 2u);
  EXPECT_TRUE(board.Finished());
  EXPECT_FALSE(board.TryTake().has_value());
  const Distribution d = board.distribution();
  EXPECT_EQ(d.replicas, 2);
  EXPECT_EQ(d.shards, 2);
  EXPECT_EQ(d.retried, 0);
}

TEST(ShardBoard, AFailedShardGoesBackFirstInLineAndCountsAsRetried) {
  FakeClock clock;
  ShardBoard board(12, 4, clock.fn());
  EXPECT_EQ(TakeAll(board), (std::vector<size_t>{0, 1, 2}));
  board.Release(Attempt{1, 4, 8, {}});
  const std::optional<Attempt> again = board.TryTake();
  ASSERT_TRUE(again);
  EXPECT_EQ(again->shard, 1u);
  EXPECT_EQ(again->begin, 4u);
  EXPECT_FALSE(board.TryTake().has_value());
  EXPECT_EQ(board.distribution().retried, 1);
}

TEST(ShardBoard, ASlowShardIsStartedAgainAndTheFirstAnswerWins) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn());
  const std::optional<Attempt> slow = board.TryTake();
  const std::optional<Attempt> quick = board.TryTake();
  ASSERT_TRUE(slow && quick);
  clock.Advance(seconds(1));
  ASSERT_TRUE(board.Deliver(*quick, "peer-2"));  // the mean finished shard: 1 s, so slow after 3 s
  EXPECT_FALSE(board.TryTake().has_value());
  clock.Advance(seconds(2));  // shard 0 has run 3 s
  const std::optional<Attempt> restart = board.TryTake();
  ASSERT_TRUE(restart);
  EXPECT_EQ(restart->shard, slow->shard);
  EXPECT_TRUE(board.Deliver(*restart, "this replica"));
  EXPECT_FALSE(board.Deliver(*slow, "peer-1")) << "the slow attempt answered second: its items are dropped";
  EXPECT_TRUE(board.Finished());
  const Distribution d = board.distribution();
  EXPECT_EQ(d.replicas, 2) << "peer-1's late answer does not count it";
  EXPECT_EQ(d.retried, 1);
}

TEST(ShardBoard, SlowMeansThreeTimesTheMeanFinishedShard) {
  FakeClock clock;
  ShardBoard board(12, 4, clock.fn());
  const std::optional<Attempt> a = board.TryTake();
  const std::optional<Attempt> b = board.TryTake();
  ASSERT_TRUE(a && b);
  clock.Advance(seconds(10));
  ASSERT_TRUE(board.Deliver(*a, "peer-1"));  // mean 10 s: slow after 30 s
  const std::optional<Attempt> c = board.TryTake();
  ASSERT_TRUE(c);
  EXPECT_EQ(c->shard, 2u);
  clock.Advance(seconds(19));  // b has run 29 s
  EXPECT_FALSE(board.TryTake().has_value());
  clock.Advance(seconds(1));  // b 30 s, c 20 s
  const std::optional<Attempt> restart = board.TryTake();
  ASSERT_TRUE(restart);
  EXPECT_EQ(restart->shard, b->shard);
  EXPECT_FALSE(board.TryTake().has_value()) << "c is not slow yet, and b runs twice now";
}

TEST(ShardBoard, AShardIsNeverSlowBeforeTheFloor) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn());
  const std::optional<Attempt> a = board.TryTake();
  ASSERT_TRUE(a && board.TryTake());
  clock.Advance(milliseconds(100));
  ASSERT_TRUE(board.Deliver(*a, "peer-1"));  // three times the mean is 0.3 s, under the floor
  clock.Advance(kSlowShardFloor - milliseconds(200));
  EXPECT_FALSE(board.TryTake().has_value());
  clock.Advance(milliseconds(100));  // shard 1 has run kSlowShardFloor
  EXPECT_TRUE(board.TryTake().has_value());
}

TEST(ShardBoard, BeforeAnyShardFinishesAShardIsSlowAfterThirtySeconds) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn());
  ASSERT_TRUE(board.TryTake());
  clock.Advance(kSlowShardBeforeAnyFinished - seconds(1));
  EXPECT_FALSE(board.TryTake().has_value());
  clock.Advance(seconds(1));
  EXPECT_TRUE(board.TryTake().has_value());
}

TEST(ShardBoard, TheLongestRunningSlowShardIsStartedAgainFirst) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn());
  ASSERT_TRUE(board.TryTake());  // shard 0
  clock.Advance(seconds(5));
  ASSERT_TRUE(board.TryTake());  // shard 1, 5 s later
  clock.Advance(kSlowShardBeforeAnyFinished);
  const std::optional<Attempt> restart = board.TryTake();
  ASSERT_TRUE(restart);
  EXPECT_EQ(restart->shard, 0u);
  const std::optional<Attempt> next = board.TryTake();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->shard, 1u);
}

TEST(ShardBoard, ASlowShardIsStartedAgainAtMostTwice) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn());
  std::optional<Attempt> a = board.TryTake();
  ASSERT_TRUE(a);
  for (int restart = 0; restart < kMaxRestartsPerShard; ++restart) {
    clock.Advance(kSlowShardBeforeAnyFinished);
    const std::optional<Attempt> again = board.TryTake();
    ASSERT_TRUE(again) << restart;
    board.Release(*a);  // the older attempt fails: one attempt runs, and it is slow in turn
    a = again;
  }
  clock.Advance(kSlowShardBeforeAnyFinished);
  EXPECT_FALSE(board.TryTake().has_value());
  EXPECT_EQ(board.distribution().retried, kMaxRestartsPerShard);
}

TEST(ShardBoard, AShardRunningTwiceIsNotStartedAThirdTime) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn());
  ASSERT_TRUE(board.TryTake());
  clock.Advance(kSlowShardBeforeAnyFinished);
  ASSERT_TRUE(board.TryTake());
  clock.Advance(kSlowShardBeforeAnyFinished * 2);
  EXPECT_FALSE(board.TryTake().has_value());
}

TEST(ShardBoard, ADeferringLaneWaitsWhilePeerLanesWork) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn());
  board.LaneStarted();
  EXPECT_FALSE(board.TryTake(/*defer=*/true).has_value());
  const std::optional<Attempt> peer = board.TryTake();
  ASSERT_TRUE(peer);
  EXPECT_EQ(peer->shard, 0u);
  EXPECT_FALSE(board.TryTake(/*defer=*/true).has_value());
  board.LaneEnded();  // the last peer lane ended: the coordinator computes the rest
  const std::optional<Attempt> own = board.TryTake(/*defer=*/true);
  ASSERT_TRUE(own);
  EXPECT_EQ(own->shard, 1u);
}

TEST(ShardBoard, ADeferringLaneTakesAFreshShardOnceAPeerHasStalled) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn());
  board.LaneStarted();
  ASSERT_TRUE(board.TryTake());  // a peer lane takes shard 0 and hangs
  clock.Advance(kSlowShardBeforeAnyFinished);
  const std::optional<Attempt> own = board.TryTake(/*defer=*/true);
  ASSERT_TRUE(own);
  EXPECT_EQ(own->shard, 1u) << "a shard nobody runs comes before the stalled one";
}

TEST(ShardBoard, TakeWithoutTimeToWaitReturnsAtOnce) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn());
  ASSERT_TRUE(board.Take(milliseconds(0)));
  EXPECT_FALSE(board.Take(milliseconds(0)).has_value());
  EXPECT_FALSE(board.Finished());
}

TEST(ShardBoard, StopCancelsTheLiveCallsAndHandsOutNothingMore) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn());
  int cancelled_0 = 0, cancelled_1 = 0;
  ASSERT_TRUE(board.SetLive(0, [&] { ++cancelled_0; }));
  ASSERT_TRUE(board.SetLive(1, [&] { ++cancelled_1; }));
  ASSERT_TRUE(board.SetLive(1, nullptr));  // lane 1's call ended
  board.Stop();
  EXPECT_EQ(cancelled_0, 1);
  EXPECT_EQ(cancelled_1, 0);
  EXPECT_TRUE(board.Finished());
  EXPECT_FALSE(board.TryTake().has_value());
  EXPECT_FALSE(board.Take(std::chrono::hours(1)).has_value()) << "a stopped board does not wait";
  EXPECT_FALSE(board.SetLive(2, [] {})) << "a call starting after the stop is refused";
  EXPECT_TRUE(board.SetLive(0, nullptr));
  board.Sleep(std::chrono::hours(1));  // returns at once: the board is finished
}

TEST(ShardBoard, AWaitingTakeWakesWhenAnotherLaneReleasesAShardAndTakesIt) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn(), kNoPoll);
  const std::optional<Attempt> failing = board.TryTake();
  ASSERT_TRUE(failing);
  WaitingLane lane(board, clock, std::chrono::hours(1));
  ASSERT_TRUE(lane.in_take());
  board.Release(*failing);
  ASSERT_TRUE(lane.Returned()) << "Release did not wake the waiting lane";
  const std::optional<Attempt> again = lane.answer();
  ASSERT_TRUE(again);
  EXPECT_EQ(again->shard, 0u);
  EXPECT_EQ(board.distribution().retried, 1);
}

TEST(ShardBoard, StopWakesEveryWaitingTakeWithNothing) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn(), kNoPoll);
  ASSERT_TRUE(board.TryTake());
  WaitingLane first(board, clock, std::chrono::hours(1));
  WaitingLane second(board, clock, std::chrono::hours(1));
  ASSERT_TRUE(first.in_take() && second.in_take());
  board.Stop();
  ASSERT_TRUE(first.Returned()) << "Stop did not wake the first lane";
  ASSERT_TRUE(second.Returned()) << "Stop did not wake the second lane";
  EXPECT_FALSE(first.answer().has_value());
  EXPECT_FALSE(second.answer().has_value());
  EXPECT_TRUE(board.Finished());
}

TEST(ShardBoard, ADeferringTakeWakesWhenTheLastPeerLaneEndsAndTakesAFreshShard) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn(), kNoPoll);
  board.LaneStarted();
  ASSERT_TRUE(board.TryTake());  // the peer lane runs shard 0
  WaitingLane own(board, clock, std::chrono::hours(1), /*defer=*/true);
  ASSERT_TRUE(own.in_take());
  board.LaneEnded();
  ASSERT_TRUE(own.Returned()) << "LaneEnded did not wake the deferring lane";
  const std::optional<Attempt> fresh = own.answer();
  ASSERT_TRUE(fresh);
  EXPECT_EQ(fresh->shard, 1u);
}

TEST(ShardBoard, AWaitingTakeWakesWithNothingWhenTheLastShardIsDelivered) {
  FakeClock clock;
  ShardBoard board(8, 4, clock.fn(), kNoPoll);
  const std::optional<Attempt> a = board.TryTake();
  const std::optional<Attempt> b = board.TryTake();
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(board.Deliver(*a, "peer-1"));
  WaitingLane lane(board, clock, std::chrono::hours(1));
  ASSERT_TRUE(lane.in_take());
  ASSERT_TRUE(board.Deliver(*b, "peer-2"));
  ASSERT_TRUE(lane.Returned()) << "the last Deliver did not wake the waiting lane";
  EXPECT_FALSE(lane.answer().has_value());
  EXPECT_TRUE(board.Finished());
  EXPECT_EQ(board.done(), 2u);
}

TEST(ShardBoard, AWaitingTakeEndsOnceAnotherThreadAdvancesTheFakeClockPastItsDeadline) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn());  // the production poll interval: no wake-up comes
  board.LaneStarted();                 // a peer lane that runs nothing: the deferring lane waits on
  WaitingLane own(board, clock, std::chrono::hours(1), /*defer=*/true);
  ASSERT_TRUE(own.in_take());
  clock.Advance(std::chrono::hours(1));
  ASSERT_TRUE(own.Returned()) << "Take did not see the fake clock pass its deadline";
  EXPECT_FALSE(own.answer().has_value());
  EXPECT_FALSE(board.Finished());
}

TEST(ShardBoard, AWaitingTakeStartsAShardAgainOnceTheFakeClockMakesItSlow) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn());
  ASSERT_TRUE(board.TryTake());
  WaitingLane lane(board, clock, std::chrono::hours(1));
  ASSERT_TRUE(lane.in_take());
  clock.Advance(kSlowShardBeforeAnyFinished);
  ASSERT_TRUE(lane.Returned()) << "Take did not look again at the running shard";
  const std::optional<Attempt> restart = lane.answer();
  ASSERT_TRUE(restart);
  EXPECT_EQ(restart->shard, 0u);
  EXPECT_EQ(board.distribution().retried, 1);
}

TEST(ShardBoard, ACallSetLiveWhileTheBoardStopsIsCancelledExactlyOnceOrRefused) {
  constexpr size_t kLanes = 4;
  for (int round = 0; round < 100; ++round) {
    FakeClock clock;
    ShardBoard board(4, 4, clock.fn());
    std::array<std::atomic<int>, kLanes> cancelled{};
    std::array<bool, kLanes> live{};
    std::latch go(kLanes + 1);
    std::vector<std::thread> lanes;
    for (size_t k = 0; k < kLanes; ++k) {
      lanes.emplace_back([&, k] {
        go.arrive_and_wait();
        live[k] = board.SetLive(k, [&cancelled, k] { ++cancelled[k]; });
      });
    }
    go.arrive_and_wait();
    board.Stop();
    for (std::thread& t : lanes) t.join();
    for (size_t k = 0; k < kLanes; ++k) {
      EXPECT_EQ(cancelled[k].load(), live[k] ? 1 : 0) << "round " << round << ", lane " << k;
      EXPECT_TRUE(board.SetLive(k, nullptr));
    }
    board.Stop();  // the calls ended: a second stop cancels nothing
    for (size_t k = 0; k < kLanes; ++k) EXPECT_EQ(cancelled[k].load(), live[k] ? 1 : 0) << "round " << round;
  }
}

TEST(ShardBoard, KeepsWarningsInOrderAndSumsBytes) {
  FakeClock clock;
  ShardBoard board(4, 4, clock.fn());
  board.Warn("first");
  board.Warn("second");
  board.AddBytes(100);
  board.AddBytes(23);
  EXPECT_EQ(board.TakeWarnings(), (std::vector<std::string>{"first", "second"}));
  EXPECT_EQ(board.distribution().bytes_exchanged, 123u);
}

using Action = LaneRetryPolicy::Action;

TEST(LaneRetryPolicy, OtherFailuresAreRetriedOnceThenTheLaneRetires) {
  LaneRetryPolicy policy;
  EXPECT_EQ(policy.OnFailure(UnavailableError("gone")).action, Action::kRetry);
  const LaneRetryPolicy::Decision d = policy.OnFailure(DeadlineExceededError("slow"));
  EXPECT_EQ(d.action, Action::kRetire);
  EXPECT_EQ(d.retire_reason, "DEADLINE_EXCEEDED: slow");
}

TEST(LaneRetryPolicy, AnAnswerResetsTheFailuresInARow) {
  LaneRetryPolicy policy;
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(policy.OnFailure(UnavailableError("blip")).action, Action::kRetry) << i;
    policy.OnAnswer();
  }
}

TEST(LaneRetryPolicy, ABusyPeerIsAskedAgainAfterABackOffThenLeftOut) {
  LaneRetryPolicy policy;
  for (int i = 1; i < kMaxBusyAnswers; ++i) {
    EXPECT_EQ(policy.OnFailure(ResourceExhaustedError("busy")).action, Action::kBackOff) << i;
  }
  const LaneRetryPolicy::Decision d = policy.OnFailure(ResourceExhaustedError("busy"));
  EXPECT_EQ(d.action, Action::kRetire);
  EXPECT_EQ(d.retire_reason, "RESOURCE_EXHAUSTED: busy (20 times in a row)");
}

TEST(LaneRetryPolicy, BusyAnswersCountAgainAfterAnAnswer) {
  LaneRetryPolicy policy;
  for (int i = 1; i < kMaxBusyAnswers; ++i)
    ASSERT_EQ(policy.OnFailure(ResourceExhaustedError("busy")).action, Action::kBackOff);
  policy.OnAnswer();
  EXPECT_EQ(policy.OnFailure(ResourceExhaustedError("busy")).action, Action::kBackOff);
}

TEST(LaneRetryPolicy, BusyAnswersDoNotCountAsFailures) {
  LaneRetryPolicy policy;
  EXPECT_EQ(policy.OnFailure(UnavailableError("blip")).action, Action::kRetry);
  EXPECT_EQ(policy.OnFailure(ResourceExhaustedError("busy")).action, Action::kBackOff);
  EXPECT_EQ(policy.OnFailure(UnavailableError("blip")).action, Action::kRetire);
}

TEST(LaneRetryPolicy, APeerThatLosesTheSceneGetsItOnceMore) {
  LaneRetryPolicy policy;
  EXPECT_EQ(policy.OnFailure(NotFoundError("evicted")).action, Action::kShareSceneAgain);
  policy.OnAnswer();  // an answer does not forgive a second loss
  const LaneRetryPolicy::Decision d = policy.OnFailure(NotFoundError("evicted"));
  EXPECT_EQ(d.action, Action::kRetire);
  EXPECT_EQ(d.retire_reason, "it lost the scene twice: NOT_FOUND: evicted");
}

TEST(LaneRetryPolicy, APeerThatRefusesIsLeftOutAtOnce) {
  for (const Status& s : {UnauthenticatedError("token"), PermissionDeniedError("denied"), InvalidArgumentError("bad"),
                          FailedPreconditionError("voxels"), UnimplementedError("old")}) {
    LaneRetryPolicy policy;
    const LaneRetryPolicy::Decision d = policy.OnFailure(s);
    EXPECT_EQ(d.action, Action::kRetire) << s.ToString();
    EXPECT_EQ(d.retire_reason, s.ToString());
  }
}

}  // namespace
}  // namespace vc::server
