#include "vc/visibility/voxel_set.h"

#include <roaring/roaring.h>

#include <algorithm>
#include <bit>
#include <cassert>
#include <new>

#include "vc/base/popcount.h"

namespace vc {
namespace {

uint64_t EstimatedSparseBytes(const std::vector<uint64_t>& words);

roaring_bitmap_t* Checked(roaring_bitmap_t* r) {
  if (r == nullptr) throw std::bad_alloc();
  return r;
}

// A dense set's members as a new bitmap.
roaring_bitmap_t* ToBitmap(const VoxelSet& s) {
  roaring_bitmap_t* r = Checked(roaring_bitmap_create());
  uint32_t buf[1024];
  size_t n = 0;
  s.ForEach([&](size_t id) {
    buf[n++] = static_cast<uint32_t>(id);
    if (n == 1024) {
      roaring_bitmap_add_many(r, n, buf);
      n = 0;
    }
  });
  roaring_bitmap_add_many(r, n, buf);
  return r;
}

}  // namespace

VoxelSet::VoxelSet(const VoxelSet& other) : n_(other.n_), words_(other.words_) {
  if (other.sparse_) sparse_ = Checked(roaring_bitmap_copy(other.sparse_));
}

VoxelSet& VoxelSet::operator=(const VoxelSet& other) {
  if (this == &other) return *this;
  Free();
  n_ = other.n_;
  words_ = other.words_;
  if (other.sparse_) sparse_ = Checked(roaring_bitmap_copy(other.sparse_));
  return *this;
}

VoxelSet::VoxelSet(VoxelSet&& other) noexcept
    : n_(other.n_), words_(std::move(other.words_)), sparse_(std::exchange(other.sparse_, nullptr)) {
  other.n_ = 0;
}

VoxelSet& VoxelSet::operator=(VoxelSet&& other) noexcept {
  if (this == &other) return *this;
  Free();
  n_ = std::exchange(other.n_, 0);
  words_ = std::move(other.words_);
  sparse_ = std::exchange(other.sparse_, nullptr);
  return *this;
}

VoxelSet::~VoxelSet() { Free(); }

void VoxelSet::Free() {
  if (sparse_) roaring_bitmap_free(sparse_);
  sparse_ = nullptr;
}

void VoxelSet::Resize(size_t n) {
  if (sparse_) {
    if (n < n_) roaring_bitmap_remove_range(sparse_, n, uint64_t{n_});
    n_ = n;
    return;
  }
  n_ = n;
  words_.resize((n + 63) / 64, 0);
  if (n % 64) words_.back() &= (uint64_t{1} << (n % 64)) - 1;
}

bool VoxelSet::SparseTest(size_t i) const { return roaring_bitmap_contains(sparse_, static_cast<uint32_t>(i)); }

void VoxelSet::SparseSet(size_t i, bool value) {
  if (value) {
    roaring_bitmap_add(sparse_, static_cast<uint32_t>(i));
  } else {
    roaring_bitmap_remove(sparse_, static_cast<uint32_t>(i));
  }
}

VC_POPCOUNT_CLONES size_t VoxelSet::count() const {
  if (sparse_) return roaring_bitmap_get_cardinality(sparse_);
  size_t n = 0;
  for (uint64_t w : words_) n += std::popcount(w);
  return n;
}

VC_POPCOUNT_CLONES size_t VoxelSet::CountAnd(const VoxelSet& other) const {
  if (sparse_ && other.sparse_) return roaring_bitmap_and_cardinality(sparse_, other.sparse_);
  if (sparse_ || other.sparse_) {
    const VoxelSet& s = sparse_ ? *this : other;
    const VoxelSet& d = sparse_ ? other : *this;
    size_t n = 0;
    s.ForEach([&](size_t id) { n += id < d.n_ && d.test(id); });
    return n;
  }
  size_t n = 0;
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) n += std::popcount(words_[i] & other.words_[i]);
  return n;
}

bool VoxelSet::Intersects(const VoxelSet& other) const {
  if (sparse_ && other.sparse_) return roaring_bitmap_intersect(sparse_, other.sparse_);
  if (sparse_ || other.sparse_) {
    const VoxelSet& s = sparse_ ? *this : other;
    const VoxelSet& d = sparse_ ? other : *this;
    roaring_uint32_iterator_t it;
    roaring_init_iterator(s.sparse_, &it);
    for (; it.has_value; roaring_advance_uint32_iterator(&it)) {
      if (it.current_value < d.n_ && d.test(it.current_value)) return true;
    }
    return false;
  }
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) {
    if (words_[i] & other.words_[i]) return true;
  }
  return false;
}

