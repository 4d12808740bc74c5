// Resident memory from /proc: touched pages raise the current figure and the peak, and a meter
// sees a span's peak whether or not the span raised the process's.
#include "vc/base/resident_memory.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <thread>

#include "testing/test_paths.h"

namespace vc {
namespace {

constexpr size_t kBlockBytes = size_t{32} << 20;

// `bytes` (32 MiB), every page written, so that it is resident; freed when the pointer goes.
std::unique_ptr<char[]> TouchedBlock(size_t bytes = kBlockBytes) {
  std::unique_ptr<char[]> block(new char[bytes]);
  std::memset(block.get(), 1, bytes);
  asm volatile("" : : "r"(block.get()) : "memory");  // the writes happen: the block escapes
  return block;
}

TEST(ResidentMemoryTest, TouchedMemoryCountsInTheCurrentFigureAndThePeak) {
  const uint64_t before = CurrentResidentBytes();
  ASSERT_GT(before, 0u) << "no /proc/self/status";
  std::unique_ptr<char[]> block = TouchedBlock();
  const uint64_t during = CurrentResidentBytes();
  EXPECT_GE(during, before + kBlockBytes / 2);
  EXPECT_GE(PeakResidentBytes(), during);
  EXPECT_EQ(static_cast<volatile char*>(block.get())[kBlockBytes - 1], 1);
}

// The peak of a span that holds a block for 20 sampling intervals, so that sampling sees it too.
uint64_t PeakOfASpanHoldingABlock() {
  ResidentPeakMeter meter(std::chrono::milliseconds(5));
  std::unique_ptr<char[]> block = TouchedBlock();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  block.reset();
  return meter.Stop();
}

TEST(ResidentMemoryTest, AMeterSeesASpansPeakAlsoBelowTheProcesssEarlierPeak) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << "ASan's quarantine keeps freed blocks resident";
  TouchedBlock(3 * kBlockBytes).reset();  // the process's peak is now above what the spans below reach
  const uint64_t resident = CurrentResidentBytes();
  ASSERT_GT(resident, 0u) << "no /proc/self/status";
  const uint64_t with_block = PeakOfASpanHoldingABlock();
  EXPECT_GE(with_block, resident + kBlockBytes / 2);
  EXPECT_LT(with_block, PeakResidentBytes());  // sampled, not the process's peak
  ResidentPeakMeter idle;
  const uint64_t without = idle.Stop();
  EXPECT_GT(without, 0u);
  EXPECT_LE(without + kBlockBytes / 2, with_block);
  EXPECT_EQ(idle.Stop(), without);  // stopped once
}

TEST(ResidentMemoryTest, AMeterOverASpanThatRaisesTheProcesssPeakReportsTheNewPeak) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << "ASan's quarantine keeps freed blocks resident";
  ResidentPeakMeter meter;
  TouchedBlock(PeakResidentBytes() + kBlockBytes).reset();  // above anything the process held
  const uint64_t peak = meter.Stop();
  EXPECT_EQ(peak, PeakResidentBytes());  // exact: this span set the process's peak
}

}  // namespace
}  // namespace vc
