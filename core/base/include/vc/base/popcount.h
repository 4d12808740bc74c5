// Internal to vc_core: bit counting over bitsets at the machine's speed.
//
// The build targets the baseline x86-64 instruction set (never -march=native), which has no
// POPCNT, so std::popcount is a call to libgcc's __popcountdi2 per word. Bitset counts (the
// greedy's gains, the sets' sizes) spent most of their time there. VC_POPCOUNT_CLONES makes GCC
// build a POPCNT copy of the function as well and pick one at load time, by the CPU (every
// x86-64 CPU since 2008 has POPCNT): run-time dispatch, as Highway does for the ray kernel.
#pragma once

// Not under ThreadSanitizer: the clones are chosen by an IFUNC resolver that runs while the
// program is being relocated, before the sanitizer's runtime is set up, and the instrumented
// resolver crashes there (visibility_test, built with -fsanitize=thread, segfaulted at start).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(__SANITIZE_THREAD__)
#define VC_POPCOUNT_CLONES __attribute__((target_clones("popcnt", "default")))
#else
#define VC_POPCOUNT_CLONES
#endif
