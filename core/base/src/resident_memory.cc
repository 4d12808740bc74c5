#include "vc/base/resident_memory.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace vc {
namespace {

// The value of a "Name:   1234 kB" line of /proc/self/status, in bytes; 0 if absent or unreadable.
uint64_t StatusKilobytesAsBytes(const char* name) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return 0;
  const size_t name_length = std::strlen(name);
  char line[256];
  unsigned long long kilobytes = 0;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    if (std::strncmp(line, name, name_length) == 0 && line[name_length] == ':') {
      if (std::sscanf(line + name_length + 1, "%llu", &kilobytes) != 1) kilobytes = 0;
      break;
    }
  }
  std::fclose(f);
  return uint64_t{kilobytes} * 1024;
}

}  // namespace

uint64_t CurrentResidentBytes() { return StatusKilobytesAsBytes("VmRSS"); }

uint64_t PeakResidentBytes() { return StatusKilobytesAsBytes("VmHWM"); }

ResidentPeakMeter::ResidentPeakMeter(std::chrono::milliseconds interval)
    : peak_before_(PeakResidentBytes()), interval_(interval), sampled_(CurrentResidentBytes()) {
  sampler_ = std::thread([this] {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, interval_, [this] { return stop_; })) {
      const uint64_t now = CurrentResidentBytes();
      if (now > sampled_.load(std::memory_order_relaxed)) sampled_.store(now, std::memory_order_relaxed);
    }
  });
}

ResidentPeakMeter::~ResidentPeakMeter() { (void)Stop(); }

uint64_t ResidentPeakMeter::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return result_;
    stop_ = true;
  }
  wake_.notify_all();
  sampler_.join();
  const uint64_t peak_after = PeakResidentBytes();
  const uint64_t sampled = std::max(sampled_.load(std::memory_order_relaxed), CurrentResidentBytes());
  std::lock_guard<std::mutex> lock(mutex_);
  stopped_ = true;
  result_ = peak_after > peak_before_ ? peak_after : std::min(sampled, peak_after == 0 ? sampled : peak_after);
  return result_;
}

}  // namespace vc
