// A visibility set (vc::VoxelSet) on the wire between replicas: a Roaring bitmap of its voxel ids
// in the portable format (github.com/RoaringBitmap/RoaringFormatSpec), run-optimized, by Debian's
// CRoaring (VoxelSet::ToPortable / FromPortable). ShardResponse.sets carries one per viewpoint
// (docs/DEPLOY.md, "Scaling out").
//
// Why Roaring and not the dense words: a station's view of a large site is a small share of its
// voxels, often in runs (a wall seen end to end), and Roaring's containers (arrays, bitmaps, runs)
// pick the smallest form per 65536 ids; a dense set never grows past its words plus a few bytes
// per 65536 ids. Pure functions, thread-safe.
#pragma once

#include <string>
#include <string_view>

#include "vc/base/status.h"
#include "vc/visibility/visibility.h"

namespace vc::wire {

// The set's ids as a portable Roaring bitmap.
std::string EncodeVoxelSet(const VoxelSet& set);
// The set of `voxels` voxels encoded in `bytes`, kept sparse when that is `compact_gain` times
// smaller (VoxelSet::Compact; 0 = dense). DATA_LOSS when `bytes` is not a whole portable Roaring
// bitmap or names an id >= voxels.
Result<VoxelSet> DecodeVoxelSet(std::string_view bytes, size_t voxels, double compact_gain = 0);

}  // namespace vc::wire
