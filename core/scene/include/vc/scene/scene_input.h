// Reading every input format a user brings: point clouds and OctoMap octrees.
//
// The format is detected from the content (magic bytes, header), never from the file name.
// gzip- and bzip2-compressed copies of the text formats are decompressed transparently. Every
// failure is a Status whose message names the source, the byte offset or line, what was expected
// and what was found. Non-finite points are dropped and counted. Sizes declared in headers are
// checked against the bytes actually present before any allocation, so a lying header cannot
// trigger a huge allocation. Coordinates are read in double, scaled to metres and stored as floats
// relative to a local frame chosen from the data, so survey coordinates keep their precision
// (docs/PLANNING.md "Coordinates"). Thread-safe: functions here share no state.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/status.h"

namespace octomap {
class OcTree;
}

namespace vc {

enum class InputFormat {
  kPly,
  kPcd,
  kXyz,            // ASCII x y z per line (space, comma or tab), optional header line
  kLas,            // ASPRS LAS 1.0-1.4, uncompressed
  kOctomapBinary,  // OctoMap .bt
  kOctomapText,    // OctoMap .ot (full, any AbstractOcTree stream of type OcTree)
  kOctomapGraph,   // OctoMap ScanGraph .graph (points plus each scan's origin)
  kE57,            // ASTM E57 1.0 (E2807): every scan's points in the world frame, and its origin
  kVoxelStream,    // vc-voxels: a compact upload's occupied voxels (vc/scene/voxel_stream.h)
};

// "ply", "pcd", "xyz", "las", "octomap-bt", "octomap-ot", "octomap-graph", "e57", "vc-voxels".
std::string_view InputFormatName(InputFormat format);

enum class Compression { kNone, kGzip, kBzip2 };
std::string_view CompressionName(Compression c);  // "none", "gzip", "bzip2"

// Decompressed bytes allowed per byte of the upload limit (see ReadLimits). Real scans compress
// 2-8x (the hall scan's bzip2: 2.9x); a zero-filled bomb compresses up to 1000x (gzip) or far more
// (bzip2), so 16 leaves room for compressible clouds and refuses bombs.
inline constexpr uint64_t kMaxDecompressionRatio = 16;
// vc-server's default --max-upload-bytes, in bytes.
inline constexpr uint64_t kDefaultMaxUploadBytes = uint64_t{1} << 30;
// Bytes one read point takes in SceneInput::points.
inline constexpr uint64_t kBytesPerPoint = sizeof(Eigen::Vector3f);

// Limits that protect the process from hostile or broken inputs. Every limit is checked before
// the memory it guards is allocated (decompression is checked while streaming). The defaults are
// ReadLimits(kDefaultMaxUploadBytes, kDefaultMemoryBudgetBytes) (voxel_scene.h: 4 GiB).
struct ReadOptions {
  // Refuse inputs that are, or decompress to, more than this many bytes.
  uint64_t max_decompressed_bytes = uint64_t{2} << 30;
  // Refuse clouds with more points than this (checked against the header before reading).
  uint64_t max_points = (uint64_t{2} << 30) / kBytesPerPoint;
  // Refuse inputs whose parsed form (points, OctoMap nodes) would take more than this many bytes.
  uint64_t max_result_bytes = uint64_t{2} << 30;
  // Metres per unit of the input's coordinates (vc-client --units; MetresPerUnit): points are
  // scaled by this as they are read. 1 for metres. Octrees and E57 files are read in metres only
  // (FormatHoldsMetres; other units are INVALID_ARGUMENT); a vc-voxels stream is in metres already
  // and is not scaled.
  double metres_per_unit = 1.0;
};

// The local frame's origin for data whose first finite point is `point_m` (metres, the input's
// frame): per axis the nearest whole number of kilometres (docs/PLANNING.md, "Coordinates"). The
// readers' rule, and the one to use for any other data that needs a frame of its own.
Eigen::Vector3d FrameOriginNear(const Eigen::Vector3d& point_m);

// Metres per unit, by the unit's name: "m" 1, "cm" 0.01, "mm" 0.001, "ft" 0.3048 (international
// foot), "us-ft" 1200/3937 (US survey foot). INVALID_ARGUMENT naming the accepted names otherwise.
Result<double> MetresPerUnit(std::string_view unit_name);

// The read limits for a job allowed `max_upload_bytes` of (compressed) upload and a memory budget
// of `memory_budget_bytes`: decompressed bytes at most min(kMaxDecompressionRatio x the upload
// limit, half the budget); the parsed result at most half the budget. vc-server and vc-client
// inspect both call this, so they accept the same inputs. Zero arguments are treated as 1.
ReadOptions ReadLimits(uint64_t max_upload_bytes, uint64_t memory_budget_bytes);

// What was read. Exactly one of `points` (point formats, .graph) or `octree` (.bt/.ot) is filled.
struct SceneInput {
  InputFormat format = InputFormat::kXyz;
  Compression compression = Compression::kNone;
  // Format specifics for people, e.g. "binary_little_endian 1.0", "binary_compressed", "LAS 1.2 PDRF 1".
  std::string detail;
  // Points in metres, local frame: the input's coordinates (LAS scale and offset applied; E57 and
  // .graph scans transformed by their poses), computed in double, scaled by
  // ReadOptions::metres_per_unit, minus frame_origin_m. Non-finite points, and E57 records marked
  // invalid, are not here.
  std::vector<Eigen::Vector3f> points;
  // .graph and .e57 only: the sensor origin of each scan, in metres, local frame.
  std::vector<Eigen::Vector3d> scan_origins;
  // Where the local frame's origin lies in the input's own frame, in metres: `points` and
  // `scan_origins` are input coordinates minus this (docs/PLANNING.md, "Coordinates"). Per axis
  // 1000 m x round(c / 1000 m) of the first finite point: zero for a scene within 500 m of its
  // frame's origin and for octrees; a whole number of kilometres for survey coordinates.
  Eigen::Vector3d frame_origin_m = Eigen::Vector3d::Zero();
  // .bt/.ot only: the tree as read, at its own resolution.
  std::shared_ptr<const octomap::OcTree> octree;
  // Points dropped because a coordinate was NaN or infinite.
  uint64_t dropped_nonfinite = 0;
  // vc-voxels only: the voxel edge (m) the points are the centres of; the scene can only be
  // voxelised at this resolution (Voxelize). 0 for every other format.
  double voxel_resolution_m = 0;

