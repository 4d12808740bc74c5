// ShardBoard: the shards of one fanned-out stage and the rules by which lanes take them; and
// LaneRetryPolicy: what a peer's lane does after a failed call (docs/DEPLOY.md, "Scaling out").
//
// A stage's viewpoints are cut into shards of a fixed size. Every lane (one per peer, and the
// coordinator's own) takes the first shard nobody runs. When none is left, an idle lane starts
// again the longest-running slow shard: one running kSlowShardFactor times longer than the mean
// finished shard (at least kSlowShardFloor; kSlowShardBeforeAnyFinished while none has finished),
// at most kMaxRestartsPerShard times. The first answer of a shard wins. A lane that defers (the
// coordinator's, with --local-shards=false) takes a fresh shard only once no peer lane is left or
// one of them has stalled.
//
// Kept apart from peers.cc's gRPC lanes so the rules are tested alone: the clock is injected (a
// fake one in tests) and each lane's call in flight is a cancel callback (gRPC's TryCancel there).
//
// Waiting: Take's `wait` is measured on the injected clock, while the lane sleeps in real time on a
// condition variable, in slices of at most the poll interval (kShardPollInterval unless a test
// says otherwise). Deliver, Release, LaneEnded and Stop wake every waiting lane at once; at the end
// of each slice Take reads the clock again (a running shard may have turned slow, or the deadline
// passed). So with a fake clock that another thread advances, a waiting Take ends within one slice
// of the deadline; with a frozen one it ends only with an attempt or a finished board. With the
// real clock this is one wait of `wait` that wakes up every poll interval.
//
// Thread-safe: the lanes of a fan-out share one board. The clock and a cancel callback run under
// the board's lock and must not call the board. LaneRetryPolicy is one lane's and not thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "vc/base/status.h"
#include "vc/plan/planner.h"

namespace vc::server {

// A shard running this many times longer than the mean finished shard is slow.
inline constexpr double kSlowShardFactor = 3.0;
// ... but never one running less than this.
inline constexpr std::chrono::seconds kSlowShardFloor{2};
// Before any shard has finished, a shard running this long is slow.
inline constexpr std::chrono::seconds kSlowShardBeforeAnyFinished{30};
// A slow shard is started again at most this many times.
inline constexpr int kMaxRestartsPerShard = 2;
// A lane waiting for a shard looks again this often (a running shard may have turned slow).
inline constexpr std::chrono::milliseconds kShardPollInterval{200};

class ShardBoard {
 public:
  using Clock = std::chrono::steady_clock;
  // The time now (Clock::now, or a test's fake clock).
  using NowFn = std::function<Clock::time_point()>;
  // Cancels a lane's call in flight.
  using CancelFn = std::function<void()>;

  // One attempt of a shard, as Take hands it out: viewpoints [begin, end) of the stage.
  struct Attempt {
    size_t shard = 0;
    size_t begin = 0;
    size_t end = 0;
    Clock::time_point started;
  };

  // Shards of `per_shard` (>= 1) of `viewpoints`, in order; the last may be smaller. A waiting Take
  // looks again every `poll_interval` (> 0) of real time.
  ShardBoard(size_t viewpoints, size_t per_shard, NowFn now = Clock::now,
             Clock::duration poll_interval = kShardPollInterval);

  // Number of shards.
  [[nodiscard]] size_t size() const { return shards_.size(); }

  // The next attempt for a lane, without waiting: the first shard nobody runs, else the
  // longest-running slow one; nullopt when there is none now, every shard is done or the board is
  // stopped. With `defer`, a shard nobody runs is taken only once no peer lane is left or one of
  // them has stalled (a slow shard).
  [[nodiscard]] std::optional<Attempt> TryTake(bool defer = false);
  // TryTake, waiting up to `wait` on the board's clock for an attempt (nullopt then; Finished()
  // tells whether any will come). Returns at once when the board finishes.
  [[nodiscard]] std::optional<Attempt> Take(Clock::duration wait, bool defer = false);
  // The attempt ended with an answer from `who`. True when it is the shard's first answer (the
  // caller keeps its items); false when another attempt answered first.
  bool Deliver(const Attempt& attempt, const std::string& who);
  // The attempt failed; its shard is free for any lane again.
  void Release(const Attempt& attempt);