void VoxelSet::Subtract(const VoxelSet& other) {
  if (sparse_ && other.sparse_) return roaring_bitmap_andnot_inplace(sparse_, other.sparse_);
  if (other.sparse_) {  // dense -= sparse
    other.ForEach([&](size_t id) {
      if (id < n_) reset(id);
    });
    return;
  }
  if (sparse_) {  // sparse -= dense: the members the dense set holds go
    std::vector<uint32_t> gone;
    ForEach([&](size_t id) {
      if (id < other.n_ && other.test(id)) gone.push_back(static_cast<uint32_t>(id));
    });
    roaring_bitmap_remove_many(sparse_, gone.size(), gone.data());
    return;
  }
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) words_[i] &= ~other.words_[i];
}

void VoxelSet::Union(const VoxelSet& other) {
  if (sparse_ && other.sparse_) {
    roaring_bitmap_or_inplace(sparse_, other.sparse_);
    if (other.n_ > n_) roaring_bitmap_remove_range(sparse_, n_, uint64_t{other.n_});
    return;
  }
  if (sparse_ || other.sparse_) {
    other.ForEach([&](size_t id) {
      if (id < n_) set(id);
    });
    return;
  }
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) words_[i] |= other.words_[i];
}

void VoxelSet::Intersect(const VoxelSet& other) {
  if (sparse_ && other.sparse_) return roaring_bitmap_and_inplace(sparse_, other.sparse_);
  if (sparse_ || other.sparse_) {
    std::vector<uint32_t> gone;
    ForEach([&](size_t id) {
      if (id >= other.n_ || !other.test(id)) gone.push_back(static_cast<uint32_t>(id));
    });
    if (sparse_) {
      roaring_bitmap_remove_many(sparse_, gone.size(), gone.data());
    } else {
      for (uint32_t id : gone) reset(id);
    }
    return;
  }
  const size_t m = std::min(words_.size(), other.words_.size());
  for (size_t i = 0; i < m; ++i) words_[i] &= other.words_[i];
  for (size_t i = m; i < words_.size(); ++i) words_[i] = 0;
}

bool VoxelSet::Contains(const VoxelSet& other) const {
  if (sparse_ && other.sparse_) return roaring_bitmap_is_subset(other.sparse_, sparse_);
  if (!sparse_ && !other.sparse_) {
    for (size_t i = 0; i < other.words_.size(); ++i) {
      if (other.words_[i] & ~(i < words_.size() ? words_[i] : 0)) return false;
    }
    return true;
  }
  bool all = true;
  other.ForEach([&](size_t id) { all = all && id < n_ && test(id); });
  return all;
}

const std::vector<uint64_t>& VoxelSet::words() const {
  assert(!sparse_ && "VoxelSet::words() on a sparse set: Densify() it first");
  return words_;
}

std::vector<uint64_t>& VoxelSet::words() {
  assert(!sparse_ && "VoxelSet::words() on a sparse set: Densify() it first");
  return words_;
}

uint64_t VoxelSet::Word(size_t k) const {
  if (!sparse_) return words_[k];
  const uint64_t lo = uint64_t{k} * 64;
  roaring_uint32_iterator_t* it = roaring_create_iterator(sparse_);
  if (it == nullptr) throw std::bad_alloc();
  uint64_t w = 0;
  if (roaring_move_uint32_iterator_equalorlarger(it, static_cast<uint32_t>(lo))) {
    while (it->has_value && it->current_value < lo + 64) {
      w |= uint64_t{1} << (it->current_value - lo);
      roaring_advance_uint32_iterator(it);
    }
  }
  roaring_free_uint32_iterator(it);
  return w;
}

// About the bytes of a dense set as a run-optimized Roaring bitmap, from one pass over its words:
// per 65536 ids the smallest of an array (2 bytes per id), a bitmap (8 KiB) and runs (4 bytes per
// run), plus a container's header. Decides Compact without building the bitmap of a set that
// stays dense (the hall's 858 sets would otherwise cost 0.7 s per plan).
namespace {
VC_POPCOUNT_CLONES uint64_t EstimatedSparseBytes(const std::vector<uint64_t>& words) {
  uint64_t bytes = 8;
  for (size_t c0 = 0; c0 < words.size(); c0 += 1024) {
    uint64_t ids = 0, runs = 0, carry = 0;
    for (size_t i = c0; i < std::min(words.size(), c0 + 1024); ++i) {
      const uint64_t w = words[i];
      ids += std::popcount(w);
      runs += std::popcount(w & ~((w << 1) | carry));  // bits that start a run
      carry = w >> 63;
    }
    if (ids > 0) bytes += 8 + std::min<uint64_t>({2 * ids, 8192, 4 * runs});
  }
  return bytes;
}
}  // namespace

