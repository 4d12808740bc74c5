#include "vc/client/export_sets.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace vc::client {

namespace fs = std::filesystem;

namespace {

bool IsStationFile(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.rfind("station_", 0) == 0 && p.extension() == ".xyz";
}

// "3 files, e.g. notes.txt".
std::string DescribeEntries(const fs::path& dir) {
  std::error_code ec;
  size_t n = 0;
  std::string first;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (n++ == 0) first = e.path().filename().string();
  }
  return std::to_string(n) + (n == 1 ? " entry, " : " entries, e.g. ") + first;
}

}  // namespace

Status PrepareExportDir(const std::string& dir, bool force) {
  const fs::path path(dir);
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    if (!fs::create_directories(path, ec) && ec) {
      return PermissionDeniedError("--export-sets " + dir + ": cannot create the directory (" + ec.message() + ")");
    }
  } else if (!fs::is_directory(path, ec)) {
    return InvalidArgumentError("--export-sets " + dir + " exists and is not a directory; name a new or empty one");
  } else if (!fs::is_empty(path, ec)) {
    if (!force) {
      return InvalidArgumentError("--export-sets " + dir + " is not empty (" + DescribeEntries(path) +
                                  "); name a new or empty directory, or add --force to write into it (its "
                                  "station_*.xyz files are replaced)");
    }
    for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
      if (e.is_regular_file() && IsStationFile(e.path())) fs::remove(e.path(), ec);
    }
  }
  // A probe: a directory that exists may still refuse files (permissions, a read-only mount).
  const fs::path probe = path / ".vc-write-probe";
  if (std::FILE* f = std::fopen(probe.c_str(), "wb")) {
    std::fclose(f);
    fs::remove(probe, ec);
    return Status::Ok();
  }
  return PermissionDeniedError("--export-sets " + dir + ": cannot write into the directory (" + std::strerror(errno) +
                               ")");
}

std::string SeenVoxelLine(const WorldPoint& center_local_m, const WorldPoint& frame_origin_m) {
  char buf[96];
  char* p = buf;
  char* const end = buf + sizeof(buf);
  for (int a = 0; a < 3; ++a) {
    if (a > 0) *p++ = ' ';
    // Rounded to the millimetre, then printed with 3 decimals: -0.0004 prints as 0.000, not -0.000.
    const double mm = std::nearbyint((center_local_m[a] + frame_origin_m[a]) * 1000.0) / 1000.0;
    p = std::to_chars(p, end, mm == 0.0 ? 0.0 : mm, std::chars_format::fixed, 3).ptr;
  }
  return std::string(buf, p);
}

Result<std::vector<std::string>> WriteSeenSets(const EvaluateJobResult& result, const std::string& dir) {
  if (result.seen_sets.empty()) {
    return FailedPreconditionError("the server sent no seen sets (an older vc-server?); --export-sets needs them");
  }
  std::vector<std::string> written;
  for (size_t k = 0; k < result.seen_sets.size(); ++k) {
    const std::string path = (fs::path(dir) / ("station_" + std::to_string(k + 1) + ".xyz")).string();
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) return PermissionDeniedError("cannot write " + path + ": " + std::strerror(errno));
    std::string text;
    result.seen_sets[k].ForEach([&](size_t id) {
      text += SeenVoxelLine(result.voxel_centers[id], result.frame_origin_m);
      text += '\n';
    });
    out.write(text.data(), std::streamsize(text.size()));
    out.close();
    if (!out) return PermissionDeniedError("cannot write " + path + " (disk full?)");
    written.push_back(path);
  }
  return written;
}

}  // namespace vc::client
