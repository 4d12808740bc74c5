// A minimal fork-join loop for the bulk passes of the visibility and planning layers. Work is cut
// into fixed-size chunks so that per-chunk partial sums, combined in chunk order, are identical for
// any thread count. Internal to vc_core.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

#include "vc/base/progress.h"
#include "vc/base/status.h"

namespace vc {

// Worker threads for `requested` (0 = hardware concurrency), at least 1 and at most `chunks`.
inline int ResolveThreads(int requested, uint64_t chunks) {
  int t = requested > 0 ? requested : static_cast<int>(std::thread::hardware_concurrency());
  t = std::max(t, 1);
  return static_cast<int>(std::min<uint64_t>(static_cast<uint64_t>(t), std::max<uint64_t>(chunks, 1)));
}

// Calls fn(chunk, begin, end) for every chunk of [0, n) of `chunk_size` items, on `threads`
// workers. Stops early and returns the token's status, naming `what`, when ctx is cancelled
// (checked per chunk).
inline Status ParallelChunks(uint64_t n, uint64_t chunk_size, int threads, const JobContext& ctx,
                             const std::function<void(uint64_t chunk, uint64_t begin, uint64_t end)>& fn,
                             const char* what = "the computation") {
  const uint64_t chunks = (n + chunk_size - 1) / chunk_size;
  const int workers = ResolveThreads(threads, chunks);
  std::atomic<uint64_t> next{0};
  std::atomic<bool> stop{false};
  auto work = [&] {
    while (!stop.load(std::memory_order_relaxed)) {
      const uint64_t c = next.fetch_add(1);
      if (c >= chunks) return;
      if (!ctx.CheckCancelled(what).ok()) {
        stop.store(true);
        return;
      }
      fn(c, c * chunk_size, std::min(n, (c + 1) * chunk_size));
    }
  };
  if (workers <= 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(workers - 1);
    for (int i = 0; i + 1 < workers; ++i) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
  }
  return ctx.CheckCancelled(what);
}

}  // namespace vc