bool VoxelSet::Compact(double gain) {
  if (sparse_ || gain <= 0) return sparse_ != nullptr;
  const double dense_bytes_estimate = double(words_.size() * sizeof(uint64_t));
  if (dense_bytes_estimate < gain * double(EstimatedSparseBytes(words_)) * 0.75) return false;  // clearly not
  roaring_bitmap_t* r = ToBitmap(*this);
  roaring_bitmap_run_optimize(r);
  roaring_bitmap_shrink_to_fit(r);
  const double dense_bytes = double(words_.size() * sizeof(uint64_t));
  if (dense_bytes < gain * double(roaring_bitmap_size_in_bytes(r))) {
    roaring_bitmap_free(r);
    return false;
  }
  sparse_ = r;
  words_ = std::vector<uint64_t>();
  return true;
}

void VoxelSet::Densify() {
  if (!sparse_) return;
  std::vector<uint64_t> w((n_ + 63) / 64, 0);
  ForEach([&](size_t id) { w[id >> 6] |= uint64_t{1} << (id & 63); });
  Free();
  words_ = std::move(w);
}

size_t VoxelSet::MemoryBytes() const {
  if (!sparse_) return words_.capacity() * sizeof(uint64_t);
  // The containers' allocated bytes, plus each container's struct and index entry (about 48
  // bytes), plus the bitmap itself.
  roaring_statistics_t st;
  roaring_bitmap_statistics(sparse_, &st);
  return sizeof(roaring_bitmap_t) + uint64_t{st.n_bytes_array_containers} + st.n_bytes_run_containers +
         st.n_bytes_bitset_containers + 48 * uint64_t{st.n_containers};
}

std::string VoxelSet::ToPortable() const {
  roaring_bitmap_t* owned = nullptr;
  const roaring_bitmap_t* r = sparse_;
  if (!r) {
    owned = ToBitmap(*this);
    roaring_bitmap_run_optimize(owned);
    r = owned;
  }
  std::string out(roaring_bitmap_portable_size_in_bytes(r), '\0');
  out.resize(roaring_bitmap_portable_serialize(r, out.data()));
  if (owned) roaring_bitmap_free(owned);
  return out;
}

Result<VoxelSet> VoxelSet::FromPortable(std::string_view bytes, size_t n, double gain) {
  roaring_bitmap_t* r = roaring_bitmap_portable_deserialize_safe(bytes.data(), bytes.size());
  if (!r || roaring_bitmap_portable_size_in_bytes(r) != bytes.size()) {
    if (r) roaring_bitmap_free(r);
    return DataLossError("a visibility set from a peer is not a whole portable Roaring bitmap (" +
                         std::to_string(bytes.size()) + " bytes)");
  }
  // CRoaring's safe deserialization only keeps its reads within the buffer; the content may still
  // be out of order (a key or value that is not ascending would make maximum() lie). One walk
  // checks that every id ascends and lies in the scene, and that the walk sees every member.
  {
    roaring_uint32_iterator_t* it = roaring_create_iterator(r);
    if (it == nullptr) {
      roaring_bitmap_free(r);
      throw std::bad_alloc();
    }
    uint64_t walked = 0;
    int64_t previous = -1;
    bool ordered = true;
    for (; it->has_value && ordered; roaring_advance_uint32_iterator(it)) {
      ordered = int64_t{it->current_value} > previous && it->current_value < n;
      previous = it->current_value;
      ++walked;
    }
    roaring_free_uint32_iterator(it);
    if (!ordered || walked != roaring_bitmap_get_cardinality(r)) {
      roaring_bitmap_free(r);
      return DataLossError("a visibility set from a peer is not an ascending set of ids below the scene's " +
                           std::to_string(n) + " voxels");
    }
  }
  VoxelSet s;
  s.n_ = n;
  s.sparse_ = r;
  roaring_bitmap_shrink_to_fit(r);
  const double dense_bytes = double((n + 63) / 64 * sizeof(uint64_t));
  if (gain <= 0 || dense_bytes < gain * double(roaring_bitmap_size_in_bytes(r))) s.Densify();
  return s;
}

VoxelSet::SparseCursor::SparseCursor(const VoxelSet& s) : it_(roaring_create_iterator(s.sparse_)) {
  if (it_ == nullptr) throw std::bad_alloc();
}

VoxelSet::SparseCursor::~SparseCursor() { roaring_free_uint32_iterator(static_cast<roaring_uint32_iterator_t*>(it_)); }

size_t VoxelSet::SparseCursor::Read(uint32_t* out, size_t max) {
  return roaring_read_uint32_iterator(static_cast<roaring_uint32_iterator_t*>(it_), out, static_cast<uint32_t>(max));
}

}  // namespace vc
