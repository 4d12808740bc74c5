#include "vc/plan/keep_out.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <utility>

#include "format.h"

namespace vc {

namespace {

using planner::Num;

constexpr const char* kAxis[3] = {"x", "y", "z"};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// The text of a field for a message: at most 24 characters, non-printables as '?'.
std::string Quoted(std::string_view s) {
  std::string out = "'";
  for (size_t i = 0; i < s.size() && i < 24; ++i) {
    out += std::isprint(static_cast<unsigned char>(s[i])) ? s[i] : '?';
  }
  if (s.size() > 24) out += "...";
  return out + "'";
}

// Squared distance from (px, py) to the segment (ax, ay)-(bx, by).
double SegmentDistance2(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = ax + t * dx - px, ey = ay + t * dy - py;
  return ex * ex + ey * ey;
}

}  // namespace

KeepOutZone KeepOutBox(const WorldPoint& min, const WorldPoint& max) {
  KeepOutZone z;
  z.shape = KeepOutShape::kBox;
  z.min = min;
  z.max = max;
  return z;
}

KeepOutZone KeepOutPolygon(double z_min_m, double z_max_m, std::vector<double> xy_m) {
  KeepOutZone z;
  z.shape = KeepOutShape::kPolygon;
  z.polygon_xy_m = std::move(xy_m);
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  for (size_t i = 0; i + 1 < z.polygon_xy_m.size(); i += 2) {
    const double x = z.polygon_xy_m[i], y = z.polygon_xy_m[i + 1];
    if (i == 0) x0 = x1 = x, y0 = y1 = y;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  z.min = WorldPoint(x0, y0, z_min_m);
  z.max = WorldPoint(x1, y1, z_max_m);
  return z;
}

Status ValidateKeepOutZone(const KeepOutZone& zone, std::string_view name) {
  const std::string n(name);
  if (zone.shape == KeepOutShape::kBox) {
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(zone.min[a])) return InvalidArgumentError(n + ": box " + kAxis[a] + "min is not finite");
      if (!std::isfinite(zone.max[a])) return InvalidArgumentError(n + ": box " + kAxis[a] + "max is not finite");
      if (zone.min[a] > zone.max[a]) {
        return InvalidArgumentError(n + ": box " + kAxis[a] + "min (" + Num(zone.min[a]) + ") exceeds " + kAxis[a] +
                                    "max (" + Num(zone.max[a]) + ")");
      }
    }
    return Status::Ok();
  }
  if (zone.shape != KeepOutShape::kPolygon) return InvalidArgumentError(n + ": unknown zone shape");
  if (!std::isfinite(zone.min.z())) return InvalidArgumentError(n + ": polygon zmin is not finite");
  if (!std::isfinite(zone.max.z())) return InvalidArgumentError(n + ": polygon zmax is not finite");
  if (zone.min.z() > zone.max.z()) {
    return InvalidArgumentError(n + ": polygon zmin (" + Num(zone.min.z()) + ") exceeds zmax (" + Num(zone.max.z()) +
                                ")");
  }
  if (zone.polygon_xy_m.size() % 2 != 0) {
    return InvalidArgumentError(n + ": polygon has an odd number of vertex coordinates (" +
                                std::to_string(zone.polygon_xy_m.size()) + "); give x,y pairs");
  }
  if (zone.polygon_xy_m.size() < 6) {
    return InvalidArgumentError(n + ": polygon has " + std::to_string(zone.polygon_xy_m.size() / 2) +
                                " vertices; it needs at least 3");
  }
  for (size_t i = 0; i < zone.polygon_xy_m.size(); ++i) {
    if (!std::isfinite(zone.polygon_xy_m[i])) {
      return InvalidArgumentError(n + ": polygon vertex " + std::to_string(i / 2 + 1) + " " + (i % 2 ? "y" : "x") +
                                  " is not finite");
    }
  }
  return Status::Ok();
}

