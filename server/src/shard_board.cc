#include "vc/server/shard_board.h"

#include <fmt/format.h>

#include <algorithm>

namespace vc::server {

ShardBoard::ShardBoard(size_t viewpoints, size_t per_shard, NowFn now, Clock::duration poll_interval)
    : now_(std::move(now)), poll_interval_(poll_interval) {
  for (size_t b = 0; b < viewpoints; b += per_shard) {
    Shard s;
    s.begin = b;
    s.end = std::min(viewpoints, b + per_shard);
    shards_.push_back(s);
  }
}

std::optional<ShardBoard::Attempt> ShardBoard::TryTake(bool defer) {
  std::lock_guard lock(mu_);
  return TryTakeLocked(defer);
}

std::optional<ShardBoard::Attempt> ShardBoard::Take(Clock::duration wait, bool defer) {
  std::unique_lock lock(mu_);
  const Clock::time_point until = now_() + wait;
  while (true) {
    if (std::optional<Attempt> a = TryTakeLocked(defer)) return a;
    const Clock::time_point now = now_();
    if (FinishedLocked() || now >= until) return std::nullopt;
    // Nothing now; a shard may come back, or one that runs turn slow, before long. The slice is
    // real time, bounded so that a deadline on an injected clock is seen within one slice.
    cv_.wait_for(lock, std::min<Clock::duration>(until - now, poll_interval_));
  }
}

std::optional<ShardBoard::Attempt> ShardBoard::TryTakeLocked(bool defer) {
  if (FinishedLocked()) return std::nullopt;
  const Clock::time_point now = now_();
  // Deferring ends when no peer lane is left or one of them has stalled on a shard.
  if (defer && lanes_ > 0 && !Stalled(now)) return std::nullopt;
  const std::optional<size_t> k = Pick(now);
  if (!k) return std::nullopt;
  Shard& s = shards_[*k];
  if (s.running > 0) ++s.restarts;
  ++s.running;
  ++s.attempts;
  s.started = now;
  return Attempt{*k, s.begin, s.end, now};
}

bool ShardBoard::Deliver(const Attempt& attempt, const std::string& who) {
  std::lock_guard lock(mu_);
  Shard& s = shards_[attempt.shard];
  --s.running;
  if (s.done) return false;
  s.done = true;
  ++done_;
  contributors_.insert(who);
  finished_time_ += now_() - attempt.started;
  cv_.notify_all();
  return true;
}

void ShardBoard::Release(const Attempt& attempt) {
  std::lock_guard lock(mu_);
  --shards_[attempt.shard].running;
  cv_.notify_all();
}

void ShardBoard::LaneStarted() {
  std::lock_guard lock(mu_);
  ++lanes_;
}

void ShardBoard::LaneEnded() {
  std::lock_guard lock(mu_);
  --lanes_;
  cv_.notify_all();
}

bool ShardBoard::SetLive(size_t lane, CancelFn cancel) {
  std::lock_guard lock(mu_);
  if (cancel && stopped_) return false;
  live_[lane] = std::move(cancel);
  return true;
}

void ShardBoard::Stop() {
  std::lock_guard lock(mu_);
  stopped_ = true;
  for (auto& [lane, cancel] : live_) {
    if (cancel) cancel();
  }
  cv_.notify_all();
}

bool ShardBoard::Finished() const {
  std::lock_guard lock(mu_);
  return FinishedLocked();
}

void ShardBoard::Sleep(Clock::duration d) {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, d, [&] { return FinishedLocked(); });
}

size_t ShardBoard::done() const {
  std::lock_guard lock(mu_);
  return done_;
}

void ShardBoard::Warn(std::string warning) {
  std::lock_guard lock(mu_);
  warnings_.push_back(std::move(warning));
}

void ShardBoard::AddBytes(uint64_t bytes) {
  std::lock_guard lock(mu_);
  bytes_ += bytes;
}

Distribution ShardBoard::distribution() const {
  std::lock_guard lock(mu_);
  Distribution d;
  d.replicas = int(contributors_.size());
  d.shards = int(shards_.size());
  for (const Shard& s : shards_) d.retried += std::max(0, s.attempts - 1);
  d.bytes_exchanged = bytes_;
  return d;
}

std::vector<std::string> ShardBoard::TakeWarnings() {
  std::lock_guard lock(mu_);
  return std::move(warnings_);
}

std::optional<size_t> ShardBoard::Pick(Clock::time_point now) const {
  for (size_t k = 0; k < shards_.size(); ++k) {
    if (!shards_[k].done && shards_[k].running == 0) return k;
  }
  return Slowest(now);
}

bool ShardBoard::Stalled(Clock::time_point now) const {
  const std::chrono::duration<double> slow = SlowAfter();
  for (const Shard& s : shards_) {
    if (!s.done && s.running > 0 && now - s.started >= slow) return true;
  }
  return false;
}

std::chrono::duration<double> ShardBoard::SlowAfter() const {
  if (done_ == 0) return kSlowShardBeforeAnyFinished;
  return std::max<std::chrono::duration<double>>(kSlowShardFloor, kSlowShardFactor * finished_time_ / double(done_));
}

std::optional<size_t> ShardBoard::Slowest(Clock::time_point now) const {
  const std::chrono::duration<double> slow = SlowAfter();
  std::optional<size_t> best;
  for (size_t k = 0; k < shards_.size(); ++k) {
    const Shard& s = shards_[k];
    if (s.done || s.running != 1 || s.restarts >= kMaxRestartsPerShard) continue;
    if (now - s.started < slow) continue;
    if (!best || s.started < shards_[*best].started) best = k;
  }
  return best;
}

LaneRetryPolicy::Decision LaneRetryPolicy::OnFailure(const Status& status) {
  switch (status.code()) {
    case StatusCode::kNotFound:  // the scene was evicted from the peer's cache: share it once more
      if (shared_again_) return {Action::kRetire, "it lost the scene twice: " + status.ToString()};
      shared_again_ = true;
      return {Action::kShareSceneAgain, {}};
    case StatusCode::kResourceExhausted:  // busy: the others take the shard meanwhile
      if (++busy_ >= kMaxBusyAnswers) {
        return {Action::kRetire, status.ToString() + fmt::format(" ({} times in a row)", busy_)};
      }
      return {Action::kBackOff, {}};
    case StatusCode::kUnauthenticated:
    case StatusCode::kPermissionDenied:
    case StatusCode::kInvalidArgument:
    case StatusCode::kFailedPrecondition:
    case StatusCode::kUnimplemented:
      return {Action::kRetire, status.ToString()};
    default:
      if (++failures_ >= kMaxLaneFailures) return {Action::kRetire, status.ToString()};
      return {Action::kRetry, {}};
  }
}

void LaneRetryPolicy::OnAnswer() { failures_ = busy_ = 0; }

}  // namespace vc::server
