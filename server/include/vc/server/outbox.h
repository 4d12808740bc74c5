// Outbox: the queue of a call's responses between the threads that produce them and the one
// write in flight on the stream.
//
// gRPC's callback API allows one outstanding write per call, so responses wait here: the first
// Post starts a write (through the `start_write` callback), each OnWriteDone starts the next.
// Flow control: a bulk Post (result chunks) waits while more than `max_bytes` are queued, so a
// slow client does not make the server buffer a whole result. Progress events coalesce: one still
// waiting is replaced by the newer one. The call ends once: Complete(status) finishes it (through
// `finish`) when the queue is written; an error status drops what has not started writing. A
// failed write or Break (the call was cancelled) drops everything and makes Post return false, so
// producers stop.
//
// Independent of gRPC (the adapter passes callbacks that call StartWrite and Finish) so its test
// runs under ThreadSanitizer. Message needs ByteSizeLong() (any protobuf message). Thread-safe:
// Post, PostProgress, Complete and Break from any thread; OnWriteDone from the stream's
// completion. The callbacks run outside the lock; `start_write` gets a pointer that stays valid
// until the matching OnWriteDone.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <utility>

#include "vc/base/progress.h"
#include "vc/base/status.h"

namespace vc::server {

// Queued bytes above which a bulk Post waits for the network.
inline constexpr size_t kMaxOutboxBytes = size_t{8} << 20;

template <class Message>
class Outbox {
 public:
  using StartWriteFn = std::function<void(const Message*)>;
  using FinishFn = std::function<void(const Status&)>;

  // `cancel` (the job's token) also stops waiting producers; it must outlive the outbox.
  Outbox(StartWriteFn start_write, FinishFn finish, const CancelToken* cancel, size_t max_bytes = kMaxOutboxBytes)
      : start_write_(std::move(start_write)), finish_(std::move(finish)), cancel_(cancel), max_bytes_(max_bytes) {}
  Outbox(const Outbox&) = delete;
  Outbox& operator=(const Outbox&) = delete;

  // Queues `message`. A bulk message first waits while over max_bytes. False when the call is
  // broken or cancelled (the message is dropped; stop producing).
  bool Post(Message&& message, bool bulk = false) { return Push(std::move(message), bulk, /*progress=*/false); }

  // Queues a progress event, replacing one still waiting (cheap; never waits).
  void PostProgress(Message&& message) {
    {
      std::lock_guard lock(mu_);
      if (queue_.size() >= 2 && queue_.back().progress) {  // the front is being written
        bytes_ -= queue_.back().bytes;
        queue_.back() = Entry(std::move(message), true);
        bytes_ += queue_.back().bytes;
        return;
      }
    }
    Push(std::move(message), /*bulk=*/false, /*progress=*/true);
  }

  // The write started by `start_write` completed; `ok` false when the stream broke.
  void OnWriteDone(bool ok) {
    std::optional<Status> finish;
    const Message* next = nullptr;
    {
      std::lock_guard lock(mu_);
      bytes_ -= queue_.front().bytes;
      queue_.pop_front();
      if (!ok) {
        broken_ = true;  // the client is gone; the call's cancellation follows
        queue_.clear();
        bytes_ = 0;
      }
      if (!queue_.empty()) {
        next = &queue_.front().message;
      } else {
        writing_ = false;
        if (final_ && !finished_) {
          finished_ = true;
          finish = final_;
        }
      }
    }
    drained_.notify_all();
    if (next != nullptr) {
      start_write_(next);
    } else if (finish) {
      finish_(*finish);
    }
  }

  // Ends the call with `status` once the queue is written (at once when idle). Only the first call
  // counts. An error replaces whatever has not started writing.
  void Complete(const Status& status) {
    bool finish_now = false;
    {
      std::lock_guard lock(mu_);
      if (final_) return;
      final_ = status;
      if (!status.ok()) {
        while (queue_.size() > (writing_ ? 1u : 0u)) {
          bytes_ -= queue_.back().bytes;
          queue_.pop_back();
        }
      }
      if (!writing_) {
        finished_ = true;
        finish_now = true;
      }
    }
    if (finish_now) finish_(status);
  }

  // The call is cancelled or gone: later Posts return false and waiting ones wake.
  void Break() {
    {
      std::lock_guard lock(mu_);
      broken_ = true;
    }
    drained_.notify_all();
  }

  // Bytes queued (including the write in flight).
  size_t queued_bytes() const {
    std::lock_guard lock(mu_);
    return bytes_;
  }

 private:
  struct Entry {
    Entry(Message&& m, bool p) : message(std::move(m)), bytes(message.ByteSizeLong()), progress(p) {}
    Message message;
    size_t bytes;
    bool progress;
  };

  bool Push(Message&& message, bool bulk, bool progress) {
    const Message* start = nullptr;
    {
      std::unique_lock lock(mu_);
      while (bulk && !broken_ && bytes_ >= max_bytes_ && !cancel_->cancelled()) {
        drained_.wait_for(lock, std::chrono::milliseconds(100));  // the token has no wake-up of its own
      }
      if (broken_ || cancel_->cancelled()) return false;
      queue_.emplace_back(std::move(message), progress);
      bytes_ += queue_.back().bytes;
      if (!writing_) {
        writing_ = true;
        start = &queue_.front().message;
      }
    }
    if (start != nullptr) start_write_(start);
    return true;
  }

  const StartWriteFn start_write_;
  const FinishFn finish_;
  const CancelToken* const cancel_;
  const size_t max_bytes_;

  mutable std::mutex mu_;
  std::condition_variable drained_;
  std::deque<Entry> queue_;
  size_t bytes_ = 0;
  bool writing_ = false;
  bool broken_ = false;
  bool finished_ = false;
  std::optional<Status> final_;
};

}  // namespace vc::server
