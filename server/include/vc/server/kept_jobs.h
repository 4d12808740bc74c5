// Detachable jobs (docs/PROTOCOL.md, "Detachable jobs"): a job that outlives its stream.
//
// A JobChannel stands between a job's producer (the worker) and the call that follows it (an
// Outbox, the "sink"). For a job with a detach grace it also keeps every event (Accepted, the bulk
// events, the latest progress, the final status), so a client that lost its stream can re-attach
// and receive them again, then follow the job live. Without a grace it only forwards, as a plain
// call did: a broken sink makes Post return false and the job is cancelled with its call.
//
// KeptJobs is the registry of a service's detachable jobs, by id: a sweeper thread cancels a
// running job whose client stayed away longer than its grace, and forgets a finished job once its
// status reached a client, or its result ttl after it ended without one. The events kept by all
// jobs together are bounded by a byte budget: a job that would exceed it stops keeping (a later
// attach is refused with RESOURCE_EXHAUSTED; a client still attached is not affected).
//
// Plain C++ over protobuf messages (Response needs ByteSizeLong and copying), so its test runs
// under ThreadSanitizer. Thread-safe.
#pragma once

#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/server/outbox.h"

namespace vc::server {

// Bytes of events kept by all detachable jobs together.
class KeptBudget {
 public:
  explicit KeptBudget(uint64_t capacity_bytes) : capacity_bytes_(capacity_bytes) {}
  // Adds `bytes` unless that would pass the capacity; false then (nothing added).
  bool TryAdd(uint64_t bytes) {
    uint64_t used = used_.load();
    do {
      if (used + bytes > capacity_bytes_) return false;
    } while (!used_.compare_exchange_weak(used, used + bytes));
    return true;
  }
  void Release(uint64_t bytes) { used_.fetch_sub(bytes); }
  uint64_t used_bytes() const { return used_.load(); }
  uint64_t capacity_bytes() const { return capacity_bytes_; }

 private:
  const uint64_t capacity_bytes_;
  std::atomic<uint64_t> used_{0};
};

// What the registry sees of a job, whatever its RPC.
class KeptJob {
 public:
  using Clock = std::chrono::steady_clock;
  KeptJob(std::string method, KeptBudget* budget) : method_(std::move(method)), budget_(budget) {}
  virtual ~KeptJob() { budget_->Release(kept_bytes_); }
  KeptJob(const KeptJob&) = delete;
  KeptJob& operator=(const KeptJob&) = delete;

  const std::string& method() const { return method_; }
  // The bearer token the job was submitted with ("" without tokens): only it may attach or cancel.
  // Set once, before the job is submitted (and so before any other thread reads it).
  const std::string& owner() const { return owner_; }
  void set_owner(std::string owner) { owner_ = std::move(owner); }
  // How long the job runs on without a client; 0 = it ends with its stream (nothing is kept).
  // Set before the job is submitted.
  std::chrono::milliseconds grace() const { return std::chrono::milliseconds(grace_ms_.load()); }
  void set_grace(std::chrono::milliseconds grace) { grace_ms_.store(grace.count()); }
  bool detachable() const { return grace_ms_.load() > 0; }
  // The job's cancellation (the core polls it); shared by every call that follows the job.
  CancelToken& token() { return token_; }
  const CancelToken& token() const { return token_; }

  // Cancels the job; its final status becomes CANCELLED with `reason` (when it ends by it).
  void Cancel(std::string reason) {
    {
      std::lock_guard lock(mu_);
      if (!cancel_reason_) cancel_reason_ = std::move(reason);
    }
    token_.Cancel();
  }
  // A call ended with `status` on a stream that did not break: if that is the job's final status,
  // it reached a client and the job may be forgotten (true then).
  bool Delivered(const Status& status) {
    std::lock_guard lock(mu_);
    if (!final_ || !(*final_ == status)) return false;
    delivered_ = true;
    return true;
  }
  // The sweeper: cancels the job with `reason` if it is still running without a client `grace`
  // after it lost its last one (checked and done under the lock, so an attach cannot slip in
  // between). True if it did.
  bool CancelIfAbandoned(Clock::time_point now, const std::string& reason) {
    {
      std::lock_guard lock(mu_);
      if (final_ || sink_attached_ || !detachable() || now - since_ < grace() || token_.cancelled()) return false;
      if (!cancel_reason_) cancel_reason_ = reason;
    }
    token_.Cancel();
    return true;
  }

  struct State {
    bool attached = false;
    bool done = false;
    bool delivered = false;
    Clock::time_point since;  // running: detached at; done: ended at
  };
  State state() const {
    std::lock_guard lock(mu_);
    return {sink_attached_, final_.has_value(), delivered_, since_};
  }

 protected:
  // Keeps `bytes` more of events; false (and drops what was kept) when the budget is spent.
  bool KeepLocked(uint64_t bytes) {
    if (dropped_) return false;
    if (budget_->TryAdd(bytes)) {
      kept_bytes_ += bytes;
      return true;
    }
    dropped_ = true;
    budget_->Release(kept_bytes_);
    kept_bytes_ = 0;
    return false;
  }
  Status FinalStatusLocked(const Status& s) const {
    if (s.code() == StatusCode::kCancelled && cancel_reason_) return CancelledError(*cancel_reason_);
    return s;
  }

