// WorkerPool: the bounded pool that runs every job's CPU work, so none runs on gRPC's threads.
//
// Admission is separate from submission: a call reserves a place (TryAdmit) as soon as its spec
// arrives, so a busy server refuses it before the client uploads anything, and submits the work
// once the upload is verified. At most `workers + queue_capacity` jobs are admitted at a time
// (running, queued or still uploading). Thread-safe.
//
// A running task holds its place as a Ticket and should drop it (Ticket::Release) before it
// tells its client the job is over: a client that retries the moment it hears the final status
// must find the place free, not be refused by a job that has already answered.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace vc::server {

class WorkerPool {
 public:
  // A reserved place; releases it on destruction unless handed to Submit.
  class Ticket {
   public:
    Ticket(Ticket&& other) noexcept : pool_(other.pool_), running_(other.running_) { other.pool_ = nullptr; }
    Ticket& operator=(Ticket&& other) noexcept {
      if (this != &other) {
        Reset();
        pool_ = other.pool_;
        running_ = other.running_;
        other.pool_ = nullptr;
      }
      return *this;
    }
    ~Ticket() { Reset(); }
    // Gives the place back now (idempotent); the destructor does it otherwise.
    void Release() { Reset(); }

   private:
    void Reset();
    friend class WorkerPool;
    Ticket(WorkerPool* pool, bool running) : pool_(pool), running_(running) {}
    WorkerPool* pool_;
    bool running_ = false;  // the place of a task a worker is running
  };

  WorkerPool(int workers, int queue_capacity);
  // Runs every submitted task (tasks must notice cancellation themselves), then joins.
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // A place for one job, or nullopt when workers + queue are all taken.
  std::optional<Ticket> TryAdmit();
  // Queues `task`; calls on_queued(position) before any worker can start it: 0 when a worker is
  // free to start it now, n when it is n-th in line. The worker hands the task its place; the
  // place is free once the task releases the ticket or returns.
  using Task = std::function<void(Ticket place)>;
  void Submit(Ticket ticket, const std::function<void(uint32_t queue_position)>& on_queued, Task task);

  int workers() const { return int(threads_.size()); }
  int queue_capacity() const { return queue_capacity_; }
  // Jobs admitted and not yet finished (uploading, queued or running).
  int admitted() const;
  // Jobs a worker is running now.
  int running() const;

 private:
  void Release(bool running);
  void WorkerLoop();

  const int queue_capacity_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Task> queue_;
  int admitted_ = 0;
  int running_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace vc::server
