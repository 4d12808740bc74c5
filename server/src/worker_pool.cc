#include "vc/server/worker_pool.h"

#include <algorithm>

namespace vc::server {

void WorkerPool::Ticket::Reset() {
  if (pool_ != nullptr) pool_->Release(running_);
  pool_ = nullptr;
}

WorkerPool::WorkerPool(int workers, int queue_capacity) : queue_capacity_(std::max(0, queue_capacity)) {
  workers = std::max(1, workers);
  threads_.reserve(size_t(workers));
  for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { WorkerLoop(); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  for (auto& t : threads_) t.join();
}

std::optional<WorkerPool::Ticket> WorkerPool::TryAdmit() {
  std::lock_guard lock(mu_);
  if (stopping_ || admitted_ >= int(threads_.size()) + queue_capacity_) return std::nullopt;
  ++admitted_;
  return Ticket(this, /*running=*/false);
}

void WorkerPool::Submit(Ticket ticket, const std::function<void(uint32_t)>& on_queued, Task task) {
  ticket.pool_ = nullptr;  // the place passes to the task, as a running ticket, when a worker starts it
  std::lock_guard lock(mu_);
  // Idle workers take the first `idle` queued tasks; the new task is at index queue_.size().
  const int idle = int(threads_.size()) - running_;
  const int index = int(queue_.size());
  on_queued(index < idle ? 0u : uint32_t(index - idle + 1));
  queue_.push_back(std::move(task));
  cv_.notify_one();
}

int WorkerPool::admitted() const {
  std::lock_guard lock(mu_);
  return admitted_;
}

int WorkerPool::running() const {
  std::lock_guard lock(mu_);
  return running_;
}

void WorkerPool::Release(bool running) {
  std::lock_guard lock(mu_);
  --admitted_;
  if (running) --running_;
}

void WorkerPool::WorkerLoop() {
  std::unique_lock lock(mu_);
  for (;;) {
    cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping and drained
    auto task = std::move(queue_.front());
    queue_.pop_front();
    ++running_;
    lock.unlock();
    task(Ticket(this, /*running=*/true));  // the task's ticket gives the place back, at the latest on return
    lock.lock();
  }
}

}  // namespace vc::server
