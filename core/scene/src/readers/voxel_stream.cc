// The vc-voxels stream (vc/scene/voxel_stream.h): encoder, and the strict reader behind ReadScene.
//
// Hand-written because it is our own format: 40 lines of varints over zlib, which does the
// compression. The reader checks every declared size against the limits and the bytes present
// before it allocates, inflates to exactly the declared length (so a deflate bomb cannot grow past
// it), and refuses keys that are not strictly ascending or out of range.
#include "vc/scene/voxel_stream.h"

#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>

#include "readers.h"
#include "vc/scene/voxel_scene.h"

namespace vc {
namespace {

constexpr uint32_t kVersion = 2;
// Version 1 (no frame origin: the local frame is the input's) is still read.
constexpr uint32_t kVersionWithoutOrigin = 1;
constexpr size_t kVersion1HeaderBytes = 44;
constexpr uint64_t kMaxPacked = (uint64_t{1} << 48) - 1;
constexpr uint64_t kMaxVarintBytes = 7;  // a 48-bit value

uint64_t Pack(const VoxelKey& k) { return (uint64_t(k.z) << 32) | (uint64_t(k.y) << 16) | uint64_t(k.x); }
VoxelKey Unpack(uint64_t v) { return {uint16_t(v & 0xFFFF), uint16_t((v >> 16) & 0xFFFF), uint16_t(v >> 32)}; }

void PutVarint(std::string& out, uint64_t v) {
  while (v >= 0x80) {
    out += char(uint8_t(v) | 0x80);
    v >>= 7;
  }
  out += char(uint8_t(v));
}

template <typename T>
void Put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // little-endian hosts only (static_assert below)
  out.append(b, sizeof(T));
}

template <typename T>
T Get(std::string_view bytes, size_t at) {
  T v;
  std::memcpy(&v, bytes.data() + at, sizeof(T));
  return v;
}

static_assert(std::endian::native == std::endian::little, "the vc-voxels layout is little-endian");

}  // namespace

Result<std::string> EncodeVoxelStream(const std::vector<VoxelKey>& keys, double resolution_m,
                                      const WorldPoint& frame_origin_m) {
  if (!(std::isfinite(resolution_m) && resolution_m > 0)) {
    return InvalidArgumentError("vc-voxels: the resolution must be finite and positive");
  }
  if (!frame_origin_m.allFinite()) return InvalidArgumentError("vc-voxels: the frame origin must be finite");
  if (keys.empty()) return InvalidArgumentError("vc-voxels: no voxel to encode");
  std::string varints;
  varints.reserve(keys.size() * 2);
  uint64_t previous = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    const uint64_t packed = Pack(keys[i]);
    if (i > 0 && packed <= previous) return InvalidArgumentError("vc-voxels: the keys must be sorted and unique");
    PutVarint(varints, i == 0 ? packed : packed - previous);
    previous = packed;
  }
  uLongf deflated_size = compressBound(uLong(varints.size()));
  std::string deflated(deflated_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(deflated.data()), &deflated_size,
                reinterpret_cast<const Bytef*>(varints.data()), uLong(varints.size()), Z_BEST_COMPRESSION) != Z_OK) {
    return InternalError("vc-voxels: zlib could not compress the keys");
  }
  deflated.resize(deflated_size);
  std::string out(kVoxelStreamMagic);
  Put<uint32_t>(out, kVersion);
  Put<double>(out, resolution_m);
  for (int a = 0; a < 3; ++a) Put<double>(out, frame_origin_m[a]);
  Put<uint64_t>(out, keys.size());
  Put<uint64_t>(out, varints.size());
  Put<uint64_t>(out, deflated.size());
  out += deflated;
  return out;
}

Result<CompactScene> CompactPointCloud(const SceneInput& input, double resolution_m, uint64_t memory_budget_bytes,
                                       const JobContext& ctx) {
  if (input.is_octree()) return FailedPreconditionError("an octree is uploaded as it is, not as a voxel stream");
  if (!input.scan_origins.empty()) {
    return FailedPreconditionError("the input carries scan origins, which a voxel stream does not keep");
  }
  VC_ASSIGN_OR_RETURN(std::vector<VoxelKey> keys, OccupiedKeys(input, resolution_m, memory_budget_bytes, ctx));
  CompactScene compact;
  VC_ASSIGN_OR_RETURN(compact.bytes, EncodeVoxelStream(keys, resolution_m, input.frame_origin_m));
  compact.resolution_m = resolution_m;
  compact.voxels = keys.size();
  return compact;
}

