// The compact upload: a scene's occupied voxels as a compressed stream of voxel keys ("vc-voxels",
// docs/PROTOCOL.md "Compact uploads"), instead of the raw points they came from.
//
// vc-client voxelises a point cloud at the working resolution with the same function the server
// uses (OccupiedKeys) and uploads the keys; the server reads the stream back as one point at each
// voxel's centre (ReadScene, format kVoxelStream), which voxelises to exactly the same voxels at
// that resolution, so a plan from a compact upload is the plan from the raw cloud. A stream can
// only be planned at its own resolution (Voxelize refuses another). The keys are in the input's
// local frame; the stream carries that frame's origin (SceneInput::frame_origin_m), so the server
// reads the same local points and the same origin as the client. It is in metres (the client
// applied any units before voxelising): ReadOptions::metres_per_unit does not apply to it.
//
// Layout, little-endian: "VCVOXELS" (8 bytes), version u32 = 2, resolution_m f64, frame origin
// 3 x f64 (x, y, z in metres, in the input's frame), voxel count u64 N, varint bytes u64 L,
// deflated bytes u64 P, then P bytes: zlib (RFC 1950) of L bytes that hold N unsigned LEB128
// varints: the first voxel's packed key (z << 32 | y << 16 | x, OctoMap keys), then each next
// key's increase (>= 1; keys strictly ascending). Nothing follows. Version 1 (still read) is the
// same without the frame origin (origin 0; a 44-byte header).
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
// Bytes before the compressed keys in a version 2 stream (the version this code writes).
inline constexpr size_t kVoxelStreamHeaderBytes = 68;

// The version 2 stream of `keys` (sorted by VoxelKey's order, unique, non-empty) at `resolution_m`,
// in a local frame whose origin is `frame_origin_m` (m, input frame). INVALID_ARGUMENT if the keys
// are not, for a resolution that is not finite and positive, or an origin that is not finite.
Result<std::string> EncodeVoxelStream(const std::vector<VoxelKey>& keys, double resolution_m,
                                      const WorldPoint& frame_origin_m = WorldPoint::Zero());

// What a compact upload holds and what it saved.
struct CompactScene {
  std::string bytes;  // the vc-voxels stream
  double resolution_m = 0;
  uint64_t voxels = 0;
};

// The compact upload of a point cloud `input` at `resolution_m` (OccupiedKeys, then
// EncodeVoxelStream with the input's frame origin). FAILED_PRECONDITION for an octree or an input that carries scan
// origins (they would be lost: upload those as they are); errors of OccupiedKeys otherwise.
Result<CompactScene> CompactPointCloud(const SceneInput& input, double resolution_m, uint64_t memory_budget_bytes,
                                       const JobContext& ctx = {});

}  // namespace vc