  // A peer lane started / ended (what deferring waits for).
  void LaneStarted();
  void LaneEnded();

  // While set, `cancel` cancels `lane`'s call in flight when the board stops; an empty one clears
  // it. False (nothing set) when the board has stopped already.
  bool SetLive(size_t lane, CancelFn cancel);
  // Stops the board: Take hands nothing out any more, and every live call is cancelled.
  void Stop();
  // Every shard is done, or the board is stopped.
  [[nodiscard]] bool Finished() const;
  // Waits up to `d` (real time), or until the board is finished (a lane's back-off).
  void Sleep(Clock::duration d);
  // Shards done.
  [[nodiscard]] size_t done() const;

  // A warning for the plan, and bytes exchanged with peers.
  void Warn(std::string warning);
  void AddBytes(uint64_t bytes);

  // Once the lanes have ended: how the shards were spread (replicas that answered, shards, attempts
  // beyond the first, bytes), and the warnings in order.
  [[nodiscard]] Distribution distribution() const;
  [[nodiscard]] std::vector<std::string> TakeWarnings();

 private:
  struct Shard {
    size_t begin = 0, end = 0;
    bool done = false;
    int running = 0;   // attempts in flight
    int attempts = 0;  // attempts started
    int restarts = 0;  // attempts started while another still ran (a slow shard)
    Clock::time_point started;
  };
  // Under mu_.
  std::optional<Attempt> TryTakeLocked(bool defer);
  bool FinishedLocked() const { return stopped_ || done_ == shards_.size(); }
  std::optional<size_t> Pick(Clock::time_point now) const;
  bool Stalled(Clock::time_point now) const;
  std::chrono::duration<double> SlowAfter() const;
  std::optional<size_t> Slowest(Clock::time_point now) const;

  const NowFn now_;
  const Clock::duration poll_interval_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Shard> shards_;
  size_t done_ = 0;
  int lanes_ = 0;
  bool stopped_ = false;
  std::chrono::duration<double> finished_time_{0};  // summed over the shards done
  std::set<std::string> contributors_;
  std::vector<std::string> warnings_;
  uint64_t bytes_ = 0;
  std::map<size_t, CancelFn> live_;
};

// A lane retires after this many failed calls in a row (a peer that is gone fails at once).
inline constexpr int kMaxLaneFailures = 2;
// A peer that answers "busy" (RESOURCE_EXHAUSTED) this many times in a row is left out.
inline constexpr int kMaxBusyAnswers = 20;
// A lane whose peer answered "busy" waits this long before it takes another shard.
inline constexpr std::chrono::milliseconds kBusyBackOff{500};

// What one peer's lane does after a shard call failed, by the failure's code: a peer that lost
// the scene gets it again (once), a busy one is asked again after kBusyBackOff (up to
// kMaxBusyAnswers in a row), one that refuses (token, arguments, voxelization, version) is left
// out at once, and any other failure is retried up to kMaxLaneFailures in a row.
class LaneRetryPolicy {
 public:
  enum class Action {
    kRetry,            // take a shard again now
    kShareSceneAgain,  // send the peer the scene, then take a shard again
    kBackOff,          // wait kBusyBackOff, then take a shard again
    kRetire,           // leave the peer out of the rest of the stage
  };
  struct Decision {
    Action action = Action::kRetry;
    std::string retire_reason;  // with kRetire: why, for the plan's warning
  };

  // After a call failed with `status` (not OK).
  [[nodiscard]] Decision OnFailure(const Status& status);
  // After a shard was answered: the failures and busy answers in a row start again from 0.
  void OnAnswer();

 private:
  int failures_ = 0;
  int busy_ = 0;
  bool shared_again_ = false;
};

}  // namespace vc::server
