// Internal to vc_core: the per-format readers behind vc::ReadScene (scene_input.h).
//
// Each reader takes the whole (already decompressed) input as bytes and returns the points or a
// Status whose message starts with the source name and names the line or byte offset, what was
// expected and what was found. Readers never throw and never read outside `bytes`: every read is
// bounds-checked, and counts declared in headers are checked against the bytes present before any
// allocation. Thread-safe: no shared state.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/status.h"
#include "vc/scene/e57.h"
#include "vc/scene/scene_input.h"

namespace vc::readers {

// The local frame of one read (docs/PLANNING.md "Coordinates"). Each coordinate is computed in
// double, scaled by ReadOptions::metres_per_unit, and stored as float minus the frame's origin: per
// axis, 1000 m x round(c / 1000 m) of the first point whose coordinates are all finite (as floats,
// in metres). A scene within 500 m of its own origin keeps origin 0 and reads exactly as a plain
// float conversion; a copy shifted by whole kilometres reads to the same local points; survey
// coordinates (x ~ 512,345 m) keep float's precision near the origin (~3e-5 m at 500 m).
class LocalFrame {
 public:
  // Coordinates in input units, `metres_per_unit` metres each.
  explicit LocalFrame(double metres_per_unit) : metres_per_unit_(metres_per_unit) {}

  // (x, y, z) in input units as a local point in metres, or nullopt if a coordinate is not finite
  // as a float (NaN, infinite, beyond float range). The first point that is finite fixes the origin.
  std::optional<Eigen::Vector3f> ToLocal(double x, double y, double z) {
    const Eigen::Vector3d m(x * metres_per_unit_, y * metres_per_unit_, z * metres_per_unit_);
    if (!origin_fixed_) {
      if (!m.cast<float>().allFinite()) return std::nullopt;
      origin_m_ = FrameOriginNear(m);
      origin_fixed_ = true;
    }
    const Eigen::Vector3f local = (m - origin_m_).cast<float>();
    if (!local.allFinite()) return std::nullopt;
    return local;
  }
  // A position in input units (a scan's origin) in the local frame, in metres, in double.
  Eigen::Vector3d ToLocal(const Eigen::Vector3d& input) const { return input * metres_per_unit_ - origin_m_; }
  // The local origin in the input's frame, in metres; zero until the first finite point.
  const Eigen::Vector3d& origin_m() const { return origin_m_; }

 private:
  double metres_per_unit_;
  Eigen::Vector3d origin_m_ = Eigen::Vector3d::Zero();
  bool origin_fixed_ = false;
};

// Points read by a point-cloud reader.
struct PointCloud {
  // A cloud read with `options.metres_per_unit`.
  explicit PointCloud(const ReadOptions& options) : frame(options.metres_per_unit) {}

  // Finite points, in metres, in the local frame `frame`.
  std::vector<Eigen::Vector3f> points;
  // The frame `points` are in; its origin is SceneInput::frame_origin_m.
  LocalFrame frame;
  // Points dropped because a coordinate was NaN, infinite or beyond float range.
  uint64_t dropped_nonfinite = 0;
  // Format specifics for people, e.g. "binary_little_endian 1.0".
  std::string detail;

