// The compact upload: a scene's occupied voxels as a compressed stream of voxel keys ("vc-voxels",
// docs/PROTOCOL.md "Compact uploads"), instead of the raw points they came from.
//
// vc-client voxelises a point cloud at the working resolution with the same function the server
// uses (OccupiedKeys) and uploads the keys; the server reads the stream back as one point at each
// voxel's centre (ReadScene, format kVoxelStream), which voxelises to exactly the same voxels at
// that resolution, so a plan from a compact upload is the plan from the raw cloud. A stream can
// only be planned at its own resolution (Voxelize refuses another).
//
// Layout, little-endian: "VCVOXELS" (8 bytes), version u32 = 1, resolution_m f64, voxel count
// u64 N, varint bytes u64 L, deflated bytes u64 P, then P bytes: zlib (RFC 1950) of L bytes that
// hold N unsigned LEB128 varints: the first voxel's packed key (z << 32 | y << 16 | x, OctoMap
// keys), then each next key's increase (>= 1; keys strictly ascending). Nothing follows.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/base/progress.h"
#include "vc/base/status.h"
#include "vc/scene/scene_input.h"

namespace vc {

inline constexpr std::string_view kVoxelStreamMagic = "VCVOXELS";
inline constexpr size_t kVoxelStreamHeaderBytes = 44;

// The stream of `keys` (sorted by VoxelKey's order, unique, non-empty) at `resolution_m`.
// INVALID_ARGUMENT if they are not, or for a resolution that is not finite and positive.
Result<std::string> EncodeVoxelStream(const std::vector<VoxelKey>& keys, double resolution_m);

// What a compact upload holds and what it saved.
struct CompactScene {
  std::string bytes;  // the vc-voxels stream
  double resolution_m = 0;
  uint64_t voxels = 0;
};

// The compact upload of a point cloud `input` at `resolution_m` (OccupiedKeys, then
// EncodeVoxelStream). FAILED_PRECONDITION for an octree or an input that carries scan origins
// (they would be lost: upload those as they are); errors of OccupiedKeys otherwise.
Result<CompactScene> CompactPointCloud(const SceneInput& input, double resolution_m, uint64_t memory_budget_bytes,
                                       const JobContext& ctx = {});

}  // namespace vc
