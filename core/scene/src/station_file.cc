#include "vc/scene/station_file.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include "readers/readers.h"
#include "vc/scene/e57.h"
#include "vc/scene/octomap_adapter.h"

namespace vc {
namespace {

using readers::LineCursor;
using readers::ParseDouble;
using readers::Quote;

constexpr double kDegToRad = M_PI / 180.0;

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// A row's fields: split at ';' when the line has one (so "1,5" stays one field, a decimal comma the
// number check then refuses), else at ',' when it has one, else at runs of spaces and tabs.
std::vector<std::string_view> SplitRow(std::string_view line) {
  const char separator = line.find(';') != std::string_view::npos   ? ';'
                         : line.find(',') != std::string_view::npos ? ','
                                                                    : '\0';
  if (separator == '\0') return readers::SplitWhitespace(line);
  std::vector<std::string_view> fields;
  for (size_t pos = 0;;) {
    const size_t end = line.find(separator, pos);
    fields.push_back(Trim(line.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos)));
    if (end == std::string_view::npos) break;
    pos = end + 1;
  }
  return fields;
}

// Which column holds what (-1: none). Without a header: x, y, z are the first three.
struct Columns {
  int x = 0, y = 1, z = 2;
  int yaw = -1, roll = -1, pitch = -1, name = -1;
  bool angles_in_rad = false;
  size_t needed() const { return size_t(std::max({x, y, z, yaw, roll, pitch, name})) + 1; }
};

// The columns a header line names; INVALID_ARGUMENT (`where`) when x, y or z is missing.
Result<Columns> HeaderColumns(const std::vector<std::string_view>& fields, const std::string& where,
                              std::string_view line) {
  Columns c;
  c.x = c.y = c.z = -1;
  int name_column = -1, id_column = -1;
  for (size_t i = 0; i < fields.size(); ++i) {
    std::string n = Lower(fields[i]);
    const int k = static_cast<int>(i);
    bool rad = false;
    for (const char* suffix : {"_m", "_deg", "_rad"}) {
      const std::string s(suffix);
      if (n.size() > s.size() && n.compare(n.size() - s.size(), s.size(), s) == 0) {
        rad = s == "_rad";
        n.resize(n.size() - s.size());
        break;
      }
    }
    if (n == "x") c.x = k;
    if (n == "y") c.y = k;
    if (n == "z") c.z = k;
    if (n == "yaw" || n == "heading") c.yaw = k;
    if (n == "roll") c.roll = k;
    if (n == "pitch") c.pitch = k;
    if (n == "roll" || n == "pitch" || n == "yaw" || n == "heading") c.angles_in_rad = c.angles_in_rad || rad;
    if (n == "name") name_column = k;
    if ((n == "id" || n == "station") && id_column < 0) id_column = k;
  }
  c.name = name_column >= 0 ? name_column : id_column;  // vc's stations.csv has both "station" and "name"
  if (c.x < 0 || c.y < 0 || c.z < 0) {
    return InvalidArgumentError(
        where + "the header " + Quote(line) +
        " names no x, y and z columns (expected e.g. \"x,y,z\" or \"name,x,y,z,roll,pitch,yaw\")");
  }
  return c;
}

// A header has no field that reads as a number.
bool IsHeader(const std::vector<std::string_view>& fields) {
  return std::none_of(fields.begin(), fields.end(), [](std::string_view f) {
    double v;
    return ParseDouble(f, &v);
  });
}

// The finite number in column `column` (named `what`) of `fields`; INVALID_ARGUMENT (`where`) otherwise.
Result<double> FiniteField(const std::vector<std::string_view>& fields, int column, const char* what,
                           const std::string& where) {
  double v = 0;
  if (!ParseDouble(fields[size_t(column)], &v)) {
    return InvalidArgumentError(where + std::string(what) + " (column " + std::to_string(column + 1) + ") " +
                                Quote(fields[size_t(column)]) + " is not a number");
  }
  if (!std::isfinite(v)) {
    return InvalidArgumentError(where + std::string(what) + " (column " + std::to_string(column + 1) + ") is " +
                                Quote(fields[size_t(column)]) + "; values must be finite");
  }
  return v;
}

// One data row as a station.
Result<KnownStation> ParseRow(const std::vector<std::string_view>& fields, const Columns& c, const std::string& where,
                              std::string_view line) {
  if (fields.size() < c.needed()) {
    return InvalidArgumentError(where + "expected at least " + std::to_string(c.needed()) + " columns, found " +
                                std::to_string(fields.size()) + ": " + Quote(line));
  }
  KnownStation s;
  VC_ASSIGN_OR_RETURN(const double x, FiniteField(fields, c.x, "x", where));
  VC_ASSIGN_OR_RETURN(const double y, FiniteField(fields, c.y, "y", where));
  VC_ASSIGN_OR_RETURN(const double z, FiniteField(fields, c.z, "z", where));
  s.position_m = WorldPoint(x, y, z);
  if (c.roll >= 0) VC_RETURN_IF_ERROR(FiniteField(fields, c.roll, "roll", where).status());
  if (c.pitch >= 0) VC_RETURN_IF_ERROR(FiniteField(fields, c.pitch, "pitch", where).status());
  if (c.yaw >= 0) {
    VC_ASSIGN_OR_RETURN(const double yaw, FiniteField(fields, c.yaw, "yaw", where));
    s.heading_rad = c.angles_in_rad ? yaw : yaw * kDegToRad;
  }
  if (c.name >= 0) s.name = std::string(fields[size_t(c.name)]);
  s.source = where.substr(0, where.size() - 2);
  return s;
}

Result<std::vector<KnownStation>> ParseText(std::string_view bytes, std::string_view source) {
  constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";  // spreadsheet exports start with one
  if (bytes.substr(0, kUtf8Bom.size()) == kUtf8Bom) bytes.remove_prefix(kUtf8Bom.size());
  std::vector<KnownStation> out;
  Columns columns;
  bool first_row = true;
  LineCursor lines(bytes);
  std::string_view raw;
  while (lines.Next(&raw)) {
    std::string_view line = raw.substr(0, raw.find('#'));
    line = Trim(line);
    if (line.empty()) continue;
    const std::string where = std::string(source) + ":" + std::to_string(lines.line_number()) + ": ";
    const std::vector<std::string_view> fields = SplitRow(line);
    if (first_row && IsHeader(fields)) {
      first_row = false;
      VC_ASSIGN_OR_RETURN(columns, HeaderColumns(fields, where, line));
      continue;
    }
    first_row = false;
    VC_ASSIGN_OR_RETURN(KnownStation s, ParseRow(fields, columns, where, line));
    out.push_back(std::move(s));
  }
  if (out.empty()) {
    return InvalidArgumentError(std::string(source) +
                                ": no station found (expected lines \"x,y,z\", a header naming x, y and z, an E57, "
                                "an OctoMap .graph or a PCD file with a VIEWPOINT)");
  }
  return out;
}

// Yaw of the scanner's +x axis in the world's xy plane; none when that axis is vertical.
std::optional<double> HeadingOf(const Eigen::Quaterniond& rotation) {
  const Eigen::Vector3d forward = rotation.normalized() * Eigen::Vector3d::UnitX();
  if (std::hypot(forward.x(), forward.y()) < 1e-9) return std::nullopt;
  return std::atan2(forward.y(), forward.x());
}

// A station from a binary pose; INVALID_ARGUMENT naming `where` when not finite.
Result<KnownStation> PoseStation(const Eigen::Vector3d& translation_m, const Eigen::Quaterniond& rotation,
                                 std::string name, std::string where) {
  if (!translation_m.allFinite()) return InvalidArgumentError(where + ": the origin is not finite");
  KnownStation s;
  s.position_m = translation_m;
  if (rotation.coeffs().allFinite()) s.heading_rad = HeadingOf(rotation);
  s.name = std::move(name);
  s.source = std::move(where);
  return s;
}

Result<std::vector<KnownStation>> ParseE57(std::string_view bytes, std::string_view source) {
  VC_ASSIGN_OR_RETURN(const std::vector<E57Scan> scans, ReadE57Scans(bytes, source));
  if (scans.empty()) return InvalidArgumentError(std::string(source) + ": the E57 file holds no scans, so no stations");
  std::vector<KnownStation> out;
  for (size_t i = 0; i < scans.size(); ++i) {
    VC_ASSIGN_OR_RETURN(KnownStation s, PoseStation(scans[i].translation_m, scans[i].rotation, scans[i].name,
                                                    std::string(source) + ", scan " + std::to_string(i)));
    out.push_back(std::move(s));
  }
  return out;
}

Result<std::vector<KnownStation>> ParseGraph(std::string_view bytes, std::string_view source) {
  VC_ASSIGN_OR_RETURN(const ScanGraphData graph, ReadScanGraph(bytes, source));
  std::vector<KnownStation> out;
  for (size_t i = 0; i < graph.origins.size(); ++i) {
    VC_ASSIGN_OR_RETURN(KnownStation s, PoseStation(graph.origins[i], graph.origin_rotations[i], "",
                                                    std::string(source) + ", scan " + std::to_string(i)));
    out.push_back(std::move(s));
  }
  return out;
}

// The PCD header's "VIEWPOINT tx ty tz qw qx qy qz" as one station.
Result<std::vector<KnownStation>> ParsePcdViewpoint(std::string_view bytes, std::string_view source) {
  LineCursor lines(bytes);
  std::string_view line;
  while (lines.Next(&line)) {
    const std::vector<std::string_view> t = readers::SplitWhitespace(line);
    if (t.empty() || t[0].front() == '#') continue;
    if (t[0] == "DATA") break;
    if (t[0] != "VIEWPOINT") continue;
    const std::string where = std::string(source) + ":" + std::to_string(lines.line_number()) + ": ";
    if (t.size() != 8) {
      return InvalidArgumentError(where + "expected \"VIEWPOINT tx ty tz qw qx qy qz\", found " + Quote(line));
    }
    static const char* kNames[] = {"tx", "ty", "tz", "qw", "qx", "qy", "qz"};
    double v[7];
    for (int k = 0; k < 7; ++k) {
      VC_ASSIGN_OR_RETURN(v[k], FiniteField(t, k + 1, kNames[k], where));
    }
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (q.norm() < 1e-9) return InvalidArgumentError(where + "the VIEWPOINT quaternion is zero");
    VC_ASSIGN_OR_RETURN(KnownStation s,
                        PoseStation(Eigen::Vector3d(v[0], v[1], v[2]), q, "", where.substr(0, where.size() - 2)));
    return std::vector<KnownStation>{std::move(s)};
  }
  return InvalidArgumentError(std::string(source) + ": the PCD header has no VIEWPOINT line, so no station");
}

// Offset of the first byte no text file holds (NUL, or a control character other than tab, CR, LF,
// form feed), or npos.
size_t FirstBinaryByte(std::string_view bytes) {
  for (size_t i = 0; i < bytes.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(bytes[i]);
    if (c < 0x20 && c != '\t' && c != '\r' && c != '\n' && c != '\f') return i;
  }
  return std::string_view::npos;
}

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && Lower(s.substr(s.size() - suffix.size())) == suffix;
}

}  // namespace

Result<std::vector<KnownStation>> ParseStationFile(std::string_view bytes, std::string_view source) {
  if (LooksLikeE57(bytes)) return ParseE57(bytes, source);
  if (readers::LooksLikePcd(bytes)) return ParsePcdViewpoint(bytes, source);
  if (EndsWith(source, ".graph")) return ParseGraph(bytes, source);
  if (const size_t binary = FirstBinaryByte(bytes); binary != std::string_view::npos) {
    Result<std::vector<KnownStation>> graph = ParseGraph(bytes, source);
    if (graph.ok()) return graph;
    return InvalidArgumentError(std::string(source) + ": binary content (byte " + std::to_string(binary) +
                                ") that is not an E57 file, an OctoMap scan graph or a PCD file; expected a "
                                "stations CSV or one of those");
  }
  return ParseText(bytes, source);
}

Result<std::vector<KnownStation>> ReadStationFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError("cannot read the stations file " + path);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return ParseStationFile(bytes.str(), path);
}

}  // namespace vc