namespace readers {

bool LooksLikeVoxelStream(std::string_view bytes) { return bytes.substr(0, 8) == kVoxelStreamMagic; }

Result<SceneInput> ReadVoxelStream(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  if (bytes.size() < kVersion1HeaderBytes) {
    return InvalidInput(source, "vc-voxels header truncated: " + std::to_string(bytes.size()) + " bytes of " +
                                    std::to_string(kVersion1HeaderBytes));
  }
  const auto version = Get<uint32_t>(bytes, 8);
  if (version != kVersion && version != kVersionWithoutOrigin) {
    return InvalidInput(source,
                        "vc-voxels version " + std::to_string(version) + " at byte 8; this server reads 1 and 2");
  }
  const size_t header_bytes = version == kVersion ? kVoxelStreamHeaderBytes : kVersion1HeaderBytes;
  if (bytes.size() < header_bytes) {
    return InvalidInput(source, "vc-voxels version 2 header truncated: " + std::to_string(bytes.size()) + " bytes of " +
                                    std::to_string(header_bytes));
  }
  const auto resolution = Get<double>(bytes, 12);
  if (!(std::isfinite(resolution) && resolution > 0)) {
    return InvalidInput(source, "vc-voxels resolution at byte 12 is not finite and positive");
  }
  WorldPoint frame_origin_m = WorldPoint::Zero();
  if (version == kVersion) {
    for (int a = 0; a < 3; ++a) frame_origin_m[a] = Get<double>(bytes, 20 + 8 * a);
    if (!frame_origin_m.allFinite()) return InvalidInput(source, "vc-voxels frame origin at byte 20 is not finite");
  }
  // The three sizes follow the resolution (version 1) or the frame origin (version 2).
  const size_t sizes_at = header_bytes - 24;
  const auto count = Get<uint64_t>(bytes, sizes_at), varint_bytes = Get<uint64_t>(bytes, sizes_at + 8),
             deflated = Get<uint64_t>(bytes, sizes_at + 16);
  auto byte = [&](size_t field) { return " (byte " + std::to_string(sizes_at + 8 * field) + ")"; };
  if (count == 0) return InvalidInput(source, "vc-voxels stream of 0 voxels" + byte(0) + "; the scene is empty");
  VC_RETURN_IF_ERROR(CheckPointLimit(count, "vc-voxels stream", source, options));
  if (count > options.max_result_bytes / kBytesPerPoint) {
    return ResourceExhaustedError(std::string(source) + ": vc-voxels stream of " + std::to_string(count) +
                                  " voxels needs more memory than allowed" + std::string(kRaiseResultLimit));
  }
  if (varint_bytes < count || varint_bytes > kMaxVarintBytes * count) {
    return InvalidInput(source, "vc-voxels declares " + std::to_string(varint_bytes) + " key bytes" + byte(1) +
                                    " for " + std::to_string(count) + " voxels; expected " + std::to_string(count) +
                                    " to " + std::to_string(kMaxVarintBytes * count));
  }
  if (varint_bytes > options.max_decompressed_bytes) {
    return ResourceExhaustedError(std::string(source) + ": vc-voxels declares " + std::to_string(varint_bytes) +
                                  " key bytes, more than the limit of " +
                                  std::to_string(options.max_decompressed_bytes) + std::string(kRaiseInputLimit));
  }
  if (deflated != bytes.size() - header_bytes) {
    return InvalidInput(source, "vc-voxels declares " + std::to_string(deflated) + " compressed bytes" + byte(2) +
                                    " but " + std::to_string(bytes.size() - header_bytes) +
                                    " follow the header: truncated or padded");
  }
  std::string varints(varint_bytes, '\0');
  uLongf inflated = uLongf(varint_bytes);
  const int z = uncompress(reinterpret_cast<Bytef*>(varints.data()), &inflated,
                           reinterpret_cast<const Bytef*>(bytes.data() + header_bytes), uLong(deflated));
  if (z != Z_OK || inflated != varint_bytes) {
    return InvalidInput(source,
                        "vc-voxels keys at byte " + std::to_string(header_bytes) + " do not inflate to the declared " +
                            std::to_string(varint_bytes) + " bytes (" +
                            (z == Z_BUF_ERROR ? std::string("more or truncated data") : std::string(zError(z))) + ")");
  }
  SceneInput in;
  in.format = InputFormat::kVoxelStream;
  in.voxel_resolution_m = resolution;
  in.frame_origin_m = frame_origin_m;
  in.points.reserve(count);
  size_t at = 0;
  uint64_t key = 0;
  for (uint64_t i = 0; i < count; ++i) {
    uint64_t v = 0;
    int shift = 0;
    while (true) {
      if (at >= varints.size()) return InvalidInput(source, "vc-voxels keys end inside voxel " + std::to_string(i));
      const auto b = uint8_t(varints[at++]);
      if (shift >= 49) return InvalidInput(source, "vc-voxels key " + std::to_string(i) + " is wider than 48 bits");
      v |= uint64_t(b & 0x7F) << shift;
      shift += 7;
      if (!(b & 0x80)) break;
    }
    if (i > 0 && v == 0) {
      return InvalidInput(source, "vc-voxels voxel " + std::to_string(i) + " repeats the previous one");
    }
    if (v > kMaxPacked - key) {
      return InvalidInput(source, "vc-voxels voxel " + std::to_string(i) + " is past the largest key");
    }
    key += v;
    const WorldPoint c = KeyToCoord(resolution, Unpack(key));
    in.points.emplace_back(float(c.x()), float(c.y()), float(c.z()));
  }
  if (at != varints.size()) {
    return InvalidInput(source,
                        "vc-voxels holds " + std::to_string(varints.size() - at) + " key bytes after its last voxel");
  }
  std::ostringstream detail;
  detail << count << " voxels of " << resolution << " m";
  in.detail = detail.str();
  return in;
}

}  // namespace readers
}  // namespace vc
