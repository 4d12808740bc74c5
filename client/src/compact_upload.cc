#include "vc/client/compact_upload.h"

#include <cctype>
#include <cstdio>
#include <map>
#include <optional>
#include <string_view>

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

// The format a file's name says, by its extension after any .gz / .bz2; none for other names.
std::optional<InputFormat> FormatOfName(std::string_view name) {
  for (std::string_view compressed : {".gz", ".bz2"}) {
    if (name.ends_with(compressed)) name.remove_suffix(compressed.size());
  }
  const size_t dot = name.rfind('.');
  if (dot == std::string_view::npos) return std::nullopt;
  std::string ext(name.substr(dot + 1));
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const std::map<std::string, InputFormat, std::less<>> kByExtension = {
      {"ply", InputFormat::kPly},        {"pcd", InputFormat::kPcd},
      {"xyz", InputFormat::kXyz},        {"txt", InputFormat::kXyz},
      {"csv", InputFormat::kXyz},        {"pts", InputFormat::kXyz},
      {"las", InputFormat::kLas},        {"bt", InputFormat::kOctomapBinary},
      {"ot", InputFormat::kOctomapText}, {"graph", InputFormat::kOctomapGraph},
      {"e57", InputFormat::kE57}};
  const auto it = kByExtension.find(ext);
  if (it == kByExtension.end()) return std::nullopt;
  return it->second;
}

// A format as people call it, a file of it with its article, and the extension it goes by (none
// for a vc-voxels stream).
struct FormatWords {
  const char* name;
  const char* file;
  const char* extension;
};

FormatWords Words(InputFormat format) {
  switch (format) {
    case InputFormat::kPly:
      return {"PLY", "a PLY file", ".ply"};
    case InputFormat::kPcd:
      return {"PCD", "a PCD file", ".pcd"};
    case InputFormat::kXyz:
      return {"XYZ text", "an XYZ text file", ".xyz"};
    case InputFormat::kLas:
      return {"LAS", "a LAS file", ".las"};
    case InputFormat::kOctomapBinary:
      return {"an OctoMap binary octree", "an OctoMap binary octree", ".bt"};
    case InputFormat::kOctomapText:
      return {"an OctoMap text octree", "an OctoMap text octree", ".ot"};
    case InputFormat::kOctomapGraph:
      return {"an OctoMap ScanGraph", "an OctoMap ScanGraph", ".graph"};
    case InputFormat::kE57:
      return {"E57", "an E57 file", ".e57"};
    case InputFormat::kVoxelStream:
      return {"a vc-voxels stream", "a vc-voxels stream", ""};  // vc-client's own upload: no file name
  }
  return {"?", "?", ""};
}

// `file` refused by the reader with `read`, said the way a user sees it: when the name claims one
// format and the (uncompressed) content is another, that comes first.
Status Refused(const Upload& file, const Status& read) {
  const std::optional<InputFormat> named = FormatOfName(file.source_name);
  if (!named || DetectCompression(file.bytes) != Compression::kNone) return read;
  const InputFormat held = DetectInputFormat(file.bytes);
  if (held == *named) return read;
  const FormatWords named_words = Words(*named);
  std::string advice = "it is binary data in no format vc reads; export it again as ";
  if (held != InputFormat::kOctomapGraph) {
    advice = "it looks like " + std::string(Words(held).name) + "; ";
    if (*Words(held).extension != '\0') advice += "rename it " + std::string(Words(held).extension) + ", or ";
    advice += "export it again as ";
  }
  return InvalidArgumentError(file.source_name + " is not " + named_words.file + " (" + advice + named_words.name +
                              "): " + read.message());
}

// The note for a file read as `held` though its name says otherwise; empty when they agree.
std::string FormatNote(const std::string& name, InputFormat held) {
  const std::optional<InputFormat> named = FormatOfName(name);
  if (!named || *named == held) return "";
  return name + " holds " + Words(held).name + ", not " + Words(*named).name + ": read as " + Words(held).name +
         " (vc goes by the content, not the name)";
}

}  // namespace

Result<PreparedUpload> PrepareUpload(Upload file, double resolution_m, bool raw, const JobContext& ctx) {
  if (raw) return Raw(std::move(file), "--raw-upload");
  // The limits vc-server applies with its defaults; a server with larger ones still gets the file.
  ReadOptions read_options = ReadLimits(kDefaultMaxUploadBytes, kDefaultMemoryBudgetBytes);
  if (!file.units.empty()) {
    Result<double> metres_per_unit = MetresPerUnit(file.units);
    if (!metres_per_unit.ok()) return Raw(std::move(file), "not read here: " + metres_per_unit.status().message());
    read_options.metres_per_unit = *metres_per_unit;
  }
  Result<SceneInput> input = ReadScene(file.bytes, file.source_name, read_options);
  if (!input.ok() && input.status().code() == StatusCode::kInvalidArgument) return Refused(file, input.status());
  if (!input.ok()) return Raw(std::move(file), "not read here: " + input.status().message());
  const std::string note = FormatNote(file.source_name, input->format);
  auto raw_with_note = [&note](Upload f, std::string why) {
    PreparedUpload p = Raw(std::move(f), std::move(why));
    p.format_note = note;
    return p;
  };
  if (input->is_octree()) return raw_with_note(std::move(file), "an octree is uploaded as it is");
  if (!input->scan_origins.empty()) return raw_with_note(std::move(file), "the scan origins it carries are kept");
  if (input->format == InputFormat::kVoxelStream) return raw_with_note(std::move(file), "already a vc-voxels stream");
  const double r = resolution_m > 0 ? resolution_m : kDefaultResolutionM;
  Result<CompactScene> compact = CompactPointCloud(*input, r, kDefaultMemoryBudgetBytes, ctx);
  if (!compact.ok()) return raw_with_note(std::move(file), "not voxelised here: " + compact.status().message());
  if (compact->bytes.size() >= file.bytes.size()) {
    return raw_with_note(std::move(file), "the vc-voxels stream is not smaller");
  }
  PreparedUpload p;
  p.format_note = note;
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