  bool is_octree() const { return octree != nullptr; }
};

// Detects the format of `bytes` (after decompression) and parses it. `source_name` only labels
// error messages (a file name or "upload"). Errors: INVALID_ARGUMENT for malformed or unsupported
// content (truncated, wrong counts, unknown types, LAZ, a bad E57 page checksum, empty cloud),
// RESOURCE_EXHAUSTED when a limit in `options` is exceeded, or when memory runs out while reading
// (never an exception).
Result<SceneInput> ReadScene(std::string_view bytes, std::string_view source_name, const ReadOptions& options = {});

// The format ReadScene reads uncompressed `bytes` as, from their first bytes (its own dispatch):
// binary content with no magic of its own is tried as an OctoMap ScanGraph (kOctomapGraph).
[[nodiscard]] InputFormat DetectInputFormat(std::string_view bytes);
// The compression ReadScene finds around `bytes` (gzip, bzip2 magic; kNone otherwise).
[[nodiscard]] Compression DetectCompression(std::string_view bytes);
// The format ReadScene reads `bytes` as: DetectInputFormat after any gzip or bzip2 (a compressed
// input is decompressed for it, within options.max_decompressed_bytes). The decompression's errors.
[[nodiscard]] Result<InputFormat> DetectSceneFormat(std::string_view bytes, std::string_view source_name,
                                                    const ReadOptions& options = {});
// Whether `format` fixes its coordinates' unit to metres, so that no --units applies: E57 (ASTM
// E2807 stores Cartesian coordinates in metres) and OctoMap octrees (their resolution is in metres).
[[nodiscard]] bool FormatHoldsMetres(InputFormat format);

// Reads a whole file and calls ReadScene. NOT_FOUND if it cannot be opened.
Result<SceneInput> ReadSceneFile(const std::string& path, const ReadOptions& options = {});

}  // namespace vc
