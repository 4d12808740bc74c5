#include "vc/server/kept_jobs.h"

#include <fmt/format.h>

namespace vc::server {

KeptJobs::KeptJobs(std::chrono::milliseconds ttl, uint64_t budget_bytes, std::chrono::milliseconds sweep_every)
    : ttl_(ttl), sweep_every_(sweep_every), budget_(budget_bytes) {
  sweeper_ = std::thread([this] {
    std::unique_lock lock(mu_);
    while (!stop_cv_.wait_for(lock, sweep_every_, [&] { return stop_; })) {
      lock.unlock();
      Sweep(Clock::now());
      lock.lock();
    }
  });
}

KeptJobs::~KeptJobs() {
  {
    std::lock_guard lock(mu_);
    stop_ = true;
  }
  stop_cv_.notify_all();
  sweeper_.join();
}

void KeptJobs::Add(const std::string& id, std::shared_ptr<KeptJob> job) {
  std::lock_guard lock(mu_);
  jobs_[id] = std::move(job);
}

Result<std::shared_ptr<KeptJob>> KeptJobs::Find(const std::string& id, const std::string& owner) const {
  std::shared_ptr<KeptJob> job;
  {
    std::lock_guard lock(mu_);
    if (const auto it = jobs_.find(id); it != jobs_.end()) job = it->second;
  }
  if (!job) {
    return NotFoundError(fmt::format(
        "no detachable job {} on this server: it was submitted without a detach grace, its result was "
        "delivered or expired (--result-ttl-seconds {}), or this replica restarted; check the job id and the "
        "address (Accepted.attach_address), or submit again",
        id, std::chrono::duration_cast<std::chrono::seconds>(ttl_).count()));
  }
  if (job->owner() != owner) {
    return PermissionDeniedError("job " + id +
                                 " was submitted with another token; only that token may attach or cancel");
  }
  return job;
}

void KeptJobs::Erase(const std::string& id) {
  std::lock_guard lock(mu_);
  jobs_.erase(id);
}

size_t KeptJobs::size() const {
  std::lock_guard lock(mu_);
  return jobs_.size();
}

void KeptJobs::Sweep(Clock::time_point now) {
  std::vector<std::pair<std::string, std::shared_ptr<KeptJob>>> jobs;
  {
    std::lock_guard lock(mu_);
    jobs.assign(jobs_.begin(), jobs_.end());
  }
  std::vector<std::string> forget;
  for (const auto& [id, job] : jobs) {
    const KeptJob::State s = job->state();
    if (s.done && s.delivered) {
      forget.push_back(id);
    } else if (s.done && !s.attached && now - s.since >= ttl_) {
      spdlog::info("job {} result expired: no client attached within {} s of its end", id,
                   std::chrono::duration_cast<std::chrono::seconds>(ttl_).count());
      forget.push_back(id);
    } else if (!s.done && !s.attached) {
      const auto grace_s = std::chrono::duration<double>(job->grace()).count();
      if (job->CancelIfAbandoned(
              now, fmt::format("job {} was cancelled: no client re-attached within its {:.0f} s detach grace", id,
                               grace_s))) {
        spdlog::info("job {}: no client re-attached within its {:.0f} s detach grace; cancelled it", id, grace_s);
      }
    }
  }
  if (forget.empty()) return;
  std::lock_guard lock(mu_);
  for (const std::string& id : forget) jobs_.erase(id);
}

}  // namespace vc::server
