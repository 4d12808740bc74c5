// Internal to vc_core: large arrays that the kernel may back with transparent huge pages.
//
// A plan fills a few arrays of tens to hundreds of MB once each (the reduction's per-station
// face values, the evaluation's per-face best values, the top-3 table). Filling fresh memory
// costs a page fault per 4 KiB page, and on a virtual machine a fault costs microseconds: on the
// hall, zeroing 15 stations' face values (152 MB) took 0.42 s, and 0.10-0.28 s with huge pages
// (docs/BENCHMARKS.md, "Plan at `0543dbd`"). Debian's default THP mode is "madvise", which
// backs only the ranges a program asks for. The advice changes no value; where the kernel
// refuses it (no THP, another OS), nothing changes at all.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace vc::internal {

// Asks for huge pages on the whole 2 MiB pages inside [p, p + bytes). Advice only.
inline void AdviseHugePages(const void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  if (bytes < kHuge) return;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p, (void)bytes;
#endif
}

// Makes v hold room for n elements (allocating here, so that running out of memory happens in
// the calling thread) without touching that memory, advised onto huge pages. v must be empty;
// a later resize(n) fills it, in whichever thread does it, with no further allocation.
template <typename T>
void ReserveOnHugePages(std::vector<T>& v, size_t n) {
  v.reserve(n);
  AdviseHugePages(v.data(), n * sizeof(T));
}

// A vector of n copies of `value`, allocated as ReserveOnHugePages does.
template <typename T>
std::vector<T> FilledOnHugePages(size_t n, const T& value) {
  std::vector<T> v;
  ReserveOnHugePages(v, n);
  v.resize(n, value);
  return v;
}

}  // namespace vc::internal
