#include "vc/wire/voxel_set_codec.h"

namespace vc::wire {

std::string EncodeVoxelSet(const VoxelSet& set) { return set.ToPortable(); }

Result<VoxelSet> DecodeVoxelSet(std::string_view bytes, size_t voxels, double compact_gain) {
  return VoxelSet::FromPortable(bytes, voxels, compact_gain);
}

}  // namespace vc::wire
