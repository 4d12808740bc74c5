#include "vc/wire/voxel_set_codec.h"

#include <roaring/roaring.h>

#include <memory>
#include <vector>

namespace vc::wire {
namespace {

struct BitmapFree {
  void operator()(roaring_bitmap_t* r) const { roaring_bitmap_free(r); }
};
using Bitmap = std::unique_ptr<roaring_bitmap_t, BitmapFree>;

}  // namespace

std::string EncodeVoxelSet(const VoxelSet& set) {
  // The ids in ascending order, one word at a time (add_many is fastest on sorted input).
  std::vector<uint32_t> ids;
  ids.reserve(set.count());
  const std::vector<uint64_t>& words = set.words();
  for (size_t w = 0; w < words.size(); ++w) {
    for (uint64_t bits = words[w]; bits != 0; bits &= bits - 1) {
      ids.push_back(static_cast<uint32_t>(w * 64 + static_cast<size_t>(__builtin_ctzll(bits))));
    }
  }
  Bitmap r(roaring_bitmap_create());
  roaring_bitmap_add_many(r.get(), ids.size(), ids.data());
  roaring_bitmap_run_optimize(r.get());
  std::string out(roaring_bitmap_portable_size_in_bytes(r.get()), '\0');
  out.resize(roaring_bitmap_portable_serialize(r.get(), out.data()));
  return out;
}

Result<VoxelSet> DecodeVoxelSet(std::string_view bytes, size_t voxels) {
  Bitmap r(roaring_bitmap_portable_deserialize_safe(bytes.data(), bytes.size()));
  if (!r || roaring_bitmap_portable_size_in_bytes(r.get()) != bytes.size()) {
    return DataLossError("a visibility set from a peer is not a whole portable Roaring bitmap (" +
                         std::to_string(bytes.size()) + " bytes)");
  }
  VoxelSet set(voxels);
  if (roaring_bitmap_is_empty(r.get())) return set;
  if (roaring_bitmap_maximum(r.get()) >= voxels) {
    return DataLossError("a visibility set from a peer names voxel " + std::to_string(roaring_bitmap_maximum(r.get())) +
                         " of a scene of " + std::to_string(voxels));
  }
  roaring_iterate(
      r.get(),
      [](uint32_t id, void* p) {
        static_cast<VoxelSet*>(p)->set(id);
        return true;
      },
      &set);
  return set;
}

}  // namespace vc::wire
