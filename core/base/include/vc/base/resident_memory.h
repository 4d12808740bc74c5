// The process's resident memory, as Linux reports it in /proc/self/status, and its peak over a
// span of time (one stage of a plan).
//
// The figures are process-wide: they count everything the process holds (the server's scene
// cache, other jobs running at the same time). They are what the kernel counts as resident (VmRSS,
// VmHWM), not what was allocated: pages never touched are not counted, and freed memory the
// allocator keeps still is. The process's own peak (VmHWM) is never reset here, so tools that read
// it from outside (scripts/load/job-memory.sh) keep seeing the lifetime peak.
// Thread-safe (each call opens its own file); one ResidentPeakMeter per span.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace vc {

// The resident memory now (VmRSS), in bytes; 0 where /proc/self/status cannot be read.
[[nodiscard]] uint64_t CurrentResidentBytes();

// The process's peak resident memory since it started (VmHWM), in bytes; 0 where
// /proc/self/status cannot be read.
[[nodiscard]] uint64_t PeakResidentBytes();

// The peak resident memory of the process over the meter's life. Exact when the span raised the
// process's peak (VmHWM at Stop above VmHWM at construction: the new peak is the span's); otherwise
// the largest VmRSS sampled every `interval` by a thread of its own, a lower bound that misses
// spikes shorter than the interval. 0 where /proc cannot be read.
class ResidentPeakMeter {
 public:
  // Starts measuring (and the sampling thread).
  explicit ResidentPeakMeter(std::chrono::milliseconds interval = std::chrono::milliseconds(10));
  ~ResidentPeakMeter();
  ResidentPeakMeter(const ResidentPeakMeter&) = delete;
  ResidentPeakMeter& operator=(const ResidentPeakMeter&) = delete;
  // Stops the sampling thread; the span's peak in bytes. Later calls return the same.
  uint64_t Stop();

 private:
  const uint64_t peak_before_;
  const std::chrono::milliseconds interval_;
  std::atomic<uint64_t> sampled_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool stopped_ = false;
  uint64_t result_ = 0;
  std::thread sampler_;
};

}  // namespace vc