bool KeepOutContains(const KeepOutZone& zone, const WorldPoint& p) {
  for (int a = 0; a < 3; ++a) {
    if (!(p[a] >= zone.min[a] && p[a] <= zone.max[a])) return false;
  }
  if (zone.shape == KeepOutShape::kBox) return true;
  // Even-odd crossing test, with points on an edge counted as inside.
  const std::vector<double>& v = zone.polygon_xy_m;
  const size_t n = v.size() / 2;
  const double px = p.x(), py = p.y();
  bool inside = false;
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const double xi = v[2 * i], yi = v[2 * i + 1], xj = v[2 * j], yj = v[2 * j + 1];
    if (SegmentDistance2(px, py, xi, yi, xj, yj) <= 1e-18) return true;
    if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

int KeepOutZoneContaining(const std::vector<KeepOutZone>& zones, const WorldPoint& p) {
  for (size_t i = 0; i < zones.size(); ++i) {
    if (KeepOutContains(zones[i], p)) return static_cast<int>(i);
  }
  return -1;
}

namespace {

// fields[first...] as numbers; INVALID_ARGUMENT naming `where` and the first that is not one,
// counted from 1 in the line.
Result<std::vector<double>> Numbers(const std::vector<std::string_view>& fields, size_t first,
                                    const std::string& where) {
  std::vector<double> values(fields.size() - first);
  for (size_t i = first; i < fields.size(); ++i) {
    std::string_view f = fields[i];
    if (!f.empty() && f.front() == '+') f.remove_prefix(1);
    const auto result = std::from_chars(f.data(), f.data() + f.size(), values[i - first]);
    if (f.empty() || result.ec != std::errc() || result.ptr != f.data() + f.size()) {
      return InvalidArgumentError(where + ": field " + std::to_string(i + 1) + " " + Quoted(fields[i]) +
                                  " is not a number");
    }
  }
  return values;
}

bool IsNumber(std::string_view f) {
  if (!f.empty() && f.front() == '+') f.remove_prefix(1);
  double v = 0;
  const auto result = std::from_chars(f.data(), f.data() + f.size(), v);
  return !f.empty() && result.ec == std::errc() && result.ptr == f.data() + f.size();
}

// One zone from a line's fields: `box,...`, `polygon,...` or six numbers (a box without its kind).
Result<KeepOutZone> ParseZone(const std::vector<std::string_view>& fields, const std::string& where) {
  std::string kind(fields[0]);
  for (char& c : kind) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (IsNumber(fields[0])) {
    if (fields.size() != 6) {
      return InvalidArgumentError(where + ": a box without its kind has 6 numbers (xmin,ymin,zmin,xmax,ymax,zmax); " +
                                  "this line has " + std::to_string(fields.size()) + " fields");
    }
    VC_ASSIGN_OR_RETURN(const std::vector<double> v, Numbers(fields, 0, where));
    return KeepOutBox(WorldPoint(v[0], v[1], v[2]), WorldPoint(v[3], v[4], v[5]));
  }
  if (kind != "box" && kind != "polygon") {
    return InvalidArgumentError(where + ": unknown zone kind " + Quoted(fields[0]) +
                                "; use box, polygon, or six numbers for a box");
  }
  VC_ASSIGN_OR_RETURN(const std::vector<double> values, Numbers(fields, 1, where));
  if (kind == "box") {
    if (values.size() != 6) {
      return InvalidArgumentError(where + ": a box has 7 fields (box,xmin,ymin,zmin,xmax,ymax,zmax); this line has " +
                                  std::to_string(fields.size()));
    }
    return KeepOutBox(WorldPoint(values[0], values[1], values[2]), WorldPoint(values[3], values[4], values[5]));
  }
  if (values.size() < 2) {
    return InvalidArgumentError(where + ": a polygon needs zmin,zmax and at least 3 vertices " +
                                "(polygon,zmin,zmax,x1,y1,x2,y2,x3,y3,...)");
  }
  return KeepOutPolygon(values[0], values[1], std::vector<double>(values.begin() + 2, values.end()));
}

}  // namespace

Result<KeepOutFile> ParseKeepOutFile(std::string_view text, std::string_view source) {
  KeepOutFile file;
  size_t line_no = 0;
  bool first = true;
  while (!text.empty()) {
    const size_t eol = text.find('\n');
    std::string_view line = text.substr(0, eol);
    text.remove_prefix(eol == std::string_view::npos ? text.size() : eol + 1);
    ++line_no;
    const std::string where = std::string(source) + ":" + std::to_string(line_no);
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    line = Trim(line);
    if (line_no == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line = Trim(line.substr(3));  // a UTF-8 byte-order mark
    if (line.empty()) continue;
    std::vector<std::string_view> fields;
    for (size_t start = 0;;) {
      const size_t comma = line.find(',', start);
      fields.push_back(Trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    // A header: the first line, when none of its fields is a number or a zone kind.
    const bool header = first && std::none_of(fields.begin(), fields.end(), [](std::string_view f) {
                          std::string lower(f);
                          for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
                          return IsNumber(f) || lower == "box" || lower == "polygon";
                        });
    first = false;
    if (header) continue;
    VC_ASSIGN_OR_RETURN(KeepOutZone zone, ParseZone(fields, where));
    VC_RETURN_IF_ERROR(ValidateKeepOutZone(zone, where));
    file.zones.push_back(std::move(zone));
    file.lines.push_back(line_no);
  }
  return file;
}

Result<std::vector<KeepOutZone>> ParseKeepOutCsv(std::string_view text, std::string_view source) {
  VC_ASSIGN_OR_RETURN(KeepOutFile file, ParseKeepOutFile(text, source));
  return std::move(file.zones);
}

std::string KeepOutCsvLine(const KeepOutZone& zone) {
  std::string line = zone.shape == KeepOutShape::kBox ? "box" : "polygon";
  auto add = [&line](double v) {
    char buf[40];
    std::snprintf(buf, sizeof(buf), ",%.17g", v);
    line.append(buf);
  };
  if (zone.shape == KeepOutShape::kBox) {
    for (int a = 0; a < 3; ++a) add(zone.min[a]);
    for (int a = 0; a < 3; ++a) add(zone.max[a]);
    return line;
  }
  add(zone.min.z());
  add(zone.max.z());
  for (double v : zone.polygon_xy_m) add(v);
  return line;
}

}  // namespace vc
