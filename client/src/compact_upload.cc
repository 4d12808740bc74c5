#include "vc/client/compact_upload.h"

#include <cstdio>

#include "vc/scene/scene_input.h"
#include "vc/scene/voxel_scene.h"
#include "vc/scene/voxel_stream.h"

namespace vc::client {
namespace {

PreparedUpload Raw(Upload file, std::string why) {
  PreparedUpload p;
  p.summary.format = "raw";
  p.summary.bytes_sent = file.bytes.size();
  p.summary.file_bytes = file.bytes.size();
  p.summary.why_raw = std::move(why);
  p.summary.units = file.units;
  p.upload = std::move(file);
  return p;
}

}  // namespace

PreparedUpload PrepareUpload(Upload file, double resolution_m, bool raw, const JobContext& ctx) {
  if (raw) return Raw(std::move(file), "--raw-upload");
  // The limits vc-server applies with its defaults; a server with larger ones still gets the file.
  ReadOptions read_options = ReadLimits(kDefaultMaxUploadBytes, kDefaultMemoryBudgetBytes);
  if (!file.units.empty()) {
    Result<double> metres_per_unit = MetresPerUnit(file.units);
    if (!metres_per_unit.ok()) return Raw(std::move(file), "not read here: " + metres_per_unit.status().message());
    read_options.metres_per_unit = *metres_per_unit;
  }
  Result<SceneInput> input = ReadScene(file.bytes, file.source_name, read_options);
  if (!input.ok()) return Raw(std::move(file), "not read here: " + input.status().message());
  if (input->is_octree()) return Raw(std::move(file), "an octree is uploaded as it is");
  if (!input->scan_origins.empty()) return Raw(std::move(file), "the scan origins it carries are kept");
  if (input->format == InputFormat::kVoxelStream) return Raw(std::move(file), "already a vc-voxels stream");
  const double r = resolution_m > 0 ? resolution_m : kDefaultResolutionM;
  Result<CompactScene> compact = CompactPointCloud(*input, r, kDefaultMemoryBudgetBytes, ctx);
  if (!compact.ok()) return Raw(std::move(file), "not voxelised here: " + compact.status().message());
  if (compact->bytes.size() >= file.bytes.size()) return Raw(std::move(file), "the vc-voxels stream is not smaller");
  PreparedUpload p;
  p.summary.format = "vc-voxels";
  p.summary.bytes_sent = compact->bytes.size();
  p.summary.file_bytes = file.bytes.size();
  p.summary.voxels = compact->voxels;
  p.summary.resolution_m = r;
  p.summary.units = file.units;
  // The stream's voxels are in metres already: it goes out without units.
  p.upload = Upload{std::move(compact->bytes), std::move(file.source_name), ""};
  return p;
}

std::string DescribeUpload(const UploadSummary& s) {
  char line[256];
  if (s.format == "vc-voxels") {
    std::snprintf(line, sizeof line, "compact upload: %llu voxels of %g m, %llu bytes instead of the file's %llu",
                  static_cast<unsigned long long>(s.voxels), s.resolution_m,
                  static_cast<unsigned long long>(s.bytes_sent), static_cast<unsigned long long>(s.file_bytes));
    return line;
  }
  std::snprintf(line, sizeof line, "raw upload of %llu bytes", static_cast<unsigned long long>(s.bytes_sent));
  return std::string(line) + " (" + s.why_raw + ")";
}

}  // namespace vc::client
