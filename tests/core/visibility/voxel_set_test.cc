// VoxelSet in both forms (vc/visibility/voxel_set.h): every operation gives the same answer with
// either side dense or sparse, against a std::vector<bool> reference; Compact takes the sparse form
// only when it is the promised factor smaller; the portable form round-trips.
#include "vc/visibility/voxel_set.h"

#include <gtest/gtest.h>

#include <random>

namespace vc {
namespace {

using Ref = std::vector<bool>;

// A set of n voxels with runs and scattered ids, and its reference.
std::pair<VoxelSet, Ref> RandomSet(size_t n, double density, std::mt19937_64& rng) {
  VoxelSet s(n);
  Ref r(n, false);
  std::bernoulli_distribution bit(density), run(0.001);
  std::uniform_int_distribution<size_t> len(1, 3000);
  for (size_t i = 0; i < n; ++i) {
    if (run(rng)) {
      for (size_t j = i, e = std::min(n, i + len(rng)); j < e; ++j) s.set(j), r[j] = true;
    } else if (bit(rng)) {
      s.set(i);
      r[i] = true;
    }
  }
  return {std::move(s), std::move(r)};
}

void ExpectEquals(const VoxelSet& s, const Ref& r) {
  ASSERT_EQ(s.size(), r.size());
  size_t n = 0;
  for (size_t i = 0; i < r.size(); ++i) {
    ASSERT_EQ(s.test(i), bool(r[i])) << "id " << i << (s.sparse() ? " (sparse)" : " (dense)");
    n += r[i];
  }
  EXPECT_EQ(s.count(), n);
  std::vector<size_t> ids;
  s.ForEach([&](size_t id) { ids.push_back(id); });
  EXPECT_EQ(ids.size(), n);
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
}

VoxelSet Sparse(VoxelSet s) {
  s.Compact(1e-12);
  EXPECT_TRUE(s.sparse());
  return s;
}

TEST(VoxelSetTest, EveryOperationAgreesInBothForms) {
  std::mt19937_64 rng(11);
  const size_t n = 200003;  // several Roaring containers, not a multiple of 64
  for (int round = 0; round < 6; ++round) {
    auto [a, ra] = RandomSet(n, round % 2 ? 0.002 : 0.3, rng);
    auto [b, rb] = RandomSet(n, round % 3 ? 0.01 : 0.5, rng);
    size_t and_count = 0;
    for (size_t i = 0; i < n; ++i) and_count += ra[i] && rb[i];
    for (bool a_sparse : {false, true}) {
      for (bool b_sparse : {false, true}) {
        SCOPED_TRACE(testing::Message() << "round " << round << " a " << (a_sparse ? "sparse" : "dense") << " b "
                                        << (b_sparse ? "sparse" : "dense"));
        const VoxelSet x = a_sparse ? Sparse(a) : a;
        const VoxelSet y = b_sparse ? Sparse(b) : b;
        ExpectEquals(x, ra);
        EXPECT_EQ(x.CountAnd(y), and_count);
        for (size_t k : {size_t{0}, size_t{7}, n / 64 - 1, n / 64}) {
          uint64_t w = 0;
          for (size_t j = 0; j < 64 && k * 64 + j < n; ++j) w |= uint64_t(ra[k * 64 + j]) << j;
          EXPECT_EQ(x.Word(k), w) << "word " << k;
        }
        Ref r(n);
        VoxelSet u = x;
        u.Union(y);
        for (size_t i = 0; i < n; ++i) r[i] = ra[i] || rb[i];
        ExpectEquals(u, r);
        EXPECT_TRUE(u.Contains(x) && u.Contains(y));
        VoxelSet d = x;
        d.Subtract(y);
        for (size_t i = 0; i < n; ++i) r[i] = ra[i] && !rb[i];
        ExpectEquals(d, r);
        EXPECT_EQ(d.CountAnd(y), 0u);
        EXPECT_EQ(x.Intersects(y), and_count > 0);
        EXPECT_FALSE(d.Intersects(y));
        EXPECT_FALSE(y.Intersects(d));
        VoxelSet m = x;
        m.Intersect(y);
        for (size_t i = 0; i < n; ++i) r[i] = ra[i] && rb[i];
        ExpectEquals(m, r);
        EXPECT_TRUE(x.Contains(m));
        EXPECT_EQ(x.Contains(y), and_count == y.count());
      }
    }
  }
}

TEST(VoxelSetTest, SparseSetsChangeCopyMoveAndResizeLikeDenseOnes) {
  std::mt19937_64 rng(5);
  auto [s, r] = RandomSet(70000, 0.01, rng);
  VoxelSet sp = Sparse(s);
  sp.set(12);
  sp.reset(13);
  r[12] = true;
  r[13] = false;
  ExpectEquals(sp, r);
  VoxelSet copy = sp;
  copy.set(69999);
  EXPECT_FALSE(sp.test(69999) && !r[69999]);  // the copy is deep
  VoxelSet moved = std::move(copy);
  EXPECT_TRUE(moved.sparse());
  EXPECT_TRUE(moved.test(69999));
  sp.Resize(1000);
  r.resize(1000);
  ExpectEquals(sp, r);
  sp.Densify();
  EXPECT_FALSE(sp.sparse());
  ExpectEquals(sp, r);
}

TEST(VoxelSetTest, CompactTakesTheSparseFormOnlyWhenItIsThatMuchSmaller) {
  const size_t n = 1 << 20;  // dense: 128 KiB
  VoxelSet wall(n);
  for (size_t i = 1000; i < 400000; ++i) wall.set(i);  // one run: a few bytes as Roaring
  VoxelSet half(n);
  std::mt19937_64 rng(3);
  std::bernoulli_distribution bit(0.5);
  for (size_t i = 0; i < n; ++i) {
    if (bit(rng)) half.set(i);  // no structure: a Roaring bitmap is as big as the words
  }
  EXPECT_FALSE(VoxelSet(half).Compact(4));
  EXPECT_FALSE(VoxelSet(wall).Compact(0));  // 0: always dense
  VoxelSet w = wall;
  ASSERT_TRUE(w.Compact(4));
  EXPECT_LT(w.MemoryBytes() * 100, wall.MemoryBytes());
  EXPECT_EQ(w.count(), wall.count());
}

TEST(VoxelSetTest, PortableFormRoundTripsAndRefusesForeignIds) {
  std::mt19937_64 rng(9);
  auto [s, r] = RandomSet(100000, 0.02, rng);
  for (const VoxelSet& x : {s, Sparse(s)}) {
    const std::string bytes = x.ToPortable();
    auto dense = VoxelSet::FromPortable(bytes, s.size(), 0);
    auto sparse = VoxelSet::FromPortable(bytes, s.size(), 1e-12);
    ASSERT_TRUE(dense.ok() && sparse.ok());
    EXPECT_FALSE(dense->sparse());
    EXPECT_TRUE(sparse->sparse());
    ExpectEquals(*dense, r);
    ExpectEquals(*sparse, r);
  }
  // Bytes CRoaring's safe deserialization accepts (it only keeps its reads in the buffer) but whose
  // ids do not ascend: {3, 5} with its two array values swapped.
  VoxelSet two(10);
  two.set(3);
  two.set(5);
  std::string swapped = two.ToPortable();
  ASSERT_GE(swapped.size(), 4u);
  std::swap(swapped[swapped.size() - 4], swapped[swapped.size() - 2]);
  std::swap(swapped[swapped.size() - 3], swapped[swapped.size() - 1]);
  EXPECT_EQ(VoxelSet::FromPortable(swapped, 10, 0).status().code(), StatusCode::kDataLoss);
  VoxelSet big(10);
  big.set(9);
  EXPECT_EQ(VoxelSet::FromPortable(big.ToPortable(), 9, 0).status().code(), StatusCode::kDataLoss);
  EXPECT_EQ(VoxelSet::FromPortable("junk", 9, 0).status().code(), StatusCode::kDataLoss);
}

}  // namespace
}  // namespace vc
