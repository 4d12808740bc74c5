// vc::ReadLimits and the limits in ReadOptions: decompression bombs and lying headers are refused
// with RESOURCE_EXHAUSTED or INVALID_ARGUMENT before the memory they ask for is allocated, and a
// std::bad_alloc inside ReadScene becomes RESOURCE_EXHAUSTED.
//
// This binary replaces the global operator new to record the largest single allocation (and, when
// asked, to throw std::bad_alloc above a size), so "refused before allocating" is measured, not
// assumed. Tests here run one at a time in their own process (gtest_discover_tests), so the
// counters are not shared with other tests.
#include <bzlib.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <new>
#include <sstream>
#include <string>
#include <utility>

#include "vc/scene/octomap_adapter.h"
#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"

namespace {

std::atomic<size_t> g_largest_allocation{0};
std::atomic<size_t> g_fail_above{SIZE_MAX};

}  // namespace

// GCC sees malloc/free through the replacement and warns of a mismatch that is not one.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(size_t size) {
  if (size > g_fail_above.load()) throw std::bad_alloc();
  size_t seen = g_largest_allocation.load();
  while (size > seen && !g_largest_allocation.compare_exchange_weak(seen, size)) {
  }
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }

namespace vc {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr size_t kMiB = size_t{1} << 20;

// Largest single allocation made while running fn.
template <typename F>
size_t LargestAllocation(F&& fn) {
  g_largest_allocation = 0;
  fn();
  return g_largest_allocation.load();
}

template <typename T>
void PutAt(std::string* s, size_t offset, T v) {
  std::memcpy(s->data() + offset, &v, sizeof(T));
}
template <typename T>
void Put(std::string* s, T v) {
  s->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

// `n` zero bytes, gzip-compressed, streamed so the test itself holds only the output.
std::string GzipZeros(size_t n) {
  z_stream zs{};
  EXPECT_EQ(deflateInit2(&zs, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY), Z_OK);
  const std::string chunk(kMiB, '\0');
  std::string out(deflateBound(&zs, n) + 64, '\0');
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  for (size_t left = n; left > 0;) {
    const size_t take = std::min(left, chunk.size());
    left -= take;
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(chunk.data()));
    zs.avail_in = static_cast<uInt>(take);
    EXPECT_NE(deflate(&zs, left == 0 ? Z_FINISH : Z_NO_FLUSH), Z_STREAM_ERROR);
  }
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

std::string Bzip2Zeros(size_t n) {
  const std::string zeros(n, '\0');
  std::string out(n / 100 + 1024, '\0');
  unsigned size = static_cast<unsigned>(out.size());
  EXPECT_EQ(
      BZ2_bzBuffToBuffCompress(out.data(), &size, const_cast<char*>(zeros.data()), static_cast<unsigned>(n), 9, 0, 0),
      BZ_OK);
  out.resize(size);
  return out;
}

TEST(ReadLimitsTest, RatioOfTheUploadLimitCappedByHalfTheBudget) {
  const ReadOptions small_upload = ReadLimits(4096, uint64_t{4} << 30);
  EXPECT_EQ(small_upload.max_decompressed_bytes, 4096 * kMaxDecompressionRatio);
  EXPECT_EQ(small_upload.max_result_bytes, uint64_t{2} << 30);
  EXPECT_EQ(small_upload.max_points, (uint64_t{2} << 30) / kBytesPerPoint);
  const ReadOptions small_budget = ReadLimits(uint64_t{1} << 30, 64 * kMiB);
  EXPECT_EQ(small_budget.max_decompressed_bytes, 32 * kMiB);
  EXPECT_EQ(small_budget.max_result_bytes, 32 * kMiB);
  const ReadOptions huge = ReadLimits(UINT64_MAX, UINT64_MAX);
  EXPECT_EQ(huge.max_decompressed_bytes, UINT64_MAX / 2);  // no overflow
  EXPECT_GT(ReadLimits(0, 0).max_decompressed_bytes, 0u);
}

TEST(ReadLimitsTest, DefaultsAreTheServerDefaults) {
  const ReadOptions d;
  const ReadOptions s = ReadLimits(kDefaultMaxUploadBytes, kDefaultMemoryBudgetBytes);
  EXPECT_EQ(d.max_decompressed_bytes, s.max_decompressed_bytes);
  EXPECT_EQ(d.max_points, s.max_points);
  EXPECT_EQ(d.max_result_bytes, s.max_result_bytes);
}

// 256 MiB of zeros in ~250 KiB of gzip (the shape of the 4.8 MB gzip that aborted
// vc-client inspect), against a 4 KiB upload limit: 64 KiB may be decompressed.
TEST(DecompressionBombTest, GzipBombRefusedWhileStreaming) {
  const std::string bomb = GzipZeros(256 * kMiB);
  const ReadOptions limits = ReadLimits(4096, uint64_t{4} << 30);
  Result<SceneInput> r = InternalError("unset");
  const auto t0 = std::chrono::steady_clock::now();
  const size_t largest = LargestAllocation([&] { r = ReadScene(bomb, "bomb.gz", limits); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(r.status().message(),
              AllOf(HasSubstr("bomb.gz: gzip input decompresses to more than the limit of 65536 bytes"),
                    HasSubstr("--max-upload-bytes"), HasSubstr("--memory-budget-bytes")));
  EXPECT_LT(largest, kMiB);  // refused while counting: the output is never allocated
  EXPECT_LT(seconds, 1.0);
}

// The 4 KB bzip2 upload that decompressed to 4.5 GiB, scaled down: 64 MiB of zeros in ~100 bytes.
TEST(DecompressionBombTest, Bzip2BombRefusedWhileStreaming) {
  const std::string bomb = Bzip2Zeros(64 * kMiB);
  ASSERT_LT(bomb.size(), 4096u);
  const ReadOptions limits = ReadLimits(4096, uint64_t{4} << 30);
  Result<SceneInput> r = InternalError("unset");
  const size_t largest = LargestAllocation([&] { r = ReadScene(bomb, "bomb.bz2", limits); });
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(r.status().message(),
              AllOf(HasSubstr("bomb.bz2: bzip2 input decompresses to more than the limit of 65536 bytes"),
                    HasSubstr("raise --max-upload-bytes or --memory-budget-bytes")));
  EXPECT_LT(largest, kMiB);
}

TEST(DecompressionBombTest, BudgetCapsTheDecompressedSize) {
  const std::string bomb = GzipZeros(16 * kMiB);
  Result<SceneInput> r = ReadScene(bomb, "b.gz", ReadLimits(uint64_t{1} << 30, 2 * kMiB));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(r.status().message(), HasSubstr("more than the limit of 1048576 bytes"));
}

TEST(DecompressionBombTest, OutputIsAllocatedOnceAtItsExactSize) {
  const size_t size = 3 * kMiB + 12345;
  const std::string packed = GzipZeros(size);
  // Zeros are no scene: the read fails after decompressing, having allocated the output once.
  const size_t largest = LargestAllocation([&] { (void)ReadScene(packed, "z.gz"); });
  EXPECT_GE(largest, size);
  EXPECT_LE(largest, size + 1);  // + 1 for the terminating NUL; no doubling, no second copy
}

// --- lying headers: each declares far more than its bytes hold; refused without allocating it.

void ExpectRefusedSmall(const std::string& input, const std::string& name, StatusCode code,
                        const std::string& message_part, ReadOptions options = {}) {
  Result<SceneInput> r = InternalError("unset");
  const size_t largest = LargestAllocation([&] { r = ReadScene(input, name, options); });
  ASSERT_FALSE(r.ok()) << name;
  EXPECT_EQ(r.status().code(), code) << r.status().ToString();
  EXPECT_THAT(r.status().message(), HasSubstr(message_part));
  EXPECT_LT(largest, 64 * 1024 + 4 * input.size()) << name;
}

ReadOptions Unlimited() {
  ReadOptions o;
  o.max_points = UINT64_MAX;
  o.max_result_bytes = UINT64_MAX;
  return o;
}

TEST(LyingHeaderTest, Ply) {
  for (const char* encoding : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    std::string ply = std::string("ply\nformat ") + encoding +
                      " 1.0\nelement vertex 2147483648\nproperty float x\nproperty float "
                      "y\nproperty float z\nend_header\n";
    for (int i = 0; i < 100; ++i) ply += "0 0 0\n";
    ExpectRefusedSmall(ply, "lie.ply", StatusCode::kResourceExhausted, "2147483648 points");
    ExpectRefusedSmall(ply, "lie.ply", StatusCode::kInvalidArgument, "file truncated?", Unlimited());
  }
  // A non-vertex element claiming 2^62 items of a list each.
  const std::string faces =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 4611686018427387904\nproperty list uchar int v\n"
      "end_header\n" +
      std::string(12 + 64, '\0');
  ExpectRefusedSmall(faces, "faces.ply", StatusCode::kInvalidArgument, "file truncated?");
}

std::string PcdHeader(const std::string& points, const std::string& data) {
  return "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + points + "\nHEIGHT 1\nPOINTS " +
         points + "\nDATA " + data + "\n";
}

TEST(LyingHeaderTest, Pcd) {
  // Without the limits the body is read, and does not hold what the header says: the ASCII body is
  // one line of one value, the binary one ends after 85 points (1024 bytes of 12-byte points).
  const std::pair<const char*, const char*> lies[] = {
      {"ascii", "lie.pcd: line 10: expected 3 values per point (FIELDS times COUNT), found 1"},
      {"binary", "lie.pcd: PCD header declares 2147483648 points but the body ends after 85; file truncated?"},
  };
  for (const auto& [data, refusal] : lies) {
    const std::string pcd = PcdHeader("2147483648", data) + std::string(1024, '1');
    ExpectRefusedSmall(pcd, "lie.pcd", StatusCode::kResourceExhausted, "2147483648 points");
    ExpectRefusedSmall(pcd, "lie.pcd", StatusCode::kInvalidArgument, refusal, Unlimited());
  }
  // binary_compressed: sizes that agree with the header, a 1 KiB block.
  std::string lzf = PcdHeader("100000000", "binary_compressed");
  Put<uint32_t>(&lzf, 1024);
  Put<uint32_t>(&lzf, 1'200'000'000u);
  lzf += std::string(1024, '\x1f');
  ExpectRefusedSmall(lzf, "lzf.pcd", StatusCode::kInvalidArgument, "cannot decompress to", Unlimited());
  // A declared size the ratio allows but the limit does not.
  ReadOptions small = Unlimited();
  small.max_decompressed_bytes = 1000;
  std::string fits = PcdHeader("1000", "binary_compressed");
  Put<uint32_t>(&fits, 1024);
  Put<uint32_t>(&fits, 12000);
  fits += std::string(1024, '\x1f');
  ExpectRefusedSmall(fits, "lzf.pcd", StatusCode::kResourceExhausted, "more than the limit of 1000", small);
}

std::string Las(uint32_t count, uint16_t record_length) {
  std::string las(227 + 2 * 20, '\0');
  std::memcpy(las.data(), "LASF", 4);
  las[24] = 1;
  las[25] = 2;
  PutAt<uint16_t>(&las, 94, 227);
  PutAt<uint32_t>(&las, 96, 227);
  las[104] = 0;
  PutAt<uint16_t>(&las, 105, record_length);
  PutAt<uint32_t>(&las, 107, count);
  for (int a = 0; a < 3; ++a) PutAt<double>(&las, 131 + 8 * a, 0.01);
  return las;
}

TEST(LyingHeaderTest, Las) {
  ExpectRefusedSmall(Las(2'147'483'648u, 20), "lie.las", StatusCode::kResourceExhausted, "2147483648 points");
  ExpectRefusedSmall(Las(2'147'483'648u, 20), "lie.las", StatusCode::kInvalidArgument, "but the body ends after 2",
                     Unlimited());
  ExpectRefusedSmall(Las(2, 65535), "long-records.las", StatusCode::kInvalidArgument, "but the body ends after 0",
                     Unlimited());
}

TEST(LyingHeaderTest, ScanGraph) {
  std::string graph;
  Put<uint32_t>(&graph, 1);
  Put<uint32_t>(&graph, 2'147'483'648u);  // points in scan 0
  graph += std::string(1024, '\x01');
  ExpectRefusedSmall(graph, "lie.graph", StatusCode::kInvalidArgument, "declares");
  std::string scans;
  Put<uint32_t>(&scans, 4'000'000'000u);
  scans += std::string(1024, '\x01');
  ExpectRefusedSmall(scans, "scans.graph", StatusCode::kInvalidArgument, "declares 4000000000 scans");
}

TEST(LyingHeaderTest, OctomapSizeLineMustMatchTheNodes) {
  // "size" claims 2^40 nodes; the node data holds 5 (root, leaf, inner, two leaves).
  const std::string bt = std::string(
                             "# Octomap OcTree binary file\nid OcTree\nsize 1099511627776\n"
                             "res 0.1\ndata\n") +
                         std::string("\x0d\x00\x06\x00", 4);
  ExpectRefusedSmall(bt, "lie.bt", StatusCode::kInvalidArgument,
                     "lie.bt: the header declares size 1099511627776 but the node data holds 5 nodes");
}

TEST(LyingHeaderTest, OctreeLargerThanTheResultLimit) {
  // A 32^3 checkerboard of occupied and free voxels: nothing prunes, 32768 leaves.
  octomap::OcTree tree(0.1);
  for (int x = 0; x < 32; ++x) {
    for (int y = 0; y < 32; ++y) {
      for (int z = 0; z < 32; ++z) {
        tree.updateNode(octomap::point3d(x * 0.1f + 0.05f, y * 0.1f + 0.05f, z * 0.1f + 0.05f), (x + y + z) % 2 == 0);
      }
    }
  }
  std::ostringstream stream;
  ASSERT_TRUE(tree.writeBinary(stream));
  const std::string bt = stream.str();
  ReadOptions options;
  options.max_result_bytes = 1000 * kOctreeNodeBytes;
  ExpectRefusedSmall(bt, "big.bt", StatusCode::kResourceExhausted, "more than the limit of 48000 bytes", options);
  Result<SceneInput> ok = ReadScene(bt, "big.bt");
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  EXPECT_EQ(CountOccupiedLeaves(*ok->octree), 32u * 32u * 32u / 2u);
}

TEST(OutOfMemoryTest, BadAllocWhileReadingIsResourceExhausted) {
  std::string xyz;
  for (int i = 0; i < 20000; ++i) xyz += std::to_string(i) + " 1 2\n";
  g_fail_above = 64 * 1024;  // the point vector outgrows this; every allocation above it fails
  Result<SceneInput> r = ReadScene(xyz, "big.xyz");
  g_fail_above = SIZE_MAX;
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(r.status().message(),
              AllOf(HasSubstr("big.xyz: reading"), HasSubstr("ran out of memory"), HasSubstr("--memory-budget-bytes")));
}

TEST(OutOfMemoryTest, BadAllocWhileVoxelisingIsResourceExhausted) {
  SceneInput in;
  for (int i = 0; i < 20000; ++i) in.points.emplace_back(float(i % 100), float(i / 100), 0.0f);
  g_fail_above = 64 * 1024;
  Result<VoxelScene> r = Voxelize(in, VoxelizeOptions{0.05});
  g_fail_above = SIZE_MAX;
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(r.status().message(), HasSubstr("ran out of memory"));
}

}  // namespace
}  // namespace vc