  // Appends (x, y, z), in input units, in the local frame if it is finite there, else counts it as
  // dropped.
  void Add(double x, double y, double z) {
    if (const std::optional<Eigen::Vector3f> local = frame.ToLocal(x, y, z)) {
      points.push_back(*local);
    } else {
      ++dropped_nonfinite;
    }
  }
};

// --- Compression (decompress.cc) ---

// Compression recognised from the leading magic bytes; kNone if none.
Compression DetectCompression(std::string_view bytes);
// Name of an unsupported container/compressor recognised by its magic ("xz", "zstd", "zip"), or "".
std::string_view DetectUnsupportedCompression(std::string_view bytes);
// Inflates a gzip/zlib (possibly multi-member) or bzip2 (possibly multi-stream) input.
// INVALID_ARGUMENT for truncated or corrupt streams, RESOURCE_EXHAUSTED past `max_bytes`.
Result<std::string> Decompress(std::string_view bytes, Compression compression, std::string_view source,
                               uint64_t max_bytes);
// Decompresses one LZF block (liblzf format, as PCD binary_compressed uses) of exactly
// `expected_size` bytes. INVALID_ARGUMENT (message without source) when corrupt or the size
// differs.
Result<std::string> LzfDecompress(std::string_view compressed, size_t expected_size);

// --- Format readers ---

// True if `bytes` starts with the PLY magic line.
bool LooksLikePly(std::string_view bytes);
// Reads PLY ascii / binary_little_endian / binary_big_endian (ply_reader.cc).
Result<PointCloud> ReadPly(std::string_view bytes, std::string_view source, const ReadOptions& options);

// True if the first non-comment header line is a PCD keyword (VERSION, FIELDS).
bool LooksLikePcd(std::string_view bytes);
// Reads PCD v0.7 ascii / binary / binary_compressed (pcd_reader.cc).
Result<PointCloud> ReadPcd(std::string_view bytes, std::string_view source, const ReadOptions& options);

// True if `bytes` starts with "LASF".
bool LooksLikeLas(std::string_view bytes);
// Reads ASPRS LAS 1.0-1.4, point formats 0-10, uncompressed (las_reader.cc).
Result<PointCloud> ReadLas(std::string_view bytes, std::string_view source, const ReadOptions& options);

// What ReadE57 read: the points of every scan (world frame, then local), and the scans (their
// poses in the file's world frame and units).
struct E57Cloud {
  PointCloud cloud;
  std::vector<E57Scan> scans;
};
// Reads ASTM E57 1.0: every /data3D scan's points, transformed by its pose (e57_reader.cc). Detect
// with LooksLikeE57 (vc/scene/e57.h).
Result<E57Cloud> ReadE57(std::string_view bytes, std::string_view source, const ReadOptions& options);

// True if the start of `bytes` is plain text (printable ASCII, UTF-8 and whitespace, no NUL).
bool LooksLikeText(std::string_view bytes);
// Reads ASCII x y z per line, space/comma/tab separated, optional header line (xyz_reader.cc).
Result<PointCloud> ReadXyz(std::string_view bytes, std::string_view source, const ReadOptions& options);

// vc-voxels (voxel_stream.cc; vc/scene/voxel_stream.h): starts with "VCVOXELS".
bool LooksLikeVoxelStream(std::string_view bytes);
// One point per voxel centre (local frame), voxel_resolution_m and frame_origin_m set (version 1:
// origin 0). INVALID_ARGUMENT naming the byte or voxel,
// RESOURCE_EXHAUSTED past the limits.
Result<SceneInput> ReadVoxelStream(std::string_view bytes, std::string_view source, const ReadOptions& options);

// --- Shared helpers ---

// "source: message" as an INVALID_ARGUMENT status.
inline Status InvalidInput(std::string_view source, std::string_view message) {
  std::string m(source);
  m += ": ";
  m += message;
  return InvalidArgumentError(std::move(m));
}

// Ends a message about ReadOptions::max_decompressed_bytes: how the user raises it (ReadLimits).
static_assert(kMaxDecompressionRatio == 16, "kRaiseInputLimit names the ratio");
inline constexpr std::string_view kRaiseInputLimit =
    " (16 x --max-upload-bytes, at most half of --memory-budget-bytes); send a smaller or less "
    "compressible scene, or raise --max-upload-bytes or --memory-budget-bytes";
// Ends a message about max_points / max_result_bytes: how the user raises them (ReadLimits).
inline constexpr std::string_view kRaiseResultLimit =
    " (set by --memory-budget-bytes); send a smaller scene or raise --memory-budget-bytes";

// RESOURCE_EXHAUSTED when a declared point count is above options.max_points.
inline Status CheckPointLimit(uint64_t declared, std::string_view what, std::string_view source,
                              const ReadOptions& options) {
  if (declared <= options.max_points) return Status::Ok();
  return ResourceExhaustedError(std::string(source) + ": " + std::string(what) + " declares " +
                                std::to_string(declared) + " points, more than the limit of " +
                                std::to_string(options.max_points) + std::string(kRaiseResultLimit));
}

// Parses all of `token` as a decimal floating-point number (leading '+' allowed, "nan"/"inf" too).
bool ParseDouble(std::string_view token, double* value);
// Parses all of `token` as a non-negative decimal integer that fits in uint64.
bool ParseUint64(std::string_view token, uint64_t* value);
// `text` shortened to at most 40 characters for error messages, non-printables escaped.
std::string Quote(std::string_view text);

// Splits `text` at runs of space/tab characters.
std::vector<std::string_view> SplitWhitespace(std::string_view text);

// Reads a T stored at bytes[offset] (caller checked bounds) in little- or big-endian order.
template <typename T>
T LoadScalar(const char* p, bool big_endian) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (big_endian) {
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

// A line cursor over text: yields lines without their "\n" / "\r\n", tracking 1-based numbers and
// byte offsets.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text) {}
  // Next line into *line; false at end of text.
  bool Next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    const size_t end = text_.find('\n', pos_);
    const size_t stop = end == std::string_view::npos ? text_.size() : end;
    *line = text_.substr(pos_, stop - pos_);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    line_start_ = pos_;
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++line_number_;
    return true;
  }
  // 1-based number of the line last returned.
  uint64_t line_number() const { return line_number_; }
  // Byte offset of the line last returned.
  size_t line_start() const { return line_start_; }
  // Byte offset just past the line last returned (start of the next).
  size_t position() const { return pos_; }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  size_t line_start_ = 0;
  uint64_t line_number_ = 0;
};

}  // namespace vc::readers
