// Format detection and dispatch for ReadScene (see scene_input.h); the readers are in readers/.
//
// Detection order: compression magic (gzip, bzip2; decompressed once, then detected again),
// OctoMap headers, PLY, LAS, E57, PCD, plain text (XYZ), and last the binary ScanGraph, which has no
// magic of its own.
#include "vc/scene/scene_input.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "readers/readers.h"
#include "vc/scene/octomap_adapter.h"

namespace vc {
namespace {

constexpr std::string_view kSupported =
    "supported: PLY, PCD v0.7, ASCII XYZ/CSV, LAS 1.0-1.4, E57 1.0, OctoMap .bt/.ot, OctoMap "
    "ScanGraph .graph, vc-voxels (vc-client's compact upload), and gzip/bzip2 copies of these";

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

Result<SceneInput> FromCloud(Result<readers::PointCloud> read, InputFormat format, std::string_view source) {
  if (!read.ok()) return read.status();
  readers::PointCloud& cloud = *read;
  if (cloud.points.empty()) {
    return readers::InvalidInput(source, "all " + std::to_string(cloud.dropped_nonfinite) +
                                             " points have non-finite coordinates; the cloud is "
                                             "empty");
  }
  SceneInput in;
  in.format = format;
  in.detail = std::move(cloud.detail);
  in.points = std::move(cloud.points);
  in.frame_origin_m = cloud.frame.origin_m();
  in.dropped_nonfinite = cloud.dropped_nonfinite;
  return in;
}

// Formats that hold metres (FormatHoldsMetres) take no other unit: an octree's keys are centred on
// its own origin, in metres (it is read as it is, frame origin 0); an E57 file's Cartesian
// coordinates and poses are metres by the standard (ASTM E2807), so a CRS in feet does not make
// them feet (docs/PLANNING.md, "Units"). INVALID_ARGUMENT naming the format's reason otherwise.
Status CheckMetricUnits(InputFormat format, std::string_view source, const ReadOptions& options) {
  if (options.metres_per_unit == 1.0) return Status::Ok();
  std::ostringstream units;
  units << options.metres_per_unit;
  const bool e57 = format == InputFormat::kE57;
  const std::string holds = e57 ? "E57 files hold metres by the standard (ASTM E2807)"
                                : "OctoMap octrees are read in metres (their resolution is in metres)";
  const std::string advice = e57 ? "read the E57 without units (with a CRS in feet, vc-client --crs alone: the file "
                                   "is read in metres)"
                                 : "read the octree without units";
  return readers::InvalidInput(source, holds + ", but units of " + units.str() + " m were given; " + advice);
}

Result<SceneInput> FromOctree(Result<std::shared_ptr<octomap::OcTree>> read, InputFormat format) {
  if (!read.ok()) {
    if (read.status().code() != StatusCode::kResourceExhausted) return read.status();
    return ResourceExhaustedError(read.status().message() + std::string(readers::kRaiseResultLimit));
  }
  SceneInput in;
  in.format = format;
  std::ostringstream detail;
  detail << "resolution " << OctreeResolution(**read) << " m";
  in.detail = detail.str();
  in.octree = std::move(*read);
  return in;
}

Result<SceneInput> ReadE57Input(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  Result<readers::E57Cloud> e57 = readers::ReadE57(bytes, source, options);
  if (!e57.ok()) return e57.status();
  std::vector<Eigen::Vector3d> origins;
  for (const E57Scan& scan : e57->scans) origins.push_back(e57->cloud.frame.ToLocal(scan.translation_m));
  if (e57->cloud.points.empty()) {
    return readers::InvalidInput(source, e57->cloud.detail + ": no valid, finite point (" +
                                             std::to_string(e57->cloud.dropped_nonfinite) +
                                             " non-finite); the cloud is empty");
  }
  VC_ASSIGN_OR_RETURN(SceneInput in, FromCloud(std::move(e57->cloud), InputFormat::kE57, source));
  in.scan_origins = std::move(origins);
  return in;
}

// Binary content with no magic of its own, read as an OctoMap ScanGraph.
Result<SceneInput> ReadGraphInput(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  Result<ScanGraphData> graph = ReadScanGraph(bytes, source, options.metres_per_unit);
  if (!graph.ok()) {
    std::string why = graph.status().message();
    const std::string prefix = std::string(source) + ": ";
    if (why.compare(0, prefix.size(), prefix) == 0) why.erase(0, prefix.size());
    return readers::InvalidInput(source,
                                 "unrecognised format: binary content that is not PLY, PCD, LAS, E57 or OctoMap "
                                 "(" +
                                     std::string(kSupported) + "); read as a ScanGraph: " + why);
  }
  if (graph->points.size() > options.max_points) {
    return ResourceExhaustedError(std::string(source) + ": ScanGraph holds " + std::to_string(graph->points.size()) +
                                  " points, more than the limit of " + std::to_string(options.max_points) +
                                  std::string(readers::kRaiseResultLimit));
  }
  if (graph->points.empty()) {
    return readers::InvalidInput(source, "ScanGraph holds " + std::to_string(graph->origins.size()) +
                                             " scans but no finite points; the cloud is empty");
  }
  SceneInput in;
  in.format = InputFormat::kOctomapGraph;
  in.detail = std::to_string(graph->origins.size()) + " scans";
  in.points = std::move(graph->points);
  in.frame_origin_m = graph->frame_origin_m;
  for (const Eigen::Vector3d& origin_m : graph->origins) in.scan_origins.push_back(origin_m - graph->frame_origin_m);
  in.dropped_nonfinite = graph->dropped_nonfinite;
  return in;
}

Result<SceneInput> ReadDecompressed(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  if (bytes.empty()) return readers::InvalidInput(source, "input is empty (0 bytes)");
  const InputFormat format = DetectInputFormat(bytes);
  switch (format) {
    case InputFormat::kOctomapBinary:
      VC_RETURN_IF_ERROR(CheckMetricUnits(format, source, options));
      return FromOctree(ReadOctreeBinary(bytes, source, options.max_result_bytes), InputFormat::kOctomapBinary);
    case InputFormat::kOctomapText:
      VC_RETURN_IF_ERROR(CheckMetricUnits(format, source, options));
      return FromOctree(ReadOctreeText(bytes, source, options.max_result_bytes), InputFormat::kOctomapText);
    case InputFormat::kVoxelStream:
      return readers::ReadVoxelStream(bytes, source, options);
    case InputFormat::kPly:
      return FromCloud(readers::ReadPly(bytes, source, options), InputFormat::kPly, source);
    case InputFormat::kLas:
      return FromCloud(readers::ReadLas(bytes, source, options), InputFormat::kLas, source);
    case InputFormat::kE57:
      VC_RETURN_IF_ERROR(CheckMetricUnits(format, source, options));
      return ReadE57Input(bytes, source, options);
    case InputFormat::kPcd:
      return FromCloud(readers::ReadPcd(bytes, source, options), InputFormat::kPcd, source);
    case InputFormat::kXyz:
      return FromCloud(readers::ReadXyz(bytes, source, options), InputFormat::kXyz, source);
    case InputFormat::kOctomapGraph:
      break;
  }
  return ReadGraphInput(bytes, source, options);
}

}  // namespace

InputFormat DetectInputFormat(std::string_view bytes) {
  if (StartsWith(bytes, "# Octomap OcTree binary file")) return InputFormat::kOctomapBinary;
  if (StartsWith(bytes, "# Octomap OcTree file")) return InputFormat::kOctomapText;
  if (readers::LooksLikeVoxelStream(bytes)) return InputFormat::kVoxelStream;
  if (readers::LooksLikePly(bytes)) return InputFormat::kPly;
  if (readers::LooksLikeLas(bytes)) return InputFormat::kLas;
  if (LooksLikeE57(bytes)) return InputFormat::kE57;
  if (readers::LooksLikePcd(bytes)) return InputFormat::kPcd;
  if (readers::LooksLikeText(bytes)) return InputFormat::kXyz;
  return InputFormat::kOctomapGraph;
}

Compression DetectCompression(std::string_view bytes) { return readers::DetectCompression(bytes); }

bool FormatHoldsMetres(InputFormat format) {
  return format == InputFormat::kE57 || format == InputFormat::kOctomapBinary || format == InputFormat::kOctomapText;
}

Result<InputFormat> DetectSceneFormat(std::string_view bytes, std::string_view source_name,
                                      const ReadOptions& options) {
  const Compression compression = readers::DetectCompression(bytes);
  if (compression == Compression::kNone) return DetectInputFormat(bytes);
  VC_ASSIGN_OR_RETURN(const std::string plain,
                      readers::Decompress(bytes, compression, source_name, options.max_decompressed_bytes));
  return DetectInputFormat(plain);
}

std::string_view InputFormatName(InputFormat format) {
  switch (format) {
    case InputFormat::kPly:
      return "ply";
    case InputFormat::kPcd:
      return "pcd";
    case InputFormat::kXyz:
      return "xyz";
    case InputFormat::kLas:
      return "las";
    case InputFormat::kOctomapBinary:
      return "octomap-bt";
    case InputFormat::kOctomapText:
      return "octomap-ot";
    case InputFormat::kOctomapGraph:
      return "octomap-graph";
    case InputFormat::kE57:
      return "e57";
    case InputFormat::kVoxelStream:
      return "vc-voxels";
  }
  return "unknown";
}

std::string_view CompressionName(Compression c) {
  switch (c) {
    case Compression::kNone:
      return "none";
    case Compression::kGzip:
      return "gzip";
    case Compression::kBzip2:
      return "bzip2";
  }
  return "unknown";
}

Eigen::Vector3d FrameOriginNear(const Eigen::Vector3d& point_m) {
  return point_m.unaryExpr([](double c) { return 1000.0 * std::round(c / 1000.0); });
}

Result<double> MetresPerUnit(std::string_view unit_name) {
  if (unit_name == "m") return 1.0;
  if (unit_name == "cm") return 0.01;
  if (unit_name == "mm") return 0.001;
  if (unit_name == "ft") return 0.3048;
  if (unit_name == "us-ft") return 1200.0 / 3937.0;
  return InvalidArgumentError("unknown length unit \"" + std::string(unit_name) +
                              "\"; use one of m, cm, mm, ft (international foot), us-ft (US survey foot)");
}

ReadOptions ReadLimits(uint64_t max_upload_bytes, uint64_t memory_budget_bytes) {
  const uint64_t upload = std::max<uint64_t>(max_upload_bytes, 1);
  const uint64_t half_budget = std::max<uint64_t>(memory_budget_bytes / 2, 1);
  const uint64_t by_upload =
      upload > UINT64_MAX / kMaxDecompressionRatio ? UINT64_MAX : upload * kMaxDecompressionRatio;
  ReadOptions o;
  o.max_decompressed_bytes = std::min(by_upload, half_budget);
  o.max_result_bytes = half_budget;
  o.max_points = half_budget / kBytesPerPoint;
  return o;
}

namespace {

Result<SceneInput> ReadSceneUnguarded(std::string_view bytes, std::string_view source_name,
                                      const ReadOptions& options) {
  const std::string_view unsupported = readers::DetectUnsupportedCompression(bytes);
  if (!unsupported.empty()) {
    return readers::InvalidInput(source_name, std::string(unsupported) +
                                                  "-compressed input is not supported; "
                                                  "decompress it first (" +
                                                  std::string(kSupported) + ")");
  }
  const Compression compression = readers::DetectCompression(bytes);
  if (compression == Compression::kNone) {
    if (bytes.size() > options.max_decompressed_bytes) {
      return ResourceExhaustedError(std::string(source_name) + ": input of " + std::to_string(bytes.size()) +
                                    " bytes is more than the limit of " +
                                    std::to_string(options.max_decompressed_bytes) +
                                    std::string(readers::kRaiseInputLimit));
    }
    return ReadDecompressed(bytes, source_name, options);
  }
  VC_ASSIGN_OR_RETURN(const std::string plain,
                      readers::Decompress(bytes, compression, source_name, options.max_decompressed_bytes));
  if (readers::DetectCompression(plain) != Compression::kNone) {
    return readers::InvalidInput(source_name, std::string(CompressionName(compression)) +
                                                  " input holds another compressed stream; "
                                                  "decompress it fully first");
  }
  const std::string label =
      std::string(source_name) + " (" + std::string(CompressionName(compression)) + "-decompressed)";
  Result<SceneInput> in = ReadDecompressed(plain, label, options);
  if (in.ok()) in->compression = compression;
  return in;
}

}  // namespace

Result<SceneInput> ReadScene(std::string_view bytes, std::string_view source_name, const ReadOptions& options) {
  return CatchOutOfMemory(std::string(source_name) + ": reading " + std::to_string(bytes.size()) + " bytes",
                          [&] { return ReadSceneUnguarded(bytes, source_name, options); });
}

Result<SceneInput> ReadSceneFile(const std::string& path, const ReadOptions& options) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return NotFoundError(path + ": is a directory");
  std::ifstream file(path, std::ios::binary);
  if (!file) return NotFoundError(path + ": cannot open file");
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > options.max_decompressed_bytes) {
    return ResourceExhaustedError(path + ": file of " + std::to_string(size) + " bytes is more than the limit of " +
                                  std::to_string(options.max_decompressed_bytes) +
                                  std::string(readers::kRaiseInputLimit));
  }
  std::ostringstream stream;
  stream << file.rdbuf();
  if (file.bad()) return NotFoundError(path + ": read error");
  return ReadScene(std::move(stream).str(), path, options);
}

}  // namespace vc