  const std::string method_;
  std::string owner_;
  std::atomic<int64_t> grace_ms_{0};
  KeptBudget* const budget_;
  CancelToken token_;

  mutable std::mutex mu_;
  bool sink_attached_ = false;
  bool delivered_ = false;
  bool dropped_ = false;
  Clock::time_point since_ = Clock::now();
  uint64_t kept_bytes_ = 0;
  std::optional<Status> final_;
  std::optional<std::string> cancel_reason_;
};

template <class Response>
class JobChannel final : public KeptJob {
 public:
  using Sink = std::shared_ptr<Outbox<Response>>;
  using KeptJob::KeptJob;

  // The submitting call's outbox: the first sink.
  void SetSink(Sink sink) {
    std::lock_guard lock(mu_);
    sink_ = std::move(sink);
    sink_attached_ = true;
  }

  // Forwards (and keeps) an event; a bulk one waits while the sink's queue is full. False when the
  // job should stop producing: it is cancelled, or (without a grace) its call is gone.
  bool Post(Response&& message, bool bulk = false) {
    Sink sink;
    {
      std::lock_guard lock(mu_);
      if (detachable() && KeepLocked(message.ByteSizeLong())) log_.push_back(message);
      if (dropped_) log_.clear();
      sink = sink_;
    }
    if (sink && !sink->Post(detachable() ? Response(message) : std::move(message), bulk)) {
      if (!detachable()) return false;
      // A sink refuses when its stream broke, or when the job was cancelled (its outbox watches
      // the job's token to wake a producer waiting on a slow client): only the first detaches, so
      // that a cancelled job's status still reaches the client that follows it.
      if (!token_.cancelled()) Detach(sink.get());
    }
    return !token_.cancelled();
  }

  // Forwards (and keeps, replacing the last) a progress event; never waits.
  void PostProgress(Response&& message) {
    Sink sink;
    {
      std::lock_guard lock(mu_);
      if (detachable()) progress_ = message;
      sink = sink_;
    }
    if (sink) sink->PostProgress(detachable() ? Response(message) : std::move(message));
  }

  // The job ended with `status` (the worker's last touch of the channel).
  void Complete(const Status& status) {
    Sink sink;
    Status final;
    {
      std::lock_guard lock(mu_);
      final_ = FinalStatusLocked(status);
      final = *final_;
      since_ = Clock::now();
      progress_.reset();
      sink = sink_;
    }
    if (sink) sink->Complete(final);
  }

  // A client re-attaches: everything kept is replayed into `sink`, then it follows the job (or
  // gets its final status at once). A client still attached is ended with ABORTED.
  Status Attach(const std::string& job_id, const Sink& sink) {
    Sink previous;
    {
      std::lock_guard lock(mu_);
      if (dropped_) {
        return ResourceExhaustedError("job " + job_id +
                                      " produced more than this server keeps for detached jobs "
                                      "(--kept-results-bytes); its events are gone: run it again and stay attached");
      }
      for (const Response& e : log_) sink->Post(Response(e));
      if (progress_) sink->PostProgress(Response(*progress_));
      if (final_) {
        sink->Complete(*final_);
        return Status::Ok();
      }
      previous = std::exchange(sink_, sink);
      sink_attached_ = true;
    }
    if (previous) {
      previous->Break();
      previous->Complete(AbortedError("another client attached to job " + job_id + "; this stream ends"));
    }
    return Status::Ok();
  }

  // `sink`'s stream broke (or its call ended): the job runs on without it.
  void Detach(const Outbox<Response>* sink) {
    std::lock_guard lock(mu_);
    if (sink_.get() != sink) return;
    sink_.reset();
    sink_attached_ = false;
    if (!final_) since_ = Clock::now();
  }

 private:
  std::vector<Response> log_;
  std::optional<Response> progress_;
  Sink sink_;
};

// The registry of a service's detachable jobs.
class KeptJobs {
 public:
  using Clock = KeptJob::Clock;
  // `ttl`: how long a result that reached no client is kept. Starts the sweeper, which runs every
  // `sweep_every`.
  KeptJobs(std::chrono::milliseconds ttl, uint64_t budget_bytes,
           std::chrono::milliseconds sweep_every = std::chrono::milliseconds(250));
  ~KeptJobs();
  KeptJobs(const KeptJobs&) = delete;
  KeptJobs& operator=(const KeptJobs&) = delete;

  KeptBudget* budget() { return &budget_; }
  std::chrono::milliseconds ttl() const { return ttl_; }

  void Add(const std::string& id, std::shared_ptr<KeptJob> job);
  // The job, or NOT_FOUND (unknown, expired, or never detachable) / PERMISSION_DENIED (`owner`
  // is not the job's).
  Result<std::shared_ptr<KeptJob>> Find(const std::string& id, const std::string& owner) const;
  void Erase(const std::string& id);
  size_t size() const;
  // One pass of the sweeper at `now` (also called by tests).
  void Sweep(Clock::time_point now);

 private:
  const std::chrono::milliseconds ttl_;
  const std::chrono::milliseconds sweep_every_;
  KeptBudget budget_;
  mutable std::mutex mu_;
  std::condition_variable stop_cv_;
  bool stop_ = false;
  std::map<std::string, std::shared_ptr<KeptJob>> jobs_;
  std::thread sweeper_;
};

}  // namespace vc::server
