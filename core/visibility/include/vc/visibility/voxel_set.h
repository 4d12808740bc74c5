// VoxelSet: a set of occupied-voxel ids (VoxelScene::occupied positions): a candidate's visibility
// set, a plan's coverable or covered voxels.
//
// Two forms (docs/DEPLOY.md, "What grows with what"; docs/BENCHMARKS.md, "Scaling out"):
// - dense: one bit per voxel of the scene, in 64-bit words. Every set starts dense; intersections
//   and unions run over words, which is fastest while a set holds a fair share of the scene.
// - sparse: a Roaring bitmap (CRoaring, Debian's libroaring-dev) of the ids, after Compact(gain)
//   found it at least `gain` times smaller. A station that sees a small share of a large site (a
//   hard range on a campus) takes a few bytes per run of voxels instead of a bit per voxel of the
//   site, so memory grows with what the stations see rather than with candidates x voxels.
// Every operation takes either form on either side (a dense accumulator with sparse candidates
// iterates the sparse ids); words() exists for the dense form only. Copyable; not thread-safe
// for writes (like std::vector).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/status.h"

struct roaring_bitmap_s;

namespace vc {

class VoxelSet {
 public:
  VoxelSet() = default;
  explicit VoxelSet(size_t n) : n_(n), words_((n + 63) / 64, 0) {}
  VoxelSet(const VoxelSet& other);
  VoxelSet& operator=(const VoxelSet& other);
  VoxelSet(VoxelSet&& other) noexcept;
  VoxelSet& operator=(VoxelSet&& other) noexcept;
  ~VoxelSet();

  // Voxels of the scene (the universe), not the members (count()).
  size_t size() const { return n_; }
  bool sparse() const { return sparse_ != nullptr; }
  // Makes the set hold n voxels: ids below the old size keep their bits, the others are clear.
  // Dense: allocates nothing when words().capacity() already holds (n + 63) / 64 words.
  void Resize(size_t n);
  bool test(size_t i) const { return sparse_ ? SparseTest(i) : ((words_[i >> 6] >> (i & 63)) & 1u); }
  void set(size_t i) {
    if (sparse_) return SparseSet(i, true);
    words_[i >> 6] |= uint64_t{1} << (i & 63);
  }
  void reset(size_t i) {
    if (sparse_) return SparseSet(i, false);
    words_[i >> 6] &= ~(uint64_t{1} << (i & 63));
  }
  size_t count() const;
  // |this AND other|.
  size_t CountAnd(const VoxelSet& other) const;
  // Whether this and other share a member (stops at the first).
  bool Intersects(const VoxelSet& other) const;
  // this &= ~other.
  void Subtract(const VoxelSet& other);
  // this |= other.
  void Union(const VoxelSet& other);
  // this &= other.
  void Intersect(const VoxelSet& other);
  // Whether every member of `other` is a member of this.
  bool Contains(const VoxelSet& other) const;

  // The dense words (dense form only: call Densify() first on a set that may be sparse).
  const std::vector<uint64_t>& words() const;
  std::vector<uint64_t>& words();
  // Word k of the dense form (bits 64k..64k+63), whichever form the set is in.
  uint64_t Word(size_t k) const;
  // Calls f(id) for every member, ascending.
  template <typename F>
  void ForEach(F&& f) const {
    if (!sparse_) {
      for (size_t w = 0; w < words_.size(); ++w) {
        for (uint64_t bits = words_[w]; bits != 0; bits &= bits - 1) {
          f(w * 64 + static_cast<size_t>(__builtin_ctzll(bits)));
        }
      }
      return;
    }
    uint32_t buf[256];
    SparseCursor c(*this);
    for (size_t got; (got = c.Read(buf, 256)) > 0;) {
      for (size_t i = 0; i < got; ++i) f(size_t{buf[i]});
    }
  }

  // Turns a dense set sparse when the Roaring bitmap (run-optimized) is at least `gain` times
  // smaller than the words; true when the set is sparse afterwards. gain <= 0: stays as it is.
  bool Compact(double gain);
  // Back to the dense form.
  void Densify();
  // Bytes the set holds on the heap now (words, or the bitmap).
  size_t MemoryBytes() const;

  // The ids as a portable Roaring bitmap (github.com/RoaringBitmap/RoaringFormatSpec): the form
  // visibility sets travel in between replicas.
  std::string ToPortable() const;
  // The set of `n` voxels in `bytes`, sparse when that is `gain` times smaller (else dense).
  // DATA_LOSS when `bytes` is not a whole portable bitmap or names an id >= n.
  static Result<VoxelSet> FromPortable(std::string_view bytes, size_t n, double gain);

 private:
  // Reads a sparse set's ids in order.
  class SparseCursor {
   public:
    explicit SparseCursor(const VoxelSet& s);
    ~SparseCursor();
    size_t Read(uint32_t* out, size_t max);

   private:
    void* it_;
  };
  bool SparseTest(size_t i) const;
  void SparseSet(size_t i, bool value);
  void Free();

  size_t n_ = 0;
  std::vector<uint64_t> words_;         // dense form (empty when sparse)
  roaring_bitmap_s* sparse_ = nullptr;  // sparse form, owned
};

}  // namespace vc
